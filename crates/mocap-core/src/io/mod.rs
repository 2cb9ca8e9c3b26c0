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
//! [`write_motion`] picks the writer the same way, and a format's crate
//! joins it through [`register_writer`] (mocap-gltf's `.glb` and `.gltf`).

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

/// Reads a motion file of a format given with [`register_reader`].
pub type ReadFn = fn(&Path) -> Result<Motion>;

/// Writes a motion file of a format given with [`register_writer`] and
/// returns notes for the person who asked: what the writer changed on the
/// way (lengths scaled to the format's units, axes turned), so that a
/// converter can say so. A writer that changes nothing returns none.
pub type WriteFn = fn(&Path, &Motion) -> Result<Vec<String>>;

/// A format given to the whole process by another crate: the extensions it
/// is chosen by, what it is, and the function that reads or writes it.
struct Registered<F> {
    /// Lower-case extensions, without the dot.
    extensions: Vec<String>,
    describe: &'static str,
    run: F,
}

/// Readers of the formats the core does not know, in the order they were
/// given ([`register_reader`]).
static REGISTERED_READERS: RwLock<Vec<Registered<ReadFn>>> = RwLock::new(Vec::new());

/// Writers of the formats the core does not know ([`register_writer`]).
static REGISTERED_WRITERS: RwLock<Vec<Registered<WriteFn>>> = RwLock::new(Vec::new());

/// Built-in extensions: [`register_reader`] cannot take them over.
const BUILT_IN: [&str; 3] = ["bvh", "asf", "amc"];

/// Built-in extensions: [`register_writer`] cannot take them over.
const BUILT_IN_WRITTEN: [&str; 1] = ["bvh"];

/// Adds `run` for `extensions` (those in `built_in` left out) to `registry`:
/// the one rule of [`register_reader`] and [`register_writer`].
fn register<F>(
    registry: &RwLock<Vec<Registered<F>>>,
    built_in: &[&str],
    extensions: &[&'static str],
    describe: &'static str,
    run: F,
) {
    let extensions: Vec<String> = extensions
        .iter()
        .map(|e| e.trim_start_matches('.').to_ascii_lowercase())
        .filter(|e| !e.is_empty() && !built_in.contains(&e.as_str()))
        .collect();
    if extensions.is_empty() {
        return;
    }
    let mut formats = registry.write().unwrap_or_else(|e| e.into_inner());
    // A later registration takes its extensions over from earlier ones.
    for format in formats.iter_mut() {
        format.extensions.retain(|e| !extensions.contains(e));
    }
    formats.retain(|r| !r.extensions.is_empty());
    formats.push(Registered {
        extensions,
        describe,
        run,
    });
}

/// The function registered in `registry` for the lower-case `extension`.
fn registered<F: Copy>(registry: &RwLock<Vec<Registered<F>>>, extension: &str) -> Option<F> {
    registry
        .read()
        .unwrap_or_else(|e| e.into_inner())
        .iter()
        .find(|r| r.extensions.iter().any(|e| e == extension))
        .map(|r| r.run)
}

/// The formats of `registry` for an error message: `, or .a or .b (what
/// they are)` for each.
fn registered_types<F>(registry: &RwLock<Vec<Registered<F>>>) -> String {
    let formats = registry.read().unwrap_or_else(|e| e.into_inner());
    let mut types = String::new();
    for format in formats.iter() {
        let extensions: Vec<String> = format.extensions.iter().map(|e| format!(".{e}")).collect();
        types += &format!(", or {} ({})", extensions.join(" or "), format.describe);
    }
    types
}

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
pub fn register_reader(extensions: &[&'static str], describe: &'static str, read: ReadFn) {
    register(&REGISTERED_READERS, &BUILT_IN, extensions, describe, read);
}

/// Makes every later [`write_motion`] and [`write_motion_noted`] in this
/// process write files ending in one of `extensions` (without the dot,
/// matched in any case) with `write`, as [`register_reader`] does for
/// reading: how a format whose library is too heavy for the core (glTF)
/// reaches `mocap convert` and every command that writes motions.
/// `describe` says what such a file is, for the error on a file of an
/// unknown type. The latest registration of an extension wins; `bvh` keeps
/// the core's writer.
///
/// ```
/// use mocap_core::io::{register_writer, write_motion_noted};
/// use mocap_core::{Error, Motion};
///
/// fn write_mine(path: &std::path::Path, _: &Motion) -> mocap_core::Result<Vec<String>> {
///     Err(Error::Invalid(format!("{}: not implemented", path.display())))
/// }
/// register_writer(&["mine"], "my format", write_mine);
/// # let walk = mocap_core::io::bvh::read_bvh(&mocap_testdata::sample_walk())?;
/// let err = write_motion_noted("take.mine".as_ref(), &walk).unwrap_err();
/// assert!(err.to_string().contains("not implemented"));
/// # Ok::<(), mocap_core::Error>(())
/// ```
pub fn register_writer(extensions: &[&'static str], describe: &'static str, write: WriteFn) {
    register(
        &REGISTERED_WRITERS,
        &BUILT_IN_WRITTEN,
        extensions,
        describe,
        write,
    );
}

/// The reader registered for the lower-case `extension`, if any.
fn registered_reader(extension: &str) -> Option<ReadFn> {
    registered(&REGISTERED_READERS, extension)
}

/// What the error on a file of an unknown type says the readers expect:
/// the built-in formats, then the registered ones.
fn expected_types() -> String {
    String::from("expected .bvh, or .asf followed by .amc") + &registered_types(&REGISTERED_READERS)
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

/// Writes a motion to `path`, choosing the format from the extension: BVH,
/// or a format given with [`register_writer`]. The writer's notes are
/// dropped; a converter that reports them calls [`write_motion_noted`].
pub fn write_motion(path: &Path, motion: &Motion) -> Result<()> {
    write_motion_noted(path, motion).map(drop)
}

/// Writes a motion as [`write_motion`] does and returns what the writer
/// says it changed on the way (none for BVH; e.g. "lengths scaled by 0.01"
/// for glTF, whose unit is the metre), for the person who asked.
pub fn write_motion_noted(path: &Path, motion: &Motion) -> Result<Vec<String>> {
    match extension(path).as_str() {
        "bvh" => bvh::write_bvh(path, motion).map(|()| Vec::new()),
        other => match registered(&REGISTERED_WRITERS, other) {
            Some(write) => write(path, motion),
            None => Err(Error::Invalid(format!(
                "{}: cannot write this type of motion file (can write .bvh{})",
                path.display(),
                registered_types(&REGISTERED_WRITERS)
            ))),
        },
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
