//! Restyling clips: `mocap style apply`.
//!
//! [`restyle`] works on motions in memory (the evaluation and the benchmark
//! call it); [`apply`] reads the files, restyles, and writes the output.
//!
//! The output keeps the source's skeleton (bone lengths) and frame rate.
//! The root's horizontal path and heading come from the source (time-warped
//! with the patches, see below for the root's path within a stride), its height from the style clip, scaled by the ratio of
//! the two performers' leg lengths (heights are measured from the world
//! origin, i.e. the ground of the capture). By default
//! ([`RootPath::FeetAlongSource`]) the output's own planted feet carry the
//! root within each stride, so they slide less, while over spans longer
//! than a second it keeps to the source's path ([`crate::contact`]);
//! [`RootPath::Source`] is the report's root, [`RootPath::Feet`] lets the
//! feet set the whole path. A style clip must be of the same
//! rig as the model (same joint names and hierarchy; other bone lengths are
//! fine). [`apply`] retargets clips of other rigs
//! ([`mocap_core::retarget`], body parts matched by joint name): a style
//! clip of another rig is played by the source's rig first; a source of
//! another rig is played by the style clip's rig (when that one is the
//! model's), restyled there, and the output played back by the source's own
//! rig, so the output keeps the source's skeleton (joints the model's rig
//! has no part for, such as fingers, are then at rest). A clip whose body
//! parts cannot be found is refused with a message naming it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use mocap_core::bodymap::BodyMap;
use mocap_core::io::{read_motion, write_motion, MotionSource};
use mocap_core::ops::resample_fps;
use mocap_core::retarget::Retargeting;
use mocap_core::rotation::{angle_between, Vec3};
use mocap_core::Motion;
use mocap_core::Skeleton;
use mocap_feet::{plant_feet_if_asked, FeetOptions, FeetReport};
use mocap_nn::device::DeviceChoice;
use serde::{Deserialize, Serialize};

use crate::contact::{
    clean_foot_contacts, root_from_feet, travelled, ContactOptions, ContactReport,
    RootFromFeetOptions, RootShift,
};
use crate::convert::{
    asymmetry_track, asymmetry_window, convert, Asymmetry, Conversion, ConvertOptions, Latents,
    Method, RootPath, StyleInput,
};
use crate::data::mirrored;
use crate::features::{compose, decompose, gait_period, sample_frames, RootTrack};
use crate::train::StyleModel;
use crate::{invalid, Result};

/// Options of `mocap style apply`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ApplyOptions {
    pub source: PathBuf,
    /// The example clip of the style.
    pub style: PathBuf,
    pub out: PathBuf,
    /// The model file; `None`: the shipped default model.
    pub model: Option<PathBuf>,
    /// 1: full style; 0: the source (default 1).
    pub strength: f32,
    /// `ElasticPatches` (default) or `FixedPatches` (keeps the source's
    /// timing); the baselines of the evaluation too.
    pub method: Method,
    /// Seconds over which the style fades in (0: none).
    pub fade_in_seconds: f64,
    /// A second style clip and its weight in the blend (`--blend CLIP:0.5`).
    pub blend: Option<(PathBuf, f32)>,
    /// Patch length in frames (default 48).
    pub patch: usize,
    /// Where the root goes (default [`RootPath::FeetAlongSource`]).
    #[serde(default)]
    pub root: RootPath,
    /// Pin the ankles on the ground by turning hips and knees
    /// ([`crate::contact::clean_foot_contacts`]).
    #[serde(default)]
    pub foot_contacts: bool,
    /// Whose left-right asymmetry the output keeps (default: the source's,
    /// so turns stay turns; [`Asymmetry`]).
    #[serde(default)]
    pub asymmetry: Asymmetry,
    /// Then hold planted feet still and above the floor on the written
    /// take (mocap-feet, as `mocap feet`).
    #[serde(default)]
    pub feet: Option<FeetOptions>,
    pub device: DeviceChoice,
}

