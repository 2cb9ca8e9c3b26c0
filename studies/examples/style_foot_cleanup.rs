//! The foot-contact cleanup (`--foot-contacts`) measured on the evaluation's
//! held-out pairs, with contacts found by height alone and with the current
//! settings (bench/results/style.md, "The root and the feet").
//!
//! ```text
//! cargo run --release -p mocap-studies --example style_foot_cleanup -- DIR... [--held-out last|first] [--model M]
//! ```
//!
//! For every set folder, the held-out walks and turns are restyled with every
//! held-out walk of another take (default settings, no cleanup), as
//! `mocap style eval` pairs them. Each output is then cleaned three ways: not
//! at all; with contacts found by height alone and no limit on the leg's
//! reach; and with the current settings
//! (`ContactOptions::default()`: contacts also end where the foot swings
//! forward past the body, and an ankle is moved only as far as the leg
//! reaches). The table gives, per set and way, the means over the pairs of
//! the evaluation's foot measures (`foot_skating`,
//! `planted_foot_sliding`), the number of outputs with a foot further
//! out from under its hip than in any of the set's real sources and style clips
//! (`largest_foot_reach`), the largest ankle shift, and the jitter.
//! A second table splits the outputs with no cleanup into quarters by how
//! far the style clip's pace (pelvis distance per second) is from the pace
//! the output's path asks for (the source's distance over the output's
//! duration), with their flat-foot sliding.
//! The classifiers are not run: style and content accuracy come from
//! `mocap style eval --foot-contacts`.

use std::path::PathBuf;

use mocap_core::Motion;
use mocap_nn::device::DeviceChoice;
use mocap_style::{
    clean_foot_contacts, held_out, labelled_paths, largest_foot_reach, list_bvh, load_clips,
    load_model, planted_foot_sliding, prepare_source, prepare_style, restyle_prepared, travelled,
    ClipFilter, ContactOptions, ConvertOptions, HeldOutTake, MotionMeasures, RigLayout,
    StageTimings, WALKING_CONTENTS,
};

const SOURCES: [&str; 3] = ["walk", "walk-turn-left", "walk-turn-right"];

#[derive(Default, Clone, Copy)]
struct Tally {
    skating: f64,
    sliding: f64,
    beyond: usize,
    max_shift: f32,
    jitter: f64,
    outputs: usize,
}

