//! Calibrated cameras (OpenCV's pinhole model) and the files that describe
//! them.
//!
//! - [`Camera`]: one camera, its projection ([`Camera::project`]) and the
//!   inverse of its lens distortion ([`Camera::undistort`]);
//! - [`CameraRig`]: the cameras of one capture;
//! - [`read_calibration`]: Pose2Sim TOML, OpenCV FileStorage YAML (EasyMocap's
//!   layout, OpenCV's calibration sample) and JSON, each read into one tree
//!   of values with their lines ([`Node`]) so that one set of functions reads
//!   and checks the cameras of all three;
//! - [`write_calibration_toml`]: Pose2Sim TOML.

use std::borrow::Cow;
use std::collections::HashSet;
use std::fmt;
use std::path::Path;

use glam::{DMat3, DQuat, DVec2, DVec3};
use mocap_core::{Error, Result};

/// Points closer than this (metres, along the camera's axis) to the plane of
/// the camera's centre, or behind it, have no projection.
const MIN_DEPTH: f64 = 1e-9;

/// At most this many fixed-point steps in [`Camera::undistort`] (OpenCV's
/// `undistortPoints` takes 5 unless told otherwise).
const UNDISTORT_STEPS: usize = 20;

/// [`Camera::undistort`] stops once distorting its estimate again lands this
/// close to the pixel's distorted coordinates (normalized units: about
/// 2e-9 px for a focal length of 2000 px).
const UNDISTORT_TOLERANCE: f64 = 1e-12;

/// How far RᵀR may be from the identity (its largest entry) for R to count
/// as a rotation. Files store matrices in single precision at times, which
/// leaves about 1e-7.
const ROTATION_TOLERANCE: f64 = 1e-5;

/// How far K's fixed entries may be from 0 and 1.
const INTRINSICS_TOLERANCE: f64 = 1e-9;

/// One calibrated pinhole camera (OpenCV model).
///
/// OpenCV's pinhole camera with its five-coefficient lens distortion
/// (Brown–Conrady: radial k1 k2 k3, tangential p1 p2), the model of
/// `cv::calibrateCamera` and `cv::projectPoints` as OpenCV's calib3d
/// documentation ("Camera Calibration and 3D Reconstruction") writes it. A
/// world point X (metres) is seen at the pixel (u, v):
///
/// ```text
/// (x_c, y_c, z_c) = R X + t                world to camera
/// x = x_c / z_c,   y = y_c / z_c           normalized image coordinates
/// r² = x² + y²
/// x' = x (1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2 x²)
/// y' = y (1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2 y²) + 2 p2 x y
/// u = fx x' + cx,  v = fy y' + cy          K = (fx, 0, cx; 0, fy, cy; 0, 0, 1)
/// ```
///
/// The camera looks down its +z axis, with x to the right of the image and y
/// down it, as OpenCV's cameras do.
///
/// Cameras read by [`read_calibration`] have passed its checks (finite
/// numbers, positive focal lengths, K of the form above, a rotation); one
/// built by hand should meet them too, or [`write_calibration_toml`] refuses
/// it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Camera {
    /// The camera's name in its calibration file.
    pub name: String,
    /// Image size in pixels: [width, height] (`[0, 0]` when the file did not
    /// say).
    pub size: [f64; 2],
    /// Intrinsic matrix K (fx, 0, cx; 0, fy, cy; 0, 0, 1).
    pub matrix: DMat3,
    /// OpenCV distortion (k1, k2, p1, p2, k3); missing ones are 0.
    pub distortion: [f64; 5],
    /// World-to-camera rotation R and translation t (metres): x_cam = R
    /// x_world + t.
    pub rotation: DMat3,
    /// World-to-camera translation t (metres): the world's origin in the
    /// camera's frame.
    pub translation: DVec3,
}

impl Camera {
    /// A world point (metres) in the camera's frame: R x_world + t.
    pub fn to_camera(&self, world: DVec3) -> DVec3 {
        self.rotation * world + self.translation
    }

    /// Pixel coordinates of a world point, with distortion; None when the
    /// point is not in front of the camera (z <= 1e-9).
    pub fn project(&self, world: DVec3) -> Option<DVec2> {
        let p = self.to_camera(world);
        // A NaN depth (from a NaN point) has no projection either.
        if p.z.is_nan() || p.z <= MIN_DEPTH {
            return None;
        }
        let normalized = DVec2::new(p.x / p.z, p.y / p.z);
        Some(self.apply_intrinsics(self.distort(normalized)))
    }

    /// Normalized, undistorted image coordinates (x/z, y/z) of a pixel: the
    /// inverse of distortion, by fixed-point iteration as OpenCV's
    /// `undistortPoints` (20 iterations or until converged).
    ///
    /// With (x'', y'') the pixel's distorted normalized coordinates
    /// (K⁻¹ applied), each step solves the model for (x, y) with the radial
    /// factor and the tangential terms taken at the previous estimate:
    /// `x = (x'' − Δx(x, y)) / (1 + k1 r² + k2 r⁴ + k3 r⁶)`, the same for y.
    /// It stops when distorting the estimate gives the pixel back to 1e-12
    /// (normalized units). As OpenCV does, when the radial factor is not
    /// positive (far outside the image, where the model folds back) the
    /// distorted coordinates are returned unchanged.
    pub fn undistort(&self, pixel: DVec2) -> DVec2 {
        let [k1, k2, p1, p2, k3] = self.distortion;
        let distorted = self.remove_intrinsics(pixel);
        let mut point = distorted;
        for _ in 0..UNDISTORT_STEPS {
            // One evaluation of the model per step serves both the test
            // (does the estimate distort back to the pixel?) and the update.
            let r2 = point.length_squared();
            let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
            if radial.is_nan() || radial <= 0.0 {
                return distorted;
            }
            let shift = tangential(point, p1, p2);
            if (point * radial + shift - distorted).length() < UNDISTORT_TOLERANCE {
                break;
            }
            point = (distorted - shift) / radial;
        }
        point
    }

    /// The camera's centre in world coordinates (-R^T t).
    pub fn centre(&self) -> DVec3 {
        -(self.rotation.transpose() * self.translation)
    }

    /// Rows of [R | t] (3x4), for DLT in normalized coordinates.
    pub fn pose_matrix(&self) -> [[f64; 4]; 3] {
        std::array::from_fn(|i| {
            let row = self.rotation.row(i);
            [row.x, row.y, row.z, self.translation[i]]
        })
    }

    /// OpenCV's distortion of normalized coordinates: (x, y) to (x', y') in
    /// the formula of [`Camera`]'s documentation.
    fn distort(&self, point: DVec2) -> DVec2 {
        let [k1, k2, p1, p2, k3] = self.distortion;
        let r2 = point.length_squared();
        let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        point * radial + tangential(point, p1, p2)
    }

    /// K applied to distorted normalized coordinates.
    fn apply_intrinsics(&self, distorted: DVec2) -> DVec2 {
        let (focal, centre) = self.focal_and_principal_point();
        distorted * focal + centre
    }

    /// K⁻¹ applied to a pixel: its distorted normalized coordinates.
    fn remove_intrinsics(&self, pixel: DVec2) -> DVec2 {
        let (focal, centre) = self.focal_and_principal_point();
        (pixel - centre) / focal
    }

    /// (fx, fy) and (cx, cy) of K (glam's matrices are stored by columns).
    fn focal_and_principal_point(&self) -> (DVec2, DVec2) {
        let k = &self.matrix;
        (
            DVec2::new(k.x_axis.x, k.y_axis.y),
            DVec2::new(k.z_axis.x, k.z_axis.y),
        )
    }
}

/// The tangential (decentering) terms of OpenCV's distortion at normalized
/// coordinates: (2 p1 x y + p2 (r² + 2 x²), p1 (r² + 2 y²) + 2 p2 x y).
fn tangential(point: DVec2, p1: f64, p2: f64) -> DVec2 {
    let (x, y) = (point.x, point.y);
    let r2 = x * x + y * y;
    DVec2::new(
        2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
        p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
    )
}

/// The cameras of one capture, in file order.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CameraRig {
    /// The cameras, in the order of their calibration file.
    pub cameras: Vec<Camera>,
}

impl CameraRig {
    /// How many cameras.
    pub fn len(&self) -> usize {
        self.cameras.len()
    }

    /// Whether the rig has no camera.
    pub fn is_empty(&self) -> bool {
        self.cameras.is_empty()
    }
}

