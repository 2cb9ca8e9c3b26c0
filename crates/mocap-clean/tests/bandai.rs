//! Tests on real takes of the Bandai Namco data set (skipped with a note
//! when the shared data is absent).

use std::path::PathBuf;

use mocap_clean::{
    add_random_noise_sigma, add_spike_noise, filter_motion, position_errors, rotation_error_deg,
    CleanModel, Filter, RandomNoise, SpikeNoise, DEFAULT_MODEL_PATH,
};
use mocap_core::io::bvh::read_bvh;
use mocap_core::{forward_kinematics, Motion};
use rand::rngs::ChaCha8Rng;
use rand::SeedableRng;

fn take(name: &str) -> Option<Motion> {
    let dir = mocap_testdata::shared_data()?;
    Some(read_bvh(&dir.join("bandai/dataset-1").join(name)).expect("readable take"))
}

/// Mean position error of one joint.
fn joint_error(a: &Motion, b: &Motion, joint: usize) -> f32 {
    let (pa, pb) = (forward_kinematics(a), forward_kinematics(b));
    (0..a.frame_count())
        .map(|f| (pa.position(f, joint) - pb.position(f, joint)).length())
        .sum::<f32>()
        / a.frame_count() as f32
}

#[test]
fn chain_corrected_noise_does_not_grow_towards_the_hands() {
    let Some(motion) = take("dataset-1_walk_normal_001.bvh") else {
        return;
    };
    let s = motion.skeleton();
    let hand = s.find("Hand_L").expect("the Bandai rig has Hand_L");
    // The joint two levels above the hand (the upper arm).
    let elbow = s.joint(hand).parent.unwrap();
    let shoulder = s.joint(elbow).parent.unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let naive = add_random_noise_sigma(
        &motion,
        5.0,
        &RandomNoise {
            chain_corrected: false,
            ..Default::default()
        },
        &mut rng,
    );
    let corrected = add_random_noise_sigma(&motion, 5.0, &RandomNoise::default(), &mut rng);
    let (nh, ns) = (
        joint_error(&motion, &naive, hand),
        joint_error(&motion, &naive, shoulder),
    );
    let (ch, cs) = (
        joint_error(&motion, &corrected, hand),
        joint_error(&motion, &corrected, shoulder),
    );
    eprintln!("naive: shoulder {ns:.2} hand {nh:.2}; corrected: shoulder {cs:.2} hand {ch:.2}");
    assert!(ch < 0.6 * nh, "corrected hand error {ch} vs naive {nh}");
    // Corrected, no joint of the arm errs by more than the arm's longest
    // bone turned by about sigma: nothing accumulates from the root (with
    // Bandai's helper root perturbed, the upper arm erred by 4 cm).
    let longest = [hand, elbow, shoulder]
        .iter()
        .map(|&j| s.joint(j).offset.length())
        .fold(0.0f32, f32::max);
    let single_bone = longest * 5f32.to_radians();
    for (joint, error) in [(hand, ch), (shoulder, cs)] {
        assert!(
            error < 1.5 * single_bone,
            "{}: {error} cm; the longest arm bone turned by 5 degrees: {single_bone} cm",
            s.joint(joint).name
        );
    }
}

#[test]
fn filters_reduce_random_noise_on_a_real_take() {
    let Some(motion) = take("dataset-1_walk_normal_001.bvh") else {
        return;
    };
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let noisy = add_random_noise_sigma(&motion, 8.0, &RandomNoise::default(), &mut rng);
    let before = rotation_error_deg(&motion, &noisy);
    let out = filter_motion(
        &noisy,
        &Filter::Butterworth {
            order: 2,
            cutoff_hz: 4.0,
        },
    )
    .unwrap();
    let after = rotation_error_deg(&motion, &out);
    assert!(after < 0.7 * before, "{before} -> {after}");
    let (p, _) = position_errors(&motion, &out);
    assert!(p.is_finite());
}

/// The shipped model and the dataset-1 takes of the test split (never seen
/// in training), when the data and the model are there.
fn shipped_model_and_test_takes() -> Option<(CleanModel, Vec<PathBuf>)> {
    let dir = mocap_testdata::shared_data()?;
    if !PathBuf::from(DEFAULT_MODEL_PATH).is_file() {
        eprintln!("note: no shipped model at {DEFAULT_MODEL_PATH}");
        return None;
    }
    let model = CleanModel::load_default(Default::default()).unwrap();
    let paths = mocap_clean::list_bvh(&[dir.join("bandai/dataset-1")]).unwrap();
    let test = mocap_clean::paths_in_split(&paths, mocap_clean::Split::Test, &Default::default());
    Some((model, test))
}

