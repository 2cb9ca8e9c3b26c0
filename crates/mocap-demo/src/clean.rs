//! Stage 2: the fused take of stage 1, on the sample's rig, cleaned by the
//! shipped denoiser, no noise added: the noise is what the sensors and the
//! fusion made. The denoiser cleans the rotations; a fused take's root is
//! as noisy as its joints, so its translation goes through a 3 Hz
//! Butterworth (as `mocap clean apply --root-filter butterworth:2:3`). A
//! classical filter alone (the same Butterworth on the rotations and the
//! root) runs beside it, and the three takes (fused, cleaned, filtered) are
//! compared with the sample.

use mocap_clean::{filter_motion, filter_translations, CleanModel, Filter};
use mocap_core::io::bvh::{read_bvh, write_bvh};
use mocap_core::rotation::angle_between;
use mocap_core::Motion;
use mocap_nn::device::DeviceChoice;
use mocap_view::{plot_lines, render_files, LinePlot, RenderOptions, Series};

use crate::chain::{aligned_with_truth, errors_against_truth, ChainTake, TruthErrors};
use crate::{require_file, viewer_command, StageContext, StageReport, StageResult};

/// Mean angle (degrees) between the local rotations of `a` and `b` in each
/// frame, over the joints with rotation channels.
fn rotation_error_per_frame(a: &Motion, b: &Motion) -> Vec<f32> {
    let skeleton = a.skeleton();
    let joints: Vec<usize> = (0..skeleton.joint_count())
        .filter(|&j| skeleton.joint(j).channels.iter().any(|c| c.is_rotation()))
        .collect();
    (0..a.frame_count())
        .map(|f| {
            joints
                .iter()
                .map(|&j| {
                    angle_between(a.local_rotation(f, j), b.local_rotation(f, j)).to_degrees()
                })
                .sum::<f32>()
                / joints.len().max(1) as f32
        })
        .collect()
}

/// The numbers of one take against the truth, named `{name}_...`.
fn report_errors(report: &mut StageReport, name: &str, what: &str, e: &TruthErrors) {
    report.number(
        &format!("position_error_{name}_mm"),
        &format!("{what} vs sample, mean per-joint position error"),
        e.position_mm,
        "mm",
    );
    report.number(
        &format!("rotation_error_{name}_deg"),
        &format!("{what} vs sample, mean angle of the local joint rotations"),
        e.rotation_deg,
        "deg",
    );
    report.number(
        &format!("jitter_{name}"),
        &format!("{what}, mean jerk of its joints (mm/frame³)"),
        e.jitter,
        "mm/frame³",
    );
}

pub(crate) fn run(context: &StageContext, report: &mut StageReport) -> StageResult {
    let options = context.options;
    require_file(&options.clean_model, "the denoiser model")?;
    let take = context.take()?;
    let sample = read_bvh(&options.sample)?;
    let fused = read_bvh(&take.path)?;
    let model = CleanModel::load(&options.clean_model, DeviceChoice::Cpu)?;
    let started = std::time::Instant::now();
    // 3 Hz: docs/research/clean.md, "Fused captures" (the cross-validated
    // cutoff takes this smooth noise for motion).
    let filter = Filter::Butterworth {
        order: 2,
        cutoff_hz: 3.0,
    };
    let cleaned = filter_translations(&model.clean(&fused, None)?, &filter)?;
    let clean_seconds = started.elapsed().as_secs_f64();
    let filtered = filter_translations(&filter_motion(&fused, &filter)?, &filter)?;

    let cleaned_path = context.path("clean", "cleaned.bvh")?;
    let filtered_path = context.path("clean", "filtered.bvh")?;
    write_bvh(&cleaned_path, &cleaned)?;
    write_bvh(&filtered_path, &filtered)?;
    report.output(
        StageContext::relative("clean", "cleaned.bvh"),
        "the fused take cleaned by the denoiser, its root by a 3 Hz Butterworth: what the next stages get",
    );
    report.output(
        StageContext::relative("clean", "filtered.bvh"),
        "the fused take through a 3 Hz Butterworth (rotations and root), for comparison",
    );
    report.viewer_command = Some(viewer_command(&[
        &options.sample,
        &take.path,
        &cleaned_path,
    ]));
    report.fact("input", take.path.display().to_string());

    let first_time = take.first_time;
    let before = errors_against_truth(&fused, &sample, first_time)?;
    let after = errors_against_truth(&cleaned, &sample, first_time)?;
    let classical = errors_against_truth(&filtered, &sample, first_time)?;
    report_errors(report, "fused", "fused take", &before);
    report_errors(report, "cleaned", "cleaned take (model)", &after);
    report_errors(
        report,
        "filtered",
        "filtered take (Butterworth)",
        &classical,
    );
    report.number(
        "jitter_sample",
        "the sample's own mean jerk over the same frames (mm/frame³)",
        before.truth_jitter,
        "mm/frame³",
    );
    report.number(
        "clean_seconds",
        "time the model (and the root's filter) took to clean the take (CPU)",
        clean_seconds,
        "s",
    );
    report.fact("model", options.clean_model.display().to_string());
    report.fact("reference filter", filter.label());
    report.note(
        "One fused take, no noise added: a demonstration, not an evaluation (bench/results/chain.md has 15 held-out takes through the same chain).",
    );
    context.pass_on(ChainTake {
        path: cleaned_path.clone(),
        stage: "clean",
        first_time,
    });

    if options.pictures {
        let strip = context.path("clean", "sample_fused_cleaned.png")?;
        render_files(
            &[
                options.sample.clone(),
                take.path.clone(),
                cleaned_path.clone(),
            ],
            &strip,
            &RenderOptions::default(),
        )?;
        report.picture(
            StageContext::relative("clean", "sample_fused_cleaned.png"),
            "sample, fused and cleaned takes, overlaid",
        );
        let plot_path = context.path("clean", "rotation_error.png")?;
        let step = fused.frame_time() as f32;
        let mut plot = LinePlot::new(
            "Rotation error against the sample",
            "time (s)",
            "mean joint rotation error (degrees)",
        );
        for (label, motion) in [
            ("fused", &fused),
            ("cleaned (model)", &cleaned),
            ("Butterworth", &filtered),
        ] {
            let (motion, truth) = aligned_with_truth(motion, &sample, first_time)?;
            plot = plot.with_series(Series::sampled(
                label,
                first_time as f32,
                step,
                &rotation_error_per_frame(&motion, &truth),
            ));
        }
        plot_lines(&plot_path, &plot)?;
        report.picture(
            StageContext::relative("clean", "rotation_error.png"),
            "rotation error per frame: fused, cleaned, classical filter",
        );
    }
    Ok(())
}
