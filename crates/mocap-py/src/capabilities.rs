//! The capabilities from Python, each through its crate's front door and the
//! entry point its CLI command calls: `clean`, `feet`, `retarget`,
//! `resample`, `mirror`, `mocap.search.Index`, `mocap.style.apply`,
//! `mocap.fuse.run`. Every call runs with the GIL released.
//!
//! `style apply` and `fuse run` are file-to-file entry points: their motions
//! go through a temporary folder, so that they run exactly as the commands
//! do (rig checks, retargeting, the floor).

use std::path::{Path, PathBuf};

use mocap_clean::{filter_motion, CleanError, CleanModel, Filter, ModelFile};
use mocap_core::io::{read_motion, write_motion};
use mocap_core::retarget::Retargeting;
use mocap_core::{ops, Motion};
use mocap_feet::{plant_feet_detected, FeetOptions};
use mocap_fuse::{
    fuse_files, BoneLengthSource, BvhWorld, FuseFilesOptions, FusionOptions, OutputFiles,
};
use mocap_nn::device::DeviceChoice;
use mocap_search::{motion_features, Ranking};
use mocap_style::{apply as style_apply_files, ApplyOptions};
use numpy::{PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::errors::{self, invalid};
use crate::motion::{skeleton_of, PyMotion};

/// Denoises a motion as `mocap clean apply` does: with the model shipped
/// with mocap (default), a model file (`model`, from `mocap clean train` or
/// `fit-wiener`), or a classical filter (`filter`, the CLI's SPEC:
/// "butterworth:ORDER:HZ", "butterworth-gcv:ORDER",
/// "savitzky-golay:WINDOW:POLYORDER", "median:WINDOW",
/// "one-euro:MIN_HZ:BETA:D_HZ"). Only rotations change. Runs on the CPU.
#[pyfunction]
#[pyo3(signature = (motion, model = None, filter = None))]
pub fn clean(
    py: Python<'_>,
    motion: PyRef<'_, PyMotion>,
    model: Option<PathBuf>,
    filter: Option<String>,
) -> PyResult<PyMotion> {
    let filter: Option<Filter> = filter
        .map(|spec| spec.parse())
        .transpose()
        .map_err(errors::capability)?;
    if model.is_some() && filter.is_some() {
        return Err(invalid("clean: give a model or a filter, not both"));
    }
    let input = &motion.inner;
    let device = DeviceChoice::Cpu;
    let cleaned = py.detach(|| -> Result<Motion, CleanError> {
        match (model, filter) {
            (_, Some(filter)) => filter_motion(input, &filter),
            (Some(path), None) => Ok(ModelFile::load(&path, device)?.clean(input, None)?.0),
            (None, None) => {
                let model = ModelFile::Network(Box::new(CleanModel::load_default(device)?));
                Ok(model.clean(input, None)?.0)
            }
        }
    });
    cleaned.map(PyMotion::new).map_err(errors::capability)
}

/// Holds planted feet still and above the floor, as `mocap feet` does:
/// contacts found from the motion, legs turned by two-bone IK. `floor`: the
/// floor's height along the up axis in the file's units (default:
/// estimated from the contacts).
#[pyfunction]
#[pyo3(signature = (motion, floor = None))]
pub fn feet(py: Python<'_>, motion: PyRef<'_, PyMotion>, floor: Option<f32>) -> PyResult<PyMotion> {
    let options = FeetOptions {
        floor,
        ..FeetOptions::default()
    };
    let input = &motion.inner;
    py.detach(|| plant_feet_detected(input, &options))
        .map(|(planted, _, _)| PyMotion::new(planted))
        .map_err(errors::core)
}

/// The motion played by another rig (`onto`: a Motion or a Skeleton of it),
/// body parts found by joint name on both, as `mocap convert --retarget`.
#[pyfunction]
pub fn retarget(
    py: Python<'_>,
    motion: PyRef<'_, PyMotion>,
    onto: &Bound<'_, PyAny>,
) -> PyResult<PyMotion> {
    let target = skeleton_of(onto)?;
    let input = &motion.inner;
    py.detach(|| Retargeting::detect(input.skeleton(), &target)?.apply(input))
        .map(PyMotion::new)
        .map_err(errors::core)
}

/// The motion at `fps` frames per second over the same time span (rotations
/// by slerp, translations linearly), as `mocap convert --fps`.
#[pyfunction]
pub fn resample(py: Python<'_>, motion: PyRef<'_, PyMotion>, fps: f64) -> PyResult<PyMotion> {
    let input = &motion.inner;
    py.detach(|| ops::resample_fps(input, fps))
        .map(PyMotion::new)
        .map_err(errors::core)
}

/// The mirror image: left and right swapped, the world reflected across the
/// rig's lateral axis, as `mocap convert --mirror`.
#[pyfunction]
pub fn mirror(py: Python<'_>, motion: PyRef<'_, PyMotion>) -> PyResult<PyMotion> {
    let input = &motion.inner;
    py.detach(|| ops::mirror_auto(input))
        .map(PyMotion::new)
        .map_err(errors::core)
}

/// A motion argument that may be a file: a Motion or a path.
enum Input<'a> {
    File(PathBuf),
    Motion(&'a Motion),
}

impl<'a> Input<'a> {
    fn of(object: &'a Bound<'_, PyAny>, what: &str) -> PyResult<Input<'a>> {
        if let Ok(motion) = object.cast::<PyMotion>() {
            return Ok(Input::Motion(&motion.get().inner));
        }
        object.extract::<PathBuf>().map(Input::File).map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "{what}: expected a mocap.Motion or a path"
            ))
        })
    }

    /// The file to give a file-to-file entry point: the path, or the motion
    /// written as `name` in `folder`.
    fn file(&self, folder: &Path, name: &str) -> mocap_core::Result<PathBuf> {
        match self {
            Input::File(path) => Ok(path.clone()),
            Input::Motion(motion) => {
                let path = folder.join(name);
                write_motion(&path, motion)?;
                Ok(path)
            }
        }
    }
}

