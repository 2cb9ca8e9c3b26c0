//! Motion search on real data: index files, queries, long takes
//! and a small evaluation on the Bandai Namco clips; the HDM05 ASF/AMC clip.
//!
//! The data is found at `<workspace>/../shared/data`, or where
//! `MOCAP_SHARED_DATA` points; without it each test prints a note and
//! returns.

use mocap_testdata::shared_data;
use std::path::{Path, PathBuf};

use mocap_search::{
    build_index, evaluate, load_clips, motion_files, search_take, EvalConfig, FeatureSequence,
    Index, IndexConfig, LabelRule, NamePattern, Ranking, SearchError, SplitRule, TakeSearchConfig,
    VALUE_COUNT,
};

/// Every `step`-th dataset-1 clip of the given contents.
fn bandai_clips(data: &Path, contents: &[&str], step: usize) -> Vec<PathBuf> {
    let files = motion_files(&[data.join("bandai/dataset-1")]).unwrap();
    files
        .into_iter()
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            contents
                .iter()
                .any(|c| name.starts_with(&format!("dataset-1_{c}_")))
        })
        .step_by(step)
        .collect()
}

fn content_rule() -> LabelRule {
    LabelRule::FromName(NamePattern::parse("bandai-content").unwrap())
}

fn small_config(trees: usize) -> IndexConfig {
    let mut config = IndexConfig::default();
    config.forest.trees = trees;
    config
}

