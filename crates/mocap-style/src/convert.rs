//! The converter, in latent space.
//!
//! Inputs: the source's latent codes (one vector per frame) and, for every
//! style, the latent codes of its clip and of the clip's mirror image.
//!
//! 1. Whitening: `x^ = C_x^-1/2 (x - m_x)` with the source's mean and
//!    covariance, and each style's sequences with the style's (computed over
//!    the clip and its mirror together).
//! 2. Patches: the source is cut into patches of `P` frames. With elastic
//!    patches, each patch may take `L = P + 4k` source frames, `|4k| <=
//!    25% P`, resampled to `P` frames; the patches follow one another in the
//!    source (the next starts where the chosen `L` ends). Each (patch,
//!    stretch) is compared by cosine similarity with every window of `P`
//!    frames of the whitened style sequences; the stretch and window with
//!    the highest similarity win. A style patch keeps its `P` frames, so the
//!    output gives `P` frames to `L` source frames: with the default `P =
//!    48`, a source stride that matches the style best when shrunk to 36
//!    frames comes out 48 frames long, at the style's pace. Fixed patches
//!    always take `L = P`. (The report does not give `P`; 48 was chosen on
//!    one fold of the Bandai takes and judged on the other:
//!    docs/research/style.md, "Patches and timing".)
//! 3. Seams: a second series of patches, offset by half a patch (each from
//!    the centre of one stretched patch to the centre of the next), is
//!    matched too, and the two are blended with linear weights along time
//!    (1 at a patch's centre, 0 at its ends).
//! 4. Colouring: the swapped whitened patches are coloured with the style's
//!    covariance and mean, `y = C_y^1/2 y^ + m_y`.
//! 5. Strength: the output latent is `(1 - s(t)) x(warp(t)) + s(t) y(t)`
//!    with `s(t) = strength * min(1, t / fade_in)`; two styles blend as
//!    `sum_k w_k y_k(t)`, the stretch of a patch being chosen by the weighted
//!    sum of the styles' similarities so both share one timing. The timing
//!    is interpolated too: the output's clock runs at the source's pace
//!    where `s = 0` and at the style's where `s = 1`, so at strength 0.5 an
//!    elastic output lasts about halfway between the source and the full
//!    style.
//! 6. Asymmetry (not in the report; [`Asymmetry::Source`], the default):
//!    the output latent gets `s(t) d(t)`, where `d` is half the difference
//!    between the latent code of the source and that of its mirror image,
//!    averaged over two strides around each source frame
//!    ([`asymmetry_track`]). Colouring gives the output the style's mean,
//!    which is left-right symmetric since the style's statistics cover its
//!    clip and its mirror; but a turn places its feet to one side of the
//!    pelvis, an offset that lies partly in the mean (the left leg held
//!    differently from the right), and with the style's mean and a straight
//!    walk's patches a turn came out as a straight walk. The half-difference
//!    is the part of the source's code that mirroring flips: over whole
//!    strides about zero for a straight walk (the mirror shows the same
//!    poses half a stride later), so walks are left nearly as before, while
//!    a turn keeps the side its feet are placed to. Averaged over two
//!    strides rather than the whole clip, a take that walks straight and
//!    then turns keeps each part's own offset; [`Asymmetry::SourceClip`]
//!    keeps one offset for the whole clip, and
//!    [`Asymmetry::Style`] leaves it out (the report's method).
//!
//! The baselines of the evaluation: [`Method::WhiteningColouring`] colours
//! the whitened source frames with the style's statistics without any
//! patch swap, [`Method::AdaIn`] matches each channel's mean and deviation.
//!
//! The style's root height is carried along the same patches, so the output
//! bobs with the style's stride; the baselines shift the source's height to
//! the style's mean.

use serde::{Deserialize, Serialize};

use crate::linalg::Statistics;
use crate::{invalid, Result};

/// Latent codes of a clip: `frames` vectors of `dim` numbers, frame after
/// frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Latents {
    pub frames: usize,
    pub dim: usize,
    pub data: Vec<f32>,
}

impl Latents {
    pub fn new(frames: usize, dim: usize, data: Vec<f32>) -> Result<Latents> {
        if data.len() != frames * dim || frames == 0 || dim == 0 {
            return Err(invalid(format!(
                "internal: {} latent numbers for {frames} frames of {dim}",
                data.len()
            )));
        }
        Ok(Latents { frames, dim, data })
    }

    pub fn frame(&self, f: usize) -> &[f32] {
        &self.data[f * self.dim..(f + 1) * self.dim]
    }

    /// The code at fractional frame `t`, linearly interpolated. Beyond the
    /// last frame the clip is reflected in time (so a patch that overhangs
    /// the end still sees motion, played backwards), then clamped.
    pub fn sample(&self, t: f32, out: &mut [f32]) {
        let last = (self.frames - 1) as f32;
        let t = reflect(t, last);
        let i = (t.floor() as usize).min(self.frames - 1);
        let j = (i + 1).min(self.frames - 1);
        let a = t - i as f32;
        for (c, o) in out.iter_mut().enumerate() {
            *o = (1.0 - a) * self.data[i * self.dim + c] + a * self.data[j * self.dim + c];
        }
    }

    /// Every frame whitened with `stats`.
    fn whitened(&self, stats: &Statistics) -> Latents {
        let mut data = vec![0.0; self.data.len()];
        for (x, w) in self
            .data
            .chunks_exact(self.dim)
            .zip(data.chunks_exact_mut(self.dim))
        {
            stats.whiten(x, w);
        }
        Latents {
            frames: self.frames,
            dim: self.dim,
            data,
        }
    }
}

fn reflect(t: f32, last: f32) -> f32 {
    let t = if t < 0.0 { -t } else { t };
    let t = if t > last { 2.0 * last - t } else { t };
    t.clamp(0.0, last)
}

