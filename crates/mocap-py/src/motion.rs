//! `mocap.Motion` and `mocap.Skeleton`: the core's data model seen from
//! Python, its arrays copied into numpy in one piece, and `mocap.read`.

use std::path::PathBuf;

use mocap_core::io::{read_motion, write_motion, MotionSource};
use mocap_core::kinematics::{forward_kinematics_range, frame_pieces};
use mocap_core::rotation::{quat_to_6d, quat_to_expmap, quat_to_mat3, Quat, Vec3};
use mocap_core::{ops, Motion, Skeleton};
use numpy::{AllowTypeChange, PyArray1, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PySlice, PySliceMethods};

use crate::errors::{self, invalid};

/// A numpy float32 array of `shape` that owns `values` (no copy).
fn array<'py>(
    py: Python<'py>,
    values: Vec<f32>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    PyArray1::from_vec(py, values).reshape(shape.to_vec())
}

/// The values of an array-like argument as float32, row-major, after
/// checking its shape: `expected` gives each dimension (`None`: any).
fn float_values(
    array: &PyArrayLikeDyn<'_, f32, AllowTypeChange>,
    what: &str,
    expected: &[Option<usize>],
    shape_text: &str,
) -> PyResult<(Vec<usize>, Vec<f32>)> {
    let view = array.as_array();
    let shape = view.shape().to_vec();
    let fits = shape.len() == expected.len()
        && shape
            .iter()
            .zip(expected)
            .all(|(&n, e)| e.is_none_or(|e| e == n));
    if !fits {
        return Err(invalid(format!(
            "{what} must have the shape {shape_text}, got {shape:?}"
        )));
    }
    Ok((shape, view.iter().copied().collect()))
}

/// The skeleton of a `Motion` or a `Skeleton`.
pub fn skeleton_of(object: &Bound<'_, PyAny>) -> PyResult<Skeleton> {
    if let Ok(motion) = object.cast::<PyMotion>() {
        return Ok(motion.get().inner.skeleton().clone());
    }
    if let Ok(skeleton) = object.cast::<PySkeleton>() {
        return Ok(skeleton.get().inner.clone());
    }
    Err(PyTypeError::new_err(format!(
        "expected a mocap.Motion or a mocap.Skeleton, got {}",
        object.get_type().name()?
    )))
}

/// Parent index of every joint, -1 for a root.
fn parents(skeleton: &Skeleton) -> Vec<i64> {
    skeleton
        .parents()
        .iter()
        .map(|p| p.map_or(-1, |p| p as i64))
        .collect()
}

/// `JOINT.CHANNEL` for every channel, in file order.
fn channel_names(skeleton: &Skeleton) -> Vec<String> {
    skeleton
        .joints()
        .iter()
        .flat_map(|j| {
            j.channels
                .iter()
                .map(|c| format!("{}.{}", j.name, c.name()))
        })
        .collect()
}

/// The rest offsets, joints × 3.
fn offsets<'py>(py: Python<'py>, skeleton: &Skeleton) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let values = skeleton
        .joints()
        .iter()
        .flat_map(|j| j.offset.to_array())
        .collect();
    array(py, values, &[skeleton.joint_count(), 3])
}

/// A skeleton: joints (parents before children), rest offsets and each
/// joint's channels in file order. `len(skeleton)` is its number of joints.
#[pyclass(name = "Skeleton", module = "mocap", frozen)]
pub struct PySkeleton {
    pub inner: Skeleton,
}

#[pymethods]
impl PySkeleton {
    /// Joint names, in skeleton order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joints().iter().map(|j| j.name.clone()).collect()
    }

    /// Parent index of every joint, -1 for a root.
    #[getter]
    fn parents(&self) -> Vec<i64> {
        parents(&self.inner)
    }

    /// Rest offsets from each joint's parent, a float32 array joints × 3.
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        offsets(py, &self.inner)
    }

    /// `JOINT.CHANNEL` for every channel in file order (`Hips.Zrotation`).
    #[getter]
    fn channel_names(&self) -> Vec<String> {
        channel_names(&self.inner)
    }

    fn __len__(&self) -> usize {
        self.inner.joint_count()
    }

    fn __repr__(&self) -> String {
        format!(
            "<mocap.Skeleton: {} joints, {} channels>",
            self.inner.joint_count(),
            self.inner.channel_count()
        )
    }
}