/// Reads a calibration by extension: `.toml` (Pose2Sim), `.yml`/`.yaml`
/// (OpenCV FileStorage YAML), `.json` (OpenCV-style JSON, see below).
///
/// - `.toml`, Pose2Sim's: one table per camera (`[cam_01]`) with `name`,
///   `size = [width, height]`, `matrix` (K, 3 rows), `distortions` (k1 k2 p1
///   p2, and k3 when there is one), `rotation` (a Rodrigues vector: the
///   rotation axis times its angle in radians), `translation` (metres) and
///   `fisheye = false`. The rotation and translation take world points to the
///   camera (x_cam = R x_world + t). Pose2Sim's `[metadata]` table is skipped;
///   `fisheye = true` is refused (OpenCV's fisheye model is not supported).
/// - `.yml` / `.yaml`, OpenCV FileStorage (`%YAML:1.0`, matrices as
///   `!!opencv-matrix` maps of `rows`, `cols`, `dt` and `data`), in two
///   layouts:
///   - EasyMocap's, with its `intri.yml` and `extri.yml` merged into one file:
///     a `names` list and for each name `K_<name>` (3x3), `dist_<name>` (1x5,
///     optional), `Rot_<name>` (3x3) or `R_<name>` (Rodrigues, 3x1), and
///     `T_<name>` (3x1). Without `names`, the cameras are those of the
///     `K_<name>` keys, in file order.
///   - the output of OpenCV's calibration sample, one camera named after the
///     file: `camera_matrix`, `distortion_coefficients` (optional),
///     `image_width` and `image_height` (optional), and either `rvec` or `R`
///     with `tvec` or `T` (without them the camera is at the world's origin,
///     looking down its z axis).
/// - `.json`: an object of cameras keyed by name, each with the keys and
///   meaning of the TOML tables (`rotation` may also be 3 rows of 3
///   numbers), or the same object under a top-level `"cameras"` key. A
///   `metadata` entry is skipped, as in the TOML.
///
/// Everywhere a matrix may be written as rows of numbers, one flat list in
/// row order, or an `!!opencv-matrix` map. Distortion lists of OpenCV's
/// longer models (8, 12 or 14 numbers) are read when their coefficients past
/// k3 are zero. Image sizes may be absent (then `[0, 0]`). Cameras keep the
/// file's order.
///
/// The file must hold at least one camera, and each is checked as it is
/// read: every number finite, the focal lengths positive, K = (fx, 0, cx; 0,
/// fy, cy; 0, 0, 1), the rotation a rotation (RᵀR = I, det R = +1), the
/// names unique. An error names the file, the line and column where the
/// format gives them, the camera and what was expected.
pub fn read_calibration(path: &Path) -> Result<CameraRig> {
    let format = Format::of(path)?;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = decode(&bytes, path)?;
    parse_calibration(text, format, path)
}

/// Writes the rig as Pose2Sim TOML (the same keys it reads), atomically.
///
/// One `[name]` table per camera, in the rig's order, then Pose2Sim's
/// `[metadata]` table. Numbers are written so that they read back exactly;
/// rotations are written as Rodrigues vectors, which read back to within
/// about 1e-15. A rig that could not be read back is refused: no camera, two
/// cameras of one name, a camera named `metadata`, or one that fails the
/// reader's checks.
pub fn write_calibration_toml(rig: &CameraRig, path: &Path) -> Result<()> {
    let text = pose2sim_toml(rig)
        .map_err(|message| Error::Invalid(format!("{}: {message}", path.display())))?;
    mocap_core::io::atomic::write_bytes_atomically(path, text.as_bytes())
}

// ---------------------------------------------------------------------------
// Reading: the formats, and the tree they are read into.

/// The calibration formats, by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Format {
    Pose2SimToml,
    OpenCvYaml,
    Json,
}

impl Format {
    /// The format of a calibration file, by its extension (any case).
    pub(crate) fn of(path: &Path) -> Result<Format> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("toml") => Ok(Format::Pose2SimToml),
            Some("yml" | "yaml") => Ok(Format::OpenCvYaml),
            Some("json") => Ok(Format::Json),
            _ => Err(Error::Invalid(format!(
                "{}: unknown calibration format: expected a .toml (Pose2Sim), \
                 .yml or .yaml (OpenCV FileStorage) or .json file",
                path.display()
            ))),
        }
    }

    /// What a file of this format holds, for "no camera" messages.
    fn expected(self) -> &'static str {
        match self {
            Format::Pose2SimToml => {
                "one table per camera ([cam_01] with name, size, matrix, distortions, \
                 rotation, translation)"
            }
            Format::OpenCvYaml => {
                "`names` and `K_<name>`, `dist_<name>`, `Rot_<name>` or `R_<name>`, \
                 `T_<name>` for each (EasyMocap), or one camera's `camera_matrix` \
                 (OpenCV's calibration)"
            }
            Format::Json => {
                "an object of cameras keyed by name (size, matrix, distortions, rotation, \
                 translation), at the top or under \"cameras\""
            }
        }
    }
}

/// The file's text: UTF-8, without a byte-order mark.
fn decode<'a>(bytes: &'a [u8], path: &Path) -> Result<&'a str> {
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok(text.strip_prefix('\u{feff}').unwrap_or(text)),
        Err(e) => {
            let valid = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or_default();
            let (line, column) = Lines::new(valid).locate(valid.len());
            Err(Error::parse(path, line, column, "not UTF-8 text"))
        }
    }
}

/// Reads the cameras of a calibration file's text; `path` is for messages.
fn parse_calibration(text: &str, format: Format, path: &Path) -> Result<CameraRig> {
    let cameras = match format {
        Format::Pose2SimToml => read_pose2sim_toml(text, path)?,
        Format::OpenCvYaml => read_opencv_yaml(text, path)?,
        Format::Json => read_json(text, path)?,
    };
    if cameras.is_empty() {
        return Err(Error::Invalid(format!(
            "no camera in {}: expected {}",
            path.display(),
            format.expected()
        )));
    }
    // Cameras are matched to their keypoint folders and reports by name.
    let mut names = HashSet::new();
    if let Some(twice) = cameras.iter().find(|c| !names.insert(c.name.as_str())) {
        return Err(Error::Invalid(format!(
            "{}: two cameras are named `{}`",
            path.display(),
            twice.name
        )));
    }
    Ok(CameraRig { cameras })
}

/// Where a value starts in its file: 1-based line and column, when known.
type At = Option<(usize, usize)>;

/// A value of a calibration file, whatever its format, with where it starts.
/// Each format's reader turns its file into this tree, so that one set of
/// functions reads and checks the cameras of all three.
#[derive(Debug)]
struct Node {
    at: At,
    kind: Kind,
}

#[derive(Debug)]
enum Kind {
    Null,
    Bool(bool),
    Number(f64),
    /// A string (in YAML, a quoted one).
    Text(String),
    /// An unquoted YAML scalar: YAML leaves it to the reader whether it is a
    /// number, a word or a boolean.
    Plain(String),
    List(Vec<Node>),
    /// Keys and values, in file order.
    Map(Vec<(String, Node)>),
}

/// Numbers laid out in rows (row-major `values`).
struct Matrix {
    rows: usize,
    cols: usize,
    values: Vec<f64>,
}

impl Matrix {
    /// Whether this is one row or one column of `n` numbers.
    fn is_vector(&self, n: usize) -> bool {
        self.values.len() == n && (self.rows == 1 || self.cols == 1)
    }
}

impl Node {
    /// The value of `key` in a map (the last one, should the key repeat).
    fn get(&self, key: &str) -> Option<&Node> {
        self.entries()?
            .iter()
            .rev()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v)
    }

    /// A map's keys and values.
    fn entries(&self) -> Option<&[(String, Node)]> {
        match &self.kind {
            Kind::Map(entries) => Some(entries),
            _ => None,
        }
    }

    fn number(&self) -> Option<f64> {
        match &self.kind {
            Kind::Number(v) => Some(*v),
            Kind::Plain(text) => yaml_number(text),
            _ => None,
        }
    }

    fn text(&self) -> Option<&str> {
        match &self.kind {
            Kind::Text(text) | Kind::Plain(text) => Some(text),
            _ => None,
        }
    }

    fn boolean(&self) -> Option<bool> {
        match &self.kind {
            Kind::Bool(b) => Some(*b),
            Kind::Plain(text) => match text.as_str() {
                "true" | "True" | "TRUE" => Some(true),
                "false" | "False" | "FALSE" => Some(false),
                _ => None,
            },
            _ => None,
        }
    }

    /// The node's numbers as a matrix: a list of numbers is one row, a list
    /// of equally long lists of numbers one row each, and an OpenCV
    /// `!!opencv-matrix` map has its `rows`, `cols` and `data` (row by row).
    fn matrix(&self) -> Option<Matrix> {
        match &self.kind {
            Kind::List(items) => {
                if let Some(values) = items.iter().map(Node::number).collect::<Option<Vec<_>>>() {
                    return Some(Matrix {
                        rows: 1,
                        cols: values.len(),
                        values,
                    });
                }
                let rows = items
                    .iter()
                    .map(|row| match &row.kind {
                        Kind::List(cells) => cells.iter().map(Node::number).collect(),
                        _ => None,
                    })
                    .collect::<Option<Vec<Vec<f64>>>>()?;
                let cols = rows.first().map_or(0, Vec::len);
                if rows.iter().any(|row| row.len() != cols) {
                    return None;
                }
                Some(Matrix {
                    rows: rows.len(),
                    cols,
                    values: rows.concat(),
                })
            }
            Kind::Map(_) => {
                let count = |key: &str| {
                    let n = self.get(key)?.number()?;
                    // Counts only; the bound keeps rows × cols far from overflow.
                    (n >= 0.0 && n.fract() == 0.0 && n <= 1e6).then_some(n as usize)
                };
                let (rows, cols) = (count("rows")?, count("cols")?);
                let data = self.get("data")?.matrix()?;
                (data.values.len() == rows * cols).then_some(Matrix {
                    rows,
                    cols,
                    values: data.values,
                })
            }
            _ => None,
        }
    }

    /// What the node is, for "…, found …" messages.
    fn describe(&self) -> String {
        match &self.kind {
            Kind::Null => "nothing (null)".into(),
            Kind::Bool(b) => format!("`{b}`"),
            Kind::Number(v) => format!("the number {v}"),
            Kind::Text(text) => format!("the text {:?}", shortened(text)),
            Kind::Plain(text) => format!("`{}`", shortened(text)),
            Kind::List(_) | Kind::Map(_) => match self.matrix() {
                Some(m) if m.rows == 1 => format!("a list of {} numbers", m.cols),
                Some(m) => format!("{} rows of {} numbers", m.rows, m.cols),
                None if matches!(self.kind, Kind::List(_)) => {
                    "a list that is not numbers, or rows of unequal lengths".into()
                }
                None if self.get("data").is_some() => {
                    "a matrix whose `rows`, `cols` and `data` do not agree".into()
                }
                None => "a table of keys".into(),
            },
        }
    }
}