/// A value per frame sampled at a fractional frame (linear, reflected
/// beyond the end like [`Latents::sample`]).
fn sample_track(track: &[f32], t: f32) -> f32 {
    let last = (track.len() - 1) as f32;
    let t = reflect(t, last);
    let i = (t.floor() as usize).min(track.len() - 1);
    let j = (i + 1).min(track.len() - 1);
    let a = t - i as f32;
    (1.0 - a) * track[i] + a * track[j]
}

/// Where the output's root (the pelvis's horizontal position) goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RootPath {
    /// Along the source's path, time-warped with the output (the report's
    /// method): the decoded strides slide on it.
    Source,
    /// Along the source's path over spans longer than a second (its shape
    /// and length), carried by the planted feet within a stride
    /// (`root_from_feet` with
    /// `RootFromFeetOptions::keep_source_path_seconds`).
    #[default]
    FeetAlongSource,
    /// Carried by the planted feet everywhere: the path's shape and length
    /// follow the strides (`root_from_feet`).
    Feet,
}

impl RootPath {
    pub const ALL: [RootPath; 3] = [RootPath::Source, RootPath::FeetAlongSource, RootPath::Feet];

    pub fn name(self) -> &'static str {
        match self {
            RootPath::Source => "source",
            RootPath::FeetAlongSource => "feet-along-source",
            RootPath::Feet => "feet",
        }
    }
}

impl std::str::FromStr for RootPath {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        RootPath::ALL
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = RootPath::ALL.iter().map(|r| r.name()).collect();
                format!("unknown root path `{s}` (expected {})", names.join(", "))
            })
    }
}

/// Whose left-right asymmetry the output keeps (step 6 of the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Asymmetry {
    /// The source's, along time: the part of its latent code that
    /// mirroring flips, averaged over two strides around each frame, is
    /// added to the output, so a turn keeps the feet's sideways placement
    /// where it turns and a straight stretch of the same take stays
    /// straight. Clips without a gait, or shorter than two strides, get one
    /// offset for the whole clip ([`Asymmetry::SourceClip`]).
    #[default]
    Source,
    /// The source's, one offset for the whole clip: the
    /// half-difference of the mean latent codes of the source and its
    /// mirror.
    SourceClip,
    /// The style's (symmetric) mean alone: the report's method.
    Style,
}

impl Asymmetry {
    pub const ALL: [Asymmetry; 3] = [Asymmetry::Source, Asymmetry::SourceClip, Asymmetry::Style];

    pub fn name(self) -> &'static str {
        match self {
            Asymmetry::Source => "source",
            Asymmetry::SourceClip => "source-clip",
            Asymmetry::Style => "style",
        }
    }

    /// Whether the output keeps the source's asymmetry (and so needs the
    /// codes of the source's mirror).
    pub fn keeps_the_source(self) -> bool {
        !matches!(self, Asymmetry::Style)
    }
}

impl std::str::FromStr for Asymmetry {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        Asymmetry::ALL
            .into_iter()
            .find(|a| a.name() == s)
            .ok_or_else(|| {
                format!("unknown asymmetry `{s}` (expected source, source-clip or style)")
            })
    }
}

/// How the source's latent codes are converted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Patch swap with elastic (stretched or shrunk) source patches.
    ElasticPatches,
    /// Patch swap with fixed patches of `P` frames (the report's baseline).
    FixedPatches,
    /// Whitening with the source's statistics and colouring with the
    /// style's, frame by frame, without patches.
    WhiteningColouring,
    /// Per-channel mean and deviation matching (AdaIN-like).
    AdaIn,
}

impl Method {
    pub const ALL: [Method; 4] = [
        Method::ElasticPatches,
        Method::FixedPatches,
        Method::WhiteningColouring,
        Method::AdaIn,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Method::ElasticPatches => "elastic-patches",
            Method::FixedPatches => "fixed-patches",
            Method::WhiteningColouring => "whitening-colouring",
            Method::AdaIn => "adain",
        }
    }
}

impl std::str::FromStr for Method {
    type Err = crate::StyleError;
    fn from_str(s: &str) -> Result<Method> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                invalid(format!(
                    "unknown method `{s}`: expected elastic-patches, fixed-patches, \
                     whitening-colouring or adain"
                ))
            })
    }
}

/// Settings of the converter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConvertOptions {
    pub method: Method,
    /// Patch length `P` in frames (even; default 48, 1.6 s at 30 fps).
    pub patch: usize,
    /// Largest stretch or shrink of a source patch, as a fraction of `P`
    /// (report: 0.25).
    pub stretch: f32,
    /// Step between candidate patch lengths, in frames (report: 4).
    pub stretch_step: usize,
    /// Weight of the converted latent (1: full style, 0: the source).
    pub strength: f32,
    /// Frames over which the strength rises from 0 (0: no fade).
    pub fade_in_frames: f32,
    /// Pin the feet during ground contacts after decoding
    /// ([`crate::clean_foot_contacts`]); applied by [`crate::apply::restyle`].
    #[serde(default)]
    pub foot_contacts: bool,
    /// Where the root goes ([`RootPath`]); applied by
    /// [`crate::apply::restyle`] after decoding, before `foot_contacts`.
    #[serde(default)]
    pub root: RootPath,
    /// Whose left-right asymmetry the output keeps ([`Asymmetry`]).
    #[serde(default)]
    pub asymmetry: Asymmetry,
}

impl Default for ConvertOptions {
    fn default() -> Self {
        ConvertOptions {
            method: Method::ElasticPatches,
            patch: 48,
            stretch: 0.25,
            stretch_step: 4,
            strength: 1.0,
            fade_in_frames: 0.0,
            foot_contacts: false,
            root: RootPath::default(),
            asymmetry: Asymmetry::default(),
        }
    }
}

