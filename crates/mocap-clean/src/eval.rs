//! Evaluation of every method (noisy input, tuned classical filters, trained
//! models) on clean takes with synthetic noise.
//!
//! Metrics, averaged over frames and joints, against the clean take:
//! - rotation error: geodesic angle between the local joint rotations, in
//!   degrees, over every joint with rotations and over the joints of body
//!   parts alone;
//! - position error: mean per-joint position error after forward kinematics
//!   (file units; centimetres for the Bandai Namco data);
//! - acceleration error: mean norm of the difference of joint accelerations
//!   (second finite differences of positions, units per frame^2).
//!
//! The noise conditions: synthetic ([`CONDITIONS`]), and with
//! [`EvalOptions::fused`] the capture stage's ([`FUSED`]), where the clean
//! take is the truth on the fused take's fitted skeleton.
//!
//! Classical filters are tuned per noise condition on validation takes (grid
//! search for the lowest rotation error) and then run on the evaluation
//! takes with those settings.
//!
//! With [`EvalOptions::despike`], every method is also preceded by spike
//! finding ([`crate::despike`]; rows `despike + METHOD`, and `despike` alone),
//! as `mocap clean apply --despike` does: spikes are looked for in the noisy input
//! and bridged, then the method runs. Its settings (threshold, span, global
//! or local rotations) are tuned per method the same way, on the spike
//! condition, by running the whole pipeline.

use std::path::PathBuf;
use std::rc::Rc;

use mocap_core::rotation::angle_between;
use mocap_core::{metrics, Motion};
use mocap_nn::device::DeviceChoice;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::dataset::{
    list_bvh, load_takes, looped_window, paths_in_split, Split, SplitFractions, Take,
};
use crate::despike::{remove_spikes, DespikeOptions};
use crate::filters::{filter_motion, Filter};
use crate::metrics::{body_part_joints, position_errors, rotation_error_deg, rotation_errors_deg};
use crate::model_file::{CleanModel, ModelFile};
use crate::noise::{add_random_noise, add_spike_noise, add_spikes, RandomNoise, Spike, SpikeNoise};
use crate::{CleanError, Result};

/// Whether `motion` is long enough for an acceleration error.
fn has_acceleration(motion: &Motion) -> bool {
    motion.frame_count() >= metrics::ACCELERATION_MIN_FRAMES
}

/// The metrics of one method under one noise condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodMetrics {
    pub method: String,
    pub condition: String,
    pub rotation_error_deg: f64,
    /// The rotation error over the joints of body parts alone: the joints
    /// a model cleans on a rig not its own (the others pass through it).
    #[serde(default)]
    pub body_rotation_error_deg: f64,
    pub position_error: f64,
    pub acceleration_error: f64,
}

/// A model to evaluate: a label and a file (`None`: the shipped default).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ModelEntry {
    pub label: String,
    pub path: Option<PathBuf>,
}

impl std::str::FromStr for ModelEntry {
    type Err = String;

    /// `LABEL=FILE`, or `FILE` (labelled by itself).
    fn from_str(text: &str) -> std::result::Result<Self, Self::Err> {
        let (label, path) = text.split_once('=').unwrap_or((text, text));
        if path.is_empty() {
            return Err(format!("{text:?}: expected LABEL=FILE or FILE"));
        }
        Ok(ModelEntry {
            label: label.into(),
            path: Some(PathBuf::from(path)),
        })
    }
}

/// Spike lengths of the spike-survival study written as `2,4,8` (frames),
/// or `none` for no study.
pub fn parse_spike_lengths(text: &str) -> std::result::Result<Vec<usize>, String> {
    if text.trim() == "none" {
        return Ok(Vec::new());
    }
    text.split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| match s.trim().parse::<usize>() {
            Ok(0) => Err(format!("{text:?}: a spike lasts at least one frame")),
            Ok(n) => Ok(n),
            Err(_) => Err(format!(
                "{text:?}: expected frame counts like 2,4,8 or none"
            )),
        })
        .collect()
}