/// At most 40 characters of a text quoted in a message.
fn shortened(text: &str) -> Cow<'_, str> {
    match text.char_indices().nth(40) {
        Some((end, _)) => format!("{}…", &text[..end]).into(),
        None => text.into(),
    }
}

/// An unquoted YAML scalar as a number, with the spellings of the
/// non-finite ones that YAML and OpenCV (`.Nan`, `.Inf`) use, which the
/// checks then refuse by name.
fn yaml_number(text: &str) -> Option<f64> {
    match text.to_ascii_lowercase().as_str() {
        ".nan" => Some(f64::NAN),
        ".inf" | "+.inf" => Some(f64::INFINITY),
        "-.inf" => Some(f64::NEG_INFINITY),
        _ => text.parse().ok(),
    }
}

/// The byte offsets where a text's lines start, to turn an offset into a
/// line and column.
struct Lines<'a> {
    text: &'a str,
    starts: Vec<usize>,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str) -> Lines<'a> {
        let starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Lines { text, starts }
    }

    /// The 1-based line and column (in characters) of a byte offset.
    fn locate(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        // `starts[0] == 0`, so at least one line starts at or before it.
        let line = self.starts.partition_point(|&start| start <= offset).max(1);
        let start = self.starts[line - 1];
        let column = self
            .text
            .get(start..offset)
            .map_or(offset - start, |s| s.chars().count());
        (line, column + 1)
    }
}

/// An error at a place of the file: a parse error with its line and column
/// when known, else one that names the file.
fn located(path: &Path, at: At, message: String) -> Error {
    match at {
        Some((line, column)) => Error::parse(path, line, column, message),
        None => Error::Invalid(format!("{}: {message}", path.display())),
    }
}

// ---------------------------------------------------------------------------
// Pose2Sim TOML and JSON: tables of cameras with the same keys.

fn read_pose2sim_toml(text: &str, path: &Path) -> Result<Vec<Camera>> {
    let lines = Lines::new(text);
    let document = toml::de::DeTable::parse(text).map_err(|e| {
        let (line, column) = e.span().map_or((1, 1), |s| lines.locate(s.start));
        Error::parse(
            path,
            line,
            column,
            format!("not valid TOML: {}", e.message().trim()),
        )
    })?;
    let mut cameras = Vec::new();
    for (key, node) in toml_table(document.get_ref(), &lines) {
        // Pose2Sim ends its calibrations with a [metadata] table (`adjusted`,
        // `error`), which is not a camera.
        if key == "metadata" {
            continue;
        }
        cameras.push(camera_from_table(&key, &node, node.at, path)?);
    }
    Ok(cameras)
}

/// A TOML table's entries as nodes, in file order.
fn toml_table(table: &toml::de::DeTable<'_>, lines: &Lines) -> Vec<(String, Node)> {
    let mut entries: Vec<_> = table.iter().collect();
    // The parser keeps a table's keys sorted; their positions give the
    // file's order.
    entries.sort_by_key(|(key, _)| key.span().start);
    entries
        .into_iter()
        .map(|(key, value)| {
            // A table opened by a `[header]` is placed at its header, other
            // values where they start.
            let offset = match value.get_ref() {
                toml::de::DeValue::Table(_) => key.span().start,
                _ => value.span().start,
            };
            let node = toml_node(value.get_ref(), lines.locate(offset), lines);
            (key.get_ref().to_string(), node)
        })
        .collect()
}

fn toml_node(value: &toml::de::DeValue<'_>, at: (usize, usize), lines: &Lines) -> Node {
    use toml::de::DeValue;
    let kind = match value {
        DeValue::String(s) => Kind::Text(s.to_string()),
        DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
            .map_or_else(|_| Kind::Text(i.to_string()), |v| Kind::Number(v as f64)),
        DeValue::Float(f) => f
            .as_str()
            .parse()
            .map_or_else(|_| Kind::Text(f.to_string()), Kind::Number),
        DeValue::Boolean(b) => Kind::Bool(*b),
        DeValue::Datetime(d) => Kind::Text(d.to_string()),
        DeValue::Array(items) => Kind::List(
            items
                .iter()
                .map(|item| toml_node(item.get_ref(), lines.locate(item.span().start), lines))
                .collect(),
        ),
        DeValue::Table(table) => Kind::Map(toml_table(table, lines)),
    };
    Node { at: Some(at), kind }
}

fn read_json(text: &str, path: &Path) -> Result<Vec<Camera>> {
    let root: Node = serde_json::from_str(text)
        .map_err(|e| crate::keypoints::json_error(path, &e, "not valid JSON: "))?;
    let cameras = match root.get("cameras") {
        Some(cameras) => cameras,
        None => &root,
    };
    // serde_json gives no positions: values are placed at their keys.
    let lines = Lines::new(text);
    let Some(entries) = cameras.entries() else {
        let (what, at) = if std::ptr::eq(cameras, &root) {
            ("the file", Some((1, 1)))
        } else {
            ("\"cameras\"", json_key_at(text, &lines, "cameras"))
        };
        return Err(located(
            path,
            at,
            format!(
                "{what} must be an object of cameras keyed by name, found {}",
                cameras.describe()
            ),
        ));
    };
    entries
        .iter()
        .filter(|(key, _)| key != "metadata")
        .map(|(key, node)| camera_from_table(key, node, json_key_at(text, &lines, key), path))
        .collect()
}

/// Where the key `key` of a JSON object is: the first `"key"` followed by a
/// colon (a camera's name may also appear as a value).
fn json_key_at(text: &str, lines: &Lines, key: &str) -> At {
    let needle = serde_json::to_string(key).ok()?;
    let mut from = 0;
    while let Some(found) = text.get(from..)?.find(&needle) {
        let start = from + found;
        let after = start + needle.len();
        if text.get(after..)?.trim_start().starts_with(':') {
            return Some(lines.locate(start));
        }
        from = after;
    }
    None
}

/// JSON into nodes, keeping the order of keys (serde_json's own map sorts
/// them unless a feature says otherwise).
impl<'de> serde::Deserialize<'de> for Node {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Node, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = Node;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a JSON value")
            }
            fn visit_unit<E>(self) -> Result<Node, E> {
                Ok(node(Kind::Null))
            }
            fn visit_bool<E>(self, b: bool) -> Result<Node, E> {
                Ok(node(Kind::Bool(b)))
            }
            fn visit_i64<E>(self, v: i64) -> Result<Node, E> {
                Ok(node(Kind::Number(v as f64)))
            }
            fn visit_u64<E>(self, v: u64) -> Result<Node, E> {
                Ok(node(Kind::Number(v as f64)))
            }
            fn visit_f64<E>(self, v: f64) -> Result<Node, E> {
                Ok(node(Kind::Number(v)))
            }
            fn visit_str<E>(self, v: &str) -> Result<Node, E> {
                Ok(node(Kind::Text(v.to_string())))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Node, A::Error> {
                let mut items = Vec::new();
                while let Some(item) = seq.next_element()? {
                    items.push(item);
                }
                Ok(node(Kind::List(items)))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Node, A::Error> {
                let mut entries = Vec::new();
                while let Some(entry) = map.next_entry::<String, Node>()? {
                    entries.push(entry);
                }
                Ok(node(Kind::Map(entries)))
            }
        }
        fn node(kind: Kind) -> Node {
            Node { at: None, kind }
        }
        deserializer.deserialize_any(Visitor)
    }
}

/// Reads one camera of a Pose2Sim table (TOML) or object (JSON): `name`,
/// `size`, `matrix`, `distortions`, `rotation`, `translation`, `fisheye`.
/// `at` is where the camera starts (JSON's values have no places of their
/// own).
fn camera_from_table(key: &str, node: &Node, at: At, path: &Path) -> Result<Camera> {
    let reading = Reading {
        path,
        camera: key,
        at,
    };
    if node.entries().is_none() {
        return Err(reading.error(
            at,
            format!(
                "must be a table of camera parameters (name, size, matrix, distortions, \
                 rotation, translation), found {}",
                node.describe()
            ),
        ));
    }
    let name = match node.get("name") {
        None => key.to_string(),
        Some(name) => name
            .text()
            .ok_or_else(|| {
                reading.error(
                    name.at,
                    format!("`name` must be a text, found {}", name.describe()),
                )
            })?
            .to_string(),
    };
    if let Some(fisheye) = node.get("fisheye") {
        match fisheye.boolean() {
            Some(false) => {}
            Some(true) => {
                return Err(reading.error(
                    fisheye.at,
                    "fisheye model not supported: `fisheye = true` is OpenCV's fisheye \
                     (Kannala-Brandt) lens model; only the pinhole model with k1 k2 p1 p2 k3 \
                     distortion is read",
                ))
            }
            None => {
                return Err(reading.error(
                    fisheye.at,
                    format!(
                        "`fisheye` must be true or false, found {}",
                        fisheye.describe()
                    ),
                ))
            }
        }
    }
    let size = match node.get("size") {
        Some(size) => reading.size("size", size)?,
        None => Field::absent([0.0; 2], "size", at),
    };
    let matrix = reading.intrinsics("matrix", reading.required(node, "matrix", at)?)?;
    let distortion =
        reading.distortion("distortions", reading.required(node, "distortions", at)?)?;
    let rotation = reading.rotation("rotation", reading.required(node, "rotation", at)?)?;
    let translation = reading.vec3("translation", reading.required(node, "translation", at)?)?;
    reading.assemble(
        name,
        Parts {
            size,
            matrix,
            distortion,
            rotation,
            translation,
        },
    )
}