impl ApplyOptions {
    /// Default options for these files.
    pub fn new(
        source: impl Into<PathBuf>,
        style: impl Into<PathBuf>,
        out: impl Into<PathBuf>,
    ) -> ApplyOptions {
        ApplyOptions {
            source: source.into(),
            style: style.into(),
            out: out.into(),
            model: None,
            strength: 1.0,
            method: Method::ElasticPatches,
            fade_in_seconds: 0.0,
            blend: None,
            patch: ConvertOptions::default().patch,
            root: RootPath::default(),
            asymmetry: Asymmetry::default(),
            foot_contacts: false,
            feet: None,
            device: DeviceChoice::Cpu,
        }
    }
}

/// Parses `--blend CLIP:WEIGHT` (the weight of the other style, in [0, 1]).
pub fn parse_blend(text: &str) -> Result<(PathBuf, f32)> {
    let (path, weight) = text.rsplit_once(':').ok_or_else(|| {
        invalid(format!(
            "--blend `{text}`: expected OTHER_STYLE_CLIP:WEIGHT, e.g. old.bvh:0.5"
        ))
    })?;
    let weight: f32 = weight.trim().parse().map_err(|_| {
        invalid(format!(
            "--blend `{text}`: the weight `{weight}` is not a number"
        ))
    })?;
    if !(0.0..=1.0).contains(&weight) {
        return Err(invalid(format!(
            "--blend `{text}`: the weight must be between 0 and 1"
        )));
    }
    Ok((PathBuf::from(path), weight))
}

/// Seconds spent in each stage of a restyle.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct StageTimings {
    /// Rig checks, resampling, mirroring the style, rotations to features.
    pub prepare: f64,
    /// The encoder on the source and the style clips (and mirrors).
    pub encode: f64,
    /// Whitening, patch matching, blending, colouring.
    pub matching: f64,
    /// The decoder.
    pub decode: f64,
    /// Features back to rotations and the output motion.
    pub compose: f64,
}

impl StageTimings {
    pub fn total(&self) -> f64 {
        self.prepare + self.encode + self.matching + self.decode + self.compose
    }
}

impl std::ops::Add for StageTimings {
    type Output = StageTimings;

    fn add(self, other: StageTimings) -> StageTimings {
        StageTimings {
            prepare: self.prepare + other.prepare,
            encode: self.encode + other.encode,
            matching: self.matching + other.matching,
            decode: self.decode + other.decode,
            compose: self.compose + other.compose,
        }
    }
}

/// A style clip ready to convert to: latent codes and root heights of the
/// clip and its mirror.
#[derive(Debug, Clone)]
pub struct StyleClip {
    /// (latent codes, pelvis height per frame) of the clip and its mirror.
    pub sequences: Vec<(Latents, Vec<f32>)>,
    /// Rest leg length of the style performer (heights are scaled by it).
    pub leg_length: f32,
}

/// Encodes a style clip and its mirror; `what` names it in errors.
pub fn prepare_style(
    model: &StyleModel,
    motion: &Motion,
    what: &str,
    timings: &mut StageTimings,
) -> Result<StyleClip> {
    let t = Instant::now();
    let motion = model.prepare(motion, what)?;
    let rig = &model.description.rig;
    let mirror = mirrored(&motion)?;
    let mut parts = Vec::new();
    for m in [&motion, &mirror] {
        let (rotations, root) = decompose(m, rig);
        parts.push((model.features(&rotations), root.heights()));
    }
    timings.prepare += t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut sequences = Vec::new();
    for (features, heights) in parts {
        sequences.push((model.encode(&features)?, heights));
    }
    timings.encode += t.elapsed().as_secs_f64();
    Ok(StyleClip {
        sequences,
        leg_length: rig.leg_length(motion.skeleton()),
    })
}

/// The result of [`restyle`].
#[derive(Debug, Clone)]
pub struct Restyled {
    pub motion: Motion,
    pub conversion: Conversion,
    pub timings: StageTimings,
    /// How far the feet moved the root from the source's path (file units;
    /// zero with [`RootPath::Source`]).
    pub root_shift: RootShift,
    /// What the foot-contact cleanup changed (`None`: not asked for).
    pub contacts: Option<ContactReport>,
    /// Seconds over which the source's asymmetry was averaged (two of its
    /// strides); `None`: over the whole clip, or not kept.
    pub asymmetry_window_s: Option<f64>,
}

