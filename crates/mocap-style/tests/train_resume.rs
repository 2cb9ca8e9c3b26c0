//! Training the style autoencoder can be interrupted and resumed: a run of
//! two epochs in one go and a run of one epoch resumed for a second give the
//! same losses (the windows of epoch `e` come from a generator seeded with
//! `(seed, e)`, and the resumable state holds the weights and Adam's moments).
//! Uses the two walks bundled in `samples/`.

use mocap_style::{train, TrainOptions};

#[test]
fn a_resumed_run_matches_an_uninterrupted_one() {
    let dir = tempfile::tempdir().unwrap();
    let takes = dir.path().join("walks");
    std::fs::create_dir(&takes).unwrap();
    for name in [
        "dataset-1_walk_normal_001.bvh",
        "dataset-1_walk_proud_001.bvh",
    ] {
        std::fs::copy(mocap_testdata::sample(name), takes.join(name)).unwrap();
    }
    let base = TrainOptions {
        inputs: vec![takes],
        hold_out: false,
        window: 32,
        batch_size: 4,
        steps_per_epoch: 2,
        epochs: 2,
        ..TrainOptions::default()
    };
    let straight = train(&TrainOptions {
        out: dir.path().join("a.safetensors"),
        ..base.clone()
    })
    .unwrap();
    let first_half = TrainOptions {
        out: dir.path().join("b.safetensors"),
        epochs: 1,
        ..base.clone()
    };
    train(&first_half).unwrap();
    let resumed = train(&TrainOptions {
        epochs: 2,
        resume: true,
        ..first_half
    })
    .unwrap();
    assert_eq!(resumed.resumed_from_epoch, 1);
    assert_eq!(straight.history.epochs.len(), 2);
    assert_eq!(resumed.history.epochs.len(), 2);
    for (a, b) in straight.history.epochs.iter().zip(&resumed.history.epochs) {
        let tolerance = 1e-5 * a.train_loss.abs().max(1e-3);
        assert!(
            (a.train_loss - b.train_loss).abs() < tolerance,
            "{a:?} vs {b:?}"
        );
    }
    // Not resumed without asking: a new run starts from epoch 0.
    let fresh = train(&TrainOptions {
        out: dir.path().join("b.safetensors"),
        epochs: 1,
        ..base
    })
    .unwrap();
    assert_eq!(fresh.resumed_from_epoch, 0);
}