/// The rotation forms `Motion.rotations` gives.
#[derive(Clone, Copy)]
enum RotationKind {
    Quat,
    Matrix,
    Expmap,
    Rot6d,
}

impl RotationKind {
    fn parse(text: &str) -> PyResult<RotationKind> {
        Ok(match text {
            "quat" => RotationKind::Quat,
            "matrix" => RotationKind::Matrix,
            "expmap" => RotationKind::Expmap,
            "6d" => RotationKind::Rot6d,
            other => {
                return Err(invalid(format!(
                    "unknown rotation kind {other:?}: expected \"quat\", \"matrix\", \"expmap\" or \"6d\""
                )))
            }
        })
    }

    /// The trailing dimensions of one rotation.
    fn shape(self) -> &'static [usize] {
        match self {
            RotationKind::Quat => &[4],
            RotationKind::Matrix => &[3, 3],
            RotationKind::Expmap => &[3],
            RotationKind::Rot6d => &[6],
        }
    }

    /// Appends one rotation in this form (quaternions w, x, y, z; matrices
    /// row by row; 6D: the matrix's first two columns).
    fn push(self, q: Quat, out: &mut Vec<f32>) {
        match self {
            RotationKind::Quat => out.extend([q.w, q.x, q.y, q.z]),
            RotationKind::Matrix => {
                let m = quat_to_mat3(q);
                for r in 0..3 {
                    out.extend(m.row(r).to_array());
                }
            }
            RotationKind::Expmap => out.extend(quat_to_expmap(q).to_array()),
            RotationKind::Rot6d => out.extend(quat_to_6d(q)),
        }
    }
}

/// A motion: a skeleton, a frame time and the channel values of every
/// frame (rotations in degrees, positions in the file's units). Immutable:
/// every operation returns a new motion. `len(motion)` is its number of
/// frames; `motion[a:b]` its frames a to b (contiguous slices).
#[pyclass(name = "Motion", module = "mocap", frozen)]
pub struct PyMotion {
    pub inner: Motion,
}

impl PyMotion {
    pub fn new(inner: Motion) -> PyMotion {
        PyMotion { inner }
    }
}

#[pymethods]
impl PyMotion {
    /// A motion of `skeleton` (a Skeleton, or a Motion whose skeleton is
    /// taken) from local joint rotations, quaternions (w, x, y, z) frames ×
    /// joints × 4 as `rotations(kind="quat", space="local")` gives them, and
    /// the root's positions frames × 3 (`positions()[:, 0]`). Rotations are
    /// written as Euler angles in each joint's channel order, each frame's
    /// nearest the previous frame's; a joint without rotation channels keeps
    /// none. Other joints with position channels take `translations`
    /// (frames × joints × 3, as `translations()` gives them) when given, else
    /// their rest offsets. `frame_time` is in seconds.
    #[staticmethod]
    #[pyo3(signature = (skeleton, rotations, root_positions, frame_time, translations = None))]
    fn from_arrays(
        py: Python<'_>,
        skeleton: &Bound<'_, PyAny>,
        rotations: PyArrayLikeDyn<'_, f32, AllowTypeChange>,
        root_positions: PyArrayLikeDyn<'_, f32, AllowTypeChange>,
        frame_time: f64,
        translations: Option<PyArrayLikeDyn<'_, f32, AllowTypeChange>>,
    ) -> PyResult<PyMotion> {
        let skeleton = skeleton_of(skeleton)?;
        let joints = skeleton.joint_count();
        let (shape, quats) = float_values(
            &rotations,
            "rotations",
            &[None, Some(joints), Some(4)],
            &format!("(frames, {joints}, 4): quaternions w, x, y, z of every joint"),
        )?;
        let frames = shape[0];
        let (_, root) = float_values(
            &root_positions,
            "root_positions",
            &[Some(frames), Some(3)],
            &format!("({frames}, 3): the root's position in each of the {frames} frames"),
        )?;
        let translations = translations
            .map(|t| {
                float_values(
                    &t,
                    "translations",
                    &[Some(frames), Some(joints), Some(3)],
                    &format!("({frames}, {joints}, 3)"),
                )
            })
            .transpose()?
            .map(|(_, values)| values);
        if let Some(i) = quats.chunks_exact(4).position(|q| {
            let norm = q.iter().map(|v| v * v).sum::<f32>().sqrt();
            !(norm.is_finite() && norm > 1e-6)
        }) {
            return Err(invalid(format!(
                "rotations[{}, {}] is not a rotation (a quaternion of length zero or not a number)",
                i / joints,
                i % joints
            )));
        }
        let motion = py
            .detach(|| {
                let mut motion = Motion::rest(skeleton, frame_time, frames)?;
                for f in 0..frames {
                    for j in 0..joints {
                        let k = (f * joints + j) * 4;
                        let q = &quats[k..k + 4];
                        let q = Quat::from_xyzw(q[1], q[2], q[3], q[0]).normalize();
                        motion.set_local_rotation(f, j, q);
                        if let Some(t) = &translations {
                            let k = (f * joints + j) * 3;
                            motion.set_local_translation(f, j, Vec3::from_slice(&t[k..k + 3]));
                        }
                    }
                    let r = &root[f * 3..f * 3 + 3];
                    motion.set_local_translation(f, 0, Vec3::from_slice(r));
                }
                Ok(motion)
            })
            .map_err(errors::core)?;
        Ok(PyMotion::new(motion))
    }