/// Mean angle (degrees) between the local rotations of the model's joints
/// in `source` and those the autoencoder gives back after encoding and
/// decoding them, with no conversion. The autoencoder only knows motion like
/// the walks it was trained on: a source it cannot reproduce (a bow, a kick)
/// cannot be restyled either, since every output pose is decoded from its
/// latent space; this measures how far a source is from that space. Run by
/// [`apply`] once per source, not by [`restyle`], which the evaluation runs
/// for every pair.
pub fn source_reconstruction_deg(model: &StyleModel, source: &Motion) -> Result<f32> {
    let source = model.prepare(source, "source")?;
    let (rotations, _) = decompose(&source, &model.description.rig);
    let latents = model.encode(&model.features(&rotations))?;
    let decoded = model.decode(&latents)?;
    let back = model.description.normalization.rotations(&decoded);
    let n = rotations.len().min(back.len()).max(1);
    let sum: f64 = rotations
        .iter()
        .zip(&back)
        .map(|(&a, &b)| angle_between(a, b) as f64)
        .sum();
    Ok((sum / n as f64).to_degrees() as f32)
}

/// A source whose [`source_reconstruction_deg`] exceeds this is far from the
/// motion the shipped model was trained on, and its content is likely lost.
/// Measured with the shipped model on every Bandai clip (the study
/// `style_familiarity`; bench/results/style.md, "Sources the model cannot
/// reproduce"): above 7 degrees lie 1.7% of the clips of the walking
/// contents it was trained on and 90.1% of the others (gestures, runs,
/// kicks...).
pub const UNFAMILIAR_SOURCE_DEG: f32 = 7.0;

/// [`ApplyReport::model`] when the shipped model restyled.
pub const BUILT_IN_MODEL: &str = "built-in default";

/// A source ready to restyle: resampled to the model's rate, its root, its
/// latent codes and, when the source's asymmetry is kept, the offset to keep
/// per frame (convert.rs, step 6). The evaluation prepares each source once
/// for all its style clips and methods.
#[derive(Debug, Clone)]
pub struct PreparedSource {
    /// The source at the model's frame rate.
    motion: Motion,
    /// The frame rate of the source as given (the output's).
    fps: f64,
    root: RootTrack,
    leg_length: f32,
    latents: Latents,
    /// The setting the source was prepared for.
    asymmetry: Asymmetry,
    /// The offset of step 6 per source frame (`None` with
    /// [`Asymmetry::Style`]).
    asymmetry_track: Option<Latents>,
    asymmetry_window_s: Option<f64>,
    /// Preparing and encoding the source (and its mirror).
    pub timings: StageTimings,
}

/// Prepares `source` (any frame rate) for [`restyle_prepared`] with the
/// asymmetry setting `asymmetry`.
pub fn prepare_source(
    model: &StyleModel,
    source: &Motion,
    asymmetry: Asymmetry,
) -> Result<PreparedSource> {
    let mut timings = StageTimings::default();
    let rig = &model.description.rig;
    let t = Instant::now();
    let src = model.prepare(source, "source")?;
    let (rotations, root) = decompose(&src, rig);
    let features = model.features(&rotations);
    // The mirror image's codes, for the source's asymmetry (convert.rs,
    // step 6), averaged over two of the source's strides.
    let mirror_features = if asymmetry.keeps_the_source() {
        let (mirror_rotations, _) = decompose(&mirrored(&src)?, rig);
        Some(model.features(&mirror_rotations))
    } else {
        None
    };
    // A source without a gait, or shorter than two strides, keeps one
    // offset for the whole clip.
    let window_frames = match asymmetry {
        Asymmetry::Source => gait_period(&src, rig).and_then(|stride| {
            asymmetry_window(Some((2.0 * stride * src.fps()) as f32), src.frame_count())
        }),
        Asymmetry::SourceClip | Asymmetry::Style => None,
    };
    timings.prepare += t.elapsed().as_secs_f64();

    let t = Instant::now();
    let latents = model.encode(&features)?;
    let mirror_latents = mirror_features.map(|f| model.encode(&f)).transpose()?;
    timings.encode += t.elapsed().as_secs_f64();

    let t = Instant::now();
    let asymmetry_track = mirror_latents
        .map(|mirror| asymmetry_track(&latents, &mirror, window_frames.map(|l| l as f32)))
        .transpose()?;
    timings.matching += t.elapsed().as_secs_f64();
    let asymmetry_window_s = window_frames.map(|l| l as f64 / src.fps());
    Ok(PreparedSource {
        leg_length: rig.leg_length(src.skeleton()),
        motion: src,
        fps: source.fps(),
        root,
        latents,
        asymmetry,
        asymmetry_track,
        asymmetry_window_s,
        timings,
    })
}