/// A temporary folder for the files of a file-to-file entry point.
fn temporary_folder() -> PyResult<tempfile::TempDir> {
    tempfile::Builder::new()
        .prefix("mocap-py-")
        .tempdir()
        .map_err(errors::temporary)
}

/// `mocap.style.apply`: see python/mocap/style.py.
#[pyfunction]
#[pyo3(signature = (source, style, strength = 1.0, model = None))]
pub fn style_apply(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    style: &Bound<'_, PyAny>,
    strength: f32,
    model: Option<PathBuf>,
) -> PyResult<PyMotion> {
    let source = Input::of(source, "source")?;
    let style = Input::of(style, "style")?;
    let folder = temporary_folder()?;
    let dir = folder.path();
    let restyled = py.detach(|| -> Result<Motion, mocap_style::StyleError> {
        let out = dir.join("restyled.bvh");
        let mut options = ApplyOptions::new(
            source.file(dir, "source.bvh")?,
            style.file(dir, "style.bvh")?,
            &out,
        );
        options.strength = strength;
        options.model = model;
        style_apply_files(&options)?;
        Ok(read_motion(&out)?)
    });
    restyled.map(PyMotion::new).map_err(errors::capability)
}

/// `mocap.fuse.run`: see python/mocap/fuse.py.
#[pyfunction]
#[pyo3(signature = (recordings, calib, body = None, method = "best", fps = 30.0))]
pub fn fuse_run(
    py: Python<'_>,
    recordings: Vec<PathBuf>,
    calib: PathBuf,
    body: Option<PathBuf>,
    method: &str,
    fps: f64,
) -> PyResult<PyMotion> {
    let fusion = FusionOptions::preset(method).map_err(errors::core)?;
    let folder = temporary_folder()?;
    let out = folder.path().join("fused.bvh");
    let options = FuseFilesOptions {
        recordings,
        calibration: calib,
        body,
        outputs: OutputFiles {
            paths: vec![out.clone()],
            bvh_units_per_metre: 100.0,
            bvh_lengths: BoneLengthSource::Fused,
            feet: None,
            bvh_world: BvhWorld::Floor,
        },
        fusion,
        fps,
    };
    py.detach(|| {
        fuse_files(&options)?;
        read_motion(&out)
    })
    .map(PyMotion::new)
    .map_err(errors::core)
}

