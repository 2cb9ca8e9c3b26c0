//! # mocap-demo
//!
//! `mocap demo`: the whole pipeline on data bundled with the project, in one
//! command, with an HTML report of what each stage did.
//!
//! One take goes through the whole chain ([`chain`]), and each stage reports
//! its error against the ground truth, the sample itself:
//!
//! 1. **fuse** ([`fuse`]): the bundled Bandai Namco walk is watched by
//!    simulated Kinect v2 sensors (mocap-fuse `sim`); their frames are sent
//!    over UDP on loopback, faster than real time, to the fusion server
//!    (mocap-fuse `net`) running in a thread; the fused joints are compared
//!    with the ground truth, written as a BVH on a fitted skeleton, and
//!    retargeted onto the sample's rig for the next stages;
//! 2. **clean** ([`clean`]): the shipped denoiser cleans that fused take,
//!    a 3 Hz Butterworth its root, with the same filter alone beside it;
//! 3. **feet** ([`feet`]): planted feet held still and above the floor
//!    (mocap-feet);
//! 4. **search** ([`search`]): a small library index (Bandai dataset-2,
//!    content labels, `models/search-*.idx`) says what the actor is doing;
//! 5. **style** ([`style`]): the take is restyled with a bundled style clip
//!    and the shipped style model (mocap-style `apply`).
//!
//! Each stage runs on its own: a failure, a missing model file or a stage
//! that is not built is caught and reported as such ([`StageStatus`]), and
//! the other stages still run. Every output file is written atomically.
//! [`report`] writes `index.html` and `report.json` in the output folder.

mod chain;
pub mod clean;
pub mod feet;
pub mod fuse;
pub mod report;
pub mod search;
pub mod style;

use std::cell::RefCell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::Instant;

use chain::ChainTake;
use mocap_core::{Error, Result};
use serde::{Deserialize, Serialize};

/// Where the workspace root was at build time: bundled files are found
/// there when the demo is not run from the repository root.
const WORKSPACE_ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// The bundled files, compiled into the binary so that an installed `mocap`
/// (no source tree beside it) still runs the demo. The two models are the
/// same bytes the libraries load by default.
const EMBEDDED: &[(&str, &[u8])] = &[
    (
        "samples/dataset-1_walk_normal_001.bvh",
        include_bytes!("../../../samples/dataset-1_walk_normal_001.bvh"),
    ),
    (
        "samples/dataset-1_walk_proud_001.bvh",
        include_bytes!("../../../samples/dataset-1_walk_proud_001.bvh"),
    ),
    (
        "models/search-bandai-content.idx",
        include_bytes!("../../../models/search-bandai-content.idx"),
    ),
    (
        "models/clean-default.safetensors",
        mocap_clean::DEFAULT_MODEL,
    ),
    (
        "models/style-default.safetensors",
        mocap_style::DEFAULT_MODEL,
    ),
];

/// A bundled file (`samples/...`, `models/...`): relative to the current
/// folder when it is there (shorter paths in the viewer commands), else in
/// the source tree the binary was built from, else the copy compiled into
/// the binary, written once to `<temp>/mocap-<version>/`.
pub fn bundled(relative: &str) -> PathBuf {
    let cache = std::env::temp_dir().join(concat!("mocap-", env!("CARGO_PKG_VERSION")));
    bundled_from(
        relative,
        &[Path::new("."), Path::new(WORKSPACE_ROOT)],
        &cache,
    )
}

/// [`bundled`] with explicit places to look and a cache folder. When a file
/// is found nowhere and cannot be written to the cache either, the
/// source-tree path is returned so that the stage reports it as missing.
fn bundled_from(relative: &str, roots: &[&Path], cache: &Path) -> PathBuf {
    for root in roots {
        let candidate = if *root == Path::new(".") {
            PathBuf::from(relative)
        } else {
            root.join(relative)
        };
        if candidate.is_file() {
            return candidate;
        }
    }
    let fallback = roots
        .last()
        .map_or_else(|| PathBuf::from(relative), |r| r.join(relative));
    let Some((_, bytes)) = EMBEDDED.iter().find(|(name, _)| *name == relative) else {
        return fallback;
    };
    let copy = cache.join(relative);
    // An earlier run's copy is reused only when it is complete and current.
    if std::fs::read(&copy).is_ok_and(|existing| existing == *bytes) {
        return copy;
    }
    let written = copy
        .parent()
        .map_or(Ok(()), std::fs::create_dir_all)
        .is_ok()
        && mocap_core::io::atomic::write_bytes_atomically(&copy, bytes).is_ok();
    if written {
        copy
    } else {
        fallback
    }
}

