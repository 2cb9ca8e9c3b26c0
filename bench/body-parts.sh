#!/bin/bash
# Body parts found without a rig file on every rig of other-rigs and parser-cases
# (bench/results/body-parts.md).
set -e
cd "$(dirname "$0")/.."
cargo build --release -p mocap-core --example body_parts_report
T=${CARGO_TARGET_DIR:-target}
D=${MOCAP_SHARED_DATA:-../shared/data}
{
  cat <<'HEADER'
# Body parts on every rig, without a rig file (mocap-core)

Made by `bash bench/body-parts.sh` (`crates/mocap-core/examples/body_parts_report.rs`), on every
BVH file of `../shared/data/other-rigs` (every folder; the 83 CMU-Daz takes of 8 subjects are one
rig) and `../shared/data/parser-cases`. How the parts are found: [`docs/rigs.md`](../../docs/rigs.md).

- "rig (how found)": `BodyMap::detect` on the file's skeleton, no rig file given.
- "renamed `joint_0..N`": the same skeleton with every joint renamed, so that no name helps: the
  parts are found from the skeleton's shape (left and right from the rest pose). "same joint by
  shape" counts the parts found by name that the shape puts at the same joint. The differences are
  where the two readings choose different joints for one part: FAIR's chest (the CMU table's
  `Spine2`; the clavicles hang from `Spine3`, which the shape takes), the CMU ASF conversion's neck
  (`lowerneck` sits at the thorax, the shape takes `upperneck`) and hands (`lhand` sits at the wrist,
  the shape takes `lfingers`).
- "left on the body's left": over every frame of every clip, with the parts found by name, the share
  of frames where the left hip (shoulder) is on the left of the body, whose left is up (pelvis to
  head) × forward (ankles to the tips of the feet). Checked on the motion, not on the names. Below
  100% are frames where the feet do not show where the body faces (a foot turned out or lifted):
  this is a check of the sides, not the sides' definition.
- The one file refused is a two-joint reader test, no body; the error names the missing parts,
  points to `--rig` and carries a rig-file template.

HEADER
  "$T/release/examples/body_parts_report" "$D/other-rigs" "$D/parser-cases"
} > bench/results/body-parts.md