/// One clip of a search index to build, as `mocap.batch.index` passes it:
/// its path, label and performer.
type LabelledClip = (PathBuf, String, Option<String>);

/// The clips `mocap search index` would index for `inputs` (files and
/// folders), in its order, with their labels from a label file or a
/// file-name pattern, and the rule's name: `mocap.batch.index`'s first
/// step, before any work is sent out.
#[pyfunction]
#[pyo3(signature = (inputs, labels = None, labels_from_name = None))]
pub fn search_clips(
    inputs: Vec<PathBuf>,
    labels: Option<PathBuf>,
    labels_from_name: Option<String>,
) -> PyResult<(Vec<LabelledClip>, String)> {
    let (rule, rule_name) =
        mocap_search::LabelRule::from_options(labels.as_deref(), labels_from_name.as_deref())
            .map_err(errors::search)?;
    let clips = mocap_search::motion_files(&inputs)
        .and_then(|paths| {
            paths
                .into_iter()
                .map(|path| {
                    let label = rule.label_of(&path)?;
                    Ok((path, label.label, label.performer))
                })
                .collect()
        })
        .map_err(errors::search)?;
    Ok((clips, rule_name))
}

/// One clip's per-frame pose features (frames x values, float32) and frame
/// rate: the work of one `mocap.batch.index` task.
#[pyfunction]
pub fn search_features<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Bound<'py, numpy::PyArray2<f32>>, f64)> {
    let (features, fps) = py
        .detach(|| mocap_search::load_features(&path))
        .map_err(errors::search)?;
    let dim = features.dim;
    let frames = features.frame_count();
    let array = numpy::PyArray1::from_vec(py, features.values).reshape([frames, dim])?;
    Ok((array, fps))
}

/// Builds a search index from labelled clips and their features (from
/// [`search_clips`] and [`search_features`]) and writes it to `output`,
/// as `mocap search index` with the same settings does: the same clips in
/// the same order give the same file, byte for byte. Returns the numbers
/// of clips and classes.
#[pyfunction]
#[pyo3(signature = (clips, features, rule_name, output, trees = 100, candidates = 64, min_entropy = 0.0, frames = 10, seed = 1, bootstrap = true))]
#[allow(clippy::too_many_arguments)]
pub fn search_build_index(
    py: Python<'_>,
    clips: Vec<LabelledClip>,
    features: Vec<(numpy::PyReadonlyArray2<'_, f32>, f64)>,
    rule_name: String,
    output: PathBuf,
    trees: usize,
    candidates: usize,
    min_entropy: f32,
    frames: usize,
    seed: u64,
    bootstrap: bool,
) -> PyResult<(usize, usize)> {
    if clips.len() != features.len() {
        return Err(invalid(format!(
            "{} clips but {} feature arrays",
            clips.len(),
            features.len()
        )));
    }
    let clips: Vec<mocap_search::Clip> = clips
        .into_iter()
        .zip(features)
        .map(|((path, label, performer), (values, fps))| {
            let dim = values.shape()[1];
            mocap_search::Clip {
                path,
                label,
                performer,
                fps,
                features: mocap_search::FeatureSequence {
                    dim,
                    values: values.as_array().iter().copied().collect(),
                },
            }
        })
        .collect();
    let mut config = mocap_search::IndexConfig {
        frames,
        ..Default::default()
    };
    config.forest.trees = trees;
    config.forest.tree.candidates_per_node = Some(candidates);
    config.forest.tree.min_entropy = min_entropy;
    config.forest.seed = seed;
    config.forest.bootstrap = bootstrap;
    py.detach(|| {
        let index = mocap_search::build_index(&clips, &rule_name, &config, false)?;
        index.save(&output)?;
        Ok((index.clips.len(), index.classes.len()))
    })
    .map_err(errors::search)
}

/// The search library shipped with mocap (Bandai contents), for
/// `Index.bundled()`.
const BUNDLED_INDEX: &[u8] = include_bytes!("../../../models/search-bandai-content.idx");

/// A motion library for retrieval by example (`mocap search index` writes
/// one): a random forest over relative pose features and the library's
/// clips. `len(index)` is its number of clips.
#[pyclass(name = "Index", module = "mocap.search", frozen)]
pub struct PyIndex {
    inner: mocap_search::Index,
}

#[pymethods]
impl PyIndex {
    /// Reads an index file written by `mocap search index`.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyIndex> {
        py.detach(|| mocap_search::Index::load(&path))
            .map(|inner| PyIndex { inner })
            .map_err(errors::search)
    }

    /// The index shipped with mocap (models/search-bandai-content.idx: the
    /// Bandai dataset's contents). Its clip paths are as stored, relative to
    /// the repository's models/ folder.
    #[staticmethod]
    fn bundled(py: Python<'_>) -> PyResult<PyIndex> {
        let path = Path::new("models/search-bandai-content.idx");
        py.detach(|| mocap_search::Index::from_bytes(BUNDLED_INDEX, path))
            .map(|inner| PyIndex { inner })
            .map_err(errors::search)
    }

    /// The class labels the forest knows.
    #[getter]
    fn classes(&self) -> Vec<String> {
        self.inner.classes.clone()
    }

    /// Classifies a clip (a Motion or a path) and ranks the library's clips
    /// by similarity (the best `top`), as `mocap search query`. `rank`:
    /// "histogram" (default), "proximity" or "features".
    #[pyo3(signature = (clip, top = 10, rank = "histogram"))]
    fn query(
        &self,
        py: Python<'_>,
        clip: &Bound<'_, PyAny>,
        top: usize,
        rank: &str,
    ) -> PyResult<PyQueryResult> {
        let ranking: Ranking = rank.parse().map_err(errors::search)?;
        let clip = Input::of(clip, "clip")?;
        let index = &self.inner;
        let report = py.detach(|| match clip {
            Input::File(path) => index.query_file(&path, top, ranking),
            Input::Motion(motion) => {
                let features = motion_features(motion)?;
                Ok(index.query("<motion>", &features, top, ranking))
            }
        });
        report
            .map(|report| PyQueryResult { report })
            .map_err(errors::search)
    }

    fn __len__(&self) -> usize {
        self.inner.clips.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "<mocap.search.Index: {} clips of {} classes>",
            self.inner.clips.len(),
            self.inner.classes.len()
        )
    }
}

