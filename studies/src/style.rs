//! Setup shared by the style studies (`studies/examples/style_*.rs`).

use std::collections::BTreeMap;
use std::path::PathBuf;

use mocap_style::{
    held_out, labelled_paths, list_bvh, load_clips, train_classifiers, Clip, ClipClassifier,
    ClipFilter, EvalOptions, Labels, Result,
};
use serde::{Deserialize, Serialize};

/// The evaluation classifiers' accuracy on real clips of one set, without
/// restyling anything: to compare classifiers ([`check_classifiers`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ClassifierCheck {
    pub set: String,
    /// On the held-out clips (style: those of the classifier's contents),
    /// trained on all the others, as in `mocap_style::evaluate`.
    pub held_out_style: f64,
    pub held_out_style_clips: usize,
    pub held_out_content: f64,
    pub held_out_content_clips: usize,
    /// Cross-validation on the training clips only (the held-out clips are
    /// not used): style leaving one content out at a time (a style must be
    /// recognised in a content it was not trained on), content leaving one
    /// style out at a time. `None` when not asked for.
    pub cross_validated_style: Option<f64>,
    pub cross_validated_content: Option<f64>,
    /// The held-out clips the style classifier got wrong, with its answer.
    pub style_errors: Vec<(String, String)>,
    /// The same for the content classifier.
    pub content_errors: Vec<(String, String)>,
}

/// Which cross-validations [`check_classifiers`] runs.
#[derive(Debug, Clone, Copy, Default)]
pub struct CrossValidate {
    pub style: bool,
    pub content: bool,
}

/// Measures the classifiers of `mocap_style::evaluate` on real clips of every set of
/// `options.inputs` (held-out accuracy and, as asked,
/// cross-validation on the training clips), so that the evaluation's
/// classifiers can be chosen on real clips, never on the method's outputs.
pub fn check_classifiers(
    options: &EvalOptions,
    cross_validate: CrossValidate,
) -> Result<Vec<ClassifierCheck>> {
    let files = labelled_paths(&list_bvh(&options.inputs)?, &ClipFilter::default())?;
    let mut sets: BTreeMap<String, Vec<(PathBuf, Labels)>> = BTreeMap::new();
    for f in files {
        sets.entry(f.1.set.clone()).or_default().push(f);
    }
    let mut out = Vec::new();
    for (set, files) in sets {
        let held = held_out(&files, options.held_out_take);
        let (test, train): (Vec<_>, Vec<_>) = files.iter().cloned().partition(|(p, _)| {
            held.contains(
                &p.file_stem()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned(),
            )
        });
        let train = load_clips(&train)?;
        let test = load_clips(&test)?;
        let (style, content) = train_classifiers(&train, options)?;
        let style_tests: Vec<&Clip> = test
            .iter()
            .filter(|c| options.classifier_filter.accepts(&c.labels))
            .collect();
        let mut style_errors = Vec::new();
        for c in &style_tests {
            let p = style.predict(&c.motion)?;
            if p != c.labels.style {
                style_errors.push((c.name.clone(), p));
            }
        }
        let mut content_errors = Vec::new();
        for c in &test {
            let p = content.predict(&c.motion)?;
            if p != c.labels.content {
                content_errors.push((c.name.clone(), p));
            }
        }
        let style_hits = style_tests.len() - style_errors.len();
        let content_hits = test.len() - content_errors.len();
        let (mut cv_style, mut cv_content) = (None, None);
        if cross_validate.style {
            let style_clips: Vec<Clip> = train
                .iter()
                .filter(|c| options.classifier_filter.accepts(&c.labels))
                .cloned()
                .collect();
            let mut folds: Vec<String> = style_clips
                .iter()
                .map(|c| c.labels.content.clone())
                .collect();
            folds.sort();
            folds.dedup();
            let (mut hits, mut n) = (0, 0);
            for fold in &folds {
                let (inside, outside): (Vec<Clip>, Vec<Clip>) = style_clips
                    .iter()
                    .cloned()
                    .partition(|c| &c.labels.content == fold);
                if outside.is_empty() {
                    continue;
                }
                let classifier = ClipClassifier::train(
                    &outside
                        .iter()
                        .map(|c| (c, c.labels.style.clone()))
                        .collect::<Vec<_>>(),
                    options.style_classifier_config(),
                )?;
                for c in &inside {
                    hits += (classifier.predict(&c.motion)? == c.labels.style) as usize;
                    n += 1;
                }
            }
            cv_style = Some(hits as f64 / n.max(1) as f64);
        }
        if cross_validate.content {
            let mut folds: Vec<String> = train.iter().map(|c| c.labels.style.clone()).collect();
            folds.sort();
            folds.dedup();
            let (mut hits, mut n) = (0, 0);
            for fold in &folds {
                let (inside, outside): (Vec<Clip>, Vec<Clip>) =
                    train.iter().cloned().partition(|c| &c.labels.style == fold);
                let classifier = ClipClassifier::train(
                    &outside
                        .iter()
                        .map(|c| (c, c.labels.content.clone()))
                        .collect::<Vec<_>>(),
                    options.content_classifier_config(),
                )?;
                for c in &inside {
                    hits += (classifier.predict(&c.motion)? == c.labels.content) as usize;
                    n += 1;
                }
            }
            cv_content = Some(hits as f64 / n.max(1) as f64);
        }
        out.push(ClassifierCheck {
            set,
            held_out_style: style_hits as f64 / style_tests.len().max(1) as f64,
            held_out_style_clips: style_tests.len(),
            held_out_content: content_hits as f64 / test.len().max(1) as f64,
            held_out_content_clips: test.len(),
            cross_validated_style: cv_style,
            cross_validated_content: cv_content,
            style_errors,
            content_errors,
        });
    }
    Ok(out)
}