/// What the demo runs on and where it writes.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DemoOptions {
    /// The report folder (created if needed; files in it are replaced).
    pub out: PathBuf,
    /// The take everything starts from (a Bandai BVH).
    pub sample: PathBuf,
    /// The example clip of the style for the restyle stage.
    pub style_clip: PathBuf,
    /// The denoiser (mocap-clean checkpoint).
    pub clean_model: PathBuf,
    /// The style autoencoder (mocap-style checkpoint).
    pub style_model: PathBuf,
    /// The search library index (`mocap search index`).
    pub search_index: PathBuf,
    /// Simulated sensors.
    pub sensors: usize,
    /// Seed of the simulation: same seed, same numbers.
    pub seed: u64,
    /// Playback speed of the UDP replay relative to real time.
    pub send_speed: f64,
    /// Draw filmstrips and plots.
    pub pictures: bool,
}

impl Default for DemoOptions {
    fn default() -> Self {
        DemoOptions {
            out: PathBuf::from("mocap-demo-report"),
            sample: bundled("samples/dataset-1_walk_normal_001.bvh"),
            style_clip: bundled("samples/dataset-1_walk_proud_001.bvh"),
            clean_model: bundled("models/clean-default.safetensors"),
            style_model: bundled("models/style-default.safetensors"),
            search_index: bundled("models/search-bandai-content.idx"),
            sensors: 3,
            seed: 1,
            send_speed: 10.0,
            pictures: true,
        }
    }
}

/// How a stage ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StageStatus {
    /// It ran; its numbers are in the report.
    Ran,
    /// Its model (or index) file is absent or empty: nothing was computed.
    ModelMissing,
    /// The library it needs is not built yet (an API the demo needs is missing).
    NotAvailable,
    /// It started and failed; the message says why.
    Failed,
}

impl StageStatus {
    /// Words for the terminal and the HTML report.
    pub fn label(self) -> &'static str {
        match self {
            StageStatus::Ran => "ran",
            StageStatus::ModelMissing => "model missing",
            StageStatus::NotAvailable => "not available",
            StageStatus::Failed => "failed",
        }
    }
}

/// One number a stage measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Number {
    /// Short machine name, e.g. `mpjpe_mm`.
    pub name: String,
    /// What it is, for people.
    pub description: String,
    pub value: f64,
    /// Unit, e.g. `mm`, `deg`, `s` (empty for counts and ratios).
    pub unit: String,
}

/// A file a stage wrote, relative to the report folder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OutputFile {
    pub path: PathBuf,
    pub description: String,
}

/// What one stage did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StageReport {
    /// `fuse`, `clean`, `feet`, `search` or `style`.
    pub name: String,
    pub title: String,
    pub status: StageStatus,
    /// Why it did not run, or what failed.
    pub message: Option<String>,
    /// Wall seconds the stage took.
    pub seconds: f64,
    pub numbers: Vec<Number>,
    /// Facts that are not numbers (the predicted class...).
    pub facts: Vec<(String, String)>,
    /// What the numbers mean and what the stage did not do.
    pub notes: Vec<String>,
    /// BVH and other data files.
    pub outputs: Vec<OutputFile>,
    /// Filmstrips and plots.
    pub pictures: Vec<OutputFile>,
    /// A `mocap view ...` command that plays the files to compare.
    pub viewer_command: Option<String>,
}

impl StageReport {
    fn new(name: &str, title: &str) -> StageReport {
        StageReport {
            name: name.to_string(),
            title: title.to_string(),
            status: StageStatus::Ran,
            message: None,
            seconds: 0.0,
            numbers: Vec::new(),
            facts: Vec::new(),
            notes: Vec::new(),
            outputs: Vec::new(),
            pictures: Vec::new(),
            viewer_command: None,
        }
    }

    /// Records a number (non-finite values are refused by the stage code
    /// before they get here; see [`StageReport::number`]).
    pub fn number(&mut self, name: &str, description: &str, value: f64, unit: &str) {
        self.numbers.push(Number {
            name: name.to_string(),
            description: description.to_string(),
            value,
            unit: unit.to_string(),
        });
    }

    /// The value of a number by name.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.numbers
            .iter()
            .find(|n| n.name == name)
            .map(|n| n.value)
    }

    fn fact(&mut self, name: &str, value: impl Into<String>) {
        self.facts.push((name.to_string(), value.into()));
    }

    fn note(&mut self, text: impl Into<String>) {
        self.notes.push(text.into());
    }

    fn output(&mut self, path: impl Into<PathBuf>, description: &str) {
        self.outputs.push(OutputFile {
            path: path.into(),
            description: description.to_string(),
        });
    }

    fn picture(&mut self, path: impl Into<PathBuf>, description: &str) {
        self.pictures.push(OutputFile {
            path: path.into(),
            description: description.to_string(),
        });
    }
}

