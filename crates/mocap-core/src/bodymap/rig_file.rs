//! Rig files: a user's description of a rig's body parts (TOML), read for
//! one skeleton or registered for the whole process, and the template
//! printed when a rig's body parts cannot be found.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::sync::RwLock;

use super::names::{best_rig, find_joint, NameIndex};
use super::{joint_list, BodyMap, BodyPart, FoundBy};
use crate::error::{line_column, Error, ParseError, Result};
use crate::skeleton::Skeleton;

/// A rig file, as written by users.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RigFile {
    name: Option<String>,
    #[serde(default)]
    parts: BTreeMap<String, String>,
    mirror: Option<MirrorSection>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MirrorSection {
    pairs: Vec<[String; 2]>,
}

impl RigFile {
    /// Parses a rig file and checks its part keys; errors name `path`,
    /// with line and column for TOML syntax.
    pub(super) fn parse(text: &str, path: &Path) -> Result<RigFile> {
        let file: RigFile = toml::from_str(text).map_err(|e| {
            let (line, column) = match e.span() {
                Some(span) => line_column(text, span.start),
                None => (1, 1),
            };
            ParseError::new(path, line, column, format!("rig file: {}", e.message()))
        })?;
        if let Some(key) = file.parts.keys().find(|k| BodyPart::from_key(k).is_none()) {
            let keys: Vec<&str> = BodyPart::ALL.iter().map(|p| p.key()).collect();
            return Err(Error::Invalid(format!(
                "{}: [parts] has unknown part {key:?}; the parts are {}",
                path.display(),
                keys.join(", ")
            )));
        }
        Ok(file)
    }

    /// Every joint name the file gives (parts and mirror pairs).
    fn joint_names(&self) -> impl Iterator<Item = &String> {
        self.parts
            .values()
            .chain(self.mirror.iter().flat_map(|m| m.pairs.iter().flatten()))
    }
}

/// A rig file given to the whole process ([`register_rig_file`]).
struct RegisteredRig {
    path: PathBuf,
    file: RigFile,
}

impl RegisteredRig {
    /// Whether `skeleton` has every joint the file names (a file with no
    /// names fits nothing: it would take over every skeleton).
    fn fits(&self, skeleton: &Skeleton) -> bool {
        let mut names = self.file.joint_names().peekable();
        names.peek().is_some() && names.all(|n| find_joint(skeleton, n).is_some())
    }
}

/// Rig files [`BodyMap::detect`] tries before the built-in rigs, in the
/// order they were given.
static REGISTERED_RIGS: RwLock<Vec<RegisteredRig>> = RwLock::new(Vec::new());

/// Reads a rig file (format in the module documentation) and makes every
/// later [`BodyMap::detect`] in this process use it for the skeletons that
/// have all the joints it names (files given earlier are tried first).
/// This is how a rig the built-in tables do not know reaches every
/// capability (`mocap --rig FILE`). Fails, naming the file (and line and
/// column for TOML syntax), on a file that cannot be read or parsed, an
/// unknown part key, or a file that names no joint.
pub fn register_rig_file(path: impl AsRef<Path>) -> Result<()> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let file = RigFile::parse(&text, path)?;
    if file.joint_names().next().is_none() {
        return Err(Error::Invalid(format!(
            "{}: the rig file names no joint: list the rig's joints under [parts] \
             (e.g. pelvis = \"Hips\")",
            path.display()
        )));
    }
    REGISTERED_RIGS
        .write()
        .unwrap_or_else(|e| e.into_inner())
        .push(RegisteredRig {
            path: path.to_path_buf(),
            file,
        });
    Ok(())
}

