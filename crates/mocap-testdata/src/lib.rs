//! Where tests, examples and benchmarks find their data, in one place.
//!
//! Real motion capture for tests lives beside the repository in
//! `../shared/data` (CI has it; see its READMEs), or wherever
//! `MOCAP_SHARED_DATA` points. Tests that need it call [`shared_data`] and
//! return early, with a note, when it is absent. Small samples that ship with
//! the project are in `samples/` ([`sample`]).

use std::path::{Path, PathBuf};

/// The repository's root folder (the Cargo workspace).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The folder of real data: `MOCAP_SHARED_DATA`, else
/// `<repository>/../shared/data`. `None` (after printing a note on standard
/// error) when it does not exist.
pub fn shared_data() -> Option<PathBuf> {
    let dir = match std::env::var_os("MOCAP_SHARED_DATA") {
        Some(d) => PathBuf::from(d),
        None => repo_root().join("../shared/data"),
    };
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "note: shared data not found at {} (set MOCAP_SHARED_DATA); skipping",
            dir.display()
        );
        None
    }
}

/// A file or folder under the shared data, when the shared data is there.
pub fn shared(relative: impl AsRef<Path>) -> Option<PathBuf> {
    shared_data().map(|d| d.join(relative))
}

/// A sample bundled in `samples/`.
pub fn sample(name: &str) -> PathBuf {
    repo_root().join("samples").join(name)
}

/// The bundled 6.5-second Bandai walk.
pub fn sample_walk() -> PathBuf {
    sample("dataset-1_walk_normal_001.bvh")
}

/// The `.bvh` files directly in `dir`, sorted by name.
pub fn bvh_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")))
        .collect();
    files.sort();
    files
}

/// The Bandai rig's joints under another naming scheme (German names, as a
/// studio's own convention might have them), which no built-in rig table
/// knows: `(Bandai name, other name)`.
pub const RENAMED_BANDAI_JOINTS: [(&str, &str); 22] = [
    ("joint_Root", "Wurzel"),
    ("Hips", "Becken"),
    ("Spine", "Wirbel"),
    ("Chest", "Brust"),
    ("Neck", "Hals"),
    ("Head", "Kopf"),
    ("Shoulder_L", "Schluesselbein_li"),
    ("UpperArm_L", "Oberarm_li"),
    ("LowerArm_L", "Unterarm_li"),
    ("Hand_L", "Handgelenk_li"),
    ("Shoulder_R", "Schluesselbein_re"),
    ("UpperArm_R", "Oberarm_re"),
    ("LowerArm_R", "Unterarm_re"),
    ("Hand_R", "Handgelenk_re"),
    ("UpperLeg_L", "Oberschenkel_li"),
    ("LowerLeg_L", "Unterschenkel_li"),
    ("Foot_L", "Knoechel_li"),
    ("Toes_L", "Zehen_li"),
    ("UpperLeg_R", "Oberschenkel_re"),
    ("LowerLeg_R", "Unterschenkel_re"),
    ("Foot_R", "Knoechel_re"),
    ("Toes_R", "Zehen_re"),
];

/// A rig file (`mocap_core::bodymap`'s format) for [`RENAMED_BANDAI_JOINTS`].
pub const RENAMED_BANDAI_RIG: &str = r#"name = "Studio (German names)"
[parts]
pelvis = "Becken"
spine = "Wirbel"
chest = "Brust"
neck = "Hals"
head = "Kopf"
left_clavicle = "Schluesselbein_li"
left_shoulder = "Oberarm_li"
left_elbow = "Unterarm_li"
left_wrist = "Handgelenk_li"
right_clavicle = "Schluesselbein_re"
right_shoulder = "Oberarm_re"
right_elbow = "Unterarm_re"
right_wrist = "Handgelenk_re"
left_hip = "Oberschenkel_li"
left_knee = "Unterschenkel_li"
left_ankle = "Knoechel_li"
left_toe = "Zehen_li"
right_hip = "Oberschenkel_re"
right_knee = "Unterschenkel_re"
right_ankle = "Knoechel_re"
right_toe = "Zehen_re"
"#;

/// The text of a Bandai BVH file with its joints renamed by
/// [`RENAMED_BANDAI_JOINTS`] (the motion is unchanged).
pub fn renamed_bandai_bvh(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let renamed: Vec<String> = text
        .lines()
        .map(|line| {
            let trimmed = line.trim_start();
            for keyword in ["ROOT ", "JOINT "] {
                if let Some(name) = trimmed.strip_prefix(keyword) {
                    let name = name.trim();
                    if let Some((_, other)) = RENAMED_BANDAI_JOINTS.iter().find(|(b, _)| *b == name)
                    {
                        let indent = &line[..line.len() - trimmed.len()];
                        return format!("{indent}{keyword}{other}");
                    }
                }
            }
            line.to_string()
        })
        .collect();
    renamed.join("\n") + "\n"
}