/// Why a stage did not produce results.
#[derive(Debug)]
pub enum StageStop {
    ModelMissing(String),
    NotAvailable(String),
    Failed(anyhow::Error),
}

impl From<anyhow::Error> for StageStop {
    fn from(e: anyhow::Error) -> Self {
        StageStop::Failed(e)
    }
}

macro_rules! stage_error_from {
    ($($t:ty),*) => {$(
        impl From<$t> for StageStop {
            fn from(e: $t) -> Self {
                StageStop::Failed(e.into())
            }
        }
    )*};
}
stage_error_from!(
    mocap_core::Error,
    // CleanError and StyleError are both this one type.
    mocap_nn::CapabilityError,
    mocap_search::SearchError,
    std::io::Error
);

/// What a stage body returns.
pub type StageResult = std::result::Result<(), StageStop>;

/// The whole demo's report (`--json` prints it).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DemoReport {
    /// The report folder.
    pub out: PathBuf,
    /// `index.html` in it.
    pub index_html: PathBuf,
    pub sample: PathBuf,
    pub options: DemoOptions,
    /// Wall seconds of the whole demo.
    pub seconds: f64,
    pub stages: Vec<StageReport>,
}

impl DemoReport {
    /// A stage by name.
    pub fn stage(&self, name: &str) -> Option<&StageReport> {
        self.stages.iter().find(|s| s.name == name)
    }
}

/// A model or index file that must be there and non-empty before a stage
/// starts; `what` names it in the message.
pub(crate) fn require_file(path: &Path, what: &str) -> StageResult {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() && m.len() > 0 => Ok(()),
        Ok(m) if m.is_file() => Err(StageStop::ModelMissing(format!(
            "{what} {} is empty (not trained yet?)",
            path.display()
        ))),
        _ => Err(StageStop::ModelMissing(format!(
            "{what} {} is missing",
            path.display()
        ))),
    }
}

/// Runs one stage, catching its errors and panics into its report.
fn run_stage(
    name: &str,
    title: &str,
    progress: &mut dyn FnMut(&str),
    body: impl FnOnce(&mut StageReport) -> StageResult,
) -> StageReport {
    progress(&format!("{title}..."));
    let started = Instant::now();
    let mut report = StageReport::new(name, title);
    let outcome = catch_unwind(AssertUnwindSafe(|| body(&mut report)));
    report.seconds = started.elapsed().as_secs_f64();
    let (status, message) = match outcome {
        Ok(Ok(())) => (StageStatus::Ran, None),
        Ok(Err(StageStop::ModelMissing(m))) => (StageStatus::ModelMissing, Some(m)),
        Ok(Err(StageStop::NotAvailable(m))) => (StageStatus::NotAvailable, Some(m)),
        Ok(Err(StageStop::Failed(e))) => (StageStatus::Failed, Some(format!("{e:#}"))),
        Err(panic) => {
            let text = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            (StageStatus::Failed, Some(format!("panicked: {text}")))
        }
    };
    report.status = status;
    report.message = message;
    if status != StageStatus::Ran {
        // Numbers of a stage that stopped half way are not results.
        report.numbers.clear();
    }
    // Only finite numbers are results; a NaN says the metric could not be
    // computed, which the report states instead of printing NaN.
    let dropped: Vec<String> = report
        .numbers
        .iter()
        .filter(|n| !n.value.is_finite())
        .map(|n| n.name.clone())
        .collect();
    if !dropped.is_empty() {
        report.numbers.retain(|n| n.value.is_finite());
        report.note(format!(
            "not computable on this take: {}",
            dropped.join(", ")
        ));
    }
    let line = match &report.message {
        Some(m) => format!("{title}: {} ({m})", status.label()),
        None => format!("{title}: {} in {:.1} s", status.label(), report.seconds),
    };
    progress(&line);
    report
}

/// Runs the demo (see the crate documentation) and writes the report
/// folder. Errors only when the report folder itself cannot be written.
pub fn run_demo(options: &DemoOptions) -> Result<DemoReport> {
    run_demo_with(options, &mut |_| {})
}

