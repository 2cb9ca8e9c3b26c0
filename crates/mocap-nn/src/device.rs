//! Device choice and seeding.
//!
//! Burn 0.22 picks the backend at run time from a [`Device`] value. The CPU
//! device is burn's `flex` backend (pure Rust, multi-threaded, fast
//! convolutions); CUDA is compiled in only with this crate's `cuda` feature,
//! which needs the NVIDIA driver at run time but no `nvcc` at build time.

use std::fmt;
use std::str::FromStr;

use burn::tensor::Device;
use serde::{Deserialize, Serialize};

use crate::{NnError, Result};

/// Where the network runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum DeviceChoice {
    /// The CPU, through burn's `flex` backend.
    #[default]
    Cpu,
    /// The NVIDIA GPU with this index (needs the `cuda` feature).
    Cuda(usize),
}

impl DeviceChoice {
    /// Whether this build can use the device (CUDA needs the `cuda` feature).
    pub fn is_compiled_in(self) -> bool {
        match self {
            DeviceChoice::Cpu => true,
            DeviceChoice::Cuda(_) => cfg!(feature = "cuda"),
        }
    }

    /// The burn device for inference (no gradients).
    pub fn device(self) -> Result<Device> {
        match self {
            DeviceChoice::Cpu => Ok(Device::flex()),
            #[cfg(feature = "cuda")]
            DeviceChoice::Cuda(index) => Ok(Device::cuda(index)),
            #[cfg(not(feature = "cuda"))]
            DeviceChoice::Cuda(_) => Err(NnError::Device(
                "this build has no CUDA support: rebuild with `--features cuda`".into(),
            )),
        }
    }

    /// The burn device for training: the same device with automatic
    /// differentiation enabled.
    pub fn training_device(self) -> Result<Device> {
        Ok(self.device()?.autodiff())
    }
}

impl fmt::Display for DeviceChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DeviceChoice::Cpu => write!(f, "cpu"),
            DeviceChoice::Cuda(i) => write!(f, "cuda:{i}"),
        }
    }
}

impl FromStr for DeviceChoice {
    type Err = NnError;

    /// Parses `cpu`, `cuda` (GPU 0) or `cuda:N`.
    fn from_str(s: &str) -> Result<Self> {
        let s = s.trim().to_ascii_lowercase();
        match s.as_str() {
            "cpu" | "flex" => Ok(DeviceChoice::Cpu),
            "cuda" | "gpu" => Ok(DeviceChoice::Cuda(0)),
            _ => match s.strip_prefix("cuda:").map(str::parse::<usize>) {
                Some(Ok(i)) => Ok(DeviceChoice::Cuda(i)),
                _ => Err(NnError::Device(format!(
                    "unknown device `{s}`: expected `cpu`, `cuda` or `cuda:N`"
                ))),
            },
        }
    }
}

/// Seeds burn's random generator on `device` (weight initialisation and
/// random tensors). Data sampling uses its own seeded generators.
pub fn seed_device(device: &Device, seed: u64) {
    device.seed(seed);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_device_names() {
        assert_eq!("cpu".parse::<DeviceChoice>().unwrap(), DeviceChoice::Cpu);
        assert_eq!(
            "CUDA:1".parse::<DeviceChoice>().unwrap(),
            DeviceChoice::Cuda(1)
        );
        assert_eq!(
            "cuda".parse::<DeviceChoice>().unwrap(),
            DeviceChoice::Cuda(0)
        );
        assert!("tpu".parse::<DeviceChoice>().is_err());
        assert_eq!(DeviceChoice::Cuda(2).to_string(), "cuda:2");
    }

    #[test]
    fn cpu_device_runs() {
        let device = DeviceChoice::Cpu.device().unwrap();
        let t = burn::tensor::Tensor::<1>::from_floats([1.0, 2.0], &device);
        let sum: f32 = t.sum().into_scalar();
        assert_eq!(sum, 3.0);
    }
}