#[test]
fn the_shipped_model_cleans_a_held_out_take() {
    let Some((model, test)) = shipped_model_and_test_takes() else {
        return;
    };
    let motion = read_bvh(&test[0]).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let noisy = add_random_noise_sigma(&motion, 8.0, &RandomNoise::default(), &mut rng);
    let donor = mocap_clean::looped_window(&read_bvh(&test[1]).unwrap(), 0, motion.frame_count());
    let (noisy, _) = add_spike_noise(
        &noisy,
        &[&donor],
        &SpikeNoise {
            max_spikes: 1,
            ..Default::default()
        },
        &mut rng,
    )
    .unwrap();
    let cleaned = model.clean(&noisy, None).unwrap();
    assert_eq!(cleaned.skeleton(), motion.skeleton());
    assert_eq!(cleaned.frame_count(), motion.frame_count());
    for f in 0..motion.frame_count() {
        assert_eq!(cleaned.root_translation(f), noisy.root_translation(f));
    }
    let before = rotation_error_deg(&motion, &noisy);
    let after = rotation_error_deg(&motion, &cleaned);
    eprintln!(
        "{}: rotation error {before:.2} -> {after:.2} degrees",
        test[0].display()
    );
    assert!(after < 0.6 * before, "{before} -> {after}");
}

#[test]
fn the_shipped_model_leaves_clean_held_out_takes_nearly_alone() {
    // A model that does not read the noise level moved clean test takes by
    // 0.81 degrees on average (its Wiener filter alone by 0.04); one that reads the
    // noise level its filter estimates should not. The filter does take
    // some vigorous motion for noise (an angry wave: estimated at 4.7
    // degrees, moved by 3.6; bench/results/clean.md), hence the median and
    // a share rather than every take.
    let Some((model, test)) = shipped_model_and_test_takes() else {
        return;
    };
    let mut moved: Vec<f64> = test
        .iter()
        .map(|path| {
            let motion = read_bvh(path).unwrap();
            let (cleaned, level) = model.clean_reporting(&motion, None).unwrap();
            let moved = rotation_error_deg(&motion, &cleaned);
            eprintln!(
                "{}: moved by {moved:.3} degrees (noise estimated at {level:?} degrees)",
                path.display()
            );
            moved
        })
        .collect();
    moved.sort_by(f64::total_cmp);
    let median = moved[moved.len() / 2];
    let under_half_degree = moved.iter().filter(|&&m| m < 0.5).count();
    assert!(median < 0.2, "median {median} degrees: {moved:?}");
    assert!(
        under_half_degree * 10 >= moved.len() * 9,
        "{under_half_degree} of {} moved by less than 0.5 degrees: {moved:?}",
        moved.len()
    );
}

#[test]
fn spikes_do_not_raise_the_noise_level_the_shipped_model_reads() {
    // Takes with spikes and no other noise (the evaluation's spikes-alone
    // condition, its seed), not bridged. With the level of all segments
    // together (`LevelEstimate::Pooled`) the spiked segments raise the level of the
    // whole take and the model smooths all of it; the median of the
    // segments' levels (the default) keeps to the rest of the take.
    use mocap_clean::LevelEstimate;
    use mocap_clean::{noisy_take, EvalOptions};
    let Some((median_model, test)) = shipped_model_and_test_takes() else {
        return;
    };
    let mut pooled_model = CleanModel::load_default(Default::default()).unwrap();
    pooled_model.set_level_estimate(LevelEstimate::Pooled);
    let takes = mocap_clean::load_takes(&test).unwrap();
    let spikes_alone = 2;
    let (mut error, mut level, mut frames) = ([0.0; 2], [0.0; 2], 0.0);
    for i in 0..takes.len() {
        let clean = &takes[i].motion;
        let spiked = noisy_take(&takes, i, spikes_alone, &EvalOptions::default())
            .unwrap()
            .0;
        for (k, model) in [&pooled_model, &median_model].into_iter().enumerate() {
            let (out, estimated) = model.clean_reporting(&spiked, None).unwrap();
            error[k] += rotation_error_deg(clean, &out) * clean.frame_count() as f64;
            level[k] += estimated.unwrap() / takes.len() as f64;
        }
        frames += clean.frame_count() as f64;
    }
    let error = error.map(|e| e / frames);
    eprintln!(
        "{} takes with spikes alone: pooled level {:.2} deg, error {:.3}; median level {:.2} deg, \
         error {:.3}",
        takes.len(),
        level[0],
        error[0],
        level[1],
        error[1]
    );
    assert!(level[1] < 0.6 * level[0], "levels {level:?}");
    assert!(error[1] < 0.9 * error[0], "errors {error:?}");
}

