//! Checkpoints: network weights in a safetensors file whose header says what
//! the weights are.
//!
//! A safetensors file starts with a JSON header that may hold a string map
//! `__metadata__`. We store there, next to burn's own keys:
//!
//! - `mocap.format` = [`FORMAT`] and `mocap.format_version` = [`FORMAT_VERSION`]:
//!   the layout of this header, bumped when it changes incompatibly;
//! - `mocap.header`: a JSON [`CheckpointHeader`] with the kind of model (for
//!   example `mocap-clean/denoiser`) and its own version, the model
//!   configuration, and a description of the training data and run;
//! - `mocap.checksum`: `crc32:` and eight hex digits, the CRC-32 of the
//!   `mocap.header` text followed by every byte after the safetensors header
//!   (the tensors' data). A flipped bit in the weights or the configuration
//!   gives a clear error instead of a network that quietly outputs garbage.
//!
//! The header is read first and the checksum checked, the model built from its
//! configuration, then the tensors are loaded into it; a tensor that is
//! missing or of the wrong shape is an error naming the file. Files of format
//! version 1 predate the checksum and are read without it.
//!
//! Training state for resuming ([`TrainingState`]) is kept apart: burn's own
//! burnpack format for the weights (it keeps the parameter ids the optimizer
//! state is keyed by), the optimizer state, and a JSON file of progress.

use std::path::{Path, PathBuf};

use burn::module::Module;
use burn::optim::ModuleOptimizer;
use burn::store::{BurnpackStore, ModuleSnapshot, SafetensorsStore};
use burn::tensor::Bytes;
use mocap_core::io::atomic::write_bytes_atomically;
use serde::{Deserialize, Serialize};

use crate::{NnError, Result};

/// Value of the `mocap.format` metadata key.
pub const FORMAT: &str = "mocap-nn checkpoint";
/// Version of the header layout: 2 added `mocap.checksum`.
pub const FORMAT_VERSION: u32 = 2;
/// The oldest header layout this build reads (without a checksum).
const OLDEST_FORMAT_VERSION: u32 = 1;

const KEY_FORMAT: &str = "mocap.format";
const KEY_VERSION: &str = "mocap.format_version";
const KEY_HEADER: &str = "mocap.header";
const KEY_CHECKSUM: &str = "mocap.checksum";

/// What a checkpoint holds, stored in its safetensors header.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckpointHeader {
    /// The kind of model, e.g. `mocap-clean/denoiser`.
    pub kind: String,
    /// Version of that model's configuration layout.
    pub kind_version: u32,
    /// The model configuration (enough to rebuild the network).
    pub config: serde_json::Value,
    /// The training data: files, splits, noise, representation...
    pub data: serde_json::Value,
    /// The training run: epochs, losses, seed, timings...
    pub training: serde_json::Value,
}

impl CheckpointHeader {
    /// Checks that the file holds `what` (kind `kind`, configuration layout
    /// `version`); the error names `origin`, the kind found and the one
    /// expected.
    pub fn expect_kind(&self, origin: &Path, kind: &str, version: u32, what: &str) -> Result<()> {
        if self.kind != kind {
            return Err(checkpoint_error(
                origin,
                format!("a `{}` file, not {what} (`{kind}`)", self.kind),
            ));
        }
        if self.kind_version != version {
            return Err(checkpoint_error(
                origin,
                format!(
                    "{what} version {}, this build reads version {version}",
                    self.kind_version
                ),
            ));
        }
        Ok(())
    }
}

