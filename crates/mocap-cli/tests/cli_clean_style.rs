//! `mocap clean` and `mocap style` end to end on the bundled takes (and, for
//! training, a few real Bandai takes when `../shared/data` is present).

use std::path::{Path, PathBuf};
use std::process::Output;

use mocap_core::io::bvh::{read_bvh, write_bvh};
use mocap_core::rotation::Vec3;
use mocap_style::{foot_skating, planted_foot_sliding, RigLayout};

mod common;
use common::{mocap, stderr};

fn sample(name: &str) -> String {
    mocap_testdata::sample(name).display().to_string()
}

/// `mocap style apply SOURCE --style STYLE -o OUT`, then `extra` options.
fn style_apply(source: &str, style: &str, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["style", "apply", source, "--style", style, "-o", path(out)];
    args.extend_from_slice(extra);
    mocap(&args)
}

fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

/// Mean absolute difference of the rotation channels of two takes with the
/// same layout, in degrees.
/// Mean geodesic angle between the local rotations of two takes (degrees):
/// unlike channel values, blind to other Euler angles for the same rotation.
fn rotation_change_deg(a: &Path, b: &Path) -> f32 {
    mocap_core::metrics::mean_rotation_error_degrees(&read_bvh(a).unwrap(), &read_bvh(b).unwrap())
        .unwrap()
}

fn mean_channel_change(a: &Path, b: &Path) -> f32 {
    let a = read_bvh(a).unwrap();
    let b = read_bvh(b).unwrap();
    let (sum, n) = a
        .values()
        .iter()
        .zip(b.values())
        .fold((0.0f32, 0usize), |(s, n), (x, y)| {
            (s + (x - y).abs(), n + 1)
        });
    sum / n as f32
}

