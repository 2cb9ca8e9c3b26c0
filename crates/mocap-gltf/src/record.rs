//! What the writer records in the file's `extras` so that reading it back
//! gives the take that was written: glTF has no place for a take's unit,
//! its turn to Y-up, its joints' channel layouts, end sites or exact frame
//! time, and other tools ignore what they do not know.
//!
//! The asset's extras hold `{"mocap": SkeletonRecord}` (where the units
//! are found first, by any tool: `asset.extras.mocap.units_per_metre`) and
//! the animation's `{"mocap": AnimationRecord}`.

use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{Channel, Skeleton};
use serde::{Deserialize, Serialize};

/// The key under which the records sit in an `extras` object.
pub const KEY: &str = "mocap";

/// The take's skeleton as glTF cannot say it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkeletonRecord {
    /// The take's length units in a metre (100 for centimetres): the file's
    /// lengths, in metres, are multiplied by it when read back.
    pub units_per_metre: f32,
    /// The rotation (x, y, z, w) that turned the take Y-up before it was
    /// written; reading undoes it. Absent when the take was Y-up.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turned: Option<[f32; 4]>,
    /// One entry for each joint of the first skin, in the skin's order.
    pub joints: Vec<JointRecord>,
}

/// One joint's channels (BVH names, in file order) and end sites (offsets
/// in metres, in the joint's frame).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointRecord {
    pub name: String,
    pub channels: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub end_sites: Vec<[f32; 3]>,
}

/// The take's frame time in seconds, exactly as the take had it (the
/// animation's key times are single precision).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AnimationRecord {
    pub frame_time: f64,
}

impl SkeletonRecord {
    /// The record of `skeleton`, whose lengths are in metres already.
    pub fn new(skeleton: &Skeleton, units_per_metre: f32, turned: Option<Quat>) -> SkeletonRecord {
        SkeletonRecord {
            units_per_metre,
            turned: turned.map(|q| q.to_array()),
            joints: skeleton
                .joints()
                .iter()
                .map(|joint| JointRecord {
                    name: joint.name.clone(),
                    channels: joint
                        .channels
                        .iter()
                        .map(|c| c.name().to_string())
                        .collect(),
                    end_sites: joint.end_sites.iter().map(|e| e.to_array()).collect(),
                })
                .collect(),
        }
    }

    /// The record of the joint named `name`.
    pub fn joint(&self, name: &str) -> Option<&JointRecord> {
        self.joints.iter().find(|j| j.name == name)
    }

    /// The turn to undo, if the take was turned.
    pub fn turned(&self) -> Option<Quat> {
        self.turned.map(Quat::from_array)
    }
}

impl JointRecord {
    /// The channels, or the name of one that is not a BVH channel.
    pub fn channels(&self) -> Result<Vec<Channel>, String> {
        self.channels
            .iter()
            .map(|name| Channel::parse(name).ok_or_else(|| name.clone()))
            .collect()
    }

    pub fn end_sites(&self) -> Vec<Vec3> {
        self.end_sites
            .iter()
            .map(|&e| Vec3::from_array(e))
            .collect()
    }
}

/// `{"mocap": record}` as glTF's raw `extras` value.
pub fn to_extras<T: Serialize>(record: &T) -> gltf_json::Extras {
    let mut object = serde_json::Map::new();
    object.insert(
        KEY.to_string(),
        serde_json::to_value(record).expect("records are plain numbers and strings"),
    );
    let text = serde_json::to_string(&object).expect("a JSON object serialises");
    Some(serde_json::value::RawValue::from_string(text).expect("serde_json wrote valid JSON"))
}

/// The record under [`KEY`] in an `extras` value: `Ok(None)` where there is
/// none (a file another tool wrote), an error message where it is there
/// but not one of ours.
pub fn from_extras<T: for<'de> Deserialize<'de>>(
    extras: &gltf_json::Extras,
) -> Result<Option<T>, String> {
    let Some(raw) = extras else {
        return Ok(None);
    };
    let Ok(serde_json::Value::Object(mut object)) = serde_json::from_str(raw.get()) else {
        return Ok(None);
    };
    match object.remove(KEY) {
        None => Ok(None),
        Some(value) => serde_json::from_value(value)
            .map(Some)
            .map_err(|e| format!("its `extras.{KEY}` record is damaged ({e})")),
    }
}