/// Options of `mocap clean eval`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalOptions {
    /// Folders or files of clean BVH takes.
    pub inputs: Vec<PathBuf>,
    /// Evaluate only the takes of the test split (use when `inputs` is the
    /// training data); otherwise every take is evaluated.
    pub test_split_only: bool,
    pub split: SplitFractions,
    pub models: Vec<ModelEntry>,
    /// Include the classical filters, tuned on validation takes.
    pub filters: bool,
    /// Validation takes used to tune the filters (from `inputs`' validation
    /// split, or the first takes when `test_split_only` is off).
    pub tune_takes: usize,
    /// Evaluate at most this many takes.
    pub max_takes: Option<usize>,
    pub random: RandomNoise,
    pub spikes: SpikeNoise,
    /// Spike lengths (frames) of the spike-survival study; empty to skip.
    pub spike_lengths: Vec<usize>,
    /// Also follow every method by spike finding, tuned on the validation
    /// takes (see the module docs).
    #[serde(default)]
    pub despike: bool,
    /// Also the condition [`FUSED`]: each take watched by three simulated
    /// Kinect sensors, fused and fitted as the capture stage does it, against
    /// its truth on the same fitted skeleton (`mocap_fuse::simulated_fused_take`).
    #[serde(default)]
    pub fused: bool,
    pub seed: u64,
    pub device: DeviceChoice,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            inputs: Vec::new(),
            test_split_only: true,
            split: SplitFractions::default(),
            models: vec![ModelEntry {
                label: "default model".into(),
                path: None,
            }],
            filters: true,
            tune_takes: 20,
            max_takes: None,
            random: RandomNoise::default(),
            spikes: SpikeNoise::default(),
            spike_lengths: vec![2, 4, 8, 16, 32, 64],
            despike: false,
            fused: false,
            seed: 7,
            device: DeviceChoice::Cpu,
        }
    }
}

/// The filter chosen for a condition and family.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TunedFilter {
    pub condition: String,
    pub filter: Filter,
    /// Mean rotation error on the tuning takes.
    pub tuning_rotation_error_deg: f64,
}

/// How much of a spike of a given length survives each method.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SpikeSurvival {
    pub length: usize,
    pub method: String,
    /// Rotation error (degrees) on the spiked joints and frames, before.
    pub noisy_error_deg: f64,
    /// The same after the method.
    pub residual_error_deg: f64,
}

/// What `mocap clean eval` reports.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalReport {
    pub takes: usize,
    pub frames: usize,
    /// One entry per method and condition.
    pub entries: Vec<MethodMetrics>,
    pub tuned_filters: Vec<TunedFilter>,
    /// The spike finding settings chosen on the validation takes for each
    /// method (`despike + METHOD`), with the mean rotation error they gave
    /// there (spike condition), when asked.
    #[serde(default)]
    pub tuned_despike: Vec<(String, DespikeOptions, f64)>,
    pub spike_survival: Vec<SpikeSurvival>,
    /// What the figures above do not say on their own: methods left out,
    /// tuning on the evaluated takes, conditions without spikes.
    #[serde(default)]
    pub notes: Vec<String>,
}

/// The noise conditions evaluated: random noise alone, spikes on top of
/// random noise, and spikes alone (the "spike noise" on its own:
/// what a method does to a spike without random noise hiding its ends).
pub const CONDITIONS: [&str; 3] = ["random", "spikes", "spikes only"];

/// The condition of [`EvalOptions::fused`], after [`CONDITIONS`]: the noise
/// the capture stage makes.
pub const FUSED: &str = "fused";

/// The conditions `options` asks for: [`CONDITIONS`], then [`FUSED`].
fn conditions(options: &EvalOptions) -> Vec<&'static str> {
    let mut out = CONDITIONS.to_vec();
    if options.fused {
        out.push(FUSED);
    }
    out
}

/// Take `i` of `takes` as the capture stage makes it: (truth, fused) on one
/// fitted skeleton (see [`EvalOptions::fused`]), the sensors seeded by the
/// evaluation's seed and the take.
fn fused_pair(takes: &[Take], i: usize, options: &EvalOptions) -> Result<(Motion, Motion)> {
    let simulation = mocap_fuse::SimulationOptions {
        sensors: 3,
        seed: options.seed ^ (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15),
        ..Default::default()
    };
    let (fused, truth) = mocap_fuse::simulated_fused_take(&takes[i].motion, &simulation)
        .map_err(|e| CleanError::Invalid(format!("{}: {e}", takes[i].path.display())))?;
    Ok((truth, fused))
}

