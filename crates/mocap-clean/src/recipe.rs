//! A training recipe: the rarely changed knobs of [`TrainOptions`] (the
//! network's shape, the synthetic noise's spike settings, the other rigs
//! the noise is put on) in a TOML file
//! (`mocap clean train --recipe FILE.toml`). Every key is optional; a key
//! not given keeps the default, and a key the recipe does not know is
//! refused, naming the file and the key.
//!
//! ```toml
//! # The shipped network's shape (models/clean-recipe.toml).
//! width = 64
//! window = 32
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::model::DenoiserConfig;
use crate::training::TrainOptions;
use crate::{CleanError, Result};

/// The recipe file's keys (see the module docs).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainRecipe {
    /// Start from the report's large network (for a GPU) instead of the
    /// small default ([`DenoiserConfig::large`]); the sizes below override it.
    pub large: Option<bool>,
    /// Channels of the first level.
    pub width: Option<usize>,
    /// Times the network halves the time axis.
    pub levels: Option<usize>,
    /// Residual blocks per level.
    pub blocks: Option<usize>,
    /// Window length in frames (a multiple of `2^levels`).
    pub window: Option<usize>,
    /// Probability that a training window gets spikes.
    pub spike_probability: Option<f32>,
    /// At most this many simultaneous spikes.
    pub max_spikes: Option<usize>,
    /// Standard deviation of a spike's duration in frames.
    pub spike_sigma: Option<f32>,
    /// Motion files whose rigs the noise is also put on
    /// ([`TrainOptions::noise_rigs`]), relative to the recipe's folder.
    pub noise_rigs: Option<Vec<PathBuf>>,
}

impl TrainRecipe {
    /// Reads a recipe file; an error names the file (and, for a key the
    /// recipe does not know, the key).
    pub fn load(path: &Path) -> Result<TrainRecipe> {
        let text = std::fs::read_to_string(path).map_err(|e| mocap_core::Error::io(path, e))?;
        let mut recipe = Self::parse(&text)
            .map_err(|e| CleanError::Invalid(format!("{}: {e}", path.display())))?;
        let folder = path.parent().unwrap_or(Path::new(""));
        for rig in recipe.noise_rigs.iter_mut().flatten() {
            *rig = folder.join(&*rig);
        }
        Ok(recipe)
    }

    /// Parses a recipe's TOML text.
    pub fn parse(text: &str) -> std::result::Result<TrainRecipe, String> {
        toml::from_str(text).map_err(|e| e.message().to_string())
    }

    /// Sets what the recipe gives in `options`.
    pub fn apply_to(&self, options: &mut TrainOptions) {
        if self.large == Some(true) {
            options.network = DenoiserConfig::large(0);
        }
        let network = &mut options.network;
        set(&mut network.width, self.width);
        set(&mut network.levels, self.levels);
        set(&mut network.blocks, self.blocks);
        set(&mut network.window, self.window);
        set(&mut options.noise.spike_probability, self.spike_probability);
        if let Some(spikes) = options.noise.spikes.as_mut() {
            set(&mut spikes.max_spikes, self.max_spikes);
            set(&mut spikes.duration_sigma_frames, self.spike_sigma);
        }
        set(&mut options.noise_rigs, self.noise_rigs.clone());
    }
}

fn set<T>(slot: &mut T, value: Option<T>) {
    if let Some(v) = value {
        *slot = v;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_recipe_sets_what_it_gives_and_keeps_the_rest() {
        let recipe = TrainRecipe::parse("width = 64\nwindow = 32\nmax_spikes = 2\n").unwrap();
        let mut options = TrainOptions::default();
        recipe.apply_to(&mut options);
        let default = TrainOptions::default();
        assert_eq!(options.network.width, 64);
        assert_eq!(options.network.window, 32);
        assert_eq!(options.network.levels, default.network.levels);
        assert_eq!(options.noise.spikes.unwrap().max_spikes, 2);
        assert_eq!(
            options.noise.spike_probability,
            default.noise.spike_probability
        );
        let mut large = TrainOptions::default();
        TrainRecipe::parse("large = true\nwindow = 32")
            .unwrap()
            .apply_to(&mut large);
        assert_eq!(
            large.network,
            DenoiserConfig {
                window: 32,
                ..DenoiserConfig::large(0)
            }
        );
    }

    #[test]
    fn the_shipped_network_recipe_reads() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/clean-recipe.toml");
        let recipe = TrainRecipe::load(&path).unwrap();
        assert_eq!((recipe.width, recipe.window), (Some(64), Some(32)));
    }

    #[test]
    fn an_unknown_key_is_refused_naming_the_file_and_the_key() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("mine.toml");
        std::fs::write(&path, "width = 64\nwidht = 32\n").unwrap();
        let error = TrainRecipe::load(&path).unwrap_err().to_string();
        assert!(
            error.contains("mine.toml") && error.contains("widht"),
            "{error}"
        );
    }
}