#[test]
fn index_round_trip_and_clear_errors_for_bad_files() {
    let Some(data) = shared_data() else { return };
    let files = bandai_clips(&data, &["walk", "bow", "run"], 3);
    let clips = load_clips(&files, &content_rule(), false).unwrap();
    let index = build_index(&clips, "bandai-content", &small_config(5), false).unwrap();
    assert_eq!(index.classes, vec!["bow", "run", "walk"]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("library.idx");
    index.save(&path).unwrap();
    let loaded = Index::load(&path).unwrap();
    assert_eq!(loaded.classes, index.classes);
    // Clip paths come back absolute (stored relative to the index's
    // folder), naming the same files; everything else is unchanged.
    for (l, c) in loaded.clips.iter().zip(&index.clips) {
        assert!(Path::new(&l.path).is_absolute(), "{}", l.path);
        assert_eq!(
            std::fs::canonicalize(&l.path).unwrap(),
            std::fs::canonicalize(&c.path).unwrap()
        );
        let mut same = l.clone();
        same.path = c.path.clone();
        assert_eq!(&same, c);
    }
    assert_eq!(loaded.clips.len(), index.clips.len());
    let bytes = std::fs::read(&path).unwrap();
    let stored = Index::from_bytes(&bytes, &path).unwrap();
    assert!(
        stored
            .clips
            .iter()
            .all(|c| Path::new(&c.path).is_relative()),
        "{:?}",
        stored.clips[0].path
    );
    assert_eq!(loaded.forest.trees(), index.forest.trees());

    let bytes = std::fs::read(&path).unwrap();
    let error = |bytes: &[u8]| Index::from_bytes(bytes, &path).unwrap_err();
    // A flipped byte in the data: checksum.
    let mut damaged = bytes.clone();
    let last = damaged.len() - 3;
    damaged[last] ^= 0x40;
    let e = error(&damaged);
    assert!(matches!(e, SearchError::BadIndex { .. }), "{e}");
    assert!(e.to_string().contains("checksum"), "{e}");
    // Cut short.
    let e = error(&bytes[..bytes.len() / 2]);
    assert!(e.to_string().contains("truncated"), "{e}");
    // Another format version or feature version: stale, rebuild.
    let mut old = bytes.clone();
    old[8] = old[8].wrapping_add(1);
    let e = error(&old);
    assert!(matches!(e, SearchError::StaleIndex { .. }), "{e}");
    assert!(e.to_string().contains("rebuild"), "{e}");
    let mut old = bytes.clone();
    old[12] = old[12].wrapping_add(1);
    assert!(matches!(error(&old), SearchError::StaleIndex { .. }));
    // Not an index at all.
    let e = error(b"HIERARCHY\nROOT Hips\n");
    assert!(e.to_string().contains("not a mocap search index"), "{e}");
    // A missing file names the path.
    let e = Index::load(&dir.path().join("missing.idx")).unwrap_err();
    assert!(e.to_string().contains("missing.idx"), "{e}");
}

#[test]
fn a_query_finds_its_class_and_long_takes_find_the_clip() {
    let Some(data) = shared_data() else { return };
    let files = bandai_clips(&data, &["walk-left", "bow", "run", "walk-back"], 1);
    let clips = load_clips(&files, &content_rule(), false).unwrap();
    // Hold out one clip of each class; index the rest.
    let mut held_out = Vec::new();
    let mut library = Vec::new();
    for clip in clips {
        if !held_out
            .iter()
            .any(|h: &mocap_search::Clip| h.label == clip.label)
        {
            held_out.push(clip);
        } else {
            library.push(clip);
        }
    }
    let index = build_index(&library, "bandai-content", &small_config(30), false).unwrap();
    let mut right = 0;
    for query in &held_out {
        let report = index.query("q", &query.features, 5, Ranking::Histogram);
        assert_eq!(report.matches.len(), 5);
        assert!(report
            .matches
            .windows(2)
            .all(|w| w[0].distance <= w[1].distance));
        if report.predicted == query.label {
            right += 1;
        }
    }
    assert!(right >= 3, "{right} of 4 held-out clips classified right");

    // A long take: the held-out clips end to end. Searching with a library
    // clip of each class must put the best range on the held-out clip of
    // that class: its centre inside that clip (the clips begin and end
    // standing, so the exact boundaries are ambiguous).
    let mut values = Vec::new();
    let mut ranges = Vec::new();
    for clip in &held_out {
        let start = values.len() / VALUE_COUNT;
        values.extend_from_slice(&clip.features.values);
        ranges.push((clip.label.clone(), start, values.len() / VALUE_COUNT));
    }
    let take = FeatureSequence {
        dim: VALUE_COUNT,
        values,
    };
    let mut found = 0;
    for (label, start, end) in &ranges {
        let query = library.iter().find(|c| &c.label == label).unwrap();
        let config = TakeSearchConfig {
            top: 1,
            ..TakeSearchConfig::default()
        };
        let best = &search_take(&index, &query.features, 30.0, &take, 30.0, &config).unwrap()[0];
        let centre = (best.start_frame + best.end_frame) / 2;
        if (*start..*end).contains(&centre) {
            found += 1;
        }
    }
    assert!(found >= 3, "{found} of 4 clips located in the take");
}

#[test]
fn evaluation_end_to_end_on_dataset_1_walks() {
    let Some(data) = shared_data() else { return };
    let files = bandai_clips(
        &data,
        &["walk", "walk-back", "walk-left", "walk-right", "run"],
        1,
    );
    let clips = load_clips(&files, &content_rule(), false).unwrap();
    let config = EvalConfig {
        index: small_config(20),
        split: SplitRule::Folds { k: 3 },
        unseen_classes: false,
        takes: false,
        ..EvalConfig::default()
    };
    let report = evaluate(&clips, "dataset-1 walks", "bandai-content", &config).unwrap();
    assert_eq!(report.classes.len(), 5);
    assert_eq!(report.methods.len(), 4);
    let forest = &report.methods[0];
    assert_eq!(forest.confusion.total() as usize, clips.len());
    // Five classes: chance is 0.2. Walking directions differ in how the
    // pelvis moves, which the features carry.
    assert!(forest.average.f_measure > 0.7, "{}", report.to_markdown());
    let markdown = report.to_markdown();
    assert!(markdown.contains("| walk-left |"));
    let json = serde_json::to_string(&report).unwrap();
    assert!(json.contains("\"method\":\"forest\""));
}

#[test]
fn hdm05_amc_clip_with_its_asf_skeleton() {
    let Some(data) = shared_data() else { return };
    let amc = data.join("hdm05-sample/HDM_bd_depositFloorR_001_120.amc");
    let rule = LabelRule::FromName(NamePattern::parse("hdm05").unwrap());
    let clips = load_clips(&[amc], &rule, false).unwrap();
    assert_eq!(clips[0].label, "depositFloorR");
    assert_eq!(clips[0].performer.as_deref(), Some("bd"));
    assert!((clips[0].fps - 120.0).abs() < 1e-6);
    // Depositing something on the floor: the pelvis goes down at some point.
    let f = &clips[0].features;
    let heights: Vec<f32> = (0..f.frame_count()).map(|k| f.frame(k)[27]).collect();
    let (low, high) = heights
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
    assert!(
        high > 0.4 && low < high - 0.1,
        "pelvis height from {low} to {high}"
    );
}

#[test]
fn unlabelled_files_and_missing_paths_are_clear_errors() {
    let Some(data) = shared_data() else { return };
    let amc = data.join("hdm05-sample/HDM_bd_depositFloorR_001_120.amc");
    let e = load_clips(&[amc], &content_rule(), false).unwrap_err();
    assert!(
        e.to_string().contains("does not match the label pattern"),
        "{e}"
    );
    let e = motion_files(&[data.join("no-such-folder")]).unwrap_err();
    assert!(e.to_string().contains("no-such-folder"), "{e}");
}