/// Restyles `source` (any frame rate; output at the same rate) to the
/// weighted styles.
pub fn restyle(
    model: &StyleModel,
    source: &Motion,
    styles: &[(&StyleClip, f32)],
    options: &ConvertOptions,
    timings: StageTimings,
) -> Result<Restyled> {
    let prepared = prepare_source(model, source, options.asymmetry)?;
    restyle_prepared(model, &prepared, styles, options, timings)
}

/// [`restyle`] of a source prepared by [`prepare_source`] with the same
/// asymmetry setting as `options`. `timings` (the style clips' preparing,
/// say) are added to the source's and this restyle's.
pub fn restyle_prepared(
    model: &StyleModel,
    source: &PreparedSource,
    styles: &[(&StyleClip, f32)],
    options: &ConvertOptions,
    mut timings: StageTimings,
) -> Result<Restyled> {
    if source.asymmetry != options.asymmetry {
        return Err(invalid(format!(
            "internal: the source was prepared for asymmetry {}, the restyle asks for {}",
            source.asymmetry.name(),
            options.asymmetry.name()
        )));
    }
    timings = timings + source.timings;
    let rig = &model.description.rig;
    let t = Instant::now();
    let leg = source.leg_length;
    // Style heights scaled to the source performer.
    let scaled: Vec<Vec<(Latents, Vec<f32>)>> = styles
        .iter()
        .map(|(s, _)| {
            let k = if s.leg_length > 0.0 {
                leg / s.leg_length
            } else {
                1.0
            };
            s.sequences
                .iter()
                .map(|(l, h)| (l.clone(), h.iter().map(|x| x * k).collect()))
                .collect()
        })
        .collect();
    timings.prepare += t.elapsed().as_secs_f64();

    let t = Instant::now();
    let inputs: Vec<StyleInput> = scaled
        .iter()
        .zip(styles)
        .map(|(seqs, (_, w))| StyleInput {
            sequences: seqs,
            weight: *w,
        })
        .collect();
    let conversion = convert(
        &source.latents,
        source.asymmetry_track.as_ref(),
        &source.root.heights(),
        &inputs,
        options,
    )?;
    timings.matching += t.elapsed().as_secs_f64();

    let t = Instant::now();
    let decoded = model.decode(&conversion.latents)?;
    timings.decode += t.elapsed().as_secs_f64();

    let t = Instant::now();
    let out_rotations = model.description.normalization.rotations(&decoded);
    let mut motion = rebuild(
        &source.motion,
        &source.root,
        &conversion,
        &out_rotations,
        rig,
    )?;
    let root_shift = RootFromFeetOptions::for_path(options.root)
        .map(|feet| root_from_feet(&mut motion, rig, &feet))
        .unwrap_or_default();
    let contacts = options
        .foot_contacts
        .then(|| clean_foot_contacts(&mut motion, rig, &ContactOptions::default()));
    let motion = if (motion.fps() - source.fps).abs() > 1e-3 * source.fps {
        resample_fps(&motion, source.fps)?
    } else {
        motion
    };
    timings.compose += t.elapsed().as_secs_f64();
    Ok(Restyled {
        motion,
        conversion,
        timings,
        root_shift,
        contacts,
        asymmetry_window_s: source.asymmetry_window_s,
    })
}