/// Every take of `takes` as (clean, noisy) under condition `condition` (an
/// index into [`conditions`]).
fn pairs(takes: &[Take], condition: usize, options: &EvalOptions) -> Result<Vec<(Motion, Motion)>> {
    (0..takes.len())
        .map(|i| match CONDITIONS.get(condition) {
            Some(_) => Ok((
                takes[i].motion.clone(),
                make_noisy(takes, i, condition, options)?,
            )),
            None => fused_pair(takes, i, options),
        })
        .collect()
}

/// Index of the spikes-only condition in [`CONDITIONS`].
const SPIKES_ONLY: usize = 2;

/// A deterministic generator for (take, condition).
fn rng_for(seed: u64, take: usize, condition: usize) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(
        seed ^ ((take as u64) << 8 | condition as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15),
    )
}

/// The noisy copy of take `i` of `takes` under `condition` (an index into
/// [`CONDITIONS`]): random noise alone, spikes (from other takes) on top of
/// random noise, or spikes alone.
fn make_noisy(takes: &[Take], i: usize, condition: usize, options: &EvalOptions) -> Result<Motion> {
    Ok(noisy_take(takes, i, condition, options)?.0)
}

/// The evaluation's noisy copy of take `i` of `takes` under `condition` (an
/// index into [`CONDITIONS`]), with the spikes it was given (none for random
/// noise alone); seeded by [`EvalOptions::seed`], the take and the
/// condition, so that studies can draw the evaluation's noise again.
pub fn noisy_take(
    takes: &[Take],
    i: usize,
    condition: usize,
    options: &EvalOptions,
) -> Result<(Motion, Vec<Spike>)> {
    let mut rng = rng_for(options.seed, i, condition);
    let clean = &takes[i].motion;
    let noisy = if condition == SPIKES_ONLY {
        clean.clone()
    } else {
        add_random_noise(clean, &options.random, &mut rng).0
    };
    if condition == 0 {
        return Ok((noisy, Vec::new()));
    }
    let donors = donor_windows(takes, i, clean.frame_count(), &mut rng);
    let refs: Vec<&Motion> = donors.iter().collect();
    if refs.is_empty() {
        return Ok((noisy, Vec::new()));
    }
    add_spike_noise(&noisy, &refs, &options.spikes, &mut rng)
}

/// Donor motions as long as `frames` from other takes (looped when shorter).
fn donor_windows(takes: &[Take], skip: usize, frames: usize, rng: &mut ChaCha8Rng) -> Vec<Motion> {
    let mut out = Vec::new();
    if takes.len() < 2 {
        return out;
    }
    for _ in 0..3 {
        let mut d = rng.random_range(0..takes.len());
        if d == skip {
            d = (d + 1) % takes.len();
        }
        let m = &takes[d].motion;
        if m.skeleton().joint_count() != takes[skip].motion.skeleton().joint_count()
            || m.frame_count() == 0
        {
            continue;
        }
        out.push(looped_window(m, 0, frames));
    }
    out
}

/// The settings of filter `family` with the lowest mean rotation error on
/// `pairs` (clean, noisy) of `condition`.
fn tune(pairs: &[(Motion, Motion)], condition: &str, family: &str) -> Result<TunedFilter> {
    let mut best: Option<(f64, Filter)> = None;
    for filter in Filter::tuning_grid(family) {
        let mut sum = 0.0;
        for (clean, noisy) in pairs {
            sum += rotation_error_deg(clean, &filter_motion(noisy, &filter)?);
        }
        let mean = sum / pairs.len().max(1) as f64;
        if best.is_none_or(|(b, _)| mean < b) {
            best = Some((mean, filter));
        }
    }
    let (error, filter) =
        best.ok_or_else(|| CleanError::Invalid(format!("no settings for `{family}`")))?;
    Ok(TunedFilter {
        condition: condition.into(),
        filter,
        tuning_rotation_error_deg: error,
    })
}

/// Spike-finding thresholds and spans tried when tuning (with global and
/// local rotations).
const DESPIKE_THRESHOLDS: [f32; 6] = [2.0, 2.5, 3.0, 4.0, 5.0, 6.0];
const DESPIKE_SPANS: [usize; 3] = [1, 2, 3];