// ---------------------------------------------------------------------------
// OpenCV FileStorage YAML.

fn read_opencv_yaml(text: &str, path: &Path) -> Result<Vec<Camera>> {
    let text = without_opencv_directive(text);
    let Some(root) = yaml_tree(&text, path)? else {
        return Ok(Vec::new());
    };
    // A document with nothing in it (`---` alone) is read as an empty scalar.
    if matches!(&root.kind, Kind::Plain(t) if t.is_empty() || t == "~" || t == "null") {
        return Ok(Vec::new());
    }
    if root.entries().is_none() {
        return Err(located(
            path,
            root.at,
            format!(
                "expected OpenCV FileStorage YAML, named values at the top level, found {}",
                root.describe()
            ),
        ));
    }
    if root.get("camera_matrix").is_some() {
        return Ok(vec![opencv_single_camera(&root, path)?]);
    }
    easymocap_cameras(&root, path)
}

/// OpenCV starts its YAML with `%YAML:1.0`, which YAML parsers refuse (YAML
/// writes `%YAML 1.0`): such lines are blanked, keeping the line numbers.
fn without_opencv_directive(text: &str) -> Cow<'_, str> {
    if !text.lines().any(|line| line.starts_with("%YAML:")) {
        return text.into();
    }
    text.split_inclusive('\n')
        .map(|line| {
            if line.starts_with("%YAML:") {
                // Keep only the line's end.
                &line[line.trim_end_matches(['\r', '\n']).len()..]
            } else {
                line
            }
        })
        .collect::<String>()
        .into()
}

/// The first YAML document of the text as a tree, or None when there is none.
/// Built from the parser's events with a stack of its own, so that deep
/// nesting cannot overflow the call stack. Tags (`!!opencv-matrix`) are left
/// out: a matrix is known by its keys.
fn yaml_tree(text: &str, path: &Path) -> Result<Option<Node>> {
    use yaml_rust2::parser::{Event, Parser};
    use yaml_rust2::scanner::TScalarStyle;

    /// A list or map whose end has not come yet; a map holds the key that
    /// waits for its value, and where that key is.
    enum Open {
        List(At, Vec<Node>),
        Map(At, Vec<(String, Node)>, Option<(String, At)>),
    }

    let mut parser = Parser::new_from_str(text);
    let mut open: Vec<Open> = Vec::new();
    loop {
        let (event, mark) = parser.next_token().map_err(|e| {
            let mark = e.marker();
            Error::parse(
                path,
                mark.line(),
                mark.col() + 1,
                format!("not valid YAML: {}", e.info()),
            )
        })?;
        // yaml-rust2's lines count from 1, its columns from 0.
        let at = Some((mark.line(), mark.col() + 1));
        let finished = match event {
            Event::StreamEnd => return Ok(None),
            Event::Scalar(value, style, _, _) => Node {
                at,
                kind: if style == TScalarStyle::Plain {
                    Kind::Plain(value)
                } else {
                    Kind::Text(value)
                },
            },
            Event::SequenceStart(..) => {
                open.push(Open::List(at, Vec::new()));
                continue;
            }
            Event::MappingStart(..) => {
                open.push(Open::Map(at, Vec::new(), None));
                continue;
            }
            Event::SequenceEnd | Event::MappingEnd => match open.pop() {
                Some(Open::List(at, items)) => Node {
                    at,
                    kind: Kind::List(items),
                },
                Some(Open::Map(at, entries, _)) => Node {
                    at,
                    kind: Kind::Map(entries),
                },
                None => continue,
            },
            // Aliases could repeat a subtree without end ("billion laughs"),
            // and OpenCV never writes them.
            Event::Alias(_) => {
                return Err(located(
                    path,
                    at,
                    "YAML aliases (`*name`) are not supported in calibration files".into(),
                ))
            }
            Event::Nothing | Event::StreamStart | Event::DocumentStart | Event::DocumentEnd => {
                continue
            }
        };
        match open.last_mut() {
            None => return Ok(Some(finished)),
            Some(Open::List(_, items)) => items.push(finished),
            Some(Open::Map(_, entries, waiting)) => match waiting.take() {
                // A map under a key (an `!!opencv-matrix`) starts on the
                // lines after it: the key's place is the one to show.
                Some((key, key_at)) => match finished.kind {
                    Kind::Map(_) => entries.push((
                        key,
                        Node {
                            at: key_at,
                            ..finished
                        },
                    )),
                    _ => entries.push((key, finished)),
                },
                None => match finished.kind {
                    Kind::Text(key) | Kind::Plain(key) => *waiting = Some((key, finished.at)),
                    _ => {
                        return Err(located(
                            path,
                            finished.at,
                            "keys must be names, not lists or maps".into(),
                        ))
                    }
                },
            },
        }
    }
}

/// The cameras of an EasyMocap calibration (intri.yml and extri.yml in one).
fn easymocap_cameras(root: &Node, path: &Path) -> Result<Vec<Camera>> {
    let names: Vec<(String, At)> = match root.get("names") {
        Some(list) => {
            let not_names = |at: At| {
                located(
                    path,
                    at,
                    format!(
                        "`names` must be a list of camera names, found {}",
                        list.describe()
                    ),
                )
            };
            let Kind::List(items) = &list.kind else {
                return Err(not_names(list.at));
            };
            items
                .iter()
                .map(|item| {
                    item.text()
                        .map(|name| (name.to_string(), item.at))
                        .ok_or_else(|| not_names(item.at))
                })
                .collect::<Result<_>>()?
        }
        None => root
            .entries()
            .unwrap_or_default()
            .iter()
            .filter_map(|(key, node)| Some((key.strip_prefix("K_")?.to_string(), node.at)))
            .collect(),
    };
    names
        .iter()
        .map(|(name, at)| easymocap_camera(root, name, *at, path))
        .collect()
}

/// One camera of an EasyMocap calibration; `at` is where it is named.
fn easymocap_camera(root: &Node, name: &str, at: At, path: &Path) -> Result<Camera> {
    let reading = Reading {
        path,
        camera: name,
        at,
    };
    let key = |prefix: &str| format!("{prefix}_{name}");
    let (k, dist, rot, rodrigues, t) = (key("K"), key("dist"), key("Rot"), key("R"), key("T"));
    let matrix = reading.intrinsics(&k, reading.required(root, &k, at)?)?;
    let distortion = match root.get(&dist) {
        Some(node) => reading.distortion(&dist, node)?,
        None => Field::absent([0.0; 5], &dist, at),
    };
    let rotation = match (root.get(&rot), root.get(&rodrigues)) {
        (Some(node), _) => reading.rotation(&rot, node)?,
        (None, Some(node)) => reading.rotation(&rodrigues, node)?,
        (None, None) => {
            return Err(reading.error(
                at,
                format!(
                    "missing `{rot}` (3x3) or `{rodrigues}` (Rodrigues) for the rotation: \
                     EasyMocap keeps them in extri.yml, apart from intri.yml; merge the two \
                     files into one"
                ),
            ))
        }
    };
    let translation = reading.vec3(&t, reading.required(root, &t, at)?)?;
    reading.assemble(
        name.to_string(),
        Parts {
            size: Field::absent([0.0; 2], "size", at),
            matrix,
            distortion,
            rotation,
            translation,
        },
    )
}