/// The output motion: the source sampled along the time warp, with the
/// decoded rotations, the source's horizontal path and heading, and the
/// converted height.
fn rebuild(
    source: &Motion,
    root: &RootTrack,
    conversion: &Conversion,
    rotations: &[mocap_core::rotation::Quat],
    rig: &crate::features::RigLayout,
) -> Result<Motion> {
    let base = sample_frames(source, &conversion.source_time)?;
    let mut pelvis: Vec<Vec3> = Vec::with_capacity(conversion.source_time.len());
    let mut heading = Vec::with_capacity(conversion.source_time.len());
    for (&t, &h) in conversion.source_time.iter().zip(&conversion.height) {
        let (p, q) = root.sample(t);
        pelvis.push(p - root.up * p.dot(root.up) + root.up * h);
        heading.push(q);
    }
    compose(base, rig, rotations, &pelvis, &heading)
}

/// What `mocap style apply` reports.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ApplyReport {
    pub source: PathBuf,
    pub style: PathBuf,
    pub blend: Option<(PathBuf, f32)>,
    pub out: PathBuf,
    pub model: String,
    pub method: Method,
    pub strength: f32,
    pub fade_in_seconds: f64,
    pub patch: usize,
    pub root: RootPath,
    /// How far the planted feet moved the root from the source's path,
    /// horizontally (file units, on the model's rig).
    pub root_shift: RootShift,
    pub foot_contacts: bool,
    /// What the foot-contact cleanup changed, with `foot_contacts`: frames
    /// per foot, how far the ankles were moved (file units, on the model's
    /// rig), and frames held back by the leg's reach.
    #[serde(default)]
    pub contacts: Option<ContactReport>,
    /// What the feet stage did on the written take (with `feet`).
    #[serde(default)]
    pub feet: Option<FeetReport>,
    pub asymmetry: Asymmetry,
    /// Seconds over which the source's asymmetry was averaged (two of its
    /// strides, [`Asymmetry::Source`]); `None`: over the whole clip (a
    /// source without a gait, or [`Asymmetry::SourceClip`]), or not kept.
    #[serde(default)]
    pub asymmetry_window_s: Option<f64>,
    pub source_frames: usize,
    pub output_frames: usize,
    pub fps: f64,
    /// Output duration over source duration (1 without elastic patches).
    pub time_scale: f64,
    /// Horizontal distance the pelvis travels in the output over the
    /// distance it travels in the source (about 1 when the root follows the
    /// source's path; the strides set it with [`RootPath::Feet`]).
    pub distance_ratio: f64,
    /// How well the autoencoder reproduces the source with no style
    /// ([`source_reconstruction_deg`], degrees); above
    /// [`UNFAMILIAR_SOURCE_DEG`] the source is unlike the model's training
    /// motion and its content is likely lost.
    pub source_reconstruction_deg: f32,
    /// Mean source frames per patch over the patch length (main series).
    pub mean_patch_stretch: f64,
    /// Mean cosine similarity of the matched patches.
    pub mean_similarity: f64,
    pub timings: StageTimings,
    /// Seconds reading the inputs and loading the model.
    pub load_seconds: f64,
    /// Seconds writing the output.
    pub write_seconds: f64,
    /// The clips that were of another rig than the model's, and what was
    /// done with them.
    #[serde(default)]
    pub retargeted: Vec<String>,
}

impl ApplyReport {
    /// A note when the shipped model reproduces the source poorly (above
    /// [`UNFAMILIAR_SOURCE_DEG`]; measured for that model only, so none for
    /// another one).
    pub fn unfamiliar_source_note(&self) -> Option<String> {
        (self.model == BUILT_IN_MODEL && self.source_reconstruction_deg > UNFAMILIAR_SOURCE_DEG)
            .then(|| {
                format!(
                    "{}: the model reproduces this source poorly ({:.1} degrees off with no \
                     style; walks like those it was trained on: about 3-5): it is unlike the \
                     walking motion the model knows, and its content is likely lost in the output",
                    self.source.display(),
                    self.source_reconstruction_deg
                )
            })
    }
}

