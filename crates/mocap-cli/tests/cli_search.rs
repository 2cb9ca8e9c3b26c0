//! `mocap search` end to end on a small real library.

use std::path::PathBuf;

mod common;
use common::mocap;

fn bandai() -> Option<PathBuf> {
    mocap_testdata::shared("bandai/dataset-2")
}

#[test]
fn index_then_query_finds_the_category() {
    let Some(data) = bandai() else { return };
    // Four takes each of three contents; the query is a fifth walk, not indexed.
    let mut library = Vec::new();
    for content in ["walk", "run", "raise-up-both-hands"] {
        for id in ["001", "004", "007", "010"] {
            library.push(data.join(format!("dataset-2_{content}_normal_{id}.bvh")));
        }
    }
    let query = data.join("dataset-2_walk_normal_013.bvh");
    let dir = tempfile::tempdir().unwrap();
    let index = dir.path().join("library.idx");
    let mut args: Vec<String> = vec!["search".into(), "index".into()];
    args.extend(library.iter().map(|p| p.display().to_string()));
    args.extend(
        [
            "--labels-from-name",
            "bandai-content",
            "--trees",
            "20",
            "-o",
            index.to_str().unwrap(),
        ]
        .map(String::from),
    );
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = mocap(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let out = mocap(&[
        "search",
        "query",
        query.to_str().unwrap(),
        "--index",
        index.to_str().unwrap(),
        "--top",
        "3",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["predicted"], "walk");
    assert_eq!(report["matches"].as_array().unwrap().len(), 3);
    assert_eq!(report["matches"][0]["label"], "walk");

    // A corrupted index is refused with a clear message.
    let mut bytes = std::fs::read(&index).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0xff;
    std::fs::write(&index, bytes).unwrap();
    let out = mocap(&[
        "search",
        "query",
        query.to_str().unwrap(),
        "--index",
        index.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(message.contains("library.idx"), "{message}");
}

#[test]
fn eval_prints_json_writes_markdown_and_draws_a_confusion_matrix_per_method() {
    let Some(data) = bandai() else { return };
    let dir = tempfile::tempdir().unwrap();
    let mut args: Vec<String> = vec!["search".into(), "eval".into()];
    for content in ["walk", "run", "raise-up-both-hands"] {
        for id in ["001", "004", "007", "010"] {
            args.push(
                data.join(format!("dataset-2_{content}_normal_{id}.bvh"))
                    .display()
                    .to_string(),
            );
        }
    }
    let plots = dir.path().join("plots");
    let markdown = dir.path().join("report.md");
    args.extend(
        [
            "--markdown",
            markdown.to_str().unwrap(),
            "--labels-from-name",
            "bandai-content",
            "--trees",
            "5",
            "--folds",
            "2",
            "--no-unseen",
            "--no-takes",
            "--json",
            "--quiet",
            "--plots",
            plots.to_str().unwrap(),
        ]
        .map(String::from),
    );
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = mocap(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let methods = report["methods"].as_array().unwrap();
    assert!(methods.len() >= 2, "forest and baselines: {methods:?}");
    let drawn = std::fs::read_dir(&plots)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with("confusion-")
        })
        .count();
    assert_eq!(drawn, 2 * methods.len(), "a PNG and an SVG per method");
    // --json prints JSON; --markdown FILE writes the tables as well.
    let tables = std::fs::read_to_string(&markdown).unwrap();
    assert!(tables.contains("| forest |"), "{tables}");
}

#[test]
fn a_query_on_an_index_moved_without_its_clips_says_so() {
    // The shipped index keeps its clips' paths relative to `models/`; a
    // copy elsewhere answers with paths that lead nowhere, and says so.
    let dir = tempfile::tempdir().unwrap();
    let moved = dir.path().join("x/y/library.idx");
    std::fs::create_dir_all(moved.parent().unwrap()).unwrap();
    let repo = mocap_testdata::repo_root();
    std::fs::copy(repo.join("models/search-bandai-content.idx"), &moved).unwrap();
    let sample = mocap_testdata::sample_walk();
    let out = mocap(&[
        "search",
        "query",
        sample.to_str().unwrap(),
        "--index",
        moved.to_str().unwrap(),
        "--top",
        "3",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("3 of the 3 clips listed are not where"),
        "{stderr}"
    );
}