/// The one camera of OpenCV's calibration sample output, named after the
/// file.
fn opencv_single_camera(root: &Node, path: &Path) -> Result<Camera> {
    let name = path.file_stem().map_or_else(
        || "camera".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let reading = Reading {
        path,
        camera: &name,
        at: root.at,
    };
    let matrix = reading.intrinsics(
        "camera_matrix",
        reading.required(root, "camera_matrix", root.at)?,
    )?;
    let distortion = match root.get("distortion_coefficients") {
        Some(node) => reading.distortion("distortion_coefficients", node)?,
        None => Field::absent([0.0; 5], "distortion_coefficients", root.at),
    };
    let mut size = Field::absent([0.0; 2], "image_width", root.at);
    for (i, key) in ["image_width", "image_height"].into_iter().enumerate() {
        if let Some(node) = root.get(key) {
            size.value[i] = node.number().ok_or_else(|| {
                reading.error(
                    node.at,
                    format!("`{key}` must be a number, found {}", node.describe()),
                )
            })?;
            size.key = key.to_string();
            size.at = node.at;
        }
    }
    let first =
        |keys: [&'static str; 2]| keys.into_iter().find_map(|key| Some((key, root.get(key)?)));
    let (rotation, translation) = match (first(["rvec", "R"]), first(["tvec", "T"])) {
        (Some((r, r_node)), Some((t, t_node))) => {
            (reading.rotation(r, r_node)?, reading.vec3(t, t_node)?)
        }
        // Without a pose, the camera's frame is the world's.
        (None, None) => (
            Field::absent(DMat3::IDENTITY, "rvec", root.at),
            Field::absent(DVec3::ZERO, "tvec", root.at),
        ),
        (Some((r, node)), None) => {
            return Err(reading.error(
                node.at,
                format!("`{r}` is given without a translation (`tvec` or `T`)"),
            ))
        }
        (None, Some((t, node))) => {
            return Err(reading.error(
                node.at,
                format!("`{t}` is given without a rotation (`rvec` or `R`)"),
            ))
        }
    };
    reading.assemble(
        name.clone(),
        Parts {
            size,
            matrix,
            distortion,
            rotation,
            translation,
        },
    )
}

// ---------------------------------------------------------------------------
// One camera's values: read, then checked.

/// The camera being read, for messages: its file, its name there, and where
/// it starts (for values whose own place the format does not give).
struct Reading<'a> {
    path: &'a Path,
    camera: &'a str,
    at: At,
}

/// A value as read, with the key it was read from and where it is.
struct Field<T> {
    value: T,
    key: String,
    at: At,
}

impl<T> Field<T> {
    /// A value the file does not give, placed at `at` for messages.
    fn absent(value: T, key: &str, at: At) -> Field<T> {
        Field {
            value,
            key: key.to_string(),
            at,
        }
    }
}

/// A camera's values as read, before the checks.
struct Parts {
    size: Field<[f64; 2]>,
    matrix: Field<DMat3>,
    distortion: Field<[f64; 5]>,
    rotation: Field<DMat3>,
    translation: Field<DVec3>,
}

impl Reading<'_> {
    /// "camera: message" at `at`, else where the camera starts.
    fn error(&self, at: At, message: impl fmt::Display) -> Error {
        located(
            self.path,
            at.or(self.at),
            format!("{}: {message}", self.camera),
        )
    }

    fn required<'n>(&self, parent: &'n Node, key: &str, at: At) -> Result<&'n Node> {
        parent
            .get(key)
            .ok_or_else(|| self.error(at, format!("missing `{key}`")))
    }

    fn field<T>(&self, value: T, key: &str, node: &Node) -> Field<T> {
        Field {
            value,
            key: key.to_string(),
            at: node.at.or(self.at),
        }
    }

    /// K: 3 rows of 3 numbers (or 9 numbers in row order).
    fn intrinsics(&self, key: &str, node: &Node) -> Result<Field<DMat3>> {
        match node.matrix() {
            Some(m) if m.values.len() == 9 && (m.rows == 3 || m.rows == 1 || m.cols == 1) => {
                Ok(self.field(from_rows(&m.values), key, node))
            }
            _ => Err(self.error(
                node.at,
                format!(
                    "`{key}` must be 3 rows of 3 numbers, found {}",
                    node.describe()
                ),
            )),
        }
    }

    /// Exactly `N` numbers, as one row or one column.
    fn numbers<const N: usize>(&self, key: &str, node: &Node, what: &str) -> Result<[f64; N]> {
        node.matrix()
            .filter(|m| m.is_vector(N))
            .and_then(|m| m.values.try_into().ok())
            .ok_or_else(|| {
                self.error(
                    node.at,
                    format!("`{key}` must be {what}, found {}", node.describe()),
                )
            })
    }

    fn vec3(&self, key: &str, node: &Node) -> Result<Field<DVec3>> {
        let [x, y, z] = self.numbers::<3>(key, node, "3 numbers")?;
        Ok(self.field(DVec3::new(x, y, z), key, node))
    }

    fn size(&self, key: &str, node: &Node) -> Result<Field<[f64; 2]>> {
        let size = self.numbers::<2>(key, node, "2 numbers, the image's width and height")?;
        Ok(self.field(size, key, node))
    }

    /// A rotation: a Rodrigues vector (3 numbers) or a matrix (3 rows of 3).
    fn rotation(&self, key: &str, node: &Node) -> Result<Field<DMat3>> {
        match node.matrix() {
            Some(m) if m.is_vector(3) => {
                let v = DVec3::new(m.values[0], m.values[1], m.values[2]);
                Ok(self.field(rotation_from_rodrigues(v), key, node))
            }
            Some(m) if m.rows == 3 && m.cols == 3 => {
                Ok(self.field(from_rows(&m.values), key, node))
            }
            _ => Err(self.error(
                node.at,
                format!(
                    "`{key}` must be a Rodrigues vector of 3 numbers (axis times angle in \
                     radians) or a rotation matrix of 3 rows of 3 numbers, found {}",
                    node.describe()
                ),
            )),
        }
    }

    /// OpenCV's distortion: k1 k2 p1 p2 [k3], or one of OpenCV's longer
    /// lists (8, 12, 14 numbers) with nothing past k3.
    fn distortion(&self, key: &str, node: &Node) -> Result<Field<[f64; 5]>> {
        let values = node
            .matrix()
            .filter(|m| m.rows == 1 || m.cols == 1)
            .map(|m| m.values)
            .unwrap_or_default();
        let mut coefficients = [0.0; 5];
        match values.len() {
            4 | 5 => coefficients[..values.len()].copy_from_slice(&values),
            8 | 12 | 14 if values[5..].iter().all(|&c| c == 0.0) => {
                coefficients.copy_from_slice(&values[..5]);
            }
            8 | 12 | 14 => {
                return Err(self.error(
                    node.at,
                    format!(
                        "`{key}` has coefficients past k3 (OpenCV's rational, thin-prism or \
                         tilted models), which are not supported: only k1 k2 p1 p2 k3"
                    ),
                ))
            }
            _ => {
                return Err(self.error(
                    node.at,
                    format!(
                        "`{key}` must be 4 or 5 numbers (k1 k2 p1 p2 [k3]), found {}",
                        node.describe()
                    ),
                ))
            }
        }
        Ok(self.field(coefficients, key, node))
    }

    /// The camera, once it passes [`check`]; a problem is reported at the
    /// value it is about.
    fn assemble(&self, name: String, parts: Parts) -> Result<Camera> {
        let camera = Camera {
            name,
            size: parts.size.value,
            matrix: parts.matrix.value,
            distortion: parts.distortion.value,
            rotation: parts.rotation.value,
            translation: parts.translation.value,
        };
        check(&camera).map_err(|problem| {
            let (key, at) = match problem.part {
                Part::Size => (&parts.size.key, parts.size.at),
                Part::Matrix => (&parts.matrix.key, parts.matrix.at),
                Part::Distortion => (&parts.distortion.key, parts.distortion.at),
                Part::Rotation => (&parts.rotation.key, parts.rotation.at),
                Part::Translation => (&parts.translation.key, parts.translation.at),
            };
            self.error(at, format!("`{key}` {}", problem.message))
        })?;
        Ok(camera)
    }
}

/// A 3x3 matrix from 9 numbers in row order (glam stores columns).
fn from_rows(values: &[f64]) -> DMat3 {
    let mut rows = [0.0; 9];
    rows.copy_from_slice(&values[..9]);
    DMat3::from_cols_array(&rows).transpose()
}

/// The rotation matrix of a Rodrigues vector v (OpenCV's `cv::Rodrigues`):
/// with θ = |v| and the unit axis k = v / θ,
/// R = cos θ I + (1 − cos θ) k kᵀ + sin θ [k]×.
fn rotation_from_rodrigues(v: DVec3) -> DMat3 {
    // A Rodrigues vector is a scaled axis: glam's quaternion from it.
    DMat3::from_quat(glam::DQuat::from_scaled_axis(v))
}

/// The Rodrigues vector of a rotation matrix, its angle in [0, π], through
/// the rotation's unit quaternion (stable near 0 and π alike).
fn rodrigues_from_rotation(rotation: DMat3) -> DVec3 {
    let mut q = DQuat::from_mat3(&rotation).normalize();
    if q.w < 0.0 {
        q = -q;
    }
    let sin_half = q.xyz().length();
    if sin_half == 0.0 {
        return DVec3::ZERO;
    }
    q.xyz() / sin_half * (2.0 * sin_half.atan2(q.w))
}

/// The value a [`Problem`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Size,
    Matrix,
    Distortion,
    Rotation,
    Translation,
}

impl Part {
    /// The value's key in Pose2Sim's TOML.
    fn toml_key(self) -> &'static str {
        match self {
            Part::Size => "size",
            Part::Matrix => "matrix",
            Part::Distortion => "distortions",
            Part::Rotation => "rotation",
            Part::Translation => "translation",
        }
    }
}

/// What is wrong with a camera: the value, and a message that follows its
/// key ("`matrix` has a zero focal length").
#[derive(Debug)]
struct Problem {
    part: Part,
    message: String,
}