/// Loads the model of `options` (or the default one).
pub fn load_model(model: Option<&Path>, device: DeviceChoice) -> Result<StyleModel> {
    match model {
        Some(p) => StyleModel::load(p, device),
        None => StyleModel::default_model(device),
    }
}

/// A retargeting from the rig of `from` (the clip an error is about) to the
/// rig of `to`, body parts found by name; the error says whose parts are
/// missing.
fn retargeting(from: &Motion, to: &Motion) -> mocap_core::Result<Retargeting> {
    let found = |skeleton: &Skeleton, whose: &str| {
        BodyMap::detect(skeleton)
            .map_err(|e| mocap_core::Error::Invalid(format!("{whose} body parts: {e}")))
    };
    let from_map = found(from.skeleton(), "this clip's")?;
    let to_map = found(to.skeleton(), "the other clip's")?;
    Retargeting::new(from.skeleton(), &from_map, to.skeleton(), &to_map)
}

/// The longest source [`apply`] restyles, in seconds: an hour. A restyle
/// holds the whole take several times over (its latent codes whiten it as a
/// whole, its gait sets the asymmetry window, the feet carry the root along
/// it): about [`SOURCE_BYTES_PER_FRAME`] per frame at the model's rate, so
/// a longer take is refused before it is read, with the memory it would need.
pub const MAX_SOURCE_SECONDS: f64 = 3600.0;

/// The longest style clip [`apply`] takes, in seconds: ten minutes. Every
/// window of a style clip and of its mirror is kept and compared with every
/// patch of the source (about [`STYLE_BYTES_PER_FRAME`] per frame).
pub const MAX_STYLE_SECONDS: f64 = 600.0;

/// Peak memory of `mocap style apply` per source frame at the model's rate:
/// how its peak grows with the take's length in `bench/memory.sh` (from
/// the 100 MB to the 1 GB take, before this limit: 81,315 to 812,565 frames
/// of a Bandai walk at 30 fps, `bench/results/memory.md`).
pub const SOURCE_BYTES_PER_FRAME: f64 = 5200.0;

/// Memory per style clip frame: the clip's and its mirror's windows of 48
/// frames of 32 latent numbers, as `f32`, and their codes.
pub const STYLE_BYTES_PER_FRAME: f64 = 13000.0;

/// Refuses a take of `frames` frames `frame_time` apart that is longer
/// than `max_seconds`, naming the file, its length, the limit and the
/// memory it would need at `bytes_per_frame` per frame at `model_fps`.
fn check_length(
    path: &Path,
    what: &str,
    (frames, frame_time): (usize, f64),
    max_seconds: f64,
    model_fps: f64,
    bytes_per_frame: f64,
) -> Result<()> {
    let seconds = frames as f64 * frame_time;
    if seconds <= max_seconds {
        return Ok(());
    }
    let fps = 1.0 / frame_time;
    let limit = (max_seconds * fps).floor() as usize;
    let minutes = |s: f64| format!("{:.0} minutes", s / 60.0);
    let gigabytes = seconds * model_fps * bytes_per_frame / 1e9;
    Err(invalid(format!(
        "{name}: style apply works on {what}s of up to {limit} frames (about {} at {fps:.0} fps); \
         this one has {frames} ({}), which would need about {gigabytes:.1} GB of memory: cut it \
         first, e.g. `mocap convert {name} --frames 0..{limit} part.bvh`",
        minutes(max_seconds),
        minutes(seconds),
        name = path.display(),
    )))
}