#[test]
fn clean_with_the_shipped_model_keeps_the_layout_denoises_and_leaves_a_clean_take_alone() {
    use mocap_clean::{add_random_noise_sigma, RandomNoise};
    use rand::SeedableRng;
    let dir = tempfile::tempdir().unwrap();
    let input = sample("dataset-1_walk_normal_001.bvh");
    let original = read_bvh(Path::new(&input)).unwrap();
    // The bundled walk is clean: the model leaves it alone (measured: 0.00
    // degrees; with the level pooled over the take's segments, 0.04).
    let output = dir.path().join("clean.bvh");
    let out = mocap(&["clean", "apply", &input, "-o", path(&output), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let cleaned = read_bvh(&output).unwrap();
    assert_eq!(report["frames"], original.frame_count());
    assert_eq!(cleaned.frame_count(), original.frame_count());
    assert_eq!(
        cleaned.skeleton().joints().len(),
        original.skeleton().joints().len()
    );
    assert_eq!(cleaned.values().len(), original.values().len());
    let change = rotation_change_deg(Path::new(&input), &output);
    assert!(change < 0.02, "a clean take changed by {change} degrees");
    // A noisy copy of it (3 degrees of the training noise) is denoised.
    let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(5);
    let noisy = add_random_noise_sigma(&original, 3.0, &RandomNoise::default(), &mut rng);
    let noisy_path = dir.path().join("noisy.bvh");
    mocap_core::io::bvh::write_bvh(&noisy_path, &noisy).unwrap();
    let denoised = dir.path().join("denoised.bvh");
    let out = mocap(&[
        "clean",
        "apply",
        path(&noisy_path),
        "-o",
        path(&denoised),
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let before = rotation_change_deg(Path::new(&input), &noisy_path);
    let after = rotation_change_deg(Path::new(&input), &denoised);
    assert!(after < 0.6 * before, "{before} -> {after} degrees");
}

#[test]
fn clean_with_a_filter_and_bad_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let input = sample("dataset-1_walk_normal_001.bvh");
    let output = dir.path().join("filtered.bvh");
    let out = mocap(&[
        "clean",
        "apply",
        &input,
        "-o",
        path(&output),
        "--filter",
        "butterworth:2:3",
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(mean_channel_change(Path::new(&input), &output) > 0.01);
    let fixed_change = rotation_change_deg(Path::new(&input), &output);

    // The cross-validated cutoff sees that this optical take is clean and
    // changes it less than a fixed 3 Hz low-pass does.
    let adaptive = dir.path().join("adaptive.bvh");
    let out = mocap(&[
        "clean",
        "apply",
        &input,
        "-o",
        path(&adaptive),
        "--filter",
        "butterworth-gcv:2",
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let adaptive_change = rotation_change_deg(Path::new(&input), &adaptive);
    assert!(
        adaptive_change < 0.5 * fixed_change,
        "gcv {adaptive_change}, fixed {fixed_change}"
    );

    // A filter spec that does not parse is a usage error (2).
    let out = mocap(&[
        "clean",
        "apply",
        &input,
        "-o",
        path(&output),
        "--filter",
        "gauss:3",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));

    // A missing take is an input error (1) naming the file, and nothing is written.
    let missing = dir.path().join("missing.bvh");
    let never = dir.path().join("never.bvh");
    let out = mocap(&["clean", "apply", path(&missing), "-o", path(&never)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("missing.bvh"), "{}", stderr(&out));
    assert!(!never.exists());

    // Without -o it is a usage error.
    let out = mocap(&["clean", "apply", &input]);
    assert_eq!(out.status.code(), Some(2));
}

/// Mean jerk of the pelvis' translation channels (file units per frame³).
fn pelvis_jerk(file: &Path) -> f32 {
    let m = read_bvh(file).unwrap();
    let pelvis = 1; // Bandai's Hips, under the still joint_Root.
    let x: Vec<_> = (0..m.frame_count())
        .map(|f| m.local_translation(f, pelvis))
        .collect();
    let jerks: Vec<f32> = x
        .windows(4)
        .map(|w| (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]).length())
        .collect();
    jerks.iter().sum::<f32>() / jerks.len() as f32
}

/// A fused capture's root is noisy: `--root-filter` cleans it, and without
/// it the root's translation is kept as it was.
#[test]
fn root_filter_cleans_the_root_translation_only_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let mut walk = read_bvh(Path::new(&sample("dataset-1_walk_normal_001.bvh"))).unwrap();
    // 1 cm of alternating noise on the pelvis, as fusion leaves it.
    for f in 0..walk.frame_count() {
        let t = walk.local_translation(f, 1);
        let noise = if f % 2 == 0 { 1.0 } else { -1.0 };
        walk.set_local_translation(f, 1, t + Vec3::new(noise, 0.0, noise));
    }
    let input = dir.path().join("noisy-root.bvh");
    write_bvh(&input, &walk).unwrap();
    let clean = |name: &str, extra: &[&str]| {
        let output = dir.path().join(name);
        let out = mocap(
            &[
                &["clean", "apply", path(&input), "-o", path(&output)][..],
                &["--filter", "butterworth:2:3", "--json"],
                extra,
            ]
            .concat(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (output, report["method"].as_str().unwrap().to_string())
    };
    let (kept, method) = clean("kept.bvh", &[]);
    assert!(!method.contains("root"), "{method}");
    let (filtered, method) = clean("root.bvh", &["--root-filter", "butterworth:2:3"]);
    assert!(method.contains("root: butterworth"), "{method}");
    let noisy = pelvis_jerk(&input);
    assert!((pelvis_jerk(&kept) - noisy).abs() < 1e-3 * noisy);
    assert!(
        pelvis_jerk(&filtered) < 0.1 * noisy,
        "{} of {noisy}",
        pelvis_jerk(&filtered)
    );
}

#[test]
fn despike_only_leaves_a_clean_take_nearly_alone() {
    let dir = tempfile::tempdir().unwrap();
    let input = sample("dataset-1_walk_normal_001.bvh");
    let output = dir.path().join("despiked.bvh");
    let out = mocap(&[
        "clean",
        "apply",
        &input,
        "-o",
        path(&output),
        "--despike",
        "--despike-only",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["method"], "spike finding only");
    // A clean capture has no spikes to bridge: its channels stay as they
    // were. So do the shipped model's, nearly: it leaves a take its Wiener
    // filter finds clean alone, and keeps the input's Euler angles where
    // the rotation barely changes.
    let despiked = mean_channel_change(Path::new(&input), &output);
    assert!(despiked < 0.01, "despike only moved channels by {despiked}");
    let modelled = dir.path().join("modelled.bvh");
    let out = mocap(&["clean", "apply", &input, "-o", path(&modelled), "--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let model_change = mean_channel_change(Path::new(&input), &modelled);
    assert!(
        model_change < 0.2,
        "the model moved channels by {model_change}"
    );

    // --despike-only needs --despike, and excludes a model or filter (usage errors).
    let out = mocap(&[
        "clean",
        "apply",
        &input,
        "-o",
        path(&output),
        "--despike-only",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let out = mocap(&[
        "clean",
        "apply",
        &input,
        "-o",
        path(&output),
        "--despike",
        "--despike-only",
        "--filter",
        "median:3",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    // A span or longest spike of no frames is a usage error naming the
    // option.
    for option in ["--despike-span", "--despike-max-frames"] {
        let out = mocap(&[
            "clean",
            "apply",
            &input,
            "-o",
            path(&output),
            "--despike",
            option,
            "0",
        ]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(stderr(&out).contains(option), "{}", stderr(&out));
    }
}

/// `mocap clean` of the bundled walk with `model`, written to
/// `dir/clean.bvh`, the report as JSON on stdout.
fn clean_walk_with(model: &Path, dir: &Path) -> std::process::Output {
    let input = sample("dataset-1_walk_normal_001.bvh");
    let output = dir.join("clean.bvh");
    mocap(&[
        "clean",
        "apply",
        &input,
        "-o",
        path(&output),
        "--model",
        path(model),
        "--json",
    ])
}

/// Forty real dataset-2 takes copied into `dir/takes` (the 10% validation
/// split by take gets several).
fn forty_takes(dir: &Path, data: &Path) -> PathBuf {
    let takes = dir.join("takes");
    std::fs::create_dir(&takes).unwrap();
    let files: Vec<PathBuf> = mocap_testdata::bvh_files(&data.join("bandai/dataset-2"));
    for file in files.iter().step_by(files.len() / 40).take(40) {
        std::fs::copy(file, takes.join(file.file_name().unwrap())).unwrap();
    }
    takes
}

#[test]
fn clean_train_writes_a_model_that_clean_can_use() {
    let Some(data) = mocap_testdata::shared_data() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let takes = forty_takes(dir.path(), &data);
    // A tiny network (its width from a recipe), a few steps, the report on
    // stdout; `extra` adds options.
    let recipe = dir.path().join("tiny.toml");
    std::fs::write(&recipe, "width = 8\n").unwrap();
    let train = |model: &Path, extra: &[&str]| {
        let mut args = vec!["clean", "train", path(&takes), "-o", path(model)];
        args.extend([
            "--steps",
            "2",
            "--batch",
            "8",
            "--recipe",
            path(&recipe),
            "--json",
        ]);
        args.extend(extra);
        mocap(&args)
    };
    let model = dir.path().join("tiny.safetensors");
    let out = train(&model, &["--epochs", "2"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["history"]["epochs"].as_array().unwrap().len(), 2);
    assert_eq!(report["description"]["network"]["width"], 8);
    assert!(model.is_file());
    assert!(model.with_extension("png").is_file());

    let out = clean_walk_with(&model, dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.path().join("clean.bvh").is_file());

    // On top of the cross-validated filter run over whole takes; the
    // description says so and `mocap clean` uses it.
    let based = dir.path().join("based.safetensors");
    let out = train(
        &based,
        &[
            "--epochs",
            "1",
            "--base-filter",
            "butterworth-gcv:2",
            "--base-context",
            "16",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["description"]["base_context"], 16);
    let out = clean_walk_with(&based, dir.path());
    assert!(out.status.success(), "{}", stderr(&out));

    // The context without a base filter is a usage error.
    let out = train(&based, &["--base-context", "16"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--base-filter"), "{}", stderr(&out));

    // A recipe key it does not know is an input error naming the file and the key.
    let typo = dir.path().join("typo.toml");
    std::fs::write(&typo, "widht = 8\n").unwrap();
    let out = mocap(&[
        "clean",
        "train",
        path(&takes),
        "-o",
        path(&based),
        "--recipe",
        path(&typo),
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("typo.toml") && stderr(&out).contains("widht"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn clean_fit_wiener_fits_a_filter_that_apply_and_eval_use() {
    let Some(data) = mocap_testdata::shared_data() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let takes = forty_takes(dir.path(), &data);
    let filter = dir.path().join("wiener.safetensors");
    let out = mocap(&[
        "clean",
        "fit-wiener",
        path(&takes),
        "-o",
        path(&filter),
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        report["description"]["takes"].as_u64().unwrap() >= 20,
        "{report}"
    );
    assert_eq!(report["description"]["segment"], 32);
    assert!(filter.is_file());

    // `mocap clean apply --model` tells the filter from a network by its header.
    let out = clean_walk_with(&filter, dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        report["method"]
            .as_str()
            .unwrap()
            .starts_with("Wiener filter"),
        "{report}"
    );
    assert!(dir.path().join("clean.bvh").is_file());

    // So does the evaluation (of 2 takes, the Wiener filter alone, with
    // more options).
    let label = format!("learned Wiener={}", path(&filter));
    let eval_with = |more: &[&str]| {
        let mut args = vec![
            "clean",
            "eval",
            path(&takes),
            "--all-takes",
            "--max-takes",
            "2",
            "--no-default-model",
            "--no-filters",
            "--spike-lengths",
            "none",
            "--model",
            &label,
            "--json",
        ];
        args.extend_from_slice(more);
        mocap(&args)
    };
    let out = eval_with(&[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("learned Wiener"), "{text}");

    // --max-sigma 0: what a method does to clean takes (the random
    // condition's input is then the clean take); a negative level is a usage
    // error that says what is expected.
    let out = eval_with(&["--max-sigma=0"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let entry = |method: &str| {
        report["entries"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["condition"] == "random" && e["method"] == method)
            .unwrap_or_else(|| panic!("no {method} entry: {report}"))["rotation_error_deg"]
            .as_f64()
            .unwrap()
    };
    assert!(entry("noisy input") < 1e-3, "{report}");
    assert!(entry("learned Wiener") < 1.0, "{report}");
    let out = eval_with(&["--max-sigma=-1"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("0 or more"), "{}", stderr(&out));

    // A mixture: spectra per content named in the file names (here 40
    // dataset-2 takes of 10 contents), the rest together, and all.
    let mixture = dir.path().join("mixture.safetensors");
    let fit_mixture = |min: &str| {
        mocap(&[
            "clean",
            "fit-wiener",
            path(&takes),
            "--mixture",
            min,
            "-o",
            path(&mixture),
            "--json",
        ])
    };
    let out = fit_mixture("20");
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<&str> = report["description"]["components"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert!(
        names.len() >= 3 && names.last() == Some(&"all"),
        "{names:?}"
    );
    let out = clean_walk_with(&mixture, dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    // The report names the component that cleaned the take.
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let method = report["method"].as_str().unwrap();
    assert!(
        names
            .iter()
            .any(|n| method.contains(&format!("spectra of {n}"))),
        "{method}"
    );
    let out = fit_mixture("0");
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));

    // Network options are not fit-wiener's (usage errors).
    let out = mocap(&[
        "clean",
        "fit-wiener",
        path(&takes),
        "--epochs",
        "3",
        "-o",
        path(&filter),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
}

/// Most a straight walk may move, mean over joints and frames, when its small
/// left-right asymmetry is kept (the bundled walk restyled as proud: about 2
/// degrees with the shipped model).
const ASYMMETRY_CHANGE_MAX_DEG: f32 = 4.0;

#[test]
fn style_apply_restyles_the_bundled_walk() {
    let dir = tempfile::tempdir().unwrap();
    let source = sample("dataset-1_walk_normal_001.bvh");
    let style = sample("dataset-1_walk_proud_001.bvh");
    let output = dir.path().join("proud.bvh");
    // `mocap style apply` of the walk in the proud style, with `extra`.
    let apply = |extra: &[&str]| {
        let mut args = vec!["--json"];
        args.extend_from_slice(extra);
        style_apply(&source, &style, &output, &args)
    };
    // Restyles with `extra` options: the JSON report and the output.
    let restyle = |extra: &[&str]| {
        let out = apply(extra);
        assert!(out.status.success(), "{}", stderr(&out));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (report, read_bvh(&output).unwrap())
    };
    let (report, restyled) = restyle(&["--strength", "0.8", "--fade-in", "1s"]);
    let original = read_bvh(Path::new(&source)).unwrap();
    assert_eq!(
        report["output_frames"].as_u64().unwrap() as usize,
        restyled.frame_count()
    );
    // The output keeps the source's skeleton.
    assert_eq!(
        restyled.skeleton().joints().len(),
        original.skeleton().joints().len()
    );
    // Elastic source patches are 0.75 P to 1.25 P frames long and become P
    // frames, so the duration changes by a factor within [1/1.25, 1/0.75].
    let scale = report["time_scale"].as_f64().unwrap();
    assert!(
        (0.8 - 1e-9..=1.0 / 0.75 + 1e-9).contains(&scale),
        "time scale {scale}"
    );

    // On the source's path (the report's root) the flat feet slide; carried
    // by the planted feet within each stride (the default) or everywhere,
    // the same restyle slides them less, and the report says how far the
    // feet moved the root (the coarse foot skating, which counts toes
    // swinging low, moves less). Only the default and the source's path
    // keep the distance the source covers.
    let (path_report, path_motion) = restyle(&["--root", "source"]);
    let (along_report, along_motion) = restyle(&[]);
    let (feet_report, feet_motion) = restyle(&["--root", "feet"]);
    assert_eq!(path_report["root"], "source");
    assert_eq!(along_report["root"], "feet-along-source");
    assert_eq!(feet_report["root"], "feet");
    assert_eq!(path_motion.frame_count(), feet_motion.frame_count());
    assert_eq!(path_motion.frame_count(), along_motion.frame_count());
    let rig = RigLayout::from_skeleton(path_motion.skeleton()).unwrap();
    let sliding = planted_foot_sliding(&path_motion, &rig);
    for (what, motion) in [("along", &along_motion), ("feet", &feet_motion)] {
        let carried = planted_foot_sliding(motion, &rig);
        eprintln!(
            "{what}: planted foot sliding {sliding} -> {carried}, foot skating {} -> {}",
            foot_skating(&path_motion, &rig),
            foot_skating(motion, &rig)
        );
        assert!(
            carried < 0.9 * sliding,
            "{what}: planted foot sliding {sliding} -> {carried}"
        );
    }
    assert_eq!(path_report["root_shift"]["max"], 0.0);
    for report in [&path_report, &along_report] {
        let ratio = report["distance_ratio"].as_f64().unwrap();
        assert!((ratio - 1.0).abs() < 0.03, "distance ratio {ratio}");
    }
    let ratio = feet_report["distance_ratio"].as_f64().unwrap();
    assert!((0.7..1.3).contains(&ratio), "distance ratio {ratio}");
    // Within a stride the feet move the root a few centimetres; everywhere,
    // further.
    let shift = |r: &serde_json::Value| r["root_shift"]["mean"].as_f64().unwrap();
    assert!(
        0.0 < shift(&along_report) && shift(&along_report) < shift(&feet_report),
        "root shift {} and {}",
        shift(&along_report),
        shift(&feet_report)
    );

    // The foot-contact cleanup says what it changed; without it, nothing.
    let (contacts_report, contacts_motion) = restyle(&["--foot-contacts"]);
    assert!(along_report["contacts"].is_null());
    let contacts = &contacts_report["contacts"];
    for side in 0..2 {
        assert!(
            contacts["frames_changed"][side].as_u64().unwrap() > 0,
            "{contacts}"
        );
    }
    let max_shift = contacts["max_shift"].as_f64().unwrap();
    let leg = rig.leg_length(contacts_motion.skeleton()) as f64;
    assert!(0.0 < max_shift && max_shift < 0.5 * leg, "{contacts}");
    assert!(
        planted_foot_sliding(&contacts_motion, &rig) < planted_foot_sliding(&along_motion, &rig),
        "{contacts}"
    );

    // The source's left-right asymmetry is kept by default; `--asymmetry
    // style` is the report's method. The bundled walk is straight, so
    // keeping its asymmetry changes little.
    let (style_report, style_motion) = restyle(&["--asymmetry", "style"]);
    assert_eq!(along_report["asymmetry"], "source");
    assert_eq!(style_report["asymmetry"], "style");
    // Averaged over two of the source's strides (about 1.1 s each), or over
    // the whole clip with `source-clip`.
    let window = along_report["asymmetry_window_s"].as_f64().unwrap();
    assert!((1.6..3.0).contains(&window), "window {window} s");
    let (clip_report, _) = restyle(&["--asymmetry", "source-clip"]);
    assert_eq!(clip_report["asymmetry"], "source-clip");
    assert!(clip_report["asymmetry_window_s"].is_null());
    assert!(style_report["asymmetry_window_s"].is_null());
    let change = mocap_core::metrics::mean_rotation_error_degrees(&along_motion, &style_motion)
        .expect("same frames and joints");
    eprintln!("keeping the straight walk's asymmetry moved it by {change} degrees");
    assert!(
        change < ASYMMETRY_CHANGE_MAX_DEG,
        "a straight walk moved by {change} degrees"
    );
    let out = apply(&["--asymmetry", "sideways"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("source"), "{}", stderr(&out));

    // A bad duration and a missing style clip are input errors (1).
    let out = apply(&["--fade-in", "soon"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("--fade-in"), "{}", stderr(&out));
    let out = style_apply(
        &source,
        path(&dir.path().join("nope.bvh")),
        &dir.path().join("x.bvh"),
        &[],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("nope.bvh"), "{}", stderr(&out));
    assert!(!dir.path().join("x.bvh").exists());
}

#[test]
fn unusable_inputs_are_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("out.bvh");
    // Frames `frames` of a bundled walk, written as `name`.
    let cut = |walk: &str, name: &str, frames: &str| {
        let clip = dir.path().join(name);
        let out = mocap(&[
            "convert",
            &sample(walk),
            path(&clip),
            "--frames",
            frames,
            "--quiet",
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        clip
    };
    // `style apply` fails, naming `file` and saying `says`, and writes nothing.
    let refused = |source: &str, style: &str, file: &str, says: &str| {
        let out = style_apply(source, style, &output, &[]);
        assert_eq!(out.status.code(), Some(1));
        assert!(
            stderr(&out).contains(file) && stderr(&out).contains(says),
            "{}",
            stderr(&out)
        );
        assert!(!output.exists());
    };
    // A style clip shorter than one patch.
    let short = cut("dataset-1_walk_proud_001.bvh", "short-style.bvh", "0..8");
    refused(
        &sample("dataset-1_walk_normal_001.bvh"),
        path(&short),
        "short-style.bvh",
        "too short",
    );
    // A one-frame source.
    let still = cut("dataset-1_walk_normal_001.bvh", "one-frame.bvh", "0..1");
    refused(
        path(&still),
        &sample("dataset-1_walk_proud_001.bvh"),
        "one-frame.bvh",
        "at least 2",
    );

    // A take of another rig than the shipped denoiser's, whose body parts
    // are not found: refused, naming the take, what is missing and --rig.
    let other_rig = dir.path().join("two-joints.bvh");
    std::fs::write(&other_rig, TWO_JOINTS_BVH).unwrap();
    let out = mocap(&["clean", "apply", path(&other_rig), "-o", path(&output)]);
    assert_eq!(out.status.code(), Some(1));
    let says = stderr(&out);
    for part in ["two-joints.bvh", "Bandai Namco", "--rig"] {
        assert!(says.contains(part), "no {part:?} in: {says}");
    }
    assert!(!output.exists());
}

/// A take of a rig of two joints (a hip and a knee): no body map finds it.
const TWO_JOINTS_BVH: &str = "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition \
    Yposition Zposition Zrotation Xrotation Yrotation\n  JOINT Knee\n  {\n    OFFSET 0 -40 0\n    \
    CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n    {\n      OFFSET 0 -40 0\n    }\n  \
    }\n}\nMOTION\nFrames: 3\nFrame Time: 0.0333333\n0 90 0 0 0 0 10 0 0\n0 90 0 0 0 0 12 0 0\n\
    0 90 0 0 0 0 14 0 0\n";

#[test]
fn clean_apply_cleans_a_take_of_another_rig_through_the_models_rig() {
    let Some(take) =
        mocap_testdata::shared("parser-cases/dme_example_crlf_leadingdot_frametime.bvh")
    else {
        eprintln!("../shared/data is absent: skipped");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("cleaned.bvh");
    let out = mocap(&["clean", "apply", path(&take), "-o", path(&output), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let method = report["method"].as_str().unwrap();
    assert!(method.contains("through the Bandai Namco rig"), "{method}");
    // The take's own skeleton and channels; the thumbs (no body part)
    // untouched;
    // the body cleaned.
    let (before, after) = (read_bvh(&take).unwrap(), read_bvh(&output).unwrap());
    assert_eq!(before.skeleton(), after.skeleton());
    assert_eq!(before.frame_count(), after.frame_count());
    let skeleton = before.skeleton();
    for name in ["LThumb", "RThumb"] {
        let j = skeleton.find(name).unwrap();
        for f in 0..before.frame_count() {
            assert_eq!(
                before.joint_values(f, j),
                after.joint_values(f, j),
                "{name}"
            );
        }
    }
    let knee = skeleton.find("LeftLeg").unwrap();
    let moved = (0..before.frame_count())
        .any(|f| before.joint_values(f, knee) != after.joint_values(f, knee));
    assert!(moved, "the knee was not cleaned");
}

/// The bundled walk's header announcing `frames` frames, and no frame
/// lines: a take of that length as far as its header says.
fn header_announcing(dir: &Path, name: &str, frames: usize) -> PathBuf {
    let text = std::fs::read_to_string(sample("dataset-1_walk_normal_001.bvh")).unwrap();
    let motion = text.find("MOTION").unwrap();
    let header = format!(
        "{}MOTION\nFrames: {frames}\nFrame Time: 0.0333333\n",
        &text[..motion]
    );
    let file = dir.join(name);
    std::fs::write(&file, header).unwrap();
    file
}

#[test]
fn style_apply_refuses_takes_too_long_before_reading_them() {
    // Restyling holds the whole take several times over: a source of ten
    // hours (1,080,000 frames at 30 fps, about a 1.3 GB file) would need
    // about 5.6 GB. It is refused from its header, with the file, its
    // length, the limit, the memory and how to cut it (reading it would
    // say the frames are missing).
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("out.bvh");
    let long = header_announcing(dir.path(), "ten-hours.bvh", 1_080_000);
    let out = style_apply(
        path(&long),
        &sample("dataset-1_walk_proud_001.bvh"),
        &output,
        &[],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let says = stderr(&out);
    for part in [
        "ten-hours.bvh",
        "style apply works on takes of up to 108000 frames (about 60 minutes at 30 fps)",
        "this one has 1080000 (600 minutes)",
        "5.6 GB",
        "mocap convert",
        "--frames 0..108000",
    ] {
        assert!(says.contains(part), "no {part:?} in: {says}");
    }
    assert!(!output.exists());
    // A style clip is an example: up to ten minutes.
    let long_style = header_announcing(dir.path(), "long-style.bvh", 20_000);
    let out = style_apply(
        &sample("dataset-1_walk_normal_001.bvh"),
        path(&long_style),
        &output,
        &[],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let says = stderr(&out);
    assert!(
        says.contains("long-style.bvh")
            && says.contains("style apply works on style clips of up to 18000 frames"),
        "{says}"
    );
    assert!(!output.exists());
}

#[test]
fn style_clips_and_sources_of_other_rigs_are_retargeted() {
    let (Some(mixamo), Some(cmu), Some(two_joints)) = (
        mocap_testdata::shared("parser-cases/bvhpython_test_freebvh.bvh"),
        mocap_testdata::shared("parser-cases/dme_example_crlf_leadingdot_frametime.bvh"),
        mocap_testdata::shared("parser-cases/bvhanim_test_simple.bvh"),
    ) else {
        eprintln!("../shared/data is absent: skipped");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (normal, proud) = (
        sample("dataset-1_walk_normal_001.bvh"),
        sample("dataset-1_walk_proud_001.bvh"),
    );
    // The proud walk played by a Mixamo rig (`mocap convert --retarget-to`).
    let proud_mixamo = dir.path().join("proud-mixamo.bvh");
    let out = mocap(&[
        "convert",
        &proud,
        "--retarget-to",
        path(&mixamo),
        path(&proud_mixamo),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let rig = read_bvh(&mixamo).unwrap();
    assert_eq!(read_bvh(&proud_mixamo).unwrap().skeleton(), rig.skeleton());

    // As a style clip: retargeted onto the source's rig, and said so.
    let output = dir.path().join("out.bvh");
    let apply = |source: &str, style: &str| style_apply(source, style, &output, &["--json"]);
    let out = apply(&normal, path(&proud_mixamo));
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let notes = report["retargeted"].as_array().unwrap();
    assert!(
        notes.len() == 1 && notes[0].as_str().unwrap().contains("proud-mixamo.bvh"),
        "{notes:?}"
    );
    let source = read_bvh(Path::new(&normal)).unwrap();
    let restyled = read_bvh(&output).unwrap();
    assert_eq!(
        restyled.skeleton().joints().len(),
        source.skeleton().joints().len()
    );
    // Same style as the clip on its own rig: the proud walk's slower stride.
    let scale = report["time_scale"].as_f64().unwrap();
    assert!(scale > 1.1, "time scale {scale}");

    // A source of a CMU-style rig: played by the style clip's rig, restyled,
    // and written on its own rig.
    let out = apply(path(&cmu), &proud);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        read_bvh(&output).unwrap().skeleton(),
        read_bvh(&cmu).unwrap().skeleton()
    );

    // A clip whose body parts cannot be found is refused, naming it.
    std::fs::remove_file(&output).unwrap();
    let out = apply(&normal, path(&two_joints));
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("bvhanim_test_simple.bvh") && stderr(&out).contains("body parts"),
        "{}",
        stderr(&out)
    );
    assert!(!output.exists());
}

#[test]
fn a_rig_file_given_with_rig_lets_info_search_clean_and_style_read_a_renamed_rig() {
    // The bundled walk with every joint renamed: no built-in rig table
    // knows the names, a rig file says which joint is which.
    let dir = tempfile::tempdir().unwrap();
    let renamed = dir.path().join("renamed.bvh");
    let walk = mocap_testdata::sample_walk();
    std::fs::write(&renamed, mocap_testdata::renamed_bandai_bvh(&walk)).unwrap();
    let rig = dir.path().join("studio.toml");
    std::fs::write(&rig, mocap_testdata::RENAMED_BANDAI_RIG).unwrap();
    let (renamed, rig, walk) = (path(&renamed), path(&rig), walk.display().to_string());
    let proud = sample("dataset-1_walk_proud_001.bvh");

    // Without the file: what needs body parts says how to give them.
    let out = mocap(&["info", renamed]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("--rig FILE"));
    let restyled_renamed = dir.path().join("restyled-renamed.bvh");
    let apply = |rig: Option<&str>, source: &str, out: &Path| {
        let mut args = Vec::from_iter(rig.map(|r| ["--rig", r]).into_iter().flatten());
        args.extend(["style", "apply", source, "--style", &proud, "-o", path(out)]);
        mocap(&args)
    };
    let out = apply(None, renamed, &restyled_renamed);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("--rig FILE"), "{}", stderr(&out));
    assert!(!restyled_renamed.exists());

    // With it: the rig is found, and search and style give what they give
    // on the original names.
    let out = mocap(&["--rig", rig, "info", "--json", renamed]);
    assert!(out.status.success(), "{}", stderr(&out));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info[0]["rig"], "Studio (German names)");
    assert_eq!(info[0]["body_parts"].as_array().unwrap().len(), 21);

    let index = mocap_testdata::repo_root().join("models/search-bandai-content.idx");
    let query = |args: &[&str]| -> serde_json::Value {
        let out = mocap(args);
        assert!(out.status.success(), "{}", stderr(&out));
        let mut v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v.as_object_mut().unwrap().remove("query");
        v
    };
    let index = path(&index);
    let plain = query(&["search", "query", &walk, "--index", index, "--json"]);
    let with_rig = query(&[
        "--rig", rig, "search", "query", renamed, "--index", index, "--json",
    ]);
    assert_eq!(plain, with_rig);

    let out = apply(Some(rig), renamed, &restyled_renamed);
    assert!(out.status.success(), "{}", stderr(&out));
    let restyled = dir.path().join("restyled.bvh");
    let out = apply(None, &walk, &restyled);
    assert!(out.status.success(), "{}", stderr(&out));
    let (a, b) = (
        read_bvh(&restyled).unwrap(),
        read_bvh(&restyled_renamed).unwrap(),
    );
    assert_eq!(a.frame_count(), b.frame_count());
    assert_eq!(b.skeleton().joint(1).name, "Becken");
    let (pa, pb) = (
        mocap_core::forward_kinematics(&a),
        mocap_core::forward_kinematics(&b),
    );
    for f in 0..a.frame_count() {
        for j in 0..a.skeleton().joint_count() {
            let d = pa.position(f, j).distance(pb.position(f, j));
            assert!(d < 0.01, "frame {f}, joint {j}: {d} cm apart");
        }
    }

    // The denoiser reads joints in its own rig's places: the renamed rig is
    // cleaned through the model's own, as the original is.
    let cleaned_renamed = dir.path().join("cleaned-renamed.bvh");
    let out = mocap(&[
        "--rig",
        rig,
        "clean",
        "apply",
        renamed,
        "-o",
        path(&cleaned_renamed),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("through the Bandai Namco rig"));
    let cleaned = dir.path().join("cleaned.bvh");
    let out = mocap(&["clean", "apply", &walk, "-o", path(&cleaned)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(rotation_change_deg(&cleaned, &cleaned_renamed) < 1e-3);

    // A rig file with a mistake stops the command before it starts.
    let typo = dir.path().join("typo.toml");
    std::fs::write(&typo, "[parts]\npelvis = \"Becken\"\nhead = Kopf\n").unwrap();
    let out = mocap(&["--rig", path(&typo), "info", renamed]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("typo.toml") && stderr(&out).contains(":3:"),
        "{}",
        stderr(&out)
    );
}

/// `mocap clean eval DIR --no-default-model --spike-lengths none` then
/// `extra`: the filters alone, quick on the bundled takes; must succeed.
fn clean_eval_filters(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "clean",
        "eval",
        path(dir),
        "--no-default-model",
        "--spike-lengths",
        "none",
    ];
    args.extend_from_slice(extra);
    let out = mocap(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    out
}

#[test]
fn clean_eval_says_what_its_figures_leave_out() {
    // One take: no validation takes to tune the filters on, and no other
    // take to paste spikes from; the report says both instead of quietly
    // showing fewer rows and spike-free spike conditions.
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(mocap_testdata::sample_walk(), dir.path().join("walk.bvh")).unwrap();
    let out = clean_eval_filters(dir.path(), &["--json"]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let notes: Vec<&str> = report["notes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    assert_eq!(notes.len(), 2, "{notes:?}");
    assert!(notes[0].contains("filters are left out"), "{notes:?}");
    assert!(notes[1].contains("no spikes"), "{notes:?}");
    // Tuned on the evaluated takes themselves: said too.
    std::fs::copy(
        mocap_testdata::sample("dataset-1_walk_proud_001.bvh"),
        dir.path().join("proud.bvh"),
    )
    .unwrap();
    let out = clean_eval_filters(dir.path(), &["--all-takes"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("tuned on the first 2 of the evaluated takes themselves"),
        "{text}"
    );
}

#[test]
fn clean_eval_names_a_take_the_model_cannot_clean_and_skips_short_takes_in_accelerations() {
    let dir = tempfile::tempdir().unwrap();
    let walk = dir.path().join("walk.bvh");
    std::fs::copy(mocap_testdata::sample_walk(), &walk).unwrap();
    // A take of 2 frames: it has rotation and position errors but no
    // acceleration, which must not turn the whole column into null.
    let short = dir.path().join("short.bvh");
    let out = mocap(&["convert", path(&walk), path(&short), "--frames", "0..2"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = clean_eval_filters(dir.path(), &["--all-takes", "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let entries = report["entries"].as_array().unwrap();
    assert!(!entries.is_empty());
    for e in entries {
        let a = e["acceleration_error"].as_f64();
        assert!(a.is_some_and(|a| a.is_finite() && a >= 0.0), "{e}");
    }
    let notes = report["notes"].to_string();
    assert!(notes.contains("under 3 frames (short)"), "{notes}");

    // A take of a rig whose body parts are not found, with the shipped
    // model asked for: refused before any work, naming the take and the
    // way out.
    std::fs::remove_file(&short).unwrap();
    let other = dir.path().join("other-rig.bvh");
    std::fs::write(&other, TWO_JOINTS_BVH).unwrap();
    let out = mocap(&["clean", "eval", path(dir.path()), "--all-takes"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("other-rig.bvh"), "{err}");
    assert!(err.contains("--no-default-model"), "{err}");
}

#[test]
fn style_apply_says_when_the_source_is_unlike_the_walks_the_model_knows() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("out.bvh");
    let proud = sample("dataset-1_walk_proud_001.bvh");
    let apply = |source: &str| style_apply(source, &proud, &out_path, &[]);
    // A walk: reproduced closely, no note.
    let walk = mocap_testdata::sample_walk().display().to_string();
    let out = apply(&walk);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        !stderr(&out).contains("reproduces this source poorly"),
        "{}",
        stderr(&out)
    );
    let Some(bow) = mocap_testdata::shared("bandai/dataset-1/dataset-1_bow_normal_001.bvh") else {
        return;
    };
    // A bow: the model cannot reproduce it, and the user is told so (the
    // output walks in place instead of bowing).
    let out = apply(&bow.display().to_string());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("reproduces this source poorly"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn clean_reads_an_amc_motion_with_the_asf_beside_it() {
    let Some(amc) = mocap_testdata::shared("hdm05-sample/HDM_bd_depositFloorR_001_120.amc") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("clean.bvh");
    let out = mocap(&[
        "clean",
        "apply",
        path(&amc),
        "-o",
        path(&out_path),
        "--filter",
        "butterworth-gcv:2",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let cleaned = read_bvh(&out_path).unwrap();
    let original = mocap_core::io::read_motion(&amc).unwrap();
    assert_eq!(cleaned.frame_count(), original.frame_count());
    // The same joints and channels (a BVH file has no joint limits).
    let names = |m: &mocap_core::Motion| -> Vec<String> {
        m.skeleton()
            .joints()
            .iter()
            .map(|j| j.name.clone())
            .collect()
    };
    assert_eq!(names(&cleaned), names(&original));
    assert_eq!(
        cleaned.skeleton().channel_count(),
        original.skeleton().channel_count()
    );
}

#[test]
fn style_apply_reads_an_amc_source_as_its_converted_bvh() {
    let Some(dir) = mocap_testdata::shared("hdm05-sample") else {
        return;
    };
    let (asf, amc) = (
        dir.join("HDM_bd.asf"),
        dir.join("HDM_bd_depositFloorR_001_120.amc"),
    );
    let tmp = tempfile::tempdir().unwrap();
    let bvh = tmp.path().join("hdm.bvh");
    let out = mocap(&["convert", path(&asf), path(&amc), path(&bvh)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let proud = sample("dataset-1_walk_proud_001.bvh");
    let restyle = |source: &Path, name: &str| {
        let out_path = tmp.path().join(name);
        let out = style_apply(path(source), &proud, &out_path, &[]);
        assert!(out.status.success(), "{}", stderr(&out));
        read_bvh(&out_path).unwrap()
    };
    let (from_amc, from_bvh) = (restyle(&amc, "a.bvh"), restyle(&bvh, "b.bvh"));
    assert_eq!(from_amc.frame_count(), from_bvh.frame_count());
    let (pa, pb) = (
        mocap_core::forward_kinematics(&from_amc),
        mocap_core::forward_kinematics(&from_bvh),
    );
    for f in 0..from_amc.frame_count() {
        for j in 0..from_amc.skeleton().joint_count() {
            let d = pa.position(f, j).distance(pb.position(f, j));
            assert!(d < 0.01, "frame {f}, joint {j}: {d} apart");
        }
    }
}

#[test]
fn style_eval_names_its_judges_and_settings_and_can_judge_style_with_the_conv_net() {
    let Some(data) = mocap_testdata::shared_data() else {
        return;
    };
    // Two dataset-2 walking styles, three takes each: the last take of each
    // is held out and restyled with the other's.
    let dir = tempfile::tempdir().unwrap();
    for style in ["active", "elderly"] {
        for take in ["001", "004", "007"] {
            let name = format!("dataset-2_walk_{style}_{take}.bvh");
            std::fs::copy(
                data.join("bandai/dataset-2").join(&name),
                dir.path().join(&name),
            )
            .unwrap();
        }
    }
    let eval = |judge: &str| {
        mocap(&[
            "style",
            "eval",
            path(dir.path()),
            "--methods",
            "elastic-patches",
            "--style-judge",
            judge,
        ])
    };
    let out = eval("conv-net");
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("style: conv net") && text.contains("content: forest"),
        "{text}"
    );
    // The report says how the outputs were restyled.
    assert!(
        text.contains("root feet-along-source, asymmetry source"),
        "{text}"
    );
    // Both real held-out walks are judged right, and so is the style clip
    // row (each real style clip is one of them).
    assert!(
        text.contains("| style clip itself | 2 | 100.0% |"),
        "{text}"
    );
    // Encoded and decoded by the shipped model, which learnt these takes'
    // styles (dataset-2's other takes), the style clips keep their style.
    assert!(
        text.contains("| style clip through the autoencoder | 2 | 100.0% |")
            && text.contains("misreads: as captured: none; through the autoencoder: none"),
        "{text}"
    );
    let out = eval("tree");
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("expected forest, conv-net or both"),
        "{}",
        stderr(&out)
    );
}

/// `style train` writes a model and its report; the loss on the feet is
/// added to the reconstruction error (same seed, same windows: a larger
/// training loss), and a negative weight is refused.
#[test]
fn style_train_adds_the_loss_on_the_feet_when_asked() {
    let Some(data) = mocap_testdata::shared_data() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let takes = dir.path().join("walks");
    std::fs::create_dir(&takes).unwrap();
    for name in [
        "dataset-2_walk_active_001.bvh",
        "dataset-2_walk_active_004.bvh",
        "dataset-2_walk_elderly_001.bvh",
        "dataset-2_walk_elderly_004.bvh",
    ] {
        std::fs::copy(data.join("bandai/dataset-2").join(name), takes.join(name)).unwrap();
    }
    let train = |weight: &str| {
        let model = dir.path().join(format!("style-{weight}.safetensors"));
        let out = mocap(&[
            "style",
            "train",
            path(&takes),
            "-o",
            path(&model),
            "--epochs",
            "1",
            "--steps",
            "3",
            "--window",
            "64",
            "--no-hold-out",
            &format!("--foot-loss={weight}"),
            "--json",
        ]);
        (out, model)
    };
    let loss = |weight: &str| {
        let (out, model) = train(weight);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(model.is_file());
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        report["history"]["epochs"][0]["train_loss"]
            .as_f64()
            .unwrap()
    };
    let (plain, feet) = (loss("0"), loss("300"));
    assert!(plain.is_finite() && feet > plain, "{plain} -> {feet}");
    let (out, _) = train("-1");
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("foot loss"), "{}", stderr(&out));
}

#[test]
fn a_damaged_model_file_is_refused_before_anything_is_written() {
    // One exponent bit flipped in the last weight of each shipped model: the
    // style model then wrote NaN values, the denoiser a take moved by tens of
    // degrees, both with exit 0.
    let dir = tempfile::tempdir().unwrap();
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let damaged = |name: &str| -> PathBuf {
        let mut bytes = std::fs::read(models.join(name)).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 0x40;
        let copy = dir.path().join(name);
        std::fs::write(&copy, bytes).unwrap();
        copy
    };
    let walk = sample("dataset-1_walk_normal_001.bvh");
    let proud = sample("dataset-1_walk_proud_001.bvh");
    let output = dir.path().join("out.bvh");

    let style_model = damaged("style-default.safetensors");
    let out = style_apply(&walk, &proud, &output, &["--model", path(&style_model)]);
    let message = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{message}");
    assert!(
        message.contains("style-default.safetensors: the file is damaged"),
        "{message}"
    );
    assert!(!output.exists());

    let clean_model = damaged("clean-default.safetensors");
    let out = clean_walk_with(&clean_model, dir.path());
    let message = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{message}");
    assert!(
        message.contains("clean-default.safetensors: the file is damaged"),
        "{message}"
    );
    assert!(!dir.path().join("clean.bvh").exists());
}

#[test]
fn clean_eval_fused_measures_takes_as_the_capture_stage_makes_them() {
    // The bundled walks watched by simulated sensors, fused and fitted: the
    // filters are tuned on that noise and measured against the truth on the
    // fused take's skeleton.
    let samples = mocap_testdata::repo_root().join("samples");
    let out = clean_eval_filters(&samples, &["--all-takes", "--fused", "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let fused: Vec<&serde_json::Value> = report["entries"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["condition"] == "fused")
        .collect();
    assert!(fused.len() > 2, "{fused:?}");
    let noisy = fused.iter().find(|e| e["method"] == "noisy input").unwrap();
    let cm = noisy["position_error"].as_f64().unwrap();
    assert!(cm > 0.5 && cm < 10.0, "{noisy}");
    let tuned = report["tuned_filters"].as_array().unwrap();
    assert!(tuned.iter().any(|t| t["condition"] == "fused"), "{tuned:?}");
}