/// Checks what the projection relies on: finite numbers, an image size of 0
/// or more, positive focal lengths and K = (fx, 0, cx; 0, fy, cy; 0, 0, 1),
/// and a rotation (RᵀR = I, det R = +1).
fn check(camera: &Camera) -> std::result::Result<(), Problem> {
    let problem = |part, message: String| Err(Problem { part, message });
    let not_finite = "holds a number that is not finite (NaN or infinity)".to_string();

    let [width, height] = camera.size;
    if !(width.is_finite() && height.is_finite()) {
        return problem(Part::Size, not_finite);
    }
    if width < 0.0 || height < 0.0 {
        return problem(
            Part::Size,
            format!("must be a width and a height of 0 pixels or more, found [{width}, {height}]"),
        );
    }

    let k = &camera.matrix;
    if !k.is_finite() {
        return problem(Part::Matrix, not_finite);
    }
    let (fx, fy) = (k.x_axis.x, k.y_axis.y);
    if fx == 0.0 || fy == 0.0 {
        return problem(
            Part::Matrix,
            format!("has a zero focal length (fx = {fx}, fy = {fy})"),
        );
    }
    if fx < 0.0 || fy < 0.0 {
        return problem(
            Part::Matrix,
            format!("has a negative focal length (fx = {fx}, fy = {fy})"),
        );
    }
    let skew = k.y_axis.x;
    if skew.abs() > INTRINSICS_TOLERANCE {
        return problem(
            Part::Matrix,
            format!("has a skew (row 1, column 2 is {skew}), which OpenCV's camera model lacks"),
        );
    }
    // Row 2's first entry, row 3's first two, and row 3's last.
    let zeros = [k.x_axis.y, k.x_axis.z, k.y_axis.z];
    if zeros.iter().any(|v| v.abs() > INTRINSICS_TOLERANCE)
        || (k.z_axis.z - 1.0).abs() > INTRINSICS_TOLERANCE
    {
        let rows = [k.row(0), k.row(1), k.row(2)].map(|r| format!("{} {} {}", r.x, r.y, r.z));
        return problem(
            Part::Matrix,
            format!(
                "must be (fx, 0, cx; 0, fy, cy; 0, 0, 1), found ({})",
                rows.join("; ")
            ),
        );
    }

    if !camera.distortion.iter().all(|c| c.is_finite()) {
        return problem(Part::Distortion, not_finite);
    }

    let r = &camera.rotation;
    if !r.is_finite() {
        return problem(Part::Rotation, not_finite);
    }
    let off = (r.transpose() * *r - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |worst, v| worst.max(v.abs()));
    if off > ROTATION_TOLERANCE {
        return problem(
            Part::Rotation,
            format!("is not a rotation: RᵀR differs from the identity by up to {off:.1e}"),
        );
    }
    let determinant = r.determinant();
    if determinant < 0.0 {
        return problem(
            Part::Rotation,
            format!("is a reflection (determinant {determinant:.3}), not a rotation"),
        );
    }

    if !camera.translation.is_finite() {
        return problem(Part::Translation, not_finite);
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// Writing Pose2Sim TOML.

/// The text of a Pose2Sim calibration, or why the rig cannot be written.
fn pose2sim_toml(rig: &CameraRig) -> std::result::Result<String, String> {
    if rig.is_empty() {
        return Err("no camera to write: a calibration file needs one".into());
    }
    let mut names = HashSet::new();
    let mut out = String::new();
    for camera in &rig.cameras {
        let name = &camera.name;
        if name == "metadata" {
            return Err(
                "a camera cannot be named `metadata`: Pose2Sim keeps that table for itself".into(),
            );
        }
        if !names.insert(name.as_str()) {
            return Err(format!(
                "two cameras are named `{name}`: Pose2Sim's tables are keyed by name"
            ));
        }
        check(camera)
            .map_err(|p| format!("camera `{name}`: `{}` {}", p.part.toml_key(), p.message))?;

        let [k1, k2, p1, p2, k3] = camera.distortion;
        // Pose2Sim writes four coefficients; k3 only when the lens has one.
        let distortions: &[f64] = if k3 == 0.0 {
            &[k1, k2, p1, p2]
        } else {
            &camera.distortion
        };
        let k = &camera.matrix;
        let matrix = [k.row(0), k.row(1), k.row(2)]
            .map(|row| numbers(&row.to_array()))
            .join(", ");
        let rotation = rodrigues_from_rotation(camera.rotation);
        out += &format!("[{}]\n", toml_key(name));
        out += &format!("name = {}\n", toml_string(name));
        out += &format!("size = {}\n", numbers(&camera.size));
        out += &format!("matrix = [{matrix}]\n");
        out += &format!("distortions = {}\n", numbers(distortions));
        out += &format!("rotation = {}\n", numbers(&rotation.to_array()));
        out += &format!(
            "translation = {}\n",
            numbers(&camera.translation.to_array())
        );
        out += "fisheye = false\n\n";
    }
    // Pose2Sim's own files end so.
    out += "[metadata]\nadjusted = false\nerror = 0.0\n";
    Ok(out)
}

/// A TOML array of numbers. Rust's `{:?}` writes the shortest text that reads
/// back to the same f64, always with a `.` or an exponent, as TOML's floats
/// want (`1088.0`, `9.5e-6`).
fn numbers(values: &[f64]) -> String {
    let items: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    format!("[{}]", items.join(", "))
}

/// A TOML key: bare when it can be, else quoted.
fn toml_key(key: &str) -> Cow<'_, str> {
    let bare = !key.is_empty()
        && key
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare {
        key.into()
    } else {
        toml_string(key).into()
    }
}

/// A TOML basic string, escaped.
fn toml_string(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Camera 1 of Pose2Sim's demo calibration, as its file has it.
    const DEMO_CAMERA_1: &str = r#"[cam_01]
name = "cam_01"
size = [ 1088.0, 1920.0]
matrix = [ [ 1681.244873046875, 0.0, 532.97369384375], [ 0.0, 1681.075439453125, 948.137390140625], [ 0.0, 0.0, 1.0]]
distortions = [ -0.000721609375, 0.002187234375, 9.5e-06, 1.078125e-05]
rotation = [ 1.6882754799999993, 1.0483220499999997, -0.41955852000000016]
translation = [ 0.3211048899999996, 0.9563320600000009, 2.8907130499999996]
fisheye = false

[metadata]
adjusted = false
error = 0.0
"#;

    /// EasyMocap's intri.yml and extri.yml in one, as OpenCV writes them:
    /// camera "1" with both rotations, camera "02" with the Rodrigues one.
    const EASYMOCAP_YAML: &str = "%YAML:1.0
---
names:
   - \"1\"
   - \"02\"
K_1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1.0e+03, 0., 6.4e+02, 0., 1.1e+03,
       3.6e+02, 0., 0., 1. ]
dist_1: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.1, 0.01, 1.0e-03, -2.0e-03, 0. ]
R_1: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ 0., 0., 1.5707963267948966 ]
Rot_1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 0., -1., 0., 1., 0., 0., 0., 0., 1. ]
T_1: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ 0.5, -0.25, 3. ]
K_02: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 900., 0., 320., 0., 900., 240., 0., 0., 1. ]
R_02: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ 0.1, -0.2, 0.3 ]
T_02: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ 1., 2., 3. ]
";

    /// The output of OpenCV's calibration sample (abridged).
    const OPENCV_SINGLE_YAML: &str = "%YAML:1.0
