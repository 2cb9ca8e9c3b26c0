//! Stage 4: what is the actor doing? The chain's take is classified and the most
//! similar clips of a small bundled library are listed.
//!
//! The library index (`models/search-bandai-content.idx`) was built with
//! `mocap search index` on Bandai Namco dataset-2 with its content labels
//! (walk, run, wave...; see `docs/demo.md` for the command). The sample is
//! from dataset-1, so it is not in the library.

use mocap_search::{Index, Ranking};
use mocap_view::{plot_bars, BarPlot, BarSeries};

use crate::{require_file, StageContext, StageReport, StageResult};

/// Library clips listed.
const TOP: usize = 5;

pub(crate) fn run(context: &StageContext, report: &mut StageReport) -> StageResult {
    let options = context.options;
    require_file(&options.search_index, "the search library index")?;
    let take = context.take()?;
    let index = Index::load(&options.search_index)?;
    let answer = index.query_file(&take.path, TOP, Ranking::Histogram)?;
    report.fact("query", take.path.display().to_string());
    let name = take
        .path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    report.fact("predicted", answer.predicted.clone());
    report.number(
        "probability",
        "the forest's probability of the predicted class",
        answer.probability as f64,
        "",
    );
    report.number(
        "library_clips",
        "clips in the library",
        index.clips.len() as f64,
        "",
    );
    report.number(
        "classes",
        "classes in the library",
        index.classes.len() as f64,
        "",
    );
    let same = answer
        .matches
        .iter()
        .filter(|m| m.label == answer.predicted)
        .count();
    report.number(
        "top_matches_of_predicted_class",
        "of the nearest library clips, how many carry the predicted class",
        same as f64,
        "",
    );
    for m in &answer.matches {
        let file = std::path::Path::new(&m.path)
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| m.path.clone());
        report.fact(
            &format!("match {}", m.rank),
            format!("{file} ({}, distance {:.3})", m.label, m.distance),
        );
    }
    report.fact("labels", index.label_rule.clone());
    report.fact("index", options.search_index.display().to_string());
    report.note(
        "The query is the chain's take (fused, cleaned, feet planted) of the sample, whose name says `walk`; the library is Bandai dataset-2, not dataset-1, so a `walk` prediction is a real test on an unseen clip, not a lookup.",
    );
    if options.pictures {
        let path = context.path("search", "class_probabilities.png")?;
        let plot = BarPlot {
            title: format!("What is the actor doing? ({name})"),
            y_label: "probability".into(),
            categories: answer
                .probabilities
                .iter()
                .map(|c| c.class.clone())
                .collect(),
            series: vec![BarSeries {
                label: "random forest".into(),
                values: answer.probabilities.iter().map(|c| c.probability).collect(),
                errors: None,
            }],
            size: (900, 450),
        };
        plot_bars(&path, &plot)?;
        report.picture(
            StageContext::relative("search", "class_probabilities.png"),
            "class probabilities of the chain's take",
        );
    }
    Ok(())
}
