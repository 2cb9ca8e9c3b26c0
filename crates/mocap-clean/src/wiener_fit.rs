//! Fitting a learned Wiener filter to the training takes of a data set and
//! writing it (`mocap clean fit-wiener`): one set of spectra, or a mixture
//! of them per kind of motion; or, with [`WienerFitOptions::rebase`], a
//! network's own Wiener filter made into a mixture and written under that
//! network.

use std::path::{Path, PathBuf};
use std::time::Instant;

use mocap_core::Motion;
use serde::{Deserialize, Serialize};

use crate::dataset::{
    list_bvh, load_takes, paths_in_split, DataDescription, Split, SplitFractions, Take,
};
use crate::model_file::CleanModel;
use crate::noise::RandomNoise;
use crate::wiener::{fit_mixture, WienerDescription, WienerFilter};
use crate::{CleanError, Result};

/// Options of `mocap clean fit-wiener`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WienerFitOptions {
    /// Folders or files of clean BVH takes; the training split is used.
    pub inputs: Vec<PathBuf>,
    pub out: PathBuf,
    pub split: SplitFractions,
    /// Frames per Fourier segment (32 measured best of 16-128 on Bandai,
    /// bench/results/clean.md).
    pub segment: usize,
    pub noise: RandomNoise,
    /// The level `N` is measured at (the noise is nearly linear in it).
    pub noise_sigma_deg: f32,
    pub seed: u64,
    /// Fit to at most this many training takes (quick runs and tests).
    pub max_train_takes: Option<usize>,
    /// Fit a mixture ([`fit_mixture`]): one component per content with at
    /// least this many training segments. `None`: one set of spectra.
    #[serde(default)]
    pub mixture_min_segments: Option<usize>,
    /// With a mixture: build it from the Wiener filter that this network
    /// model corrects (keeping its noise covariance, so the level the
    /// network reads means the same) and write that network, not
    /// retrained, with the mixture under it.
    #[serde(default)]
    pub rebase: Option<PathBuf>,
}

impl Default for WienerFitOptions {
    fn default() -> Self {
        WienerFitOptions {
            inputs: Vec::new(),
            out: PathBuf::from("clean-wiener.safetensors"),
            split: SplitFractions::default(),
            segment: 32,
            noise: RandomNoise::default(),
            noise_sigma_deg: 5.0,
            seed: 1,
            max_train_takes: None,
            mixture_min_segments: None,
            rebase: None,
        }
    }
}

/// What fitting wrote.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WienerFitReport {
    pub model: PathBuf,
    pub description: WienerDescription,
    pub data: DataDescription,
    pub seconds: f64,
}

/// Fits a filter to the training takes of `options.inputs` and writes it.
pub fn fit_wiener(options: &WienerFitOptions) -> Result<WienerFitReport> {
    let started = Instant::now();
    let paths = list_bvh(&options.inputs)?;
    let mut train_paths = paths_in_split(&paths, Split::Train, &options.split);
    if let Some(max) = options.max_train_takes {
        train_paths.truncate(max);
    }
    let takes = load_takes(&train_paths)?;
    if let Some(model_path) = &options.rebase {
        return rebase(options, model_path, &takes, &paths, started);
    }
    let motions: Vec<&Motion> = takes.iter().map(|t| &t.motion).collect();
    let mut filter = WienerFilter::fit(
        &motions,
        &options.noise,
        options.noise_sigma_deg,
        options.segment,
        options.seed,
    )?;
    if let Some(min_segments) = options.mixture_min_segments {
        filter = fit_mixture(&filter, &takes, min_segments)?;
    }
    let data = DataDescription {
        train_takes: filter.description.takes,
        train_frames: filter.description.frames,
        validation_takes: paths_in_split(&paths, Split::Validation, &options.split).len(),
        ..DataDescription::new(
            &options.inputs,
            &paths,
            options.split,
            filter.description.fps as f64,
        )
    };
    let data_json = serde_json::to_value(&data)
        .map_err(|e| CleanError::Invalid(format!("describing the data: {e}")))?;
    filter.save(&options.out, data_json)?;
    Ok(WienerFitReport {
        model: options.out.clone(),
        description: filter.description,
        data,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// [`fit_wiener`] with [`WienerFitOptions::rebase`].
fn rebase(
    options: &WienerFitOptions,
    model_path: &Path,
    takes: &[Take],
    paths: &[PathBuf],
    started: Instant,
) -> Result<WienerFitReport> {
    let min_segments = options.mixture_min_segments.ok_or_else(|| {
        CleanError::Invalid("rebasing a network needs a mixture to put under it".into())
    })?;
    let model = CleanModel::load(model_path, Default::default())?;
    let base = model.base_wiener().cloned().ok_or_else(|| {
        CleanError::Invalid(format!(
            "{}: this model corrects no Wiener filter",
            model_path.display()
        ))
    })?;
    let mixture = fit_mixture(&base, takes, min_segments)?;
    let description = mixture.description.clone();
    let model = model.with_base_wiener(mixture)?;
    let data = DataDescription {
        train_takes: description.takes,
        train_frames: description.frames,
        validation_takes: paths_in_split(paths, Split::Validation, &options.split).len(),
        ..DataDescription::new(
            &options.inputs,
            paths,
            options.split,
            description.fps as f64,
        )
    };
    let (mut header_data, training) = CleanModel::header_of(model_path)?;
    if let Some(record) = header_data.as_object_mut() {
        record.insert(
            "rebased".into(),
            serde_json::json!({
                "network_from": model_path.display().to_string(),
                "mixture_min_segments": min_segments,
                "mixture_data": data,
            }),
        );
    }
    model.save(&options.out, header_data, training)?;
    Ok(WienerFitReport {
        model: options.out.clone(),
        description,
        data,
        seconds: started.elapsed().as_secs_f64(),
    })
}