/// [`run_demo`], calling `progress` with a line of text as each stage
/// starts and ends.
pub fn run_demo_with(options: &DemoOptions, progress: &mut dyn FnMut(&str)) -> Result<DemoReport> {
    let started = Instant::now();
    std::fs::create_dir_all(&options.out).map_err(|e| Error::io(&options.out, e))?;
    let context = StageContext {
        options,
        take: RefCell::new(None),
    };
    let stages = vec![
        run_stage("fuse", "Fuse: simulated sensors over UDP", progress, |r| {
            fuse::run(&context, r)
        }),
        run_stage(
            "clean",
            "Clean: the fused take denoised by the shipped model",
            progress,
            |r| clean::run(&context, r),
        ),
        run_stage("feet", "Feet: planted feet held still", progress, |r| {
            feet::run(&context, r)
        }),
        run_stage(
            "search",
            "Search: what is the actor doing?",
            progress,
            |r| search::run(&context, r),
        ),
        run_stage("style", "Style: the walk restyled", progress, |r| {
            style::run(&context, r)
        }),
    ];
    let mut demo = DemoReport {
        out: options.out.clone(),
        index_html: options.out.join("index.html"),
        sample: options.sample.clone(),
        options: options.clone(),
        seconds: 0.0,
        stages,
    };
    demo.seconds = started.elapsed().as_secs_f64();
    report::write(&demo)?;
    Ok(demo)
}

/// What every stage sees.
pub struct StageContext<'a> {
    pub options: &'a DemoOptions,
    /// The latest take of the chain (see [`chain`]).
    take: RefCell<Option<ChainTake>>,
}

impl StageContext<'_> {
    /// The latest take of the chain, or why there is none.
    pub(crate) fn take(&self) -> std::result::Result<ChainTake, StageStop> {
        self.take.borrow().clone().ok_or_else(|| {
            StageStop::NotAvailable(
                "no take to work on: the fuse stage, which starts the chain, did not run".into(),
            )
        })
    }

    /// Makes `take` the one the next stages work on.
    pub(crate) fn pass_on(&self, take: ChainTake) {
        *self.take.borrow_mut() = Some(take);
    }

    /// A path in the report folder (`stage/file`), its folder created.
    pub(crate) fn path(&self, stage: &str, file: &str) -> std::io::Result<PathBuf> {
        let dir = self.options.out.join(stage);
        std::fs::create_dir_all(&dir)?;
        Ok(dir.join(file))
    }

    /// `stage/file` relative to the report folder.
    pub(crate) fn relative(stage: &str, file: &str) -> PathBuf {
        Path::new(stage).join(file)
    }
}

/// Quotes a path for a shell command when it needs it.
pub fn shell_quote(path: &Path) -> String {
    let s = path.display().to_string();
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-+,:=@".contains(c))
    {
        s
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// `mocap view A B ...`.
pub(crate) fn viewer_command(paths: &[&Path]) -> String {
    let mut s = String::from("mocap view");
    for p in paths {
        s.push(' ');
        s.push_str(&shell_quote(p));
    }
    s
}

/// Units of length per metre of a motion, from the height of its first
/// frame (mocap-fuse's guess: centimetres, inches or metres).
pub(crate) fn units_per_metre(motion: &mocap_core::Motion) -> f32 {
    // The first frame only: every stage asks, for every take it compares.
    let poses = mocap_core::kinematics::forward_kinematics_range(motion, 0..1);
    let n = motion.skeleton().joint_count();
    let (mut low, mut high) = (f32::MAX, f32::MIN);
    for j in 0..n {
        let y = poses.position(0, j).y;
        low = low.min(y);
        high = high.max(y);
    }
    mocap_fuse::guess_units_per_metre(high - low)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_files_come_from_the_binary_when_no_source_tree_is_there() {
        let nowhere = tempfile::tempdir().unwrap();
        let cache = tempfile::tempdir().unwrap();
        let absent_root = nowhere.path().join("no-repository");
        for (relative, bytes) in EMBEDDED {
            let path = bundled_from(relative, &[absent_root.as_path()], cache.path());
            assert!(path.starts_with(cache.path()), "{}", path.display());
            assert_eq!(std::fs::read(&path).unwrap(), *bytes);
            // A second call reuses the copy.
            assert_eq!(
                bundled_from(relative, &[absent_root.as_path()], cache.path()),
                path
            );
        }
        // The embedded sample is the real take.
        let sample = bundled_from(
            "samples/dataset-1_walk_normal_001.bvh",
            &[absent_root.as_path()],
            cache.path(),
        );
        let motion = mocap_core::io::bvh::read_bvh(&sample).unwrap();
        assert_eq!(motion.skeleton().joints().len(), 22);
        // A file that is not bundled stays missing.
        let unknown = bundled_from("models/unknown.idx", &[absent_root.as_path()], cache.path());
        assert!(!unknown.exists());
    }

    #[test]
    fn the_source_tree_comes_first() {
        let cache = tempfile::tempdir().unwrap();
        let path = bundled_from(
            "samples/dataset-1_walk_normal_001.bvh",
            &[Path::new(WORKSPACE_ROOT)],
            cache.path(),
        );
        assert!(path.starts_with(WORKSPACE_ROOT));
    }
}
