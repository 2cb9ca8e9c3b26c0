//! Speed of motion search on a real library: index build time, query
//! latency, how query time grows with the library (clips replicated 100x
//! and 1000x), and our forest against scikit-learn on the same feature
//! matrix (this program writes the matrix; `bench/search/sklearn_compare.py`
//! reads it).
//!
//! ```text
//! cargo run --release -p mocap-search --example bench -- \
//!     --labels-from-name bandai-content --features-csv /tmp/features.csv \
//!     ../shared/data/bandai/dataset-2
//! ```
//!
//! Prints Markdown. The split for the scikit-learn comparison: every fifth
//! clip in path order is a test clip (paths are sorted by class, so every
//! class is in both parts).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use mocap_search::{
    argmax, build_index, load_clips, load_features, motion_files, Forest, Index, IndexConfig,
    IntervalLayout, LabelRule, LibraryClip, NamePattern, Ranking, Samples, VALUE_COUNT,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut dirs = Vec::new();
    let mut pattern = String::from("bandai-content");
    let mut csv: Option<PathBuf> = None;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--labels-from-name" => pattern = args.next().ok_or("pattern needed")?,
            "--features-csv" => csv = Some(PathBuf::from(args.next().ok_or("path needed")?)),
            dir => dirs.push(PathBuf::from(dir)),
        }
    }
    let threads = rayon::current_num_threads();
    println!(
        "Threads: {threads}. Library: {}.\n",
        dirs.iter()
            .map(|d| d.display().to_string())
            .collect::<Vec<_>>()
            .join(" + ")
    );

    // Index build: reading and features, then training.
    let rule = LabelRule::FromName(NamePattern::parse(&pattern)?);
    let t = Instant::now();
    let files = motion_files(&dirs)?;
    let clips = load_clips(&files, &rule, false)?;
    let read_s = t.elapsed().as_secs_f64();
    let frames: usize = clips.iter().map(|c| c.frame_count()).sum();
    let t = Instant::now();
    let config = IndexConfig::default();
    let index = build_index(&clips, &pattern, &config, false)?;
    let train_s = t.elapsed().as_secs_f64();
    let dir = std::env::temp_dir().join(format!("mocap-search-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("library.idx");
    let t = Instant::now();
    index.save(&path)?;
    let save_s = t.elapsed().as_secs_f64();
    let size = std::fs::metadata(&path)?.len();
    let t = Instant::now();
    let index = Index::load(&path)?;
    let load_s = t.elapsed().as_secs_f64();
    std::fs::remove_dir_all(&dir)?;
    println!(
        "## Index build ({} clips, {frames} frames, {} classes)\n",
        clips.len(),
        index.classes.len()
    );
    println!("| step | seconds |\n| --- | ---: |");
    println!(
        "| read {} files, FK, per-frame features | {read_s:.2} |",
        files.len()
    );
    println!("| resample, interval means, train 100 trees, library histograms | {train_s:.2} |");
    println!("| save index ({:.1} MB) | {save_s:.3} |", size as f64 / 1e6);
    println!("| load and check index | {load_s:.3} |\n");

    // Query latency on 50 library files.
    let queries: Vec<&Path> = files
        .iter()
        .step_by((files.len() / 50).max(1))
        .map(|p| p.as_path())
        .take(50)
        .collect();
    let mut read_ms = Vec::new();
    let mut query_ms = Vec::new();
    for q in &queries {
        let t = Instant::now();
        let (features, _) = load_features(q)?;
        read_ms.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        let report = index.query("q", &features, 10, Ranking::Histogram);
        query_ms.push(t.elapsed().as_secs_f64() * 1e3);
        std::hint::black_box(report);
    }
    println!(
        "## Query latency ({} queries, top 10, histogram ranking)\n",
        queries.len()
    );
    println!("| step | median ms | mean ms |\n| --- | ---: | ---: |");
    println!(
        "| read BVH, FK, features | {:.2} | {:.2} |",
        median(&mut read_ms),
        mean(&read_ms)
    );
    println!(
        "| resample, forest, rank library | {:.3} | {:.3} |\n",
        median(&mut query_ms),
        mean(&query_ms)
    );

    // Scaling: the library replicated. Only the histograms take part in
    // histogram ranking, so the copies carry only those (the resampled
    // features and leaves of 1000 copies would not fit in memory).
    println!("## Query time against library size (histogram ranking, top 10)\n");
    println!("| library clips | median ms per query | mean ms |\n| ---: | ---: | ---: |");
    let (features, _) = load_features(queries[0])?;
    for copies in [1usize, 10, 100, 1000] {
        let mut big = index.clone();
        big.clips = (0..copies)
            .flat_map(|_| index.clips.iter())
            .map(|c| LibraryClip {
                resampled: Vec::new(),
                leaves: Vec::new(),
                ..c.clone()
            })
            .collect();
        let mut ms = Vec::new();
        let runs = if copies >= 100 { 10 } else { 30 };
        for _ in 0..runs {
            let t = Instant::now();
            std::hint::black_box(big.query("q", &features, 10, Ranking::Histogram));
            ms.push(t.elapsed().as_secs_f64() * 1e3);
        }
        println!(
            "| {} | {:.2} | {:.2} |",
            big.clips.len(),
            median(&mut ms),
            mean(&ms)
        );
    }

    // Our forest on a fixed split, and the matrix for scikit-learn.
    let layout = IntervalLayout::all(config.frames, VALUE_COUNT);
    let labels: Vec<u32> = clips
        .iter()
        .map(|c| index.classes.binary_search(&c.label).unwrap() as u32)
        .collect();
    let rows: Vec<Vec<f32>> = clips
        .iter()
        .map(|c| layout.interval_means(&c.features.resample(config.frames)))
        .collect();
    let is_test = |k: usize| k % 5 == 4;
    let train: Vec<usize> = (0..clips.len()).filter(|&k| !is_test(k)).collect();
    let test: Vec<usize> = (0..clips.len()).filter(|&k| is_test(k)).collect();
    let train_rows: Vec<f32> = train
        .iter()
        .flat_map(|&k| rows[k].iter().copied())
        .collect();
    let train_labels: Vec<u32> = train.iter().map(|&k| labels[k]).collect();
    let samples = Samples::new(
        &train_rows,
        layout.dim(),
        &train_labels,
        index.classes.len(),
    )?;
    let t = Instant::now();
    let forest = Forest::train(&samples, &config.forest, &|| {});
    let fit_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let predicted: Vec<usize> = test
        .iter()
        .map(|&k| argmax(&forest.predict(&rows[k])))
        .collect();
    let predict_s = t.elapsed().as_secs_f64();
    let right = test
        .iter()
        .zip(&predicted)
        .filter(|(&k, &p)| labels[k] as usize == p)
        .count();
    println!(
        "\n## Forest on a fixed split ({} train, {} test clips, {} features)\n",
        train.len(),
        test.len(),
        layout.dim()
    );
    println!("| implementation | train s | predict s | accuracy |\n| --- | ---: | ---: | ---: |");
    println!(
        "| mocap-search (100 trees, 64 candidates, entropy) | {fit_s:.3} | {predict_s:.4} | {:.4} |",
        right as f64 / test.len() as f64
    );
    if let Some(csv) = csv {
        let mut out = std::io::BufWriter::new(std::fs::File::create(&csv)?);
        for (k, row) in rows.iter().enumerate() {
            write!(
                out,
                "{},{}",
                labels[k],
                if is_test(k) { "test" } else { "train" }
            )?;
            for v in row {
                write!(out, ",{v}")?;
            }
            writeln!(out)?;
        }
        eprintln!("feature matrix written to {}", csv.display());
    }
    Ok(())
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len().max(1) as f64
}