/// Reads a source or style clip after checking its length (see
/// [`check_length`]): from its header where the file says it (BVH), so that
/// a take too long is refused before it is read; else once read.
fn read_checked(
    path: &Path,
    what: &str,
    max_seconds: f64,
    model_fps: f64,
    bytes_per_frame: f64,
) -> Result<Motion> {
    let check = |length| check_length(path, what, length, max_seconds, model_fps, bytes_per_frame);
    let sources = MotionSource::group(&[path.to_path_buf()])?;
    if let Some(length) = sources
        .first()
        .map(MotionSource::announced_length)
        .transpose()?
        .flatten()
    {
        check(length)?;
    }
    let motion = read_motion(path)?;
    check((motion.frame_count(), motion.frame_time()))?;
    Ok(motion)
}

/// Restyles a file and writes the result (see the module docs).
pub fn apply(options: &ApplyOptions) -> Result<ApplyReport> {
    let t = Instant::now();
    let model = load_model(options.model.as_deref(), options.device)?;
    let fps = model.description.fps;
    let source = read_checked(
        &options.source,
        "take",
        MAX_SOURCE_SECONDS,
        fps,
        SOURCE_BYTES_PER_FRAME,
    )?;
    // Checked here too, where the source's file name is known: the restyle
    // itself names it only "source".
    crate::train::require_two_frames(&source, &options.source.display().to_string())?;
    let style_clip = |path: &Path| {
        read_checked(
            path,
            "style clip",
            MAX_STYLE_SECONDS,
            fps,
            STYLE_BYTES_PER_FRAME,
        )
    };
    let style = style_clip(&options.style)?;
    let blend = match &options.blend {
        Some((path, w)) => Some((style_clip(path)?, *w, path)),
        None => None,
    };
    // The rig the restyle runs on: the source's when it is the model's,
    // else the style clip's when that one is (the output is retargeted back).
    let rig = &model.description.rig;
    let fits = |m: &Motion| rig.check_skeleton(m.skeleton(), "").is_ok();
    let mut retargeted = Vec::new();
    let (source_on_rig, back) = if fits(&source) {
        (source.clone(), None)
    } else if fits(&style) {
        let name = options.source.display();
        let cannot = |e| {
            invalid(format!(
                "{name}: another rig than the model's, not retargeted: {e}"
            ))
        };
        let there = retargeting(&source, &style).map_err(cannot)?;
        let back = retargeting(&style, &source).map_err(cannot)?;
        let there = there.apply(&source).map_err(cannot)?;
        retargeted.push(format!(
            "{name}: another rig than the model's: played by the style clip's rig, restyled, \
             and played back by its own rig"
        ));
        (there, Some(back))
    } else {
        // Neither is of the model's rig: the rig check's message.
        rig.check_skeleton(source.skeleton(), &options.source.display().to_string())?;
        unreachable!("the source's rig was found not to fit")
    };
    // Style clips of other rigs are played by the rig the restyle runs on.
    let mut onto_rig = |clip: Motion, path: &Path| -> Result<Motion> {
        if fits(&clip) {
            return Ok(clip);
        }
        let name = path.display();
        let moved = retargeting(&clip, &source_on_rig)
            .and_then(|r| r.apply(&clip))
            .map_err(|e| {
                invalid(format!(
                    "{name}: another rig than the model's, not retargeted: {e}"
                ))
            })?;
        retargeted.push(format!(
            "{name}: another rig than the model's: retargeted onto the source's rig"
        ));
        Ok(moved)
    };
    let style = onto_rig(style, &options.style)?;
    let blend = match blend {
        Some((motion, w, path)) => Some((onto_rig(motion, path)?, w, path)),
        None => None,
    };
    let load_seconds = t.elapsed().as_secs_f64();
    let mut timings = StageTimings::default();
    let style_clip = prepare_style(
        &model,
        &style,
        &options.style.display().to_string(),
        &mut timings,
    )?;
    let other = match &blend {
        Some((motion, _, path)) => Some(prepare_style(
            &model,
            motion,
            &path.display().to_string(),
            &mut timings,
        )?),
        None => None,
    };
    // Checked here as well as in `convert`, to name the file.
    if matches!(
        options.method,
        Method::ElasticPatches | Method::FixedPatches
    ) {
        let clips = std::iter::once((&style_clip, &options.style))
            .chain(other.iter().zip(blend.iter().map(|b| b.2)));
        for (clip, path) in clips {
            let frames = clip
                .sequences
                .iter()
                .map(|(l, _)| l.frames)
                .max()
                .unwrap_or(0);
            if frames < options.patch {
                return Err(invalid(format!(
                    "{}: the style clip is too short: {frames} frames, a patch needs {} \
                     (use a longer clip, or a shorter --patch)",
                    path.display(),
                    options.patch
                )));
            }
        }
    }
    let mut styles = vec![(&style_clip, 1.0 - blend.as_ref().map_or(0.0, |b| b.1))];
    if let (Some(o), Some((_, w, _))) = (&other, &blend) {
        styles.push((o, *w));
    }
    let convert_options = ConvertOptions {
        method: options.method,
        patch: options.patch,
        strength: options.strength,
        fade_in_frames: (options.fade_in_seconds * model.description.fps) as f32,
        root: options.root,
        foot_contacts: options.foot_contacts,
        asymmetry: options.asymmetry,
        ..ConvertOptions::default()
    };
    let restyled = restyle(&model, &source_on_rig, &styles, &convert_options, timings)?;
    let output = match &back {
        Some(back) => back.apply(&restyled.motion)?,
        None => restyled.motion.clone(),
    };
    let (output, feet) = plant_feet_if_asked(output, options.feet.as_ref()).map_err(|e| {
        invalid(format!(
            "{}: --feet, on the restyled take: {e}",
            options.source.display()
        ))
    })?;
    let t = Instant::now();
    write_motion(&options.out, &output)?;
    let write_seconds = t.elapsed().as_secs_f64();
    let main: Vec<_> = restyled
        .conversion
        .matches
        .iter()
        .filter(|m| m.series == 1)
        .collect();
    let mean_patch_stretch = if main.is_empty() {
        1.0
    } else {
        main.iter().map(|m| m.source_length as f64).sum::<f64>()
            / (main.len() * options.patch) as f64
    };
    let sims: Vec<f64> = restyled
        .conversion
        .matches
        .iter()
        .flat_map(|m| m.style.iter().map(|s| s.2 as f64))
        .collect();
    Ok(ApplyReport {
        source: options.source.clone(),
        style: options.style.clone(),
        blend: options.blend.clone(),
        out: options.out.clone(),
        model: options
            .model
            .as_ref()
            .map_or(BUILT_IN_MODEL.to_string(), |p| p.display().to_string()),
        method: options.method,
        strength: options.strength,
        fade_in_seconds: options.fade_in_seconds,
        patch: options.patch,
        root: options.root,
        root_shift: restyled.root_shift,
        contacts: restyled.contacts,
        foot_contacts: options.foot_contacts,
        feet,
        asymmetry: options.asymmetry,
        asymmetry_window_s: restyled.asymmetry_window_s,
        source_frames: source.frame_count(),
        output_frames: output.frame_count(),
        fps: output.fps(),
        time_scale: output.duration() / source.duration(),
        // Measured on the model's rig (before any retargeting back).
        distance_ratio: (travelled(&restyled.motion, rig) / travelled(&source_on_rig, rig)) as f64,
        source_reconstruction_deg: source_reconstruction_deg(&model, &source_on_rig)?,
        mean_patch_stretch,
        mean_similarity: if sims.is_empty() {
            f64::NAN
        } else {
            sims.iter().sum::<f64>() / sims.len() as f64
        },
        timings: restyled.timings,
        load_seconds,
        write_seconds,
        retargeted,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blend_argument() {
        let (p, w) = parse_blend("clips/old walk.bvh:0.25").unwrap();
        assert_eq!(p, PathBuf::from("clips/old walk.bvh"));
        assert_eq!(w, 0.25);
        assert!(parse_blend("old.bvh").is_err());
        assert!(parse_blend("old.bvh:x").is_err());
        assert!(parse_blend("old.bvh:1.5").is_err());
    }
}