/// The spike-finding settings that give the lowest mean rotation error
/// when the spikes are bridged in the tuning takes (spike condition) and
/// `cleaner` runs on them (`None`: bridging alone).
fn tune_despike(
    takes: &[Take],
    cleaner: Option<&Cleaner>,
    options: &EvalOptions,
) -> Result<(DespikeOptions, f64)> {
    let noisy: Vec<Motion> = (0..takes.len())
        .map(|i| make_noisy(takes, i, 1, options))
        .collect::<Result<_>>()?;
    let mut best: Option<(f64, DespikeOptions)> = None;
    for span in DESPIKE_SPANS {
        for threshold in DESPIKE_THRESHOLDS {
            for global in [true, false] {
                let despike = DespikeOptions {
                    threshold,
                    span,
                    global,
                    ..DespikeOptions::default()
                };
                let mut sum = 0.0;
                for (take, m) in takes.iter().zip(&noisy) {
                    let bridged = remove_spikes(m, &despike).0;
                    let out = match cleaner {
                        Some(c) => c.run(&bridged)?,
                        None => bridged,
                    };
                    sum += rotation_error_deg(&take.motion, &out);
                }
                let mean = sum / takes.len().max(1) as f64;
                if best.is_none_or(|(b, _)| mean < b) {
                    best = Some((mean, despike));
                }
            }
        }
    }
    let (error, despike) = best.expect("settings to try");
    Ok((despike, error))
}

#[derive(Clone)]
enum Cleaner {
    Filter(Filter),
    /// A network or a Wiener filter.
    Model(Rc<ModelFile>),
}

impl Cleaner {
    fn run(&self, noisy: &Motion) -> Result<Motion> {
        match self {
            Cleaner::Filter(f) => filter_motion(noisy, f),
            Cleaner::Model(m) => Ok(m.clean(noisy, None)?.0),
        }
    }
}

/// The cleaners of a condition: its tuned filters, then the models.
fn cleaners_for(
    filters: &[(String, Cleaner)],
    models: &[(String, Cleaner)],
) -> Vec<(String, Cleaner)> {
    filters.iter().chain(models).cloned().collect()
}

/// A method of the evaluation: a cleaner's output (`None`: the noisy input
/// itself), followed by spike finding or not.
struct Method {
    label: String,
    cleaner: Option<usize>,
    despike: Option<DespikeOptions>,
}

/// Runs the methods on one noisy take and hands each output to `take`:
/// every cleaner runs once, the spike-finding rows reuse its output.
fn run_methods(
    cleaners: &[&(String, Cleaner)],
    methods: &[Method],
    noisy: &Motion,
    mut take: impl FnMut(usize, &Motion),
) -> Result<()> {
    let outputs: Vec<Motion> = cleaners
        .iter()
        .map(|(_, c)| c.run(noisy))
        .collect::<Result<_>>()?;
    for (k, method) in methods.iter().enumerate() {
        match (&method.despike, method.cleaner) {
            // As `mocap clean apply --despike` does: spikes bridged first.
            (Some(d), cleaner) => {
                let bridged = remove_spikes(noisy, d).0;
                match cleaner {
                    Some(i) => take(k, &cleaners[i].1.run(&bridged)?),
                    None => take(k, &bridged),
                }
            }
            (None, cleaner) => take(k, cleaner.map_or(noisy, |i| &outputs[i])),
        }
    }
    Ok(())
}

/// The methods: `cleaners` as they are, then (when spike finding is asked)
/// spike finding alone and before every cleaner, with settings tuned per
/// method on `tune_takes` (remembered by label in `tuned`).
fn methods(
    cleaners: &[&(String, Cleaner)],
    options: &EvalOptions,
    tune_takes: &[Take],
    tuned: &mut Vec<(String, DespikeOptions, f64)>,
) -> Result<Vec<Method>> {
    let mut out: Vec<Method> = cleaners
        .iter()
        .enumerate()
        .map(|(i, (label, _))| Method {
            label: label.clone(),
            cleaner: Some(i),
            despike: None,
        })
        .collect();
    if !options.despike {
        return Ok(out);
    }
    let with_despike = std::iter::once(("despike".to_string(), None)).chain(
        cleaners
            .iter()
            .enumerate()
            .map(|(i, (label, _))| (format!("despike + {label}"), Some(i))),
    );
    for (label, cleaner) in with_despike {
        let despike = match tuned.iter().find(|(l, _, _)| *l == label) {
            Some((_, d, _)) => *d,
            None => {
                let (d, error) =
                    tune_despike(tune_takes, cleaner.map(|i| &cleaners[i].1), options)?;
                tuned.push((label.clone(), d, error));
                d
            }
        };
        out.push(Method {
            label,
            cleaner,
            despike: Some(despike),
        });
    }
    Ok(out)
}

