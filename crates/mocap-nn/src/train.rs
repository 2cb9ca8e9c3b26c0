//! The training loop shared by the learned capabilities: epochs of optimiser
//! steps with a progress bar, a validation pass after each epoch, a loss
//! history, and a hook to checkpoint.
//!
//! The model-specific parts (how a batch is drawn, the loss, validation) are
//! closures, so each capability keeps its method in its own crate.

use std::io::IsTerminal;
use std::time::Instant;

use burn::module::Module;
use burn::optim::{GradientsParams, ModuleOptimizer};
use burn::tensor::Tensor;
use indicatif::{ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize};

use crate::NnError;

/// Losses and timing of one epoch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpochRecord {
    /// 0-based epoch index.
    pub epoch: usize,
    /// Mean training loss over the epoch's steps.
    #[serde(deserialize_with = "nan_if_null")]
    pub train_loss: f64,
    /// Validation loss after the epoch (NaN where there was nothing to
    /// validate on).
    #[serde(deserialize_with = "nan_if_null")]
    pub valid_loss: f64,
    /// Training samples seen in the epoch.
    pub samples: usize,
    /// Wall-clock seconds of the training steps (validation excluded).
    pub train_seconds: f64,
}

/// JSON has no NaN: serde_json writes a NaN loss as `null`, which a resumed
/// run must read back as NaN.
fn nan_if_null<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(deserializer)?.unwrap_or(f64::NAN))
}

/// The losses of every epoch so far (what a resumed run continues).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct History {
    pub epochs: Vec<EpochRecord>,
}

impl History {
    /// Training samples per second over all epochs.
    pub fn samples_per_second(&self) -> f64 {
        let samples: usize = self.epochs.iter().map(|e| e.samples).sum();
        let seconds: f64 = self.epochs.iter().map(|e| e.train_seconds).sum();
        if seconds > 0.0 {
            samples as f64 / seconds
        } else {
            0.0
        }
    }

    /// Area under the validation curve over the first `epochs` epochs (sum of
    /// the validation losses, one per epoch), or `None` when fewer ran.
    pub fn valid_area(&self, epochs: usize) -> Option<f64> {
        (self.epochs.len() >= epochs)
            .then(|| self.epochs[..epochs].iter().map(|e| e.valid_loss).sum())
    }
}

/// Set by a front end's `--quiet`: no training progress bars at all.
static PROGRESS_HIDDEN: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// The seed of one epoch's random draws (windows, noise) from a run's seed:
/// each epoch draws anew, and the same run seed repeats the whole run, also
/// when it is resumed at an epoch.
pub fn epoch_seed(seed: u64, epoch: usize) -> u64 {
    seed ^ (epoch as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15)
}

/// Hides (or shows again) every training progress bar of this process; the
/// CLI calls it for `--quiet`.
pub fn hide_progress(hidden: bool) {
    PROGRESS_HIDDEN.store(hidden, std::sync::atomic::Ordering::Relaxed);
}

/// A progress bar on stderr, hidden when stderr is not a terminal (logs and
/// CI stay clean) or after [`hide_progress`].
pub fn progress_bar(steps: u64) -> ProgressBar {
    if PROGRESS_HIDDEN.load(std::sync::atomic::Ordering::Relaxed)
        || !std::io::stderr().is_terminal()
    {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(steps);
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:30}] {pos}/{len} steps, eta {eta} {msg}",
        )
        .expect("valid progress template")
        .progress_chars("=> "),
    );
    bar
}

