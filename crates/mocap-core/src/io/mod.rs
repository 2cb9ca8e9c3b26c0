//! Reading and writing motion files.
//!
//! - [`bvh`]: Biovision Hierarchy, read and write;
//! - [`asf_amc`]: Acclaim skeleton and motion (CMU, HDM05), read;
//! - [`positions`]: global joint positions as CSV or JSON;
//! - [`atomic`]: writing a file so that it is either whole or absent.
//!
//! [`read_motion`] picks the reader from the file names, so that every
//! command accepts the same inputs. Formats the core does not know (a
//! capability's own, such as mocap-fuse's sensor recordings) join them
//! through [`register_reader`]: every later [`read_motion`],
//! [`read_motions`] and [`MotionSource::group`] in the process reads them.

pub mod asf_amc;
pub mod atomic;
pub mod bvh;
pub mod positions;

use std::path::{Path, PathBuf};
use std::sync::RwLock;

use crate::error::{Error, Result};
use crate::motion::Motion;

/// The kinds of motion input a command accepts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MotionSource {
    /// One BVH file.
    Bvh(PathBuf),
    /// An ASF skeleton with one AMC motion of it.
    AsfAmc { asf: PathBuf, amc: PathBuf },
    /// One file of a format given to the process with [`register_reader`],
    /// read by the reader registered for its extension.
    Registered(PathBuf),
}

/// A reader given to the whole process ([`register_reader`]).
struct RegisteredReader {
    /// Lower-case extensions, without the dot.
    extensions: Vec<String>,
    describe: &'static str,
    read: fn(&Path) -> Result<Motion>,
}

/// Readers of the formats the core does not know, in the order they were
/// given ([`register_reader`]).
static REGISTERED_READERS: RwLock<Vec<RegisteredReader>> = RwLock::new(Vec::new());

/// Built-in extensions: [`register_reader`] cannot take them over.
const BUILT_IN: [&str; 3] = ["bvh", "asf", "amc"];

