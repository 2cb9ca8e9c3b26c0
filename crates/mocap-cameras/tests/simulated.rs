//! The capture stage against a ground truth: the bundled Bandai walk filmed
//! by simulated cameras through a simulated 2D pose estimator.

use std::path::Path;

use mocap_cameras::{
    evaluate_trial, read_trial, simulate_to_folder, CameraEvalOptions, CameraEvalReport,
    CameraSimOptions, CaptureOptions,
};

fn simulated(folder: &Path, options: &CameraSimOptions) {
    simulate_to_folder(&mocap_testdata::sample_walk(), folder, options).unwrap();
}

fn evaluate(folder: &Path) -> CameraEvalReport {
    evaluate_trial(&CameraEvalOptions {
        capture: CaptureOptions::new(folder),
        truth: Some(folder.join("truth.trc")),
        reference: None,
        person: 0,
    })
    .unwrap()
}

fn mpjpe(report: &CameraEvalReport, method: &str) -> f64 {
    let m = report.methods.iter().find(|m| m.method == method).unwrap();
    m.mpjpe_mm.unwrap()
}

#[test]
fn without_estimator_errors_every_method_finds_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    let trial = dir.path().join("exact");
    simulated(
        &trial,
        &CameraSimOptions {
            pixel_noise: 0.0,
            miss_rate: 0.0,
            swap_rate: 0.0,
            outlier_rate: 0.0,
            occlusion: false,
            ..CameraSimOptions::default()
        },
    );
    let report = evaluate(&trial);
    for m in &report.methods {
        assert!(m.mpjpe_mm.unwrap() < 0.5, "{}: {:?}", m.method, m.mpjpe_mm);
        assert!(m.coverage > 0.95, "{}: {}", m.method, m.coverage);
    }
}

#[test]
fn leaving_out_views_that_disagree_beats_plain_dlt_on_a_noisy_estimator() {
    let dir = tempfile::tempdir().unwrap();
    let trial = dir.path().join("noisy");
    simulated(&trial, &CameraSimOptions::default());
    let report = evaluate(&trial);
    let (plain, scores, robust) = (
        mpjpe(&report, "plain"),
        mpjpe(&report, "scores"),
        mpjpe(&report, "robust"),
    );
    assert!(plain > 10.0 && plain < 40.0, "plain DLT {plain:.1} mm");
    assert!(
        scores < plain,
        "scores {scores:.1} against plain {plain:.1}"
    );
    assert!(
        robust < 0.8 * plain,
        "robust {robust:.1} against plain {plain:.1}"
    );
    assert_eq!(report.best_over_plain.unwrap(), robust.min(scores) / plain);
}

#[test]
fn cameras_with_missing_and_uneven_frames_are_matched_by_frame_number() {
    let dir = tempfile::tempdir().unwrap();
    let trial = dir.path().join("gaps");
    simulated(&trial, &CameraSimOptions::default());
    // Camera 2 lost frames 30-39 and its last frame.
    let cam2 = trial.join("pose/cam02_json");
    let mut files: Vec<_> = std::fs::read_dir(&cam2)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    files.sort();
    let last = files.len() - 1;
    for (i, f) in files.iter().enumerate() {
        if (30..40).contains(&i) || i == last {
            std::fs::remove_file(f).unwrap();
        }
    }
    let read = read_trial(&CaptureOptions::new(&trial)).unwrap();
    assert_eq!(
        read.frames,
        files.len(),
        "the union of every camera's frames"
    );
    let notes = read.notes.join("\n");
    assert!(notes.contains("10 frame files missing"), "{notes}");
    assert!(notes.contains("different frame counts"), "{notes}");
    // The frames without camera 2 are still triangulated from the other three.
    let report = evaluate(&trial);
    let robust = report
        .methods
        .iter()
        .find(|m| m.method == "robust")
        .unwrap();
    assert!(robust.coverage > 0.95, "{}", robust.coverage);
}
