//! Stage 2: the shipped denoiser on the sample with synthetic markerless
//! noise.
//!
//! The model is trained on the Bandai rig (23 joints); the fused skeleton of
//! stage 1 has another layout, so the model cannot clean it. The honest demo
//! is on the sample: mocap-clean's chain-corrected random noise
//! (`mocap_clean::add_random_noise_sigma`, `noise_sigma_deg` per joint) is added to
//! the take, the model cleans the noisy take, and the errors of the noisy
//! and cleaned takes against the original are reported, with a classical
//! filter (zero-phase Butterworth, not tuned) for reference.

use mocap_clean::{
    add_random_noise_sigma, filter_motion, position_errors, rotation_error_deg, CleanModel, Filter,
    RandomNoise,
};
use mocap_core::io::bvh::{read_bvh, write_bvh};
use mocap_core::rotation::angle_between;
use mocap_core::Motion;
use mocap_nn::device::DeviceChoice;
use mocap_view::{plot_lines, render_files, LinePlot, RenderOptions, Series};
use rand::rngs::ChaCha8Rng;
use rand::SeedableRng;

use crate::{
    require_file, units_per_metre, viewer_command, StageContext, StageReport, StageResult,
};

/// Mean geodesic angle (degrees) between the local rotations of the joints
/// with rotation channels, per frame.
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

pub(crate) fn run(context: &StageContext, report: &mut StageReport) -> StageResult {
    let options = context.options;
    require_file(&options.clean_model, "the denoiser model")?;
    let motion = read_bvh(&options.sample)?;
    let model = CleanModel::load(&options.clean_model, DeviceChoice::Cpu)?;
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let noisy = add_random_noise_sigma(
        &motion,
        options.noise_sigma_deg,
        &RandomNoise::default(),
        &mut rng,
    );
    let started = std::time::Instant::now();
    let cleaned = model.clean(&noisy, None)?;
    let clean_seconds = started.elapsed().as_secs_f64();
    let filter = Filter::Butterworth {
        order: 2,
        cutoff_hz: 6.0,
    };
    let filtered = filter_motion(&noisy, &filter)?;

    let noisy_path = context.path("clean", "noisy.bvh")?;
    let cleaned_path = context.path("clean", "cleaned.bvh")?;
    write_bvh(&noisy_path, &noisy)?;
    write_bvh(&cleaned_path, &cleaned)?;
    report.output(
        StageContext::relative("clean", "noisy.bvh"),
        "the sample with synthetic markerless noise",
    );
    report.output(
        StageContext::relative("clean", "cleaned.bvh"),
        "the noisy take cleaned by the denoiser",
    );
    report.viewer_command = Some(viewer_command(&[
        &options.sample,
        &noisy_path,
        &cleaned_path,
    ]));

    let mm = 1000.0 / units_per_metre(&motion) as f64;
    let (noisy_position, noisy_acceleration) = position_errors(&noisy, &motion);
    let (cleaned_position, cleaned_acceleration) = position_errors(&cleaned, &motion);
    let (filtered_position, _) = position_errors(&filtered, &motion);
    report.number(
        "noise_sigma_deg",
        "standard deviation of the per-joint rotation noise added",
        options.noise_sigma_deg as f64,
        "deg",
    );
    report.number(
        "rotation_error_noisy_deg",
        "noisy take vs sample, mean geodesic angle of the local joint rotations",
        rotation_error_deg(&noisy, &motion),
        "deg",
    );
    report.number(
        "rotation_error_cleaned_deg",
        "cleaned take vs sample, mean geodesic angle of the local joint rotations",
        rotation_error_deg(&cleaned, &motion),
        "deg",
    );
    report.number(
        "rotation_error_filtered_deg",
        "Butterworth-filtered noisy take vs sample (classical reference)",
        rotation_error_deg(&filtered, &motion),
        "deg",
    );
    report.number(
        "position_error_noisy_mm",
        "noisy take vs sample, mean per-joint position error",
        noisy_position * mm,
        "mm",
    );
    report.number(
        "position_error_cleaned_mm",
        "cleaned take vs sample, mean per-joint position error",
        cleaned_position * mm,
        "mm",
    );
    report.number(
        "position_error_filtered_mm",
        "Butterworth-filtered noisy take vs sample",
        filtered_position * mm,
        "mm",
    );
    report.number(
        "acceleration_error_noisy",
        "noisy take vs sample, acceleration error (mm per frame^2)",
        noisy_acceleration * mm,
        "mm/frame²",
    );
    report.number(
        "acceleration_error_cleaned",
        "cleaned take vs sample, acceleration error (mm per frame^2)",
        cleaned_acceleration * mm,
        "mm/frame²",
    );
    report.number(
        "clean_seconds",
        "time the model took to clean the take (CPU)",
        clean_seconds,
        "s",
    );
    report.fact("model", options.clean_model.display().to_string());
    report.fact("reference filter", filter.label());
    report.note(
        "The model is trained on the Bandai rig, so it is tested here on the sample with synthetic noise (chain-corrected random noise of mocap-clean's noise module), not on the fused skeleton of the fuse stage.",
    );
    report.note(
        "One noise draw on one take: a demonstration, not an evaluation (see `mocap clean eval` for held-out takes).",
    );

    if options.pictures {
        let strip = context.path("clean", "sample_noisy_cleaned.png")?;
        render_files(
            &[
                options.sample.clone(),
                noisy_path.clone(),
                cleaned_path.clone(),
            ],
            &strip,
            &RenderOptions::default(),
        )?;
        report.picture(
            StageContext::relative("clean", "sample_noisy_cleaned.png"),
            "sample, noisy and cleaned takes, overlaid",
        );
        let plot_path = context.path("clean", "rotation_error.png")?;
        let step = motion.frame_time() as f32;
        let plot = LinePlot::new(
            "Rotation error against the sample",
            "time (s)",
            "mean joint rotation error (degrees)",
        )
        .with_series(Series::sampled(
            "noisy",
            0.0,
            step,
            &rotation_error_per_frame(&noisy, &motion),
        ))
        .with_series(Series::sampled(
            "cleaned (model)",
            0.0,
            step,
            &rotation_error_per_frame(&cleaned, &motion),
        ))
        .with_series(Series::sampled(
            "Butterworth",
            0.0,
            step,
            &rotation_error_per_frame(&filtered, &motion),
        ));
        plot_lines(&plot_path, &plot)?;
        report.picture(
            StageContext::relative("clean", "rotation_error.png"),
            "rotation error per frame: noisy, cleaned, classical filter",
        );
    }
    Ok(())
}