#[test]
fn spike_finding_leaves_clean_held_out_takes_nearly_alone() {
    // `mocap clean apply --despike` bridges what it takes for spikes before the
    // model runs; on clean takes whatever it finds is a false alarm. Measured
    // on the 116 test takes: 18 get some, all but one moved by at most 0.06
    // degrees (mostly one-frame bridges of fast hands); the vigorous
    // `dataset-1_call_normal_001` by 0.8 (bench/results/clean.md).
    use mocap_clean::{remove_spikes, DespikeOptions};
    let Some(dir) = mocap_testdata::shared_data() else {
        return;
    };
    let paths = mocap_clean::list_bvh(&[dir.join("bandai")]).unwrap();
    let test = mocap_clean::paths_in_split(&paths, mocap_clean::Split::Test, &Default::default());
    let mut moved: Vec<f64> = test
        .iter()
        .map(|path| {
            let motion = read_bvh(path).unwrap();
            let (bridged, found) = remove_spikes(&motion, &DespikeOptions::default());
            let moved = rotation_error_deg(&motion, &bridged);
            if !found.is_empty() {
                eprintln!(
                    "{}: {} spikes found, moved by {moved:.3} degrees",
                    path.display(),
                    found.len()
                );
            }
            moved
        })
        .collect();
    moved.sort_by(f64::total_cmp);
    let nearly_untouched = moved.iter().filter(|&&m| m < 0.1).count();
    let mean = moved.iter().sum::<f64>() / moved.len() as f64;
    eprintln!(
        "{nearly_untouched} of {} takes moved by less than 0.1 degrees, mean change {mean:.3} degrees",
        moved.len()
    );
    assert!(
        nearly_untouched * 20 >= moved.len() * 19,
        "{nearly_untouched} of {} moved by less than 0.1 degrees: {moved:?}",
        moved.len()
    );
    assert!(mean < 0.05, "mean change {mean} degrees: {moved:?}");
}

#[test]
fn a_long_spike_in_a_real_take_is_found_and_bridged() {
    use mocap_clean::{add_spikes, Spike};
    use mocap_clean::{remove_spikes, DespikeOptions};
    let (Some(motion), Some(donor)) = (
        take("dataset-1_walk_normal_001.bvh"),
        take("dataset-1_dance-short_normal_001.bvh"),
    ) else {
        return;
    };
    assert!(donor.frame_count() >= motion.frame_count());
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut spikes = [Spike {
        joint: 0,
        start: 40,
        frames: 32,
    }];
    let (spiked, spikes) = add_spikes(
        &motion,
        &[&donor],
        &SpikeNoise::default(),
        &mut spikes,
        &mut rng,
    )
    .unwrap();
    let s = spikes[0];
    let subtree = motion.skeleton().subtree(s.joint);
    let error = |m: &Motion| -> f32 {
        let mut sum = 0.0;
        for f in s.start..s.start + s.frames {
            for &j in &subtree {
                sum += mocap_core::rotation::angle_between(
                    motion.local_rotation(f, j),
                    m.local_rotation(f, j),
                );
            }
        }
        sum.to_degrees() / (s.frames * subtree.len()) as f32
    };
    let (repaired, found) = remove_spikes(&spiked, &DespikeOptions::default());
    eprintln!(
        "spike at {} frames {}..{}: {:.1} -> {:.1} degrees; found {found:?}",
        motion.skeleton().joint(s.joint).name,
        s.start,
        s.start + s.frames,
        error(&spiked),
        error(&repaired)
    );
    // That spike and nothing else (the walk itself has none).
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!((found[0].start, found[0].frames), (s.start, s.frames));
    assert!(error(&repaired) < 0.5 * error(&spiked));
}