---
calibration_time: \"Mon Jan  1 12:00:00 2024\"
image_width: 1280
image_height: 720
flags: 0
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 9.1e+02, 0., 6.4e+02, 0., 9.2e+02, 3.6e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ -0.2, 0.05, 0., 0., -0.01 ]
avg_reprojection_error: 0.25
";

    /// Two cameras under "cameras", not in alphabetical order, one with a
    /// rotation matrix.
    const JSON_CAMERAS: &str = r#"{
  "cameras": {
    "side": {
      "size": [1920, 1080],
      "matrix": [[1500.0, 0.0, 960.0], [0.0, 1500.0, 540.0], [0.0, 0.0, 1.0]],
      "distortions": [0.01, -0.02, 0.0, 0.0, 0.003],
      "rotation": [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
      "translation": [0.1, 0.2, 4.0]
    },
    "front": {
      "size": [1920, 1080],
      "matrix": [[1400.0, 0.0, 950.0], [0.0, 1410.0, 530.0], [0.0, 0.0, 1.0]],
      "distortions": [0.0, 0.0, 0.0, 0.0],
      "rotation": [0.0, 0.5, 0.0],
      "translation": [0.0, 0.0, 3.0]
    }
  }
}"#;

    fn parse(text: &str, format: Format) -> Result<CameraRig> {
        parse_calibration(text, format, Path::new("calibration"))
    }

    fn demo_camera_1() -> Camera {
        parse(DEMO_CAMERA_1, Format::Pose2SimToml)
            .unwrap()
            .cameras
            .remove(0)
    }

    fn assert_close(a: DMat3, b: DMat3, tolerance: f64) {
        assert!(a.abs_diff_eq(b, tolerance), "{a:?}\n  != {b:?}");
    }

    /// Equal, except for rotations written as Rodrigues vectors.
    fn assert_same_rig(read: &CameraRig, written: &CameraRig) {
        assert_eq!(read.len(), written.len());
        for (a, b) in read.cameras.iter().zip(&written.cameras) {
            assert_eq!(a.name, b.name);
            assert_eq!(a.size, b.size);
            assert_eq!(a.matrix, b.matrix);
            assert_eq!(a.distortion, b.distortion);
            assert_eq!(a.translation, b.translation);
            assert_close(a.rotation, b.rotation, 1e-14);
        }
    }

    fn some_camera(name: &str, distortion: [f64; 5], rodrigues: DVec3) -> Camera {
        Camera {
            name: name.into(),
            size: [1088.0, 1920.0],
            matrix: from_rows(&[
                1681.25,
                0.0,
                532.97369384375,
                0.0,
                1681.0754,
                948.1,
                0.0,
                0.0,
                1.0,
            ]),
            distortion,
            rotation: rotation_from_rodrigues(rodrigues),
            translation: DVec3::new(0.3211048899999996, -9.5e-6, 2.89e3),
        }
    }

    #[test]
    fn toml_round_trip_gives_the_same_rig() {
        let rig = CameraRig {
            cameras: vec![
                some_camera(
                    "cam_02",
                    [-7.2e-4, 2.1e-3, 9.5e-6, 1.1e-5, 0.0],
                    DVec3::new(1.688, 1.048, -0.42),
                ),
                // A name that must be quoted, k3, and a half-turn (the
                // Rodrigues vector's hardest case).
                some_camera(
                    "Cam \"A\" 1",
                    [0.1, -0.2, 0.0, 0.0, 0.03],
                    DVec3::new(0.0, std::f64::consts::PI, 0.0),
                ),
                some_camera("cam-01", [0.0; 5], DVec3::ZERO),
            ],
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("Calib.toml");
        write_calibration_toml(&rig, &path).unwrap();
        let read = read_calibration(&path).unwrap();
        assert_same_rig(&read, &rig);
        // Pose2Sim's layout: a table a camera, then [metadata].
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("[cam_02]\nname = \"cam_02\"\n"), "{text}");
        assert!(
            text.contains("distortions = [-0.00072, 0.0021, 9.5e-6, 1.1e-5]\n"),
            "{text}"
        );
        assert!(text.contains("[\"Cam \\\"A\\\" 1\"]\n"), "{text}");
        assert!(
            text.ends_with("[metadata]\nadjusted = false\nerror = 0.0\n"),
            "{text}"
        );
        // TOML's other ways of writing numbers read alike.
        let other = DEMO_CAMERA_1
            .replace("1681.244873046875", "1_681.244_873_046_875")
            .replace("[ 1088.0, 1920.0]", "[1088, +1_920]");
        assert_eq!(
            parse(&other, Format::Pose2SimToml).unwrap().cameras[0],
            demo_camera_1()
        );
        // Writing what was read gives the same text.
        write_calibration_toml(&read, &path).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
    }

    #[test]
    fn writing_refuses_a_rig_it_could_not_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.toml");
        let camera = some_camera("a", [0.0; 5], DVec3::ZERO);
        let mut no_focal = camera.clone();
        no_focal.matrix.x_axis.x = 0.0;
        let mut not_finite = camera.clone();
        not_finite.translation.y = f64::NAN;
        let mut metadata = camera.clone();
        metadata.name = "metadata".into();
        let cases = [
            (vec![], "no camera to write"),
            (
                vec![camera.clone(), camera.clone()],
                "two cameras are named `a`",
            ),
            (vec![no_focal], "`matrix` has a zero focal length"),
            (
                vec![not_finite],
                "`translation` holds a number that is not finite",
            ),
            (vec![metadata], "cannot be named `metadata`"),
        ];
        for (cameras, expected) in cases {
            let e = write_calibration_toml(&CameraRig { cameras }, &path).unwrap_err();
            let message = e.to_string();
            assert!(
                message.contains("out.toml") && message.contains(expected),
                "{message}"
            );
        }
        assert!(!path.exists());
    }

    #[test]
    fn easymocap_yaml_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("calibration.yml");
        std::fs::write(&path, EASYMOCAP_YAML).unwrap();
        let rig = read_calibration(&path).unwrap();
        let names: Vec<&str> = rig.cameras.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["1", "02"]);
        let one = &rig.cameras[0];
        assert_eq!(one.size, [0.0, 0.0]);
        assert_eq!(one.matrix.row(0), DVec3::new(1000.0, 0.0, 640.0));
        assert_eq!(one.matrix.row(1), DVec3::new(0.0, 1100.0, 360.0));
        assert_eq!(one.distortion, [-0.1, 0.01, 1e-3, -2e-3, 0.0]);
        // `Rot_1` is taken as it is, row by row: a quarter turn about z.
        assert_eq!(one.rotation.row(0), DVec3::new(0.0, -1.0, 0.0));
        assert_eq!(one.translation, DVec3::new(0.5, -0.25, 3.0));
        let two = &rig.cameras[1];
        assert_eq!(two.distortion, [0.0; 5]);
        assert_close(
            two.rotation,
            rotation_from_rodrigues(DVec3::new(0.1, -0.2, 0.3)),
            0.0,
        );
        assert_eq!(two.translation, DVec3::new(1.0, 2.0, 3.0));
        // `R_1` agrees with `Rot_1`: the two layouts read alike.
        assert_close(
            rotation_from_rodrigues(DVec3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2)),
            one.rotation,
            1e-15,
        );

        // Without `names`, the cameras are those of the `K_` keys.
        let unnamed = EASYMOCAP_YAML.replace("names:\n   - \"1\"\n   - \"02\"\n", "");
        let rig = parse(&unnamed, Format::OpenCvYaml).unwrap();
        assert_eq!(rig.cameras[1].name, "02");
    }

    #[test]
    fn opencv_calibration_yaml_is_read_as_one_camera() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("left.yaml");
        std::fs::write(&path, OPENCV_SINGLE_YAML).unwrap();
        let rig = read_calibration(&path).unwrap();
        assert_eq!(rig.len(), 1);
        let camera = &rig.cameras[0];
        assert_eq!(camera.name, "left");
        assert_eq!(camera.size, [1280.0, 720.0]);
        assert_eq!(camera.matrix.row(1), DVec3::new(0.0, 920.0, 360.0));
        assert_eq!(camera.distortion, [-0.2, 0.05, 0.0, 0.0, -0.01]);
        assert_eq!(camera.rotation, DMat3::IDENTITY);
        assert_eq!(camera.translation, DVec3::ZERO);

        // With a pose (and YAML's own directive).
        let posed = OPENCV_SINGLE_YAML.replace("%YAML:1.0", "%YAML 1.0")
            + "rvec: [ 0., 0.3, 0. ]\ntvec: [ 0.1, 0.2, 0.3 ]\n";
        let camera = parse(&posed, Format::OpenCvYaml).unwrap().cameras.remove(0);
        assert_close(camera.rotation, DMat3::from_rotation_y(0.3), 1e-15);
        assert_eq!(camera.translation, DVec3::new(0.1, 0.2, 0.3));
    }

    #[test]
    fn json_is_read_in_file_order_under_cameras_or_at_the_top() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rig.json");
        std::fs::write(&path, JSON_CAMERAS).unwrap();
        let rig = read_calibration(&path).unwrap();
        let names: Vec<&str> = rig.cameras.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["side", "front"]);
        let side = &rig.cameras[0];
        assert_eq!(side.size, [1920.0, 1080.0]);
        assert_eq!(side.distortion, [0.01, -0.02, 0.0, 0.0, 0.003]);
        assert_eq!(side.rotation.row(1), DVec3::new(1.0, 0.0, 0.0));
        let front = &rig.cameras[1];
        assert_eq!(front.matrix.row(1), DVec3::new(0.0, 1410.0, 530.0));
        assert_close(front.rotation, DMat3::from_rotation_y(0.5), 1e-15);
        assert_eq!(front.translation, DVec3::new(0.0, 0.0, 3.0));

        // The same object at the top, and the rig written as TOML reads back.
        let inner = JSON_CAMERAS
            .trim()
            .strip_prefix("{\n  \"cameras\":")
            .unwrap();
        let top = parse(inner.strip_suffix('}').unwrap(), Format::Json).unwrap();
        assert_eq!(top, rig);
        let toml = dir.path().join("rig.toml");
        write_calibration_toml(&rig, &toml).unwrap();
        assert_same_rig(&read_calibration(&toml).unwrap(), &rig);
    }

    #[test]
    fn projection_follows_opencv_distortion_model() {
        let camera = Camera {
            name: "c".into(),
            size: [1000.0, 800.0],
            matrix: from_rows(&[1000.0, 0.0, 500.0, 0.0, 1100.0, 400.0, 0.0, 0.0, 1.0]),
            distortion: [0.1, 0.01, 0.001, 0.002, 0.001],
            rotation: DMat3::IDENTITY,
            translation: DVec3::ZERO,
        };
        // x = 0.2, y = -0.1: r² = 0.05, radial = 1 + 0.005 + 0.000025 +
        // 0.000000125 = 1.005025125;
        // x' = 0.2 radial + 2 p1 x y + p2 (r² + 2x²) = 0.201005025 − 0.00004 + 0.00026
        // y' = −0.1 radial + p1 (r² + 2y²) + 2 p2 x y = −0.1005025125 + 0.00007 − 0.00008
        let pixel = camera.project(DVec3::new(0.4, -0.2, 2.0)).unwrap();
        assert!(
            (pixel.x - (1000.0 * 0.201225025 + 500.0)).abs() < 1e-9,
            "{pixel}"
        );
        assert!(
            (pixel.y - (1100.0 * -0.1005125125 + 400.0)).abs() < 1e-9,
            "{pixel}"
        );
        // On the axis there is no distortion.
        assert_eq!(
            camera.project(DVec3::new(0.0, 0.0, 5.0)),
            Some(DVec2::new(500.0, 400.0))
        );
        // Behind, on the camera's plane, or NaN: no projection.
        for p in [
            DVec3::new(0.1, 0.0, -1.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::NAN,
        ] {
            assert_eq!(camera.project(p), None, "{p}");
        }
    }

    #[test]
    fn project_and_undistort_invert_each_other_on_the_demo_camera() {
        let camera = demo_camera_1();
        // And a lens with far more distortion than the demo's (a typical
        // action camera without its fisheye mode).
        let mut strong = camera.clone();
        strong.distortion = [-0.28, 0.08, 1e-3, -5e-4, -0.01];
        for camera in [camera, strong] {
            let mut worst = 0.0f64;
            for i in 0..=34 {
                for j in 0..=60 {
                    let pixel = DVec2::new(i as f64 * 32.0, j as f64 * 32.0);
                    let normalized = camera.undistort(pixel);
                    // A world point on the pixel's ray, 2.5 m away.
                    let in_camera = normalized.extend(1.0) * 2.5;
                    let world = camera.rotation.transpose() * (in_camera - camera.translation);
                    let back = camera.project(world).unwrap();
                    worst = worst.max(back.distance(pixel));
                }
            }
            assert!(worst < 1e-6, "{:?}: {worst} px", camera.distortion);
        }
    }

    #[test]
    fn centre_and_pose_matrix_agree_with_the_projection() {
        let camera = demo_camera_1();
        let centre = camera.centre();
        assert!(camera.to_camera(centre).length() < 1e-12);
        let p = DVec3::new(0.3, -0.2, 1.1);
        let rows = camera.pose_matrix();
        let in_camera = camera.to_camera(p);
        for (i, row) in rows.iter().enumerate() {
            let v = row[0] * p.x + row[1] * p.y + row[2] * p.z + row[3];
            assert!((v - in_camera[i]).abs() < 1e-12);
        }
        // Points in front of the camera are those along its third row.
        assert!(camera.project(centre + camera.rotation.row(2)).is_some());
        assert!(camera.project(centre - camera.rotation.row(2)).is_none());
    }

    #[test]
    fn rodrigues_vectors_match_glam_and_come_back() {
        for v in [
            DVec3::ZERO,
            DVec3::new(1e-12, 0.0, 0.0),
            DVec3::new(1.688, 1.048, -0.42),
            DVec3::new(0.0, 0.0, 3.0),
            DVec3::new(-2.0, 1.0, 0.5),
        ] {
            let expected = DMat3::from_quat(DQuat::from_scaled_axis(v));
            assert_close(rotation_from_rodrigues(v), expected, 1e-15);
            let back = rodrigues_from_rotation(rotation_from_rodrigues(v));
            assert!(back.abs_diff_eq(v, 1e-14), "{v} -> {back}");
        }
    }

    /// Writes `contents` as `name` and reads it: the error's text.
    fn read_error(dir: &Path, name: &str, contents: &[u8]) -> String {
        let path = dir.join(name);
        std::fs::write(&path, contents).unwrap();
        match read_calibration(&path) {
            Ok(rig) => panic!("{name} was read: {rig:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn bad_files_are_refused_with_the_file_line_and_what_was_expected() {
        let dir = tempfile::tempdir().unwrap();
        let toml = |from: &str, to: &str| {
            assert!(DEMO_CAMERA_1.contains(from), "{from}");
            DEMO_CAMERA_1.replacen(from, to, 1)
        };
        // One camera's object, with `field` added.
        let json_fields = |field: &str| {
            format!(
                r#"{{"matrix": [[900, 0, 320], [0, 900, 240], [0, 0, 1]],
                    "distortions": [0, 0, 0, 0], "translation": [0, 0, 2], {field}}}"#
            )
        };
        let json_camera = |field: &str| format!(r#"{{"a": {}}}"#, json_fields(field));
        let cases: Vec<(&str, String, &[&str])> = vec![
            (
                "a.toml",
                toml("fisheye = false", "fisheye = true"),
                &["a.toml:8:", "cam_01: fisheye model not supported"],
            ),
            (
                "b.toml",
                toml("[ 0.0, 0.0, 1.0]]", "]"),
                &[
                    "b.toml:4:10:",
                    "cam_01: `matrix` must be 3 rows of 3 numbers, found 2 rows of 3 numbers",
                ],
            ),
            (
                "c.toml",
                toml("1681.244873046875", "0.0"),
                &["c.toml:4:", "`matrix` has a zero focal length"],
            ),
            (
                "d.toml",
                toml("0.3211048899999996", "nan"),
                &[
                    "d.toml:7:",
                    "`translation` holds a number that is not finite",
                ],
            ),
            (
                "e.toml",
                toml("distortions", "distortion"),
                &["e.toml:1:", "cam_01: missing `distortions`"],
            ),
            (
                "f.toml",
                toml("0.002187234375, ", ""),
                &["f.toml:5:", "`distortions` must be 4 or 5 numbers"],
            ),
            (
                "g.toml",
                toml("[cam_01]", "[cam_01"),
                &["g.toml:1:", "not valid TOML"],
            ),
            (
                "h.toml",
                toml("[ 0.0, 0.0, 1.0]]", "[ 0.0, 1.0, 1.0]]"),
                &["h.toml:4:", "must be (fx, 0, cx; 0, fy, cy; 0, 0, 1)"],
            ),
            ("i.toml", String::new(), &["no camera in", "i.toml"]),
            (
                "j.toml",
                toml("rotation = [", "rotation = [ 0.1,"),
                &[
                    "j.toml:6:",
                    "`rotation` must be a Rodrigues vector of 3 numbers",
                ],
            ),
            (
                "a.json",
                json_camera(r#""rotation": [[2, 0, 0], [0, 1, 0], [0, 0, 1]]"#),
                &["a.json:1:", "a: `rotation` is not a rotation"],
            ),
            (
                "b.json",
                json_camera(r#""rotation": [[-1, 0, 0], [0, 1, 0], [0, 0, 1]]"#),
                &["b.json:1:", "`rotation` is a reflection"],
            ),
            (
                "c.json",
                json_camera(r#""rotatio": [0, 0, 0]"#),
                &["c.json:1:", "a: missing `rotation`"],
            ),
            (
                "d.json",
                json_camera(r#""rotation": [0, 0, 0], "fisheye": true"#),
                &["fisheye model not supported"],
            ),
            (
                "e.json",
                "{\"a\": {\n  \"matrix\": [1, 2,, 3]}}".into(),
                &["e.json:2:", "not valid JSON"],
            ),
            (
                "f.json",
                "[1, 2]".into(),
                &["f.json:1:1:", "must be an object of cameras keyed by name"],
            ),
            (
                "g.json",
                format!(
                    "{{\"x\": {0}, \"y\": {0}}}",
                    json_fields(r#""rotation": [0, 0, 0], "name": "same""#)
                ),
                &["g.json", "two cameras are named `same`"],
            ),
            (
                "a.yml",
                EASYMOCAP_YAML.replace("T_02", "Translation_02"),
                &["a.yml:5:", "02: missing `T_02`"],
            ),
            (
                "b.yml",
                EASYMOCAP_YAML.replace("R_02", "Rvec_02"),
                &["b.yml:5:", "missing `Rot_02` (3x3) or `R_02`", "extri.yml"],
            ),
            (
                "c.yml",
                EASYMOCAP_YAML.replace("   cols: 5", "   cols: 4"),
                &[
                    "c.yml:12:",
                    "1: `dist_1` must be 4 or 5 numbers",
                    "do not agree",
                ],
            ),
            (
                "d.yml",
                OPENCV_SINGLE_YAML.to_string() + "tvec: [1, 2, 3]\n",
                &["d.yml:18:", "`tvec` is given without a rotation"],
            ),
            (
                "e.yml",
                "%YAML:1.0\nnames: [a\nK_a: 1\n".into(),
                &["e.yml:", "not valid YAML"],
            ),
            (
                "f.yml",
                "%YAML:1.0\n---\n".into(),
                &["no camera in", "f.yml"],
            ),
            (
                "g.yml",
                OPENCV_SINGLE_YAML.replace("9.2e+02", ".Nan"),
                &[
                    "g.yml:7:",
                    "`camera_matrix` holds a number that is not finite",
                ],
            ),
            (
                "calib.txt",
                "whatever".into(),
                &["calib.txt: unknown calibration format"],
            ),
        ];
        for (name, contents, expected) in cases {
            let message = read_error(dir.path(), name, contents.as_bytes());
            for fragment in expected {
                assert!(
                    message.contains(fragment),
                    "{name}: {message:?} lacks {fragment:?}"
                );
            }
        }
        let message = read_error(dir.path(), "bytes.toml", b"[cam_01]\nname = \"\xff\"\n");
        assert!(
            message.contains("bytes.toml:2:9: not UTF-8 text"),
            "{message}"
        );
        let missing = read_calibration(&dir.path().join("missing.toml")).unwrap_err();
        assert!(matches!(missing, Error::Io { .. }), "{missing}");
    }

    #[test]
    fn no_input_makes_the_readers_panic() {
        // Every prefix of every sample, and samples with characters changed
        // by a fixed pseudo-random sequence: each either reads or is refused.
        let samples = [
            (DEMO_CAMERA_1, Format::Pose2SimToml),
            (EASYMOCAP_YAML, Format::OpenCvYaml),
            (OPENCV_SINGLE_YAML, Format::OpenCvYaml),
            (JSON_CAMERAS, Format::Json),
        ];
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        const CHARACTERS: &[u8] = b" \n\t:-[]{},\"'!%&*#01.e9xK_";
        for (text, format) in samples {
            for end in (0..=text.len()).filter(|&i| text.is_char_boundary(i)) {
                let _ = parse(&text[..end], format);
            }
            for _ in 0..300 {
                let mut bytes = text.as_bytes().to_vec();
                for _ in 0..1 + next() % 4 {
                    let at = (next() % bytes.len() as u64) as usize;
                    if bytes[at].is_ascii() {
                        bytes[at] = CHARACTERS[(next() % CHARACTERS.len() as u64) as usize];
                    }
                }
                if let Ok(text) = std::str::from_utf8(&bytes) {
                    let _ = parse(text, format);
                }
            }
        }
    }

    fn pose2sim_demo() -> Option<std::path::PathBuf> {
        let demo = mocap_testdata::shared("pose2sim-demo")?;
        if !demo.is_dir() {
            eprintln!("note: {} not found; skipping", demo.display());
            return None;
        }
        Some(demo)
    }

    #[test]
    fn pose2sim_demo_calibration_is_read_and_round_trips() {
        let Some(demo) = pose2sim_demo() else { return };
        let rig = read_calibration(&demo.join("S00_Calibration/Calib_qualisys.toml")).unwrap();
        let names: Vec<&str> = rig.cameras.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["cam_01", "cam_02", "cam_03", "cam_04"]);
        assert_eq!(rig.cameras[0], demo_camera_1());
        for camera in &rig.cameras {
            assert_eq!(camera.size, [1088.0, 1920.0]);
            assert_eq!(camera.distortion[4], 0.0);
            // The cameras stand 3 to 5 m from the world's origin, where the
            // participant is.
            let distance = camera.centre().length();
            assert!(
                (2.5..5.5).contains(&distance),
                "{}: {distance}",
                camera.name
            );
            assert!(camera.project(DVec3::new(0.0, 0.0, 1.0)).is_some());
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("Calib.toml");
        write_calibration_toml(&rig, &path).unwrap();
        assert_same_rig(&read_calibration(&path).unwrap(), &rig);
    }
}