impl ConvertOptions {
    pub fn validate(&self) -> Result<()> {
        if self.patch < 4 || self.patch % 2 == 1 {
            return Err(invalid(format!(
                "the patch length must be an even number of frames, at least 4 (got {})",
                self.patch
            )));
        }
        if !(0.0..0.9).contains(&self.stretch) || self.stretch_step == 0 {
            return Err(invalid(format!(
                "the stretch must be in [0, 0.9) and its step positive (got {} and {})",
                self.stretch, self.stretch_step
            )));
        }
        if !(0.0..=1.0).contains(&self.strength) {
            return Err(invalid(format!(
                "the strength must be between 0 and 1 (got {})",
                self.strength
            )));
        }
        if self.fade_in_frames.is_nan() || self.fade_in_frames < 0.0 {
            return Err(invalid("the fade-in must be a non-negative duration"));
        }
        // A patch too short to stretch by one step would quietly give fixed
        // patches under the elastic name.
        if self.method == Method::ElasticPatches && self.patch_lengths().len() < 2 {
            let shortest = (self.stretch_step as f32 / self.stretch).ceil() as usize;
            return Err(invalid(format!(
                "elastic patches stretch a patch by up to {:.0}% in steps of {} frames, so a \
                 patch of {} frames cannot stretch: use a patch of {} frames or more, or fixed \
                 patches (--method fixed-patches)",
                self.stretch * 100.0,
                self.stretch_step,
                self.patch,
                shortest + shortest % 2,
            )));
        }
        Ok(())
    }

    /// Candidate source lengths of a patch: `P + k * step` within
    /// `+-stretch * P` (just `P` for fixed patches).
    pub fn patch_lengths(&self) -> Vec<usize> {
        if self.method != Method::ElasticPatches {
            return vec![self.patch];
        }
        let reach = (self.stretch * self.patch as f32 + 1e-4).floor() as usize;
        let steps = reach / self.stretch_step;
        let mut v: Vec<usize> = (0..=2 * steps)
            .map(|i| self.patch + i * self.stretch_step)
            .filter_map(|l| l.checked_sub(steps * self.stretch_step))
            .filter(|&l| l >= 2)
            .collect();
        v.dedup();
        v
    }
}

/// One style to convert to: the latent codes of its clip and of the clip's
/// mirror (or any sequences of the style), the root height of every frame
/// of each (already scaled to the source performer), and its weight in a
/// blend.
#[derive(Debug, Clone, Copy)]
pub struct StyleInput<'a> {
    pub sequences: &'a [(Latents, Vec<f32>)],
    pub weight: f32,
}

/// The style window a patch was swapped with: (sequence, first frame,
/// cosine similarity).
pub type StyleMatch = (usize, usize, f32);

/// Where one output patch came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatchMatch {
    /// 1: the main series; 2: the series offset by half a patch.
    pub series: u8,
    /// First output frame of the patch (where the strength slows or
    /// speeds the timing, the output frame its styled frame falls on).
    pub output_start: usize,
    /// First source frame (fractional) and source frames taken.
    pub source_start: f32,
    pub source_length: f32,
    /// For every style: (sequence, first frame, cosine similarity).
    pub style: Vec<StyleMatch>,
}

/// The converted latent codes and what goes with them.
#[derive(Debug, Clone)]
pub struct Conversion {
    /// Output latent codes (strength applied).
    pub latents: Latents,
    /// Source frame (fractional) shown at every output frame.
    pub source_time: Vec<f32>,
    /// Root height of every output frame (strength applied).
    pub height: Vec<f32>,
    /// Strength of every output frame.
    pub strength: Vec<f32>,
    /// The matched patches (empty for the baselines).
    pub matches: Vec<PatchMatch>,
}

/// Unit-length windows of `P` frames of whitened style sequences.
struct WindowBank {
    width: usize,
    vectors: Vec<f32>,
    /// (sequence, first frame) of every window.
    index: Vec<(usize, usize)>,
}

impl WindowBank {
    fn new(sequences: &[Latents], patch: usize) -> WindowBank {
        let dim = sequences[0].dim;
        let width = patch * dim;
        let mut vectors = Vec::new();
        let mut index = Vec::new();
        for (s, seq) in sequences.iter().enumerate() {
            for start in 0..=seq.frames.saturating_sub(patch) {
                if start + patch > seq.frames {
                    break;
                }
                let w = &seq.data[start * dim..(start + patch) * dim];
                let norm = w.iter().map(|x| x * x).sum::<f32>().sqrt().max(1e-12);
                vectors.extend(w.iter().map(|x| x / norm));
                index.push((s, start));
            }
        }
        WindowBank {
            width,
            vectors,
            index,
        }
    }

    /// The window most similar to a unit-length query: (window, cosine).
    fn best(&self, query: &[f32]) -> (usize, f32) {
        let mut best = (0, f32::NEG_INFINITY);
        for (i, w) in self.vectors.chunks_exact(self.width).enumerate() {
            let dot: f32 = w.iter().zip(query).map(|(a, b)| a * b).sum();
            if dot > best.1 {
                best = (i, dot);
            }
        }
        best
    }
}

/// A style ready for matching: statistics, whitened sequences, windows.
struct PreparedStyle<'a> {
    input: StyleInput<'a>,
    stats: Statistics,
    whitened: Vec<Latents>,
    bank: Option<WindowBank>,
}