impl Tally {
    fn add(&mut self, motion: &Motion, rig: &RigLayout, real_reach: f64, max_shift: f32) {
        let measures = MotionMeasures::of(motion, rig);
        self.skating += measures.foot_skating;
        self.sliding += measures.planted_foot_sliding;
        self.beyond += (measures.foot_reach > real_reach) as usize;
        self.max_shift = self.max_shift.max(max_shift);
        self.jitter += measures.jitter;
        self.outputs += 1;
    }
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut option = |flag: &str| -> Option<String> {
        let i = args.iter().position(|a| a == flag)?;
        let value = args.get(i + 1).cloned().expect("a value after the flag");
        args.drain(i..i + 2);
        Some(value)
    };
    let which: HeldOutTake = option("--held-out")
        .map(|s| s.parse().expect("--held-out last|first"))
        .unwrap_or_default();
    let model_path = option("--model").map(PathBuf::from);
    let reach_limits: Vec<f32> = option("--reach-limits").map_or_else(Vec::new, |s| {
        s.split(',')
            .map(|v| v.parse().expect("--reach-limits: numbers"))
            .collect()
    });
    let tolerances: Vec<f32> = option("--height-tolerances").map_or_else(Vec::new, |s| {
        s.split(',')
            .map(|v| v.parse().expect("--height-tolerances: numbers"))
            .collect()
    });
    if args.is_empty() {
        eprintln!(
            "usage: style_foot_cleanup DIR... [--held-out last|first] [--model M] [--reach-limits A,B,..] \
             [--height-tolerances A,B,..]"
        );
        std::process::exit(2);
    }
    let model = load_model(model_path.as_deref(), DeviceChoice::Cpu).expect("model");
    let rig = &model.description.rig;
    let before = ContactOptions {
        height_tolerance: 0.05,
        ease_frames: 4,
        min_frames: 3,
        split_at_swing: false,
        reach_limit: f32::INFINITY,
    };
    let mut ways = vec![
        ("no cleanup".to_string(), None),
        (
            "cleanup by height alone, no reach limit".to_string(),
            Some(before),
        ),
        (
            "cleanup (default)".to_string(),
            Some(ContactOptions::default()),
        ),
    ];
    for &height_tolerance in &tolerances {
        ways.push((
            format!("cleanup, height tolerance {height_tolerance}"),
            Some(ContactOptions {
                height_tolerance,
                ..ContactOptions::default()
            }),
        ));
    }
    for &reach_limit in &reach_limits {
        ways.push((
            format!("cleanup, reach limit {reach_limit}"),
            Some(ContactOptions {
                reach_limit,
                ..ContactOptions::default()
            }),
        ));
    }
    println!(
        "| set | cleanup | outputs | foot skating (cm/s) | planted foot sliding (cm/s) | \
         feet beyond real reach (outputs) | largest ankle shift (cm) | jitter |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    let mut paces = Vec::new();
    for dir in &args {
        let filter = ClipFilter {
            contents: WALKING_CONTENTS.map(String::from).to_vec(),
            styles: Vec::new(),
        };
        let files = labelled_paths(&list_bvh(&[PathBuf::from(dir)]).expect("a folder"), &filter)
            .expect("labelled clips");
        let held = held_out(&files, which);
        let test: Vec<_> = files
            .into_iter()
            .filter(|(p, _)| held.contains(&p.file_stem().unwrap().to_string_lossy().to_string()))
            .collect();
        let test = load_clips(&test).expect("held-out clips");
        // As the evaluation: clips shorter than two patches are left out.
        let min_seconds = 2.0 * ConvertOptions::default().patch as f64 / model.description.fps;
        let long_enough: Vec<_> = test
            .iter()
            .filter(|c| c.motion.duration() >= min_seconds)
            .collect();
        let styles: Vec<_> = long_enough
            .iter()
            .filter(|c| c.labels.content == "walk")
            .collect();
        let sources: Vec<_> = long_enough
            .iter()
            .filter(|c| SOURCES.contains(&c.labels.content.as_str()))
            .collect();
        // As the evaluation: the furthest any real source or style clip puts
        // a foot from under its hip.
        let real_reach = sources
            .iter()
            .chain(&styles)
            .map(|c| largest_foot_reach(&c.motion, rig))
            .fold(0.0, f64::max);
        let prepared: Vec<_> = styles
            .iter()
            .map(|c| {
                let mut t = StageTimings::default();
                prepare_style(&model, &c.motion, &c.name, &mut t).expect("style clip")
            })
            .collect();
        let mut tallies = vec![Tally::default(); ways.len()];
        // The sources themselves, and as the autoencoder gives them back
        // (strength 0: their own latent codes decoded, no style).
        let (mut real, mut reconstructed) = (Tally::default(), Tally::default());
        // Per output with no cleanup: how far the style clip's pace is from
        // the pace the output's path asks for, and its flat-foot sliding.
        let mut by_pace: Vec<(f64, f64)> = Vec::new();
        for source in &sources {
            let options = ConvertOptions::default();
            let prepared_source =
                prepare_source(&model, &source.motion, options.asymmetry).expect("source");
            real.add(&source.motion, rig, real_reach, 0.0);
            let own = ConvertOptions {
                strength: 0.0,
                ..options
            };
            let style_self = prepare_style(
                &model,
                &source.motion,
                &source.name,
                &mut StageTimings::default(),
            )
            .expect("source as style clip");
            let back = restyle_prepared(
                &model,
                &prepared_source,
                &[(&style_self, 1.0)],
                &own,
                StageTimings::default(),
            )
            .expect("reconstruction");
            reconstructed.add(&back.motion, rig, real_reach, 0.0);
            for (clip, style) in styles.iter().zip(&prepared) {
                if clip.name == source.name {
                    continue;
                }
                let out = restyle_prepared(
                    &model,
                    &prepared_source,
                    &[(style, 1.0)],
                    &options,
                    StageTimings::default(),
                )
                .expect("restyle");
                let pace = |m: &Motion, distance: f32| distance as f64 / m.duration();
                let asked = pace(&out.motion, travelled(&out.motion, rig));
                let given = pace(&clip.motion, travelled(&clip.motion, rig));
                by_pace.push((
                    (given / asked).ln().abs(),
                    planted_foot_sliding(&out.motion, rig),
                ));
                for (tally, (_, way)) in tallies.iter_mut().zip(&ways) {
                    let mut motion = out.motion.clone();
                    let shift =
                        way.map_or(0.0, |o| clean_foot_contacts(&mut motion, rig, &o).max_shift);
                    tally.add(&motion, rig, real_reach, shift);
                }
            }
        }
        let set = PathBuf::from(dir);
        let set = set.file_name().unwrap().to_string_lossy();
        let rows = [
            ("real sources", &real),
            (
                "sources through the autoencoder (strength 0)",
                &reconstructed,
            ),
        ];
        for (name, tally) in rows
            .into_iter()
            .chain(ways.iter().map(|w| w.0.as_str()).zip(&tallies))
        {
            let n = tally.outputs.max(1) as f64;
            println!(
                "| {set} | {name} | {} | {:.2} | {:.2} | {} | {:.1} | {:.4} |",
                tally.outputs,
                tally.skating / n,
                tally.sliding / n,
                tally.beyond,
                tally.max_shift,
                tally.jitter / n,
            );
        }
        paces.push((set.to_string(), by_pace));
    }
    // The second table: outputs with no cleanup in four equal groups by
    // |ln(style clip's pace / output's pace)|, the pace being the distance
    // the pelvis travels per second.
    println!();
    println!(
        "| set | pace mismatch \\|ln(style clip's pace / output's pace)\\| | outputs | \
         planted foot sliding (cm/s) |"
    );
    println!("| --- | --- | --- | --- |");
    for (set, mut rows) in paces {
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let n = rows.len();
        for q in 0..4 {
            let part = &rows[q * n / 4..(q + 1) * n / 4];
            let (Some(first), Some(last)) = (part.first(), part.last()) else {
                continue;
            };
            println!(
                "| {set} | {:.2}-{:.2} | {} | {:.2} |",
                first.0,
                last.0,
                part.len(),
                part.iter().map(|r| r.1).sum::<f64>() / part.len() as f64
            );
        }
    }
}