/// A progress bar for other long work (evaluations): `len` items of
/// `what`, hidden like [`progress_bar`].
pub fn work_bar(len: u64, what: &str) -> ProgressBar {
    if PROGRESS_HIDDEN.load(std::sync::atomic::Ordering::Relaxed)
        || !std::io::stderr().is_terminal()
    {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}, eta {eta}")
            .expect("valid progress template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

/// One optimiser step: back-propagates `loss` through `model` and updates
/// its parameters with learning rate `lr`. Returns the updated model and the
/// loss value (for the progress bar and [`run_epochs`]' divergence check).
pub fn optimizer_step<M: Module>(
    model: M,
    optimizer: &mut ModuleOptimizer,
    loss: Tensor<1>,
    lr: f64,
) -> (M, f64) {
    let value: f32 = loss.clone().into_scalar();
    let grads = GradientsParams::from_grads(loss.backward(), &model);
    (optimizer.step(lr, model, grads), value as f64)
}

/// Sizes of a training run.
#[derive(Debug, Clone, Copy)]
pub struct EpochPlan {
    /// Total number of epochs (a resumed run continues up to this count).
    pub epochs: usize,
    /// Optimiser steps per epoch.
    pub steps_per_epoch: usize,
    /// Samples in one step (for the samples-per-second figure).
    pub batch_size: usize,
}

/// Runs the epochs that `history` does not have yet, up to `plan.epochs`.
///
/// `train_step(state, epoch, step)` does one optimiser step and returns its
/// loss; `validate(state, epoch)` returns the validation loss;
/// `after_epoch(state, history)` runs after each epoch (checkpointing). A
/// loss that is not a finite number stops the run with
/// [`NnError::Diverged`] before the epoch is recorded, so the last saved
/// epoch stays the last good one.
pub fn run_epochs<S, E: From<NnError>>(
    state: &mut S,
    history: &mut History,
    plan: EpochPlan,
    mut train_step: impl FnMut(&mut S, usize, usize) -> Result<f64, E>,
    mut validate: impl FnMut(&mut S, usize) -> Result<f64, E>,
    mut after_epoch: impl FnMut(&mut S, &History) -> Result<(), E>,
) -> Result<(), E> {
    let first = history.epochs.len();
    if first >= plan.epochs {
        return Ok(());
    }
    let bar = progress_bar(((plan.epochs - first) * plan.steps_per_epoch) as u64);
    for epoch in first..plan.epochs {
        let start = Instant::now();
        let mut sum = 0.0;
        for step in 0..plan.steps_per_epoch {
            let loss = train_step(state, epoch, step)?;
            if !loss.is_finite() {
                return Err(NnError::Diverged {
                    loss,
                    epoch: epoch + 1,
                }
                .into());
            }
            sum += loss;
            bar.inc(1);
            bar.set_message(format!(
                "epoch {}/{} loss {:.5}",
                epoch + 1,
                plan.epochs,
                sum / (step + 1) as f64
            ));
        }
        let train_seconds = start.elapsed().as_secs_f64();
        let valid_loss = validate(state, epoch)?;
        let record = EpochRecord {
            epoch,
            train_loss: sum / plan.steps_per_epoch.max(1) as f64,
            valid_loss,
            samples: plan.steps_per_epoch * plan.batch_size,
            train_seconds,
        };
        let line = format!(
            "epoch {:>3}: train {:.5}  valid {:.5}  ({:.0} samples/s)",
            epoch + 1,
            record.train_loss,
            record.valid_loss,
            record.samples as f64 / train_seconds.max(1e-9)
        );
        // A hidden bar prints nothing: logs still get one line per epoch.
        if bar.is_hidden() {
            eprintln!("{line}");
        } else {
            bar.println(line);
        }
        history.epochs.push(record);
        after_epoch(state, history)?;
    }
    bar.finish_and_clear();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::nn::{Linear, LinearConfig};
    use burn::optim::AdamConfig;
    use burn::tensor::Device;

    /// A run without validation clips records NaN validation losses; its
    /// history, written as JSON (NaN becomes `null`), reads back.
    #[test]
    fn a_history_without_validation_losses_reads_back() {
        let history = History {
            epochs: vec![EpochRecord {
                epoch: 0,
                train_loss: 0.5,
                valid_loss: f64::NAN,
                samples: 8,
                train_seconds: 1.0,
            }],
        };
        let json = serde_json::to_string(&history).unwrap();
        assert!(json.contains("\"valid_loss\":null"), "{json}");
        let back: History = serde_json::from_str(&json).unwrap();
        assert!(back.epochs[0].valid_loss.is_nan());
        assert_eq!(back.epochs[0].train_loss, 0.5);
    }

    /// A loss that turns into NaN stops the run at that epoch, after the
    /// epochs before it were recorded and saved.
    #[test]
    fn a_diverging_loss_stops_the_run() {
        let mut history = History::default();
        let mut saved = 0;
        let plan = EpochPlan {
            epochs: 5,
            steps_per_epoch: 3,
            batch_size: 1,
        };
        let result = run_epochs(
            &mut saved,
            &mut history,
            plan,
            |_, epoch, step| {
                Ok(if epoch == 2 && step == 1 {
                    f64::NAN
                } else {
                    1.0
                })
            },
            |_, _| Ok(1.0),
            |saved, _| {
                *saved += 1;
                Ok::<(), NnError>(())
            },
        );
        match result {
            Err(NnError::Diverged { loss, epoch }) => {
                assert!(loss.is_nan());
                assert_eq!(epoch, 3);
            }
            other => panic!("expected Diverged, got {other:?}"),
        }
        assert_eq!(history.epochs.len(), 2);
        assert_eq!(saved, 2);
    }

    /// Fits y = 2x + 1 with the loop and Adam: the loss must fall.
    #[test]
    fn loop_fits_a_line() {
        let device = Device::flex().autodiff();
        device.seed(1);
        let mut model: Linear = LinearConfig::new(1, 1).init(&device);
        let mut optimizer = AdamConfig::new().init();
        let xs: Vec<f32> = (0..32).map(|i| i as f32 / 16.0 - 1.0).collect();
        let ys: Vec<f32> = xs.iter().map(|x| 2.0 * x + 1.0).collect();
        let x = Tensor::<1>::from_floats(xs.as_slice(), &device).reshape([32, 1]);
        let y = Tensor::<1>::from_floats(ys.as_slice(), &device).reshape([32, 1]);
        let mut history = History::default();
        let plan = EpochPlan {
            epochs: 4,
            steps_per_epoch: 50,
            batch_size: 32,
        };
        let mut state = (&mut model, &mut optimizer);
        run_epochs(
            &mut state,
            &mut history,
            plan,
            |(model, optimizer), _, _| {
                let loss = (model.forward(x.clone()) - y.clone()).powi_scalar(2).mean();
                let (updated, value) = optimizer_step((**model).clone(), optimizer, loss, 0.05);
                **model = updated;
                Ok::<f64, NnError>(value)
            },
            |(model, _), _| {
                let loss = (model.forward(x.clone()) - y.clone()).powi_scalar(2).mean();
                let value: f32 = loss.into_scalar();
                Ok(value as f64)
            },
            |_, _| Ok(()),
        )
        .unwrap();
        assert_eq!(history.epochs.len(), 4);
        let first = history.epochs[0].valid_loss;
        let last = history.epochs[3].valid_loss;
        assert!(last < 0.1 * first, "loss {first} -> {last}");
        assert_eq!(
            history.valid_area(2).unwrap(),
            first + history.epochs[1].valid_loss
        );
    }
}