/// Converts `source` (latent codes and root height per frame) to the
/// styles. Weights of the styles are normalised to sum to one.
/// `source_asymmetry` is the offset of step 6 per source frame, from
/// [`asymmetry_track`]; [`Asymmetry::Source`] and
/// [`Asymmetry::SourceClip`] need it, [`Asymmetry::Style`] ignores it.
pub fn convert(
    source: &Latents,
    source_asymmetry: Option<&Latents>,
    source_height: &[f32],
    styles: &[StyleInput],
    options: &ConvertOptions,
) -> Result<Conversion> {
    options.validate()?;
    if styles.is_empty() {
        return Err(invalid("no style to convert to"));
    }
    if source.frames < 2 || source_height.len() != source.frames {
        return Err(invalid(format!(
            "the source needs at least 2 frames with a root height each (got {} frames)",
            source.frames
        )));
    }
    let total_weight: f32 = styles.iter().map(|s| s.weight.max(0.0)).sum();
    if total_weight.is_nan() || total_weight <= 0.0 {
        return Err(invalid("the style weights must not all be zero"));
    }
    let dim = source.dim;
    let patch = options.patch;
    let uses_patches = matches!(
        options.method,
        Method::ElasticPatches | Method::FixedPatches
    );
    let mut prepared = Vec::with_capacity(styles.len());
    for (k, s) in styles.iter().enumerate() {
        if s.sequences.is_empty()
            || s.sequences
                .iter()
                .any(|(l, h)| l.dim != dim || h.len() != l.frames)
        {
            return Err(invalid(format!(
                "internal: style {k} has no or inconsistent sequences"
            )));
        }
        let longest = s.sequences.iter().map(|(l, _)| l.frames).max().unwrap_or(0);
        if uses_patches && longest < patch {
            return Err(invalid(format!(
                "the style clip is too short: {longest} frames, a patch needs {patch}"
            )));
        }
        let stats = Statistics::of_rows(s.sequences.iter().map(|(l, _)| l.data.as_slice()), dim);
        let whitened: Vec<Latents> = s
            .sequences
            .iter()
            .map(|(l, _)| l.whitened(&stats))
            .collect();
        let bank = uses_patches.then(|| WindowBank::new(&whitened, patch));
        prepared.push(PreparedStyle {
            input: StyleInput {
                sequences: s.sequences,
                weight: s.weight.max(0.0) / total_weight,
            },
            stats,
            whitened,
            bank,
        });
    }
    let asymmetry = match (options.asymmetry.keeps_the_source(), source_asymmetry) {
        (false, _) => None,
        (true, Some(track)) => {
            if track.dim != dim || track.frames != source.frames {
                return Err(invalid(format!(
                    "internal: the source's asymmetry has {} frames of {} values, the source {} of {}",
                    track.frames, track.dim, source.frames, dim
                )));
            }
            Some(track)
        }
        (true, None) => return Err(invalid(
            "internal: keeping the source's asymmetry needs its track (from the source's mirror)",
        )),
    };
    let source_stats = Statistics::of_rows([source.data.as_slice()], dim);
    let source_white = source.whitened(&source_stats);

    // The converted (coloured) latent and height of every output frame, and
    // the source time of every output frame.
    let (source_time, converted, converted_height, matches) = if uses_patches {
        swap_patches(&source_white, &prepared, options)
    } else {
        let frames = source.frames;
        let mut converted = vec![0.0; frames * dim];
        let mut height = vec![0.0; frames];
        let source_mean_height = source_height.iter().sum::<f32>() / frames as f32;
        let mut buf = vec![0.0; dim];
        for p in &prepared {
            let style_mean_height = mean_height(p.input.sequences);
            for f in 0..frames {
                let x = source.frame(f);
                match options.method {
                    Method::WhiteningColouring => p.stats.colour(source_white.frame(f), &mut buf),
                    _ => {
                        for c in 0..dim {
                            let sd = source_stats.std[c];
                            let z = if sd > 1e-9 {
                                (x[c] as f64 - source_stats.mean[c]) / sd
                            } else {
                                0.0
                            };
                            buf[c] = (z * p.stats.std[c] + p.stats.mean[c]) as f32;
                        }
                    }
                }
                for c in 0..dim {
                    converted[f * dim + c] += p.input.weight * buf[c];
                }
                height[f] +=
                    p.input.weight * (source_height[f] - source_mean_height + style_mean_height);
            }
        }
        let time: Vec<f32> = (0..frames).map(|f| f as f32).collect();
        (time, converted, height, Vec::new())
    };

    // Strength and fade-in: interpolate between the (time-warped) source and
    // the converted latent, and between the source's timing and the style's.
    // On the styled timeline (frame `o` of the patches, source time `T(o)`)
    // the strength is `s(o) = strength * min(1, o / fade_in)`, and the output
    // clock advances by `(1 - s) (T(o + 1) - T(o)) + s` per styled frame:
    // the source's pace at strength 0, the style's at 1 (where the clock is
    // the styled timeline itself).
    let strength_at = |o: f32| {
        let fade = if options.fade_in_frames > 0.0 {
            (o / options.fade_in_frames).min(1.0)
        } else {
            1.0
        };
        options.strength * fade
    };
    let styled = source_time.len();
    let mut clock = vec![0.0f32; styled];
    for o in 1..styled {
        let s = strength_at((o - 1) as f32);
        clock[o] = clock[o - 1] + (1.0 - s) * (source_time[o] - source_time[o - 1]) + s;
    }
    let frames = clock[styled - 1].round() as usize + 1;
    let mut data = vec![0.0; frames * dim];
    let mut height = vec![0.0; frames];
    let mut strength = vec![0.0; frames];
    let mut output_time = vec![0.0; frames];
    let mut x = vec![0.0; dim];
    let mut kept = vec![0.0; dim];
    let mut o = 0;
    for q in 0..frames {
        // The styled frames `o`, `o + 1` around output frame `q`, and where
        // between them it falls.
        let t = q as f32;
        while o + 2 < styled && clock[o + 1] <= t {
            o += 1;
        }
        let next = (o + 1).min(styled - 1);
        let span = clock[next] - clock[o];
        let a = if span > 0.0 {
            ((t - clock[o]) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let u = if a >= 1.0 {
            source_time[next]
        } else {
            source_time[o] + a * (source_time[next] - source_time[o])
        };
        let s = strength_at(o as f32 + a);
        output_time[q] = u;
        strength[q] = s;
        source.sample(u, &mut x);
        if let Some(track) = asymmetry {
            track.sample(u, &mut kept);
        }
        for c in 0..dim {
            let y = (1.0 - a) * converted[o * dim + c] + a * converted[next * dim + c];
            data[q * dim + c] = (1.0 - s) * x[c] + s * (y + kept[c]);
        }
        let y_height = (1.0 - a) * converted_height[o] + a * converted_height[next];
        height[q] = (1.0 - s) * sample_track(source_height, u) + s * y_height;
    }
    let source_time = output_time;
    let matches = matches
        .into_iter()
        .map(|m| PatchMatch {
            output_start: clock[m.output_start.min(styled - 1)].round() as usize,
            ..m
        })
        .collect();
    Ok(Conversion {
        latents: Latents::new(frames, dim, data)?,
        source_time,
        height,
        strength,
        matches,
    })
}

/// Step 6: the offset the output keeps from the source, per source frame.
///
/// Per frame, `d(t) = (x(t) - x~(t)) / 2` is the part of the source's code
/// that mirroring flips (`x~` the code of the source's mirror image, frame
/// by frame). Within a straight walk the mirror shows the same pose half a
/// stride later, so `d` swings with the stride about a mean near zero; a
/// turn shifts that mean to one side. The track is `d` averaged:
///
/// - `window_frames = None`, or a clip no longer than the window: over the
///   whole clip, `(m_x - m_x~) / 2` ([`Asymmetry::SourceClip`]);
/// - `Some(L)`: a Hann window of `L` frames around each frame. With `L` two
///   strides long, the window's spectrum is zero at the stride frequency
///   and at every harmonic of it, so the swing within a stride cancels
///   while a change from walking straight to turning shows within about a
///   stride. Near the ends of the clip the window keeps its whole length
///   inside the clip (the first and last half-windows hold its value), so
///   the cancellation holds there too.
pub fn asymmetry_track(
    source: &Latents,
    mirror: &Latents,
    window_frames: Option<f32>,
) -> Result<Latents> {
    if mirror.dim != source.dim || mirror.frames != source.frames {
        return Err(invalid(format!(
            "internal: the source's mirror has {} frames of {} values, the source {} of {}",
            mirror.frames, mirror.dim, source.frames, source.dim
        )));
    }
    let (frames, dim) = (source.frames, source.dim);
    let half_difference: Vec<f64> = source
        .data
        .iter()
        .zip(&mirror.data)
        .map(|(&x, &m)| 0.5 * (x as f64 - m as f64))
        .collect();
    let window = asymmetry_window(window_frames, frames);
    let data = windowed_mean(&half_difference, dim, window);
    Latents::new(frames, dim, data)
}

/// The mean of each of the `dim` channels of `values` (frame after frame)
/// around each frame: over a Hann window of `window` frames that stays
/// whole inside the clip (its first and last half-windows hold the value
/// at the ends), or over the whole clip when `window` is `None`. A Hann
/// window of `l` frames has a spectrum that vanishes at every multiple of
/// 2/l cycles per frame, so with `l` two strides long it cancels whatever
/// repeats with the stride ([`Asymmetry::Source`]).
pub fn windowed_mean(values: &[f64], dim: usize, window: Option<usize>) -> Vec<f32> {
    let frames = values.len() / dim.max(1);
    let mut data = Vec::with_capacity(frames * dim);
    match window.filter(|&l| l >= 1 && l < frames) {
        None => {
            let mut mean = vec![0.0f64; dim];
            for row in values.chunks_exact(dim) {
                mean.iter_mut().zip(row).for_each(|(m, d)| *m += d);
            }
            let n = frames.max(1) as f64;
            let mean: Vec<f32> = mean.iter().map(|m| (m / n) as f32).collect();
            for _ in 0..frames {
                data.extend_from_slice(&mean);
            }
        }
        Some(l) => {
            let weights: Vec<f64> = (0..l)
                .map(|k| {
                    let phase = std::f64::consts::TAU * (k as f64 + 0.5) / l as f64;
                    0.5 - 0.5 * phase.cos()
                })
                .collect();
            let total: f64 = weights.iter().sum();
            let mut mean = vec![0.0f64; dim];
            for f in 0..frames {
                let start = (f as f64 - l as f64 / 2.0)
                    .round()
                    .clamp(0.0, (frames - l) as f64) as usize;
                mean.iter_mut().for_each(|m| *m = 0.0);
                for (k, w) in weights.iter().enumerate() {
                    let row = &values[(start + k) * dim..(start + k + 1) * dim];
                    mean.iter_mut().zip(row).for_each(|(m, d)| *m += w * d);
                }
                data.extend(mean.iter().map(|m| (m / total) as f32));
            }
        }
    }
    data
}

/// The window [`asymmetry_track`] averages over, in frames, for a window of
/// `window_frames` asked on a clip of `frames`: `None` (the whole clip) when
/// none is asked or the clip is no longer than it.
pub fn asymmetry_window(window_frames: Option<f32>, frames: usize) -> Option<usize> {
    window_frames
        .map(|l| l.round().max(1.0) as usize)
        .filter(|&l| l < frames)
}

fn mean_height(sequences: &[(Latents, Vec<f32>)]) -> f32 {
    let n: usize = sequences.iter().map(|(_, h)| h.len()).sum();
    sequences.iter().flat_map(|(_, h)| h.iter()).sum::<f32>() / n.max(1) as f32
}

/// The unit-length query of a patch: the whitened source sampled at `times`.
fn query(source: &Latents, times: impl Iterator<Item = f32>, out: &mut Vec<f32>) {
    out.clear();
    let dim = source.dim;
    let mut buf = vec![0.0; dim];
    for t in times {
        source.sample(t, &mut buf);
        out.extend_from_slice(&buf);
    }
    let norm = out.iter().map(|x| x * x).sum::<f32>().sqrt().max(1e-12);
    out.iter_mut().for_each(|x| *x /= norm);
}

type Swapped = (Vec<f32>, Vec<f32>, Vec<f32>, Vec<PatchMatch>);

/// Steps 2 to 4 of the module docs: the source time, converted latent and
/// height of every output frame, and the matches.
fn swap_patches(source: &Latents, styles: &[PreparedStyle], options: &ConvertOptions) -> Swapped {
    let p = options.patch;
    let dim = source.dim;
    let end = (source.frames - 1) as f32;
    let lengths = options.patch_lengths();
    let mut q = Vec::with_capacity(p * dim);
    let best_per_style = |q: &[f32]| -> Vec<StyleMatch> {
        styles
            .iter()
            .map(|s| {
                let bank = s.bank.as_ref().expect("patch methods build banks");
                let (w, sim) = bank.best(q);
                let (seq, start) = bank.index[w];
                (seq, start, sim)
            })
            .collect()
    };

    // Series 1: consecutive patches, each with its best length.
    let mut series1: Vec<PatchMatch> = Vec::new();
    let mut start = 0.0f32;
    while start <= end {
        let mut best: Option<(f32, usize, Vec<StyleMatch>)> = None;
        for &len in &lengths {
            let step = len as f32 / p as f32;
            query(source, (0..p).map(|i| start + i as f32 * step), &mut q);
            let found = best_per_style(&q);
            let score: f32 = found
                .iter()
                .zip(styles)
                .map(|(m, s)| s.input.weight * m.2)
                .sum();
            if best.as_ref().is_none_or(|b| score > b.0) {
                best = Some((score, len, found));
            }
        }
        let (_, len, style) = best.expect("at least one patch length");
        series1.push(PatchMatch {
            series: 1,
            output_start: series1.len() * p,
            source_start: start,
            source_length: len as f32,
            style,
        });
        start += len as f32;
    }

    // The time warp: output frame -> source frame, linear within a patch.
    let mut warp: Vec<f32> = Vec::with_capacity(series1.len() * p);
    for m in &series1 {
        let step = m.source_length / p as f32;
        warp.extend((0..p).map(|i| m.source_start + i as f32 * step));
    }
    let frames = warp
        .iter()
        .position(|&t| t > end + 1e-4)
        .unwrap_or(warp.len())
        .max(1);

    // Series 2: from the centre of each patch to the centre of the next.
    let half = p / 2;
    let mut series2: Vec<PatchMatch> = Vec::new();
    for k in 0..series1.len().saturating_sub(1) {
        let o0 = k * p + half;
        if o0 >= frames {
            break;
        }
        query(source, warp[o0..o0 + p].iter().copied(), &mut q);
        series2.push(PatchMatch {
            series: 2,
            output_start: o0,
            source_start: warp[o0],
            source_length: warp[o0 + p - 1] - warp[o0] + series1[k + 1].source_length / p as f32,
            style: best_per_style(&q),
        });
    }

    // Blend weights: series 1 weighs 1 at its patch centres and 0 at the
    // seams, where series 2 is at its centres; series 1 alone where series 2
    // has no patch (the first and last half patches).
    let weight1 = |o: usize| -> f32 {
        let covered2 = o >= half && (o - half) / p < series2.len();
        if !covered2 {
            return 1.0;
        }
        let centre = (o / p * p) as f32 + (p as f32 - 1.0) / 2.0;
        (1.0 - (o as f32 - centre).abs() / (p as f32 / 2.0)).clamp(0.0, 1.0)
    };

    let mut converted = vec![0.0f32; frames * dim];
    let mut height = vec![0.0f32; frames];
    let mut white = vec![0.0f32; dim];
    let mut coloured = vec![0.0f32; dim];
    for o in 0..frames {
        let w1 = weight1(o);
        let m1 = &series1[o / p];
        let m2 = (w1 < 1.0).then(|| &series2[(o - half) / p]);
        for (k, s) in styles.iter().enumerate() {
            white.iter_mut().for_each(|x| *x = 0.0);
            let mut h = 0.0;
            let mut add = |m: &PatchMatch, w: f32| {
                let (seq, first, _) = m.style[k];
                let f = first + (o - m.output_start);
                let src = s.whitened[seq].frame(f);
                for c in 0..dim {
                    white[c] += w * src[c];
                }
                h += w * s.input.sequences[seq].1[f];
            };
            add(m1, w1);
            if let Some(m2) = m2 {
                add(m2, 1.0 - w1);
            }
            s.stats.colour(&white, &mut coloured);
            for c in 0..dim {
                converted[o * dim + c] += s.input.weight * coloured[c];
            }
            height[o] += s.input.weight * h;
        }
    }
    warp.truncate(frames);
    let mut matches = series1;
    matches.extend(series2);
    (warp, converted, height, matches)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sources of these tests have no asymmetry to keep (step 6),
    /// unless a test says otherwise: they are their own mirror images.
    fn no_asymmetry(x: &Latents) -> Latents {
        asymmetry_track(x, x, None).unwrap()
    }

    /// A latent sequence of a gait-like signal with period `period` frames.
    fn periodic(frames: usize, period: f32, phase: f32) -> Latents {
        let dim = 6;
        let mut data = Vec::with_capacity(frames * dim);
        for f in 0..frames {
            let a = std::f32::consts::TAU * f as f32 / period + phase;
            data.extend([
                a.sin(),
                a.cos(),
                (2.0 * a).sin() * 0.5,
                (2.0 * a).cos() * 0.3,
                0.2 * (3.0 * a).sin(),
                0.1,
            ]);
        }
        Latents::new(frames, dim, data).unwrap()
    }

    /// A style's sequences: latent codes and root height per frame.
    type Sequences = Vec<(Latents, Vec<f32>)>;

    fn style_of(latents: Latents) -> Sequences {
        let h = vec![90.0; latents.frames];
        vec![(latents, h)]
    }

    /// A 300-frame source stepping every 30 frames, a style stepping every
    /// 38, and the source's root height.
    fn stepping_every_30_and_38() -> (Latents, Sequences, Vec<f32>) {
        let x = periodic(300, 30.0, 0.3);
        let y = style_of(periodic(240, 38.0, 0.0));
        (x, y, vec![90.0; 300])
    }

    #[test]
    fn patch_lengths_follow_the_report() {
        let o = ConvertOptions::default();
        assert_eq!(o.patch_lengths(), vec![36, 40, 44, 48, 52, 56, 60]);
        let o = ConvertOptions { patch: 32, ..o };
        assert_eq!(o.patch_lengths(), vec![24, 28, 32, 36, 40]);
        let fixed = ConvertOptions {
            method: Method::FixedPatches,
            ..o
        };
        assert_eq!(fixed.patch_lengths(), vec![32]);
        let small = ConvertOptions { patch: 16, ..o };
        assert_eq!(small.patch_lengths(), vec![12, 16, 20]);
    }

    /// Converting a clip to its own style with fixed patches gives it back:
    /// every patch finds itself (or an identical window one period away),
    /// except the last patch, which overhangs the end of the clip and is
    /// matched on the reflected clip.
    #[test]
    fn a_clip_in_its_own_style_is_unchanged() {
        let x = periodic(200, 30.0, 0.0);
        let h = vec![90.0; 200];
        let seqs = vec![(x.clone(), h.clone())];
        let options = ConvertOptions {
            method: Method::FixedPatches,
            ..ConvertOptions::default()
        };
        let c = convert(
            &x,
            Some(&no_asymmetry(&x)),
            &h,
            &[StyleInput {
                sequences: &seqs,
                weight: 1.0,
            }],
            &options,
        )
        .unwrap();
        assert_eq!(c.latents.frames, 200);
        let inside = (200 - options.patch) * 6;
        let worst = c.latents.data[..inside]
            .iter()
            .zip(&x.data)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f32::max);
        assert!(worst < 1e-3, "{worst}");
    }

    /// A source stepping every 30 frames converted to a style stepping every
    /// 38: elastic patches shrink the source patches, so the output lasts
    /// about 38/30 as long; fixed patches keep the length.
    #[test]
    fn elastic_patches_take_the_style_timing() {
        let (x, y, h) = stepping_every_30_and_38();
        let style = [StyleInput {
            sequences: &y,
            weight: 1.0,
        }];
        let elastic = convert(
            &x,
            Some(&no_asymmetry(&x)),
            &h,
            &style,
            &ConvertOptions::default(),
        )
        .unwrap();
        let ratio = elastic.latents.frames as f32 / 300.0;
        assert!(
            (ratio - 38.0 / 30.0).abs() < 0.1,
            "output/source length {ratio}"
        );
        // The warp is increasing and covers the source.
        assert!(elastic.source_time.windows(2).all(|w| w[1] > w[0]));
        assert!(*elastic.source_time.last().unwrap() > 290.0);
        let fixed = convert(
            &x,
            Some(&no_asymmetry(&x)),
            &h,
            &style,
            &ConvertOptions {
                method: Method::FixedPatches,
                ..ConvertOptions::default()
            },
        )
        .unwrap();
        assert_eq!(fixed.latents.frames, 300);
    }

    #[test]
    fn the_strength_interpolates_the_timing_too() {
        let (x, y, h) = stepping_every_30_and_38();
        let style = [StyleInput {
            sequences: &y,
            weight: 1.0,
        }];
        let at = |strength: f32| {
            convert(
                &x,
                Some(&no_asymmetry(&x)),
                &h,
                &style,
                &ConvertOptions {
                    strength,
                    ..ConvertOptions::default()
                },
            )
            .unwrap()
        };
        let (none, half, full) = (at(0.0), at(0.5), at(1.0));
        // Strength 0: the source, frame for frame.
        assert!(
            none.latents.frames.abs_diff(300) <= 1,
            "{}",
            none.latents.frames
        );
        let off = none
            .latents
            .data
            .iter()
            .zip(&x.data)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(off < 1e-3, "{off}");
        // Half: a duration about halfway, and the warp still increasing.
        let middle = (300 + full.latents.frames) as f32 / 2.0;
        let frames = half.latents.frames as f32;
        assert!((frames - middle).abs() < 3.0, "{frames} against {middle}");
        assert!(half.source_time.windows(2).all(|w| w[1] > w[0]));
        assert!(*half.source_time.last().unwrap() > 290.0);
        assert!(half.strength.iter().all(|&s| s == 0.5));
        // The patches' output frames move with the timing.
        let last = |c: &Conversion| c.matches.iter().map(|m| m.output_start).max().unwrap();
        assert!(last(&none) < last(&half) && last(&half) < last(&full));
    }

    #[test]
    fn strength_zero_is_the_source_and_fade_in_ramps() {
        let x = periodic(120, 30.0, 0.0);
        let y = style_of(periodic(120, 30.0, 1.0));
        let h = vec![90.0; 120];
        let style = [StyleInput {
            sequences: &y,
            weight: 1.0,
        }];
        let options = ConvertOptions {
            method: Method::FixedPatches,
            strength: 0.0,
            ..ConvertOptions::default()
        };
        let c = convert(&x, Some(&no_asymmetry(&x)), &h, &style, &options).unwrap();
        assert_eq!(c.latents.data, x.data);
        let fade = ConvertOptions {
            strength: 0.8,
            fade_in_frames: 60.0,
            ..options
        };
        let c = convert(&x, Some(&no_asymmetry(&x)), &h, &style, &fade).unwrap();
        assert_eq!(c.strength[0], 0.0);
        assert!((c.strength[30] - 0.4).abs() < 1e-5);
        assert!((c.strength[100] - 0.8).abs() < 1e-5);
    }

    #[test]
    fn baselines_match_the_style_statistics() {
        let x = periodic(200, 30.0, 0.0);
        let mut y = periodic(200, 30.0, 0.0);
        for v in y.data.iter_mut() {
            *v = 2.0 * *v + 1.0;
        }
        let ys = style_of(y.clone());
        let h = vec![90.0; 200];
        for method in [Method::WhiteningColouring, Method::AdaIn] {
            let options = ConvertOptions {
                method,
                ..ConvertOptions::default()
            };
            let c = convert(
                &x,
                Some(&no_asymmetry(&x)),
                &h,
                &[StyleInput {
                    sequences: &ys,
                    weight: 1.0,
                }],
                &options,
            )
            .unwrap();
            let got = Statistics::of_rows([c.latents.data.as_slice()], 6);
            let want = Statistics::of_rows([y.data.as_slice()], 6);
            for d in 0..6 {
                assert!((got.mean[d] - want.mean[d]).abs() < 1e-3, "{method:?}");
                assert!((got.std[d] - want.std[d]).abs() < 1e-2, "{method:?}");
            }
        }
    }

    /// Step 6: a source held off-centre by `d` (its mirror by `-d`, half a
    /// stride later) comes out `strength * d` away from the same conversion
    /// with the style's symmetric mean, at every frame and for every method,
    /// averaged over the whole clip or over two strides; without the
    /// asymmetry track (made from the mirror) it is refused.
    #[test]
    fn the_source_asymmetry_is_kept() {
        let d = [0.3f32, -0.2, 0.0, 0.1, 0.0, 0.05];
        let offset = |l: Latents, sign: f32| {
            let data = (l.data.iter().enumerate())
                .map(|(i, v)| v + sign * d[i % l.dim])
                .collect();
            Latents::new(l.frames, l.dim, data).unwrap()
        };
        // 300 frames are ten whole strides, so the mirror's stride-average
        // equals the source's and the half-difference of the means is `d`.
        let x = offset(periodic(300, 30.0, 0.0), 1.0);
        let mirror = offset(periodic(300, 30.0, std::f32::consts::PI), -1.0);
        let h = vec![90.0; 300];
        let y = style_of(periodic(240, 38.0, 0.0));
        let style = [StyleInput {
            sequences: &y,
            weight: 1.0,
        }];
        for method in Method::ALL {
            let kept = ConvertOptions {
                method,
                strength: 0.6,
                ..ConvertOptions::default()
            };
            let symmetric = ConvertOptions {
                asymmetry: Asymmetry::Style,
                ..kept
            };
            let b = convert(&x, None, &h, &style, &symmetric).unwrap();
            // Over the whole clip, and over two strides around each frame:
            // the window of two strides cancels the swing within a stride.
            for window in [None, Some(60.0)] {
                let track = asymmetry_track(&x, &mirror, window).unwrap();
                let a = convert(&x, Some(&track), &h, &style, &kept).unwrap();
                assert_eq!(a.latents.frames, b.latents.frames, "{method:?}");
                for (i, (u, v)) in a.latents.data.iter().zip(&b.latents.data).enumerate() {
                    let want = 0.6 * d[i % 6];
                    assert!(
                        (u - v - want).abs() < 1e-4,
                        "{method:?} {window:?}: {} != {want}",
                        u - v
                    );
                }
            }
            let err = convert(&x, None, &h, &style, &kept).unwrap_err();
            assert!(err.to_string().contains("mirror"), "{err}");
        }
    }

    /// Step 6 along time: a take that walks straight for 150 frames (five
    /// strides) and then holds off-centre by `d`. Averaged over two strides,
    /// the offset kept is exactly 0 wherever the window lies in the straight
    /// part and exactly `d` wherever it lies in the offset part, rising in
    /// between; over the whole clip it is `d / 2` everywhere. A window of
    /// one and a half strides lets the swing within a stride through.
    #[test]
    fn the_asymmetry_follows_the_take() {
        let d = [0.3f32, -0.2, 0.0, 0.1, 0.0, 0.05];
        let offset_after_150 = |l: Latents, sign: f32| {
            let dim = l.dim;
            let data = (l.data.iter().enumerate())
                .map(|(i, v)| {
                    if i / dim >= 150 {
                        v + sign * d[i % dim]
                    } else {
                        *v
                    }
                })
                .collect();
            Latents::new(l.frames, dim, data).unwrap()
        };
        let x = offset_after_150(periodic(300, 30.0, 0.0), 1.0);
        let mirror = offset_after_150(periodic(300, 30.0, std::f32::consts::PI), -1.0);
        let track = asymmetry_track(&x, &mirror, Some(60.0)).unwrap();
        for f in 0..300 {
            for (&got, &dc) in track.frame(f).iter().zip(&d) {
                let want = match f {
                    0..=90 => Some(0.0),
                    210.. => Some(dc),
                    _ => None,
                };
                match want {
                    Some(want) => assert!((got - want).abs() < 1e-5, "frame {f}: {got} != {want}"),
                    // Between the two: on the way from 0 to d.
                    None => assert!(got.abs() <= dc.abs() + 1e-5 && got * dc >= -1e-6),
                }
            }
        }
        let whole = asymmetry_track(&x, &mirror, None).unwrap();
        for f in 0..300 {
            for (&got, &dc) in whole.frame(f).iter().zip(&d) {
                assert!((got - dc / 2.0).abs() < 1e-5);
            }
        }
        let short = asymmetry_track(&x, &mirror, Some(45.0)).unwrap();
        let swing = (0..=90)
            .map(|f| short.frame(f)[0].abs())
            .fold(0.0, f32::max);
        assert!(
            swing > 0.01,
            "a window of 1.5 strides left a swing of {swing}"
        );
        // A window as long as the clip is the whole clip.
        assert_eq!(
            asymmetry_track(&x, &mirror, Some(300.0)).unwrap().data,
            whole.data
        );
    }

    #[test]
    fn a_style_clip_shorter_than_a_patch_is_an_error() {
        let x = periodic(100, 30.0, 0.0);
        let y = style_of(periodic(20, 30.0, 0.0));
        let err = convert(
            &x,
            Some(&no_asymmetry(&x)),
            &vec![90.0; 100],
            &[StyleInput {
                sequences: &y,
                weight: 1.0,
            }],
            &ConvertOptions::default(),
        )
        .unwrap_err();
        assert!(err.to_string().contains("too short"), "{err}");
    }
}