/// An error naming the first of `takes` that `model` (`entry`) cannot
/// clean, said before any work: it would otherwise fail on that take,
/// unnamed, after minutes of tuning.
fn refuse_other_rigs(model: &ModelFile, entry: &ModelEntry, takes: &[Take]) -> Result<()> {
    for take in takes {
        model.check_rig(&take.motion).map_err(|e| {
            CleanError::Invalid(format!(
                "{}: the model \"{}\" cannot clean this take: {e}. To evaluate the filters on \
                 takes of other rigs, {}",
                take.path.display(),
                entry.label,
                if entry.path.is_none() {
                    "leave the shipped model out with --no-default-model"
                } else {
                    "leave this --model out"
                }
            ))
        })?;
    }
    Ok(())
}

/// Runs the evaluation.
pub fn evaluate(options: &EvalOptions) -> Result<EvalReport> {
    if options.models.is_empty() && !options.filters {
        return Err(CleanError::Invalid(
            "nothing to evaluate: no model and no filters (--no-default-model and --no-filters \
             with no --model)"
                .into(),
        ));
    }
    let paths = list_bvh(&options.inputs)?;
    let (mut eval_paths, tune_paths) = if options.test_split_only {
        (
            paths_in_split(&paths, Split::Test, &options.split),
            paths_in_split(&paths, Split::Validation, &options.split),
        )
    } else {
        (paths.clone(), paths.clone())
    };
    if let Some(max) = options.max_takes {
        eval_paths.truncate(max);
    }
    if eval_paths.is_empty() {
        return Err(CleanError::Invalid(
            "no takes to evaluate (is the test split empty?)".into(),
        ));
    }
    let takes = load_takes(&eval_paths)?;
    let mut models = Vec::new();
    for m in &options.models {
        let model = match &m.path {
            Some(p) => ModelFile::load(p, options.device)?,
            None => ModelFile::Network(Box::new(CleanModel::load_default(options.device)?)),
        };
        refuse_other_rigs(&model, m, &takes)?;
        models.push((m.label.clone(), Cleaner::Model(Rc::new(model))));
    }
    let mut tuned_filters = Vec::new();
    let mut per_condition: Vec<Vec<(String, Cleaner)>> = Vec::new();
    let tune_takes = if options.filters || options.despike {
        load_takes(&tune_paths[..options.tune_takes.min(tune_paths.len())])?
    } else {
        Vec::new()
    };
    if options.despike {
        // Spike finding is tuned per model on these takes too.
        for (m, (_, cleaner)) in options.models.iter().zip(&models) {
            if let Cleaner::Model(model) = cleaner {
                refuse_other_rigs(model, m, &tune_takes)?;
            }
        }
    }
    let mut notes = Vec::new();
    if options.filters && tune_takes.len() < 2 {
        notes.push(format!(
            "the classical filters are left out: tuning them needs at least two validation \
             takes, and the validation split of these {} takes holds {} (give more takes, or \
             --all-takes to tune on the evaluated takes themselves)",
            paths.len(),
            tune_takes.len()
        ));
    } else if !options.test_split_only && (options.filters || options.despike) {
        notes.push(format!(
            "the filters{} were tuned on the first {} of the evaluated takes themselves \
             (--all-takes): their figures are optimistic next to those of a model on takes it \
             never saw",
            if options.despike {
                " and spike finding"
            } else {
                ""
            },
            tune_takes.len()
        ));
    }
    let short: Vec<_> = takes
        .iter()
        .filter(|t| !has_acceleration(&t.motion))
        .collect();
    if !short.is_empty() {
        notes.push(format!(
            "{} take(s) of under {min} frames ({}) are left out of the acceleration errors, \
             which need {min}",
            short.len(),
            short
                .iter()
                .map(|t| t.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            min = metrics::ACCELERATION_MIN_FRAMES,
        ));
    }
    if takes.len() < 2 {
        notes.push(
            "one take: a spike pastes another take's motion, so the spike conditions have no \
             spikes here (evaluate two takes or more)"
                .into(),
        );
    }
    let names = conditions(options);
    for (condition, name) in names.iter().enumerate() {
        let mut cleaners = Vec::new();
        if options.filters && tune_takes.len() >= 2 {
            let tune_pairs = pairs(&tune_takes, condition, options)?;
            for family in Filter::FAMILIES {
                let t = tune(&tune_pairs, name, family)?;
                cleaners.push((t.filter.label(), Cleaner::Filter(t.filter)));
                tuned_filters.push(t);
            }
        }
        per_condition.push(cleaners);
    }
    if options.despike && tune_takes.len() < 2 {
        return Err(CleanError::Invalid(
            "tuning spike finding needs at least two validation takes".into(),
        ));
    }
    let mut tuned_despike = Vec::new();

    let mut entries = Vec::new();
    for (condition, filters) in per_condition.iter().enumerate() {
        let owned = cleaners_for(filters, &models);
        let cleaners: Vec<_> = owned.iter().collect();
        let methods = methods(&cleaners, options, &tune_takes, &mut tuned_despike)?;
        // Frame-weighted sums of the three metrics and the frames each was
        // defined on: a take too short for the acceleration is left out of
        // its mean, not made NaN of it. Only for that reason: a method that
        // outputs NaN on some take still shows as NaN (null in JSON).
        let mut sums = vec![[0.0f64; 4]; methods.len() + 1];
        let mut weights = vec![[0.0f64; 4]; methods.len() + 1];
        let bar = mocap_nn::train::work_bar(
            takes.len() as u64,
            &format!("takes cleaned ({} noise)", names[condition]),
        );
        for i in 0..takes.len() {
            let fused;
            let (clean, noisy) = if condition < CONDITIONS.len() {
                (&takes[i].motion, make_noisy(&takes, i, condition, options)?)
            } else {
                fused = fused_pair(&takes, i, options)?;
                (&fused.0, fused.1.clone())
            };
            let w = clean.frame_count() as f64;
            let any = clean.frame_count() > 0;
            let parts = body_part_joints(clean);
            let defined = [any, any, has_acceleration(clean), any && !parts.is_empty()];
            let mut add = |slot: usize, m: &Motion| {
                let (r, body) = rotation_errors_deg(clean, m, &parts);
                let (p, a) = position_errors(clean, m);
                for (metric, value) in [r, p, a, body].into_iter().enumerate() {
                    if defined[metric] {
                        sums[slot][metric] += value * w;
                        weights[slot][metric] += w;
                    }
                }
            };
            add(0, &noisy);
            run_methods(&cleaners, &methods, &noisy, |k, m| add(k + 1, m))?;
            bar.inc(1);
        }
        bar.finish_and_clear();
        let labels = std::iter::once("noisy input").chain(methods.iter().map(|m| m.label.as_str()));
        for ((label, s), w) in labels.zip(&sums).zip(&weights) {
            // NaN (JSON null) only when no take defines the metric.
            let mean = |metric: usize| {
                if w[metric] > 0.0 {
                    s[metric] / w[metric]
                } else {
                    f64::NAN
                }
            };
            entries.push(MethodMetrics {
                method: label.to_string(),
                condition: names[condition].into(),
                rotation_error_deg: mean(0),
                body_rotation_error_deg: mean(3),
                position_error: mean(1),
                acceleration_error: mean(2),
            });
        }
    }

    // Spike survival: one spike of each length in the middle of each take
    // (no random noise), error measured on the spiked joints and frames;
    // the filters are those tuned for spikes alone.
    let mut spike_survival = Vec::new();
    let spike_filters = per_condition.get(SPIKES_ONLY).map_or(&[][..], |f| &f[..]);
    let owned = cleaners_for(spike_filters, &models);
    let cleaners: Vec<_> = owned.iter().collect();
    let spike_methods = methods(&cleaners, options, &tune_takes, &mut tuned_despike)?;
    for &length in &options.spike_lengths {
        let mut noisy_sum = 0.0;
        let mut residual = vec![0.0; spike_methods.len()];
        let mut count = 0usize;
        for i in 0..takes.len() {
            let clean = &takes[i].motion;
            if clean.frame_count() < length + 8 {
                continue;
            }
            let mut rng = rng_for(options.seed, i, 100 + length);
            let donors = donor_windows(&takes, i, clean.frame_count(), &mut rng);
            let refs: Vec<&Motion> = donors.iter().collect();
            if refs.is_empty() {
                continue;
            }
            let mut spikes = [Spike {
                joint: 0,
                start: (clean.frame_count() - length) / 2,
                frames: length,
            }];
            let (noisy, spikes) = add_spikes(clean, &refs, &options.spikes, &mut spikes, &mut rng)?;
            let s = spikes[0];
            let region = |m: &Motion| {
                let joints = clean.skeleton().subtree(s.joint);
                let mut e = 0.0;
                for f in s.start..s.start + s.frames {
                    for &j in &joints {
                        e += angle_between(clean.local_rotation(f, j), m.local_rotation(f, j))
                            .to_degrees() as f64;
                    }
                }
                e / (s.frames * joints.len()) as f64
            };
            noisy_sum += region(&noisy);
            run_methods(&cleaners, &spike_methods, &noisy, |k, m| {
                residual[k] += region(m)
            })?;
            count += 1;
        }
        if count == 0 {
            continue;
        }
        for (k, method) in spike_methods.iter().enumerate() {
            spike_survival.push(SpikeSurvival {
                length,
                method: method.label.clone(),
                noisy_error_deg: noisy_sum / count as f64,
                residual_error_deg: residual[k] / count as f64,
            });
        }
    }

    Ok(EvalReport {
        takes: takes.len(),
        frames: takes.iter().map(|t| t.motion.frame_count()).sum(),
        entries,
        tuned_filters,
        tuned_despike,
        spike_survival,
        notes,
    })
}

impl EvalReport {
    /// The report as Markdown tables.
    pub fn to_markdown(&self) -> String {
        let mut s = format!("{} takes, {} frames.\n\n", self.takes, self.frames);
        for note in &self.notes {
            s += &format!("Note: {note}.\n\n");
        }
        if !self.tuned_despike.is_empty() {
            s += "Spike finding tuned (spike condition):\n\n\
                  | method | threshold | span (frames) | rotations | longest spike (frames) | rotation error there (deg) |\n\
                  | --- | ---: | ---: | --- | ---: | ---: |\n";
            for (label, d, error) in &self.tuned_despike {
                s += &format!(
                    "| {label} | {} | {} | {} | {} | {error:.3} |\n",
                    d.threshold,
                    d.span,
                    if d.global { "global" } else { "local" },
                    d.max_frames
                );
            }
            s += "\n";
        }
        let mut conditions: Vec<&str> = Vec::new();
        for e in &self.entries {
            if !conditions.contains(&e.condition.as_str()) {
                conditions.push(&e.condition);
            }
        }
        for condition in conditions {
            s += &format!("### Noise: {condition}\n\n| method | rotation error (deg) | body parts alone (deg) | position error (cm) | acceleration error (cm/frame^2) |\n| --- | ---: | ---: | ---: | ---: |\n");
            for e in self.entries.iter().filter(|e| e.condition == condition) {
                s += &format!(
                    "| {} | {:.3} | {:.3} | {:.3} | {:.4} |\n",
                    e.method,
                    e.rotation_error_deg,
                    e.body_rotation_error_deg,
                    e.position_error,
                    e.acceleration_error
                );
            }
            s += "\n";
        }
        if !self.spike_survival.is_empty() {
            s += "### Spike survival (one spike of the given length, no random noise; error on the spiked joints and frames, degrees)\n\n| length (frames) | method | before | after | surviving |\n| ---: | --- | ---: | ---: | ---: |\n";
            for r in &self.spike_survival {
                s += &format!(
                    "| {} | {} | {:.2} | {:.2} | {:.0}% |\n",
                    r.length,
                    r.method,
                    r.noisy_error_deg,
                    r.residual_error_deg,
                    100.0 * r.residual_error_deg / r.noisy_error_deg.max(1e-9)
                );
            }
        }
        s
    }
}