fn checkpoint_error(path: &Path, message: impl Into<String>) -> NnError {
    NnError::Checkpoint {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// Writes `module`'s weights and `header` to `path` (atomically).
pub fn save_weights<M: Module>(path: &Path, module: &M, header: &CheckpointHeader) -> Result<()> {
    let bytes = weights_to_bytes(module, header).map_err(|m| checkpoint_error(path, m))?;
    write_bytes_atomically(path, &bytes)?;
    Ok(())
}

/// The safetensors bytes of `module`'s weights with `header`.
pub fn weights_to_bytes<M: Module>(
    module: &M,
    header: &CheckpointHeader,
) -> std::result::Result<Vec<u8>, String> {
    let header_json = serde_json::to_string(header).map_err(|e| e.to_string())?;
    let mut store = SafetensorsStore::from_bytes(None)
        .metadata(KEY_FORMAT, FORMAT)
        .metadata(KEY_VERSION, FORMAT_VERSION.to_string())
        .metadata(KEY_HEADER, header_json);
    module
        .save_into(&mut store)
        .map_err(|e| format!("cannot serialise the weights: {e}"))?;
    let bytes = store
        .get_bytes()
        .map_err(|e| format!("cannot serialise the weights: {e}"))?;
    seal(&bytes)
}

/// `bytes` (a checkpoint) with its header's `mocap.checksum` set to the
/// checksum of its configuration and tensors, and its format version set to
/// [`FORMAT_VERSION`]. The tensors' data is kept byte for byte: only the
/// safetensors header is rewritten.
pub fn seal(bytes: &[u8]) -> std::result::Result<Vec<u8>, String> {
    let (header_len, _) = safetensors::SafeTensors::read_metadata(bytes)
        .map_err(|e| format!("not a safetensors file ({e})"))?;
    let data = &bytes[8 + header_len..];
    let mut json: serde_json::Map<String, serde_json::Value> =
        serde_json::from_slice(&bytes[8..8 + header_len])
            .map_err(|e| format!("bad safetensors header: {e}"))?;
    let metadata = json
        .entry("__metadata__")
        .or_insert_with(|| serde_json::Value::Object(Default::default()))
        .as_object_mut()
        .ok_or("the safetensors `__metadata__` is not a map")?;
    let header = metadata
        .get(KEY_HEADER)
        .and_then(|h| h.as_str())
        .ok_or_else(|| format!("missing `{KEY_HEADER}`"))?;
    let checksum = checksum(header, data);
    metadata.insert(KEY_CHECKSUM.into(), checksum.into());
    metadata.insert(KEY_VERSION.into(), FORMAT_VERSION.to_string().into());
    let mut text = serde_json::to_vec(&json).map_err(|e| e.to_string())?;
    // safetensors pads its header with spaces so that the data starts on an
    // 8-byte boundary.
    text.resize(text.len().next_multiple_of(8), b' ');
    let mut out = Vec::with_capacity(8 + text.len() + data.len());
    out.extend_from_slice(&(text.len() as u64).to_le_bytes());
    out.extend_from_slice(&text);
    out.extend_from_slice(data);
    Ok(out)
}

/// The `mocap.checksum` value of a checkpoint whose `mocap.header` is
/// `header` and whose tensors' data is `data`.
fn checksum(header: &str, data: &[u8]) -> String {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(header.as_bytes());
    hasher.update(data);
    format!("crc32:{:08x}", hasher.finalize())
}

/// Reads the header of the checkpoint at `path`.
pub fn read_header(path: &Path) -> Result<CheckpointHeader> {
    let bytes = std::fs::read(path).map_err(|e| mocap_core::Error::io(path, e))?;
    header_from_bytes(&bytes, path)
}

/// Reads the header of checkpoint bytes; `origin` names them in errors.
pub fn header_from_bytes(bytes: &[u8], origin: &Path) -> Result<CheckpointHeader> {
    let (header_len, metadata) = safetensors::SafeTensors::read_metadata(bytes)
        .map_err(|e| checkpoint_error(origin, format!("not a safetensors file ({e})")))?;
    let map = metadata.metadata().clone().unwrap_or_default();
    match map.get(KEY_FORMAT) {
        Some(f) if f == FORMAT => {}
        Some(f) => {
            return Err(checkpoint_error(
                origin,
                format!("expected a `{FORMAT}` file, found `{f}`"),
            ))
        }
        None => {
            return Err(checkpoint_error(
                origin,
                format!(
                    "a safetensors file without the `{KEY_FORMAT}` header: not written by mocap"
                ),
            ))
        }
    }
    let version: u32 = map
        .get(KEY_VERSION)
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| checkpoint_error(origin, format!("missing or bad `{KEY_VERSION}`")))?;
    if !(OLDEST_FORMAT_VERSION..=FORMAT_VERSION).contains(&version) {
        return Err(checkpoint_error(
            origin,
            format!(
                "checkpoint format version {version}, this build reads versions \
                 {OLDEST_FORMAT_VERSION} to {FORMAT_VERSION}"
            ),
        ));
    }
    let header = map
        .get(KEY_HEADER)
        .ok_or_else(|| checkpoint_error(origin, format!("missing `{KEY_HEADER}`")))?;
    if version >= 2 {
        let stored = map
            .get(KEY_CHECKSUM)
            .ok_or_else(|| checkpoint_error(origin, format!("missing `{KEY_CHECKSUM}`")))?;
        let actual = checksum(header, &bytes[8 + header_len..]);
        if *stored != actual {
            return Err(checkpoint_error(
                origin,
                format!(
                    "the file is damaged: its checksum is {actual}, its header says {stored} \
                     (copy or retrain the model)"
                ),
            ));
        }
    }
    serde_json::from_str(header)
        .map_err(|e| checkpoint_error(origin, format!("bad `{KEY_HEADER}` JSON: {e}")))
}

/// Refuses a configuration that asks for more weights than the checkpoint
/// holds, before the model is built: a damaged or hostile header must not
/// make the loader allocate what the file does not justify. `wanted` is the
/// configuration's parameter count (saturating).
pub fn check_parameter_count(bytes: &[u8], origin: &Path, wanted: usize) -> Result<()> {
    let tensors = safetensors::SafeTensors::deserialize(bytes)
        .map_err(|e| checkpoint_error(origin, format!("not a safetensors file ({e})")))?;
    let stored: usize = tensors
        .iter()
        .map(|(_, view)| view.shape().iter().product::<usize>())
        .sum();
    if wanted > stored {
        return Err(checkpoint_error(
            origin,
            format!("the model configuration asks for {wanted} weights, the file holds {stored}"),
        ));
    }
    Ok(())
}

/// Loads the weights in `bytes` into `module` (built from the header's
/// configuration). Every tensor of the module must be present with its shape.
pub fn load_weights_from_bytes<M: Module>(
    bytes: Vec<u8>,
    origin: &Path,
    mut module: M,
) -> Result<M> {
    let mut store = SafetensorsStore::from_bytes(Some(bytes));
    let result = module
        .load_from(&mut store)
        .map_err(|e| checkpoint_error(origin, format!("cannot read the weights: {e}")))?;
    if !result.is_success() || !result.missing.is_empty() {
        return Err(checkpoint_error(
            origin,
            format!(
                "the weights do not fit the model: {} missing, {} errors ({})",
                result.missing.len(),
                result.errors.len(),
                result
                    .errors
                    .iter()
                    .map(|e| e.to_string())
                    .chain(result.missing.iter().map(|(p, _)| format!("missing {p}")))
                    .take(3)
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        ));
    }
    Ok(module)
}

/// Loads the weights at `path` into `module`.
pub fn load_weights<M: Module>(path: &Path, module: M) -> Result<M> {
    let bytes = std::fs::read(path).map_err(|e| mocap_core::Error::io(path, e))?;
    load_weights_from_bytes(bytes, path, module)
}

/// The files of a resumable training state in a folder: `model.bpk`,
/// `optimizer.bpk` and `progress.json`.
#[derive(Debug, Clone)]
pub struct TrainingState {
    pub dir: PathBuf,
}

impl TrainingState {
    pub fn new(dir: impl Into<PathBuf>) -> TrainingState {
        TrainingState { dir: dir.into() }
    }

    fn model_path(&self) -> PathBuf {
        self.dir.join("model.bpk")
    }

    fn optimizer_path(&self) -> PathBuf {
        self.dir.join("optimizer.bpk")
    }

    fn progress_path(&self) -> PathBuf {
        self.dir.join("progress.json")
    }

    /// Whether a complete state is there to resume from.
    pub fn exists(&self) -> bool {
        self.model_path().is_file()
            && self.optimizer_path().is_file()
            && self.progress_path().is_file()
    }

    /// Saves the model, the optimizer and `progress` (each file atomically;
    /// the progress file last, so a state is only complete once it is written).
    pub fn save<M: Module, P: Serialize>(
        &self,
        module: &M,
        optimizer: &ModuleOptimizer,
        progress: &P,
    ) -> Result<()> {
        std::fs::create_dir_all(&self.dir).map_err(|e| mocap_core::Error::io(&self.dir, e))?;
        let mut store = BurnpackStore::from_bytes(None);
        module
            .save_into(&mut store)
            .map_err(|e| checkpoint_error(&self.model_path(), e.to_string()))?;
        let model_bytes = store
            .get_bytes()
            .map_err(|e| checkpoint_error(&self.model_path(), e.to_string()))?;
        write_bytes_atomically(&self.model_path(), &model_bytes)?;
        let optim_bytes = optimizer
            .into_bytes()
            .map_err(|e| checkpoint_error(&self.optimizer_path(), e.to_string()))?;
        write_bytes_atomically(&self.optimizer_path(), &optim_bytes)?;
        let json = serde_json::to_vec_pretty(progress)
            .map_err(|e| checkpoint_error(&self.progress_path(), e.to_string()))?;
        write_bytes_atomically(&self.progress_path(), &json)?;
        Ok(())
    }

    /// Loads the model weights into `module` (keeping the parameter ids the
    /// optimizer state refers to), the optimizer state into `optimizer`, and
    /// the progress.
    pub fn load<M: Module, P: for<'de> Deserialize<'de>>(
        &self,
        mut module: M,
        optimizer: ModuleOptimizer,
    ) -> Result<(M, ModuleOptimizer, P)> {
        let read = |p: &Path| std::fs::read(p).map_err(|e| mocap_core::Error::io(p, e));
        let model_bytes = read(&self.model_path())?;
        let mut store = BurnpackStore::from_bytes(Some(Bytes::from_bytes_vec(model_bytes)));
        let result = module
            .load_from(&mut store)
            .map_err(|e| checkpoint_error(&self.model_path(), e.to_string()))?;
        if !result.is_success() || !result.missing.is_empty() {
            return Err(checkpoint_error(
                &self.model_path(),
                "the saved weights do not fit the model configuration",
            ));
        }
        let optimizer = optimizer
            .from_bytes(Bytes::from_bytes_vec(read(&self.optimizer_path())?))
            .map_err(|e| checkpoint_error(&self.optimizer_path(), e.to_string()))?;
        let progress = serde_json::from_slice(&read(&self.progress_path())?)
            .map_err(|e| checkpoint_error(&self.progress_path(), e.to_string()))?;
        Ok((module, optimizer, progress))
    }

    /// The model, optimizer and epoch history a training run starts from:
    /// those saved here when `resume` is asked and a complete state is
    /// there, else the fresh `module` and `optimizer` with no epochs.
    pub fn resume_or_start<M: Module>(
        &self,
        resume: bool,
        module: M,
        optimizer: ModuleOptimizer,
    ) -> Result<(M, ModuleOptimizer, crate::train::History)> {
        if resume && self.exists() {
            let (module, optimizer, progress): (M, ModuleOptimizer, Progress) =
                self.load(module, optimizer)?;
            Ok((module, optimizer, progress.history))
        } else {
            Ok((module, optimizer, crate::train::History::default()))
        }
    }
}

/// What a training run starts from, and where it writes besides its model
/// file: see [`start_run`].
pub struct RunStart<M> {
    /// The resumable state: `state_dir` when given, else the model file's
    /// name with extension `state`.
    pub state: TrainingState,
    /// The picture of the curves: `plot` when given, else the model file's
    /// name with extension `png`.
    pub plot: PathBuf,
    /// The network, Adam and the epochs run so far: the saved ones when
    /// resuming from a complete state, else the fresh network, a new Adam
    /// and no epochs.
    pub model: M,
    pub optimizer: ModuleOptimizer,
    pub history: crate::train::History,
}

/// Starts (or resumes) the training run of every learned capability, which
/// writes `model_file`.
pub fn start_run<M: Module>(
    model_file: &Path,
    state_dir: Option<&Path>,
    plot: Option<&Path>,
    resume: bool,
    fresh: M,
) -> Result<RunStart<M>> {
    let state = TrainingState::new(
        state_dir.map_or_else(|| model_file.with_extension("state"), Path::to_path_buf),
    );
    let plot = plot.map_or_else(|| model_file.with_extension("png"), Path::to_path_buf);
    let (model, optimizer, history) =
        state.resume_or_start(resume, fresh, burn::optim::AdamConfig::new().init())?;
    Ok(RunStart {
        state,
        plot,
        model,
        optimizer,
        history,
    })
}

/// What a resumable training state records besides the weights and the
/// optimizer: the history of the epochs run so far.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Progress {
    pub history: crate::train::History,
}

/// What every learned capability writes at the end of an epoch, in this
/// order: the resumable state (`state`), the model file `out` (so an
/// interrupted run still leaves a usable model of its last finished epoch)
/// and the loss curves `plot`.
#[allow(clippy::too_many_arguments)]
pub fn save_epoch<M: Module>(
    state: &TrainingState,
    training_model: &M,
    optimizer: &ModuleOptimizer,
    history: &crate::train::History,
    out: &Path,
    inference_model: &impl Module,
    header: &CheckpointHeader,
    plot: &Path,
    plot_options: &crate::plot::PlotOptions,
) -> Result<()> {
    state.save(
        training_model,
        optimizer,
        &Progress {
            history: history.clone(),
        },
    )?;
    save_weights(out, inference_model, header)?;
    crate::plot::plot_history(plot, history, plot_options)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_header_of_another_kind_or_version_is_refused_by_name() {
        let header = CheckpointHeader {
            kind: "mocap-clean/wiener".into(),
            kind_version: 1,
            config: serde_json::Value::Null,
            data: serde_json::Value::Null,
            training: serde_json::Value::Null,
        };
        let origin = Path::new("models/m.safetensors");
        header
            .expect_kind(origin, "mocap-clean/wiener", 1, "a Wiener filter")
            .unwrap();
        let other = header
            .expect_kind(origin, "mocap-clean/denoiser", 1, "a denoiser")
            .unwrap_err()
            .to_string();
        assert_eq!(
            other,
            "models/m.safetensors: a `mocap-clean/wiener` file, not a denoiser (`mocap-clean/denoiser`)"
        );
        let newer = header
            .expect_kind(origin, "mocap-clean/wiener", 2, "a Wiener filter")
            .unwrap_err()
            .to_string();
        assert!(
            newer.contains("a Wiener filter version 1, this build reads version 2"),
            "{newer}"
        );
    }

    /// Checkpoint bytes of format version 1 (no checksum) holding one
    /// tensor of four f32.
    fn unsealed_checkpoint() -> Vec<u8> {
        let values: Vec<u8> = [1.0f32, -2.0, 0.5, 3.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = safetensors::tensor::TensorView::new(safetensors::Dtype::F32, vec![4], &values)
            .unwrap();
        let header = CheckpointHeader {
            kind: "test/model".into(),
            kind_version: 1,
            config: serde_json::json!({"width": 4}),
            data: serde_json::Value::Null,
            training: serde_json::Value::Null,
        };
        let metadata = std::collections::HashMap::from([
            (KEY_FORMAT.to_string(), FORMAT.to_string()),
            (KEY_VERSION.to_string(), "1".to_string()),
            (
                KEY_HEADER.to_string(),
                serde_json::to_string(&header).unwrap(),
            ),
        ]);
        safetensors::serialize([("w", view)], Some(metadata)).unwrap()
    }

    #[test]
    fn a_sealed_checkpoint_reads_back_and_keeps_its_tensors() {
        let old = unsealed_checkpoint();
        let sealed = seal(&old).unwrap();
        let header = header_from_bytes(&sealed, Path::new("m.safetensors")).unwrap();
        assert_eq!(header.config, serde_json::json!({"width": 4}));
        let (old_len, _) = safetensors::SafeTensors::read_metadata(&old).unwrap();
        let (new_len, metadata) = safetensors::SafeTensors::read_metadata(&sealed).unwrap();
        assert_eq!(old[8 + old_len..], sealed[8 + new_len..]);
        let map = metadata.metadata().clone().unwrap();
        assert_eq!(map[KEY_VERSION], FORMAT_VERSION.to_string());
        assert!(map[KEY_CHECKSUM].starts_with("crc32:"), "{map:?}");
        // Files written before checksums existed still load.
        header_from_bytes(&old, Path::new("old.safetensors")).unwrap();
    }

    #[test]
    fn a_flipped_bit_in_the_weights_or_the_configuration_is_refused() {
        let sealed = seal(&unsealed_checkpoint()).unwrap();
        let (header_len, _) = safetensors::SafeTensors::read_metadata(&sealed).unwrap();
        let mut weights = sealed.clone();
        // The exponent's top bit of the last f32.
        let last = weights.len() - 1;
        weights[last] ^= 0x40;
        let e = header_from_bytes(&weights, Path::new("m.safetensors"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.safetensors: the file is damaged"), "{e}");

        let mut config = sealed.clone();
        let header_text = std::str::from_utf8(&config[8..8 + header_len]).unwrap();
        let at = 8 + header_text.find("width").unwrap() + "width\\\":".len();
        assert_eq!(config[at], b'4', "{header_text}");
        config[at] = b'5';
        let e = header_from_bytes(&config, Path::new("m.safetensors"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("the file is damaged"), "{e}");

        let mut no_checksum = sealed;
        let text = std::str::from_utf8(&no_checksum[8..8 + header_len])
            .unwrap()
            .replace(KEY_CHECKSUM, "mocap.checksun");
        no_checksum[8..8 + header_len].copy_from_slice(text.as_bytes());
        let e = header_from_bytes(&no_checksum, Path::new("m.safetensors"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing `mocap.checksum`"), "{e}");
    }
}