/// The map `file` (read from `path`) gives `skeleton`: the parts it lists,
/// the others from the closest naming convention. Fails, naming the file,
/// on a joint the skeleton lacks or a required part still missing.
pub(super) fn map_from_file(file: &RigFile, path: &Path, skeleton: &Skeleton) -> Result<BodyMap> {
    let where_ = path.display();
    let mut map = best_rig(&NameIndex::new(skeleton)).map;
    map.rig = file
        .name
        .clone()
        .unwrap_or_else(|| path.display().to_string());
    map.found_by = FoundBy::RigFile;
    for (key, joint_name) in &file.parts {
        let part = BodyPart::from_key(key).expect("part keys are checked when parsed");
        let joint = find_joint(skeleton, joint_name).ok_or_else(|| {
            Error::Invalid(format!(
                "{where_}: [parts] {key} = {joint_name:?}, but the skeleton has no such \
                 joint (joints: {})",
                joint_list(skeleton)
            ))
        })?;
        map.joints[part.index()] = Some(joint);
    }
    if let Some(mirror) = &file.mirror {
        for [left, right] in &mirror.pairs {
            let find = |name: &String| {
                find_joint(skeleton, name).ok_or_else(|| {
                    Error::Invalid(format!(
                        "{where_}: [mirror] pair [{left:?}, {right:?}]: the skeleton has \
                         no joint {name:?}"
                    ))
                })
            };
            map.extra_pairs.push((find(left)?, find(right)?));
        }
    }
    let missing: Vec<String> = map
        .missing()
        .into_iter()
        .filter(|p| p.is_required())
        .map(|p| p.key().to_string())
        .collect();
    if !missing.is_empty() {
        return Err(Error::Invalid(format!(
            "{where_}: no joint for the required parts {}; add them under [parts]",
            missing.join(", ")
        )));
    }
    Ok(map)
}

/// What the registered rig files say about `skeleton`: the map of the first
/// that fits it (with its own errors), else a description of each file
/// given and the joints it names that the skeleton lacks (a misspelt name
/// in one would otherwise look like no file at all).
pub(super) fn registered_map(
    skeleton: &Skeleton,
) -> std::result::Result<Result<BodyMap>, Vec<String>> {
    let registered = REGISTERED_RIGS.read().unwrap_or_else(|e| e.into_inner());
    if let Some(rig) = registered.iter().find(|rig| rig.fits(skeleton)) {
        return Ok(map_from_file(&rig.file, &rig.path, skeleton));
    }
    Err(registered
        .iter()
        .map(|rig| {
            let lacking: Vec<String> = rig
                .file
                .joint_names()
                .filter(|n| find_joint(skeleton, n).is_none())
                .map(|n| format!("{n:?}"))
                .take(4)
                .collect();
            format!(
                "{} names {}, which this skeleton lacks",
                rig.path.display(),
                lacking.join(", ")
            )
        })
        .collect())
}

/// A rig file for `skeleton` with the `found` joints filled in and the
/// other parts left as comments to fill in (required ones marked). With
/// `sides_unknown`, the left/right parts found are a guess, said so in a
/// comment.
pub(super) fn template(
    skeleton: &Skeleton,
    found: &[Option<usize>; BodyPart::COUNT],
    sides_unknown: bool,
) -> String {
    let mut out = String::from(
        "name = \"my rig\"   # shown by `mocap info`\n\
         [parts]           # part = \"joint name\"; uncomment and fill in the TODO lines\n",
    );
    if sides_unknown {
        out += "# CHECK: left and right are a guess (swap left_* and right_* if wrong)\n";
    }
    for part in BodyPart::ALL {
        let line = match found[part.index()] {
            Some(joint) => format!("{} = {:?}", part.key(), skeleton.joint(joint).name),
            None => format!("# {} = \"\"", part.key()),
        };
        let note = match (found[part.index()], part.is_required()) {
            (Some(_), _) => String::new(),
            (None, true) => format!(" # TODO, required: {}", part.point()),
            (None, false) => format!(" # optional: {}", part.point()),
        };
        if note.is_empty() {
            let _ = writeln!(out, "{line}");
        } else {
            let _ = writeln!(out, "{line:<24}{note}");
        }
    }
    out
}