/// Makes every later [`read_motion`], [`read_motions`] and
/// [`MotionSource::group`] in this process read files ending in one of
/// `extensions` (without the dot, matched in any case) with `read`:
/// how a capability's own file format (mocap-fuse's sensor recordings)
/// reaches every command that reads motions without the core depending on
/// it. `describe` says what such a file is, for the error on a file of an
/// unknown type ("a sensor recording"). An extension registered again is
/// read by the latest reader (registering twice is harmless); the built-in
/// extensions (`bvh`, `asf`, `amc`) keep their readers. Folder searches
/// ([`find_files`], [`find_bvh_files`]) are not affected.
///
/// ```
/// use mocap_core::io::{read_motion, register_reader};
/// use mocap_core::{Error, Motion};
///
/// fn read_mine(path: &std::path::Path) -> mocap_core::Result<Motion> {
///     Err(Error::Invalid(format!("{}: not implemented", path.display())))
/// }
/// register_reader(&["mine"], "my format", read_mine);
/// let err = read_motion("take.mine".as_ref()).unwrap_err();
/// assert!(err.to_string().contains("not implemented"));
/// ```
pub fn register_reader(
    extensions: &[&'static str],
    describe: &'static str,
    read: fn(&Path) -> Result<Motion>,
) {
    let extensions: Vec<String> = extensions
        .iter()
        .map(|e| e.trim_start_matches('.').to_ascii_lowercase())
        .filter(|e| !e.is_empty() && !BUILT_IN.contains(&e.as_str()))
        .collect();
    if extensions.is_empty() {
        return;
    }
    let mut readers = REGISTERED_READERS
        .write()
        .unwrap_or_else(|e| e.into_inner());
    // A later registration takes its extensions over from earlier ones.
    for reader in readers.iter_mut() {
        reader.extensions.retain(|e| !extensions.contains(e));
    }
    readers.retain(|r| !r.extensions.is_empty());
    readers.push(RegisteredReader {
        extensions,
        describe,
        read,
    });
}

/// The reader registered for the lower-case `extension`, if any.
fn registered_reader(extension: &str) -> Option<fn(&Path) -> Result<Motion>> {
    REGISTERED_READERS
        .read()
        .unwrap_or_else(|e| e.into_inner())
        .iter()
        .find(|r| r.extensions.iter().any(|e| e == extension))
        .map(|r| r.read)
}

/// What the error on a file of an unknown type says the readers expect:
/// the built-in formats, then the registered ones.
fn expected_types() -> String {
    let mut expected = String::from("expected .bvh, or .asf followed by .amc");
    let readers = REGISTERED_READERS.read().unwrap_or_else(|e| e.into_inner());
    for reader in readers.iter() {
        let extensions: Vec<String> = reader.extensions.iter().map(|e| format!(".{e}")).collect();
        expected += &format!(", or {} ({})", extensions.join(" or "), reader.describe);
    }
    expected
}

impl MotionSource {
    /// Groups command-line paths into motions: each `.bvh` is one motion; an
    /// `.asf` pairs with every `.amc` that follows it (`X.asf A.amc B.amc`);
    /// an `.amc` with no `.asf` before it takes the one beside it
    /// ([`asf_amc::skeleton_file_for`]); a file of a registered format
    /// ([`register_reader`]) is one motion.
    pub fn group(paths: &[PathBuf]) -> Result<Vec<MotionSource>> {
        let mut sources = Vec::new();
        let mut current_asf: Option<&PathBuf> = None;
        for path in paths {
            match extension(path).as_str() {
                "bvh" => sources.push(MotionSource::Bvh(path.clone())),
                "asf" => current_asf = Some(path),
                // An AMC takes the ASF given before it, else the one beside
                // it (`asf_amc::skeleton_file_for`).
                "amc" => sources.push(MotionSource::AsfAmc {
                    asf: match current_asf {
                        Some(asf) => asf.clone(),
                        None => asf_amc::skeleton_file_for(path)?,
                    },
                    amc: path.clone(),
                }),
                other if registered_reader(other).is_some() => {
                    sources.push(MotionSource::Registered(path.clone()))
                }
                _ => {
                    return Err(Error::Invalid(format!(
                        "{}: unknown motion file type ({})",
                        path.display(),
                        expected_types()
                    )))
                }
            }
        }
        if let (Some(asf), false) = (
            current_asf,
            sources
                .iter()
                .any(|s| matches!(s, MotionSource::AsfAmc { .. })),
        ) {
            return Err(Error::Invalid(format!(
                "{}: an ASF skeleton needs at least one AMC motion after it",
                asf.display()
            )));
        }
        Ok(sources)
    }

    /// A short name for messages and reports.
    pub fn display_name(&self) -> String {
        match self {
            MotionSource::Bvh(p) => p.display().to_string(),
            MotionSource::AsfAmc { amc, .. } => amc.display().to_string(),
            MotionSource::Registered(path) => path.display().to_string(),
        }
    }

    /// The number of frames and the frame time of the motion, from the
    /// file's header, without reading the frames, where the format gives
    /// them there (BVH's `Frames:` and `Frame Time:`); `None` where only
    /// reading the motion tells (AMC). For refusing a take too long for a
    /// command before it is read.
    pub fn announced_length(&self) -> Result<Option<(usize, f64)>> {
        match self {
            MotionSource::Bvh(path) => {
                let (_, frames, frame_time) = bvh::read_bvh_header(path)?;
                Ok(Some((frames, frame_time)))
            }
            MotionSource::AsfAmc { .. } | MotionSource::Registered(_) => Ok(None),
        }
    }

    pub fn read(&self) -> Result<Motion> {
        match self {
            MotionSource::Bvh(path) => bvh::read_bvh(path),
            MotionSource::AsfAmc { asf, amc } => asf_amc::read_asf_amc(asf, amc),
            MotionSource::Registered(path) => match registered_reader(&extension(path)) {
                Some(read) => read(path),
                None => Err(Error::Invalid(format!(
                    "{}: no reader is registered for this file type ({})",
                    path.display(),
                    expected_types()
                ))),
            },
        }
    }
}

/// Reads every motion named by `paths` (see [`MotionSource::group`]).
pub fn read_motions(paths: &[PathBuf]) -> Result<Vec<(MotionSource, Motion)>> {
    MotionSource::group(paths)?
        .into_iter()
        .map(|s| s.read().map(|m| (s, m)))
        .collect()
}

/// Reads one motion file: a BVH file, an AMC motion with the ASF skeleton
/// beside it ([`asf_amc::skeleton_file_for`]), or a file of a registered
/// format ([`register_reader`]).
pub fn read_motion(path: &Path) -> Result<Motion> {
    // One path groups into one motion or an error (a lone `.asf` is one).
    let source = MotionSource::group(&[path.to_path_buf()])?
        .pop()
        .expect("a path that groups without error is one motion");
    source.read()
}

/// Writes a motion to `path`, choosing the format from the extension.
pub fn write_motion(path: &Path, motion: &Motion) -> Result<()> {
    match extension(path).as_str() {
        "bvh" => bvh::write_bvh(path, motion),
        _ => Err(Error::Invalid(format!(
            "{}: can only write .bvh motion files",
            path.display()
        ))),
    }
}

/// The files among `inputs` whose extension is one of `extensions` (lower
/// case; files are matched in any case): files as given, folders searched
/// recursively; sorted and without repeats. An input that does not exist is
/// an error naming it.
pub fn find_files(inputs: &[PathBuf], extensions: &[&str]) -> Result<Vec<PathBuf>> {
    fn walk(dir: &Path, extensions: &[&str], out: &mut Vec<PathBuf>) -> Result<()> {
        let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
        for entry in entries {
            let path = entry.map_err(|e| Error::io(dir, e))?.path();
            if path.is_dir() {
                walk(&path, extensions, out)?;
            } else if extensions.contains(&extension(&path).as_str()) {
                out.push(path);
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    for input in inputs {
        if input.is_dir() {
            walk(input, extensions, &mut out)?;
        } else if input.is_file() {
            out.push(input.clone());
        } else {
            return Err(Error::Invalid(format!(
                "{}: no such file or folder",
                input.display()
            )));
        }
    }
    out.sort();
    out.dedup();
    Ok(out)
}

/// The BVH files among `inputs` (files as given, folders searched
/// recursively), sorted and without repeats. An input that does not exist,
/// or no BVH file at all, is an error naming the inputs.
pub fn find_bvh_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let out = find_files(inputs, &["bvh"])?;
    if out.is_empty() {
        let names: Vec<String> = inputs.iter().map(|p| p.display().to_string()).collect();
        return Err(Error::Invalid(format!(
            "no .bvh files in {}",
            names.join(", ")
        )));
    }
    Ok(out)
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}
