//! Training and evaluation data: clean BVH takes, split by take into
//! training, validation and test sets (windows of one take never cross
//! splits), and windows of frames cut from them.

use std::path::{Path, PathBuf};

use mocap_core::io::bvh::read_bvh;
use mocap_core::Motion;
use serde::{Deserialize, Serialize};

use crate::Result;

/// Which set a take belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Split {
    Train,
    Validation,
    Test,
}

/// Fractions of takes held out for validation and test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SplitFractions {
    pub validation: f64,
    pub test: f64,
}

impl Default for SplitFractions {
    fn default() -> Self {
        SplitFractions {
            validation: 0.1,
            test: 0.1,
        }
    }
}

/// FNV-1a with a final mix: a fixed hash (unlike the standard library's, it does not change
/// between Rust versions), so splits are the same on every machine.
fn fnv1a(text: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    // FNV's high bits mix poorly for names that differ in their last
    // characters; finish with the splitmix64 mixer.
    h ^= h >> 30;
    h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^ (h >> 31)
}

/// The split of a take, decided by a hash of its file name (without folder
/// or extension), so adding takes never moves existing ones.
pub fn split_of(take_name: &str, fractions: &SplitFractions) -> Split {
    let u = (fnv1a(take_name) >> 11) as f64 / (1u64 << 53) as f64;
    if u < fractions.test {
        Split::Test
    } else if u < fractions.test + fractions.validation {
        Split::Validation
    } else {
        Split::Train
    }
}

/// The BVH files among `inputs` (files, or folders searched recursively),
/// sorted by path.
pub fn list_bvh(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    Ok(mocap_core::io::find_bvh_files(inputs)?)
}

/// A clean take.
#[derive(Debug, Clone)]
pub struct Take {
    /// File name without folder or extension.
    pub name: String,
    pub path: PathBuf,
    pub motion: Motion,
}

/// The take name of a path (file stem).
pub fn take_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Reads takes.
pub fn load_takes(paths: &[PathBuf]) -> Result<Vec<Take>> {
    paths
        .iter()
        .map(|p| {
            Ok(Take {
                name: take_name(p),
                path: p.clone(),
                motion: read_bvh(p)?,
            })
        })
        .collect()
}

/// The paths of `split` among `paths`.
pub fn paths_in_split(paths: &[PathBuf], split: Split, fractions: &SplitFractions) -> Vec<PathBuf> {
    paths
        .iter()
        .filter(|p| split_of(&take_name(p), fractions) == split)
        .cloned()
        .collect()
}

/// Frames `start..start + frames` of `motion` as a motion of its own.
pub fn window(motion: &Motion, start: usize, frames: usize) -> Motion {
    let c = motion.skeleton().channel_count();
    let values = motion.values()[start * c..(start + frames) * c].to_vec();
    Motion::new(
        motion.skeleton().clone(),
        motion.frame_time(),
        frames,
        values,
    )
    .expect("a window of a valid motion is valid")
}

/// `frames` frames of `motion` from `start` on, starting over at its first
/// frame when it ends: spike donors as long as the motion they spike, taken
/// from a shorter take.
pub fn looped_window(motion: &Motion, start: usize, frames: usize) -> Motion {
    let n = motion.frame_count().max(1);
    let mut values = Vec::with_capacity(frames * motion.skeleton().channel_count());
    for f in 0..frames {
        values.extend_from_slice(motion.frame((start + f) % n));
    }
    Motion::new(
        motion.skeleton().clone(),
        motion.frame_time(),
        frames,
        values,
    )
    .expect("frames of a valid motion make a valid motion")
}

/// What a model was trained on, stored in its checkpoint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataDescription {
    /// The folders or files given.
    pub inputs: Vec<String>,
    pub split: SplitFractions,
    pub train_takes: usize,
    pub train_frames: usize,
    pub validation_takes: usize,
    pub validation_frames: usize,
    pub test_takes: usize,
    pub fps: f64,
    /// Names of the validation and test takes (held out).
    pub held_out: Vec<String>,
}

impl DataDescription {
    /// The description of data `inputs` listing `paths`, split by `split`:
    /// the test and held-out takes filled in, the training and validation
    /// counts zero (the caller knows what it loaded).
    pub fn new(inputs: &[PathBuf], paths: &[PathBuf], split: SplitFractions, fps: f64) -> Self {
        DataDescription {
            inputs: inputs.iter().map(|p| p.display().to_string()).collect(),
            split,
            train_takes: 0,
            train_frames: 0,
            validation_takes: 0,
            validation_frames: 0,
            test_takes: paths_in_split(paths, Split::Test, &split).len(),
            fps,
            held_out: paths
                .iter()
                .map(|p| take_name(p))
                .filter(|n| split_of(n, &split) != Split::Train)
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_are_stable_and_roughly_proportional() {
        let f = SplitFractions::default();
        let names: Vec<String> = (0..2000).map(|i| format!("take_{i:04}")).collect();
        let test = names
            .iter()
            .filter(|n| split_of(n, &f) == Split::Test)
            .count();
        let valid = names
            .iter()
            .filter(|n| split_of(n, &f) == Split::Validation)
            .count();
        assert!((150..250).contains(&test), "{test}");
        assert!((150..250).contains(&valid), "{valid}");
        assert_eq!(split_of("take_0001", &f), split_of("take_0001", &f));
    }

    #[test]
    fn windows_cut_frames() {
        let m = crate::test_support::synthetic_motion(30, 4);
        let w = window(&m, 10, 5);
        assert_eq!(w.frame_count(), 5);
        assert_eq!(w.frame(0), m.frame(10));
        assert_eq!(w.frame(4), m.frame(14));
    }

    #[test]
    fn looped_windows_start_over() {
        let m = crate::test_support::synthetic_motion(30, 4);
        let w = looped_window(&m, 25, 10);
        assert_eq!(w.frame_count(), 10);
        assert_eq!(w.frame(4), m.frame(29));
        assert_eq!(w.frame(5), m.frame(0));
        assert_eq!(w.frame(9), m.frame(4));
    }
}