    /// The skeleton (joints, offsets, channels).
    #[getter]
    fn skeleton(&self) -> PySkeleton {
        PySkeleton {
            inner: self.inner.skeleton().clone(),
        }
    }

    /// Joint names, in skeleton order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        let joints = self.inner.skeleton().joints();
        joints.iter().map(|j| j.name.clone()).collect()
    }

    /// Parent index of every joint, -1 for a root.
    #[getter]
    fn parents(&self) -> Vec<i64> {
        parents(self.inner.skeleton())
    }

    /// Rest offsets from each joint's parent, a float32 array joints × 3.
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        offsets(py, self.inner.skeleton())
    }

    /// Seconds between frames, as written in the file.
    #[getter]
    fn frame_time(&self) -> f64 {
        self.inner.frame_time()
    }

    /// Frames per second.
    #[getter]
    fn fps(&self) -> f64 {
        self.inner.fps()
    }

    /// Length of the take in seconds.
    #[getter]
    fn duration(&self) -> f64 {
        self.inner.duration()
    }

    /// The channel values, a float32 array frames × channels (a copy):
    /// rotations in degrees, positions in the file's units, columns in
    /// file order (`channel_names`).
    #[getter]
    fn channels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let shape = [
            self.inner.frame_count(),
            self.inner.skeleton().channel_count(),
        ];
        PyArray1::from_slice(py, self.inner.values()).reshape(shape.to_vec())
    }

    /// `JOINT.CHANNEL` for every column of `channels` (`Hips.Zrotation`).
    #[getter]
    fn channel_names(&self) -> Vec<String> {
        channel_names(self.inner.skeleton())
    }

    /// Global joint positions by forward kinematics, a float32 array
    /// frames × joints × 3 in the file's units.
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let motion = &self.inner;
        let (frames, joints) = (motion.frame_count(), motion.skeleton().joint_count());
        let values = py.detach(|| {
            let mut out = Vec::with_capacity(frames * joints * 3);
            for piece in frame_pieces(frames) {
                let poses = forward_kinematics_range(motion, piece);
                out.extend(poses.positions.iter().flat_map(|p| p.to_array()));
            }
            out
        });
        array(py, values, &[frames, joints, 3])
    }

    /// Joint rotations of every frame, float32: `kind` "quat" (frames ×
    /// joints × 4, w, x, y, z), "matrix" (frames × joints × 3 × 3, row by
    /// row: a matrix times a column vector rotates it), "expmap" (× 3, axis
    /// times angle in radians) or "6d" (× 6, the matrix's first two
    /// columns); `space` "local" (relative to the parent, as the channels
    /// hold them) or "global" (forward kinematics).
    #[pyo3(signature = (kind = "quat", space = "local"))]
    fn rotations<'py>(
        &self,
        py: Python<'py>,
        kind: &str,
        space: &str,
    ) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let kind = RotationKind::parse(kind)?;
        let global = match space {
            "local" => false,
            "global" => true,
            other => {
                return Err(invalid(format!(
                    "unknown rotation space {other:?}: expected \"local\" or \"global\""
                )))
            }
        };
        let motion = &self.inner;
        let (frames, joints) = (motion.frame_count(), motion.skeleton().joint_count());
        let size: usize = kind.shape().iter().product();
        let values = py.detach(|| {
            let mut out = Vec::with_capacity(frames * joints * size);
            if global {
                for piece in frame_pieces(frames) {
                    let poses = forward_kinematics_range(motion, piece);
                    for &q in &poses.rotations {
                        kind.push(q, &mut out);
                    }
                }
            } else {
                for f in 0..frames {
                    for j in 0..joints {
                        kind.push(motion.local_rotation(f, j), &mut out);
                    }
                }
            }
            out
        });
        let mut shape = vec![frames, joints];
        shape.extend(kind.shape());
        array(py, values, &shape)
    }

    /// Local joint translations (position channels where a joint has them,
    /// else its rest offset), a float32 array frames × joints × 3.
    fn translations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let motion = &self.inner;
        let (frames, joints) = (motion.frame_count(), motion.skeleton().joint_count());
        let values = py.detach(|| {
            let mut out = Vec::with_capacity(frames * joints * 3);
            for f in 0..frames {
                for j in 0..joints {
                    out.extend(motion.local_translation(f, j).to_array());
                }
            }
            out
        });
        array(py, values, &[frames, joints, 3])
    }

    /// Writes the motion to `path`, atomically: BVH (`.bvh`) or glTF (`.glb`,
    /// `.gltf`: a skinned body in metres, Y up).
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let motion = &self.inner;
        py.detach(|| write_motion(&path, motion))
            .map_err(errors::core)
    }

    fn __len__(&self) -> usize {
        self.inner.frame_count()
    }

    /// `motion[a:b]`: the frames a to b, as a new motion (negative and
    /// missing bounds as for lists; the step must be 1).
    fn __getitem__(&self, key: &Bound<'_, PyAny>) -> PyResult<PyMotion> {
        let Ok(slice) = key.cast::<PySlice>() else {
            return Err(PyTypeError::new_err(
                "a motion is indexed by a slice of frames, motion[a:b]; for one frame's values \
                 use motion.channels[i]",
            ));
        };
        let n = self.inner.frame_count();
        let indices = slice.indices(n as isize)?;
        if indices.step != 1 {
            return Err(invalid(format!(
                "motion[a:b:{}]: only contiguous frames can be sliced; to change the frame \
                 rate use mocap.resample(motion, fps)",
                indices.step
            )));
        }
        let range = indices.start as usize..(indices.stop.max(indices.start)) as usize;
        ops::trim(&self.inner, range)
            .map(PyMotion::new)
            .map_err(errors::core)
    }

    fn __repr__(&self) -> String {
        let m = &self.inner;
        format!(
            "<mocap.Motion: {} joints, {} frames at {:.4} fps ({:.2} s)>",
            m.skeleton().joint_count(),
            m.frame_count(),
            m.fps(),
            m.duration()
        )
    }
}

/// Reads a motion file: BVH, an ASF skeleton with its AMC motion
/// (`read("x.asf", "x.amc")`, or the AMC alone with its ASF beside it), or
/// a sensor recording (`.jsonl`, NTU `.skeleton`), or glTF (`.glb`, `.gltf`:
/// the first skin and its first animation).
#[pyfunction]
#[pyo3(signature = (path, amc = None))]
pub fn read(py: Python<'_>, path: PathBuf, amc: Option<PathBuf>) -> PyResult<PyMotion> {
    let motion = py.detach(|| match amc {
        None => read_motion(&path),
        Some(amc) => {
            let sources = MotionSource::group(&[path.clone(), amc])?;
            match sources.as_slice() {
                [source] => source.read(),
                _ => Err(mocap_core::Error::Invalid(format!(
                    "{}: give an .asf skeleton and one .amc motion of it",
                    path.display()
                ))),
            }
        }
    });
    motion.map(PyMotion::new).map_err(errors::core)
}