/// The answer to a query: the predicted label, every label's probability
/// and the ranked library clips.
#[pyclass(name = "QueryResult", module = "mocap.search", frozen)]
pub struct PyQueryResult {
    report: mocap_search::QueryReport,
}

#[pymethods]
impl PyQueryResult {
    /// The predicted class label.
    #[getter]
    fn label(&self) -> String {
        self.report.predicted.clone()
    }

    /// The predicted label's probability.
    #[getter]
    fn probability(&self) -> f32 {
        self.report.probability
    }

    /// Every label with a non-zero probability, most likely first.
    #[getter]
    fn probabilities(&self) -> Vec<(String, f32)> {
        let p = &self.report.probabilities;
        p.iter().map(|c| (c.class.clone(), c.probability)).collect()
    }

    /// The nearest library clips, best first.
    #[getter]
    fn matches(&self) -> Vec<PyMatch> {
        let matches = self.report.matches.iter().cloned();
        matches.map(|inner| PyMatch { inner }).collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "<mocap.search.QueryResult: {} (probability {:.2}), {} matches>",
            self.report.predicted,
            self.report.probability,
            self.report.matches.len()
        )
    }

    fn __str__(&self) -> String {
        self.report.to_text()
    }
}

/// One ranked library clip.
#[pyclass(name = "Match", module = "mocap.search", frozen)]
pub struct PyMatch {
    inner: mocap_search::Match,
}

#[pymethods]
impl PyMatch {
    /// 1 for the nearest clip.
    #[getter]
    fn rank(&self) -> usize {
        self.inner.rank
    }

    /// The clip's file.
    #[getter]
    fn path(&self) -> String {
        self.inner.path.clone()
    }

    /// The clip's class label.
    #[getter]
    fn label(&self) -> String {
        self.inner.label.clone()
    }

    /// Its distance to the query (smaller is nearer).
    #[getter]
    fn distance(&self) -> f32 {
        self.inner.distance
    }

    fn __repr__(&self) -> String {
        format!(
            "<mocap.search.Match {}: {} ({}, distance {:.3})>",
            self.inner.rank, self.inner.path, self.inner.label, self.inner.distance
        )
    }
}
