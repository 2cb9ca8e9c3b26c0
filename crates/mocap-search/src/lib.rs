//! # mocap-search
//!
//! Motion retrieval by example: a query clip is classified and the most
//! similar clips of a motion library are found, robust to the performer's
//! body size and to differences in timing.
//!
//! The method, following the report this crate implements:
//!
//! 1. features: every frame becomes 76 numbers describing the pose in a
//!    body-centred frame, divided by the body height (the report uses 56;
//!    the values are named in [`VALUE_NAMES`], computed by
//!    [`motion_features`]);
//! 2. intervals: each clip is resampled to `N` frames (10) and each value
//!    is averaged over every interval of those frames with running sums, in
//!    constant time per interval ([`IntervalLayout`]);
//! 3. forest: a random forest (100 trees, [`Forest`]) whose tests compare
//!    one interval mean with a threshold, grown by information gain; its
//!    leaves hold class histograms;
//! 4. index: classification averages the leaf histograms; ranking sorts the
//!    library by the Euclidean distance between histograms (eq. 8)
//!    ([`Index::query`]).
//!
//! Beyond the report: [`Ranking::Proximity`] ranks by forest proximity,
//! which finds clips of classes the forest never saw, and [`find_in_take`]
//! finds the time ranges of a long recording where a motion like the query
//! happens. [`evaluate_files`] measures all of it, with a deterministic
//! tree, a single random tree and a DTW nearest-neighbour baseline for
//! comparison.
//!
//! ## Entry points (what `mocap search` calls)
//!
//! - [`index_files`]: labelled clips to an [`Index`], then [`Index::save`];
//! - [`Index::load`] and [`Index::query_file`]: a clip's class and the most
//!   similar library clips ([`QueryReport`]);
//! - [`find_in_take`]: where in a long take a motion like the query happens
//!   ([`TakeReport`]);
//! - [`evaluate_files`]: precision, recall and F per class, ranking quality
//!   and the baselines ([`EvalReport`], with
//!   [`EvalReport::to_markdown`] and [`EvalReport::plot_confusions`]).
//!
//! The pieces underneath ([`motion_features`], [`IntervalLayout`],
//! [`Forest`] with [`Samples`]) are public for crates that train their own
//! forests on the same features (mocap-style's style classifiers).
//!
//! ```no_run
//! use std::path::{Path, PathBuf};
//! use mocap_search::{index_files, Index, IndexConfig, LabelRule, NamePattern, Ranking};
//!
//! let rule = LabelRule::FromName(NamePattern::parse("bandai-content")?);
//! let library = [PathBuf::from("bandai/dataset-2")];
//! let index = index_files(&library, &rule, "bandai-content", &IndexConfig::default(), true)?;
//! index.save(Path::new("library.idx"))?;
//!
//! let index = Index::load(Path::new("library.idx"))?;
//! let report = index.query_file(Path::new("query.bvh"), 10, Ranking::Histogram)?;
//! print!("{}", report.to_text());
//! # Ok::<(), mocap_search::SearchError>(())
//! ```

mod clips;
mod dtw;
mod error;
mod eval;
mod features;
mod forest;
mod index;
mod intervals;
mod labels;
mod plots;
mod scores;
mod take;

pub use clips::{load_clips, load_features, load_motion, motion_files, Clip};
pub use error::{Result, SearchError};
pub use eval::{
    evaluate, evaluate_files, evaluate_train_test, stratified_folds, EvalConfig, EvalReport, Fold,
    MethodScores, NoveltyRow, RankingScores, SplitRule, TakeEvalReport, TakeMethodScores,
    UnseenReport,
};
pub use features::{motion_features, VALUE_COUNT, VALUE_NAMES};
pub use forest::{argmax, Forest, ForestConfig, Samples, Tree, TreeConfig};
pub use index::{
    build_index, index_files, ClassProbability, Index, IndexConfig, LibraryClip, Match,
    QueryReport, Ranking,
};
pub use intervals::{FeatureSequence, IntervalLayout};
pub use labels::{ClipLabel, LabelFile, LabelRule, NamePattern};
pub use scores::{ClassScores, ConfusionMatrix};
pub use take::{find_in_take, search_take, TakeMatch, TakeMethod, TakeReport, TakeSearchConfig};
