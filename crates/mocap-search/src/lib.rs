//! # mocap-search
//!
//! Motion retrieval by example: a query clip is classified and the most
//! similar clips of a motion library are found, robust to the performer's
//! body size and to differences in timing.
//!
//! The method, following the report this crate implements:
//!
//! 1. [`features`]: every frame becomes 76 numbers describing the pose in a
//!    body-centred frame, divided by the body height (the report uses 56;
//!    which values and why are listed in [`features`]);
//! 2. [`intervals`]: each clip is resampled to `N` frames (10) and each
//!    value is averaged over every interval of those frames with running
//!    sums, in constant time per interval;
//! 3. [`forest`]: a random forest (100 trees) whose tests compare one
//!    interval mean with a threshold, grown by information gain; its leaves
//!    hold class histograms;
//! 4. [`index`]: classification averages the leaf histograms; ranking sorts
//!    the library by the Euclidean distance between histograms (eq. 8).
//!
//! Beyond the report: [`index::Ranking::Proximity`] ranks by forest
//! proximity, which finds clips of classes the forest never saw, and
//! [`take`] finds the time ranges of a long recording where a motion like
//! the query happens. [`eval`] measures all of it, with a deterministic
//! tree, a single random tree and a DTW nearest-neighbour baseline for
//! comparison.
//!
//! Typical use (what `mocap search` does):
//!
//! ```no_run
//! use std::path::{Path, PathBuf};
//! use mocap_search::{build_index, load_clips, motion_files, Index, IndexConfig, LabelRule, NamePattern, Ranking};
//!
//! let files = motion_files(&[PathBuf::from("bandai/dataset-2")])?;
//! let rule = LabelRule::FromName(NamePattern::parse("bandai-content")?);
//! let clips = load_clips(&files, &rule, true)?;
//! let index = build_index(&clips, "bandai-content", &IndexConfig::default(), true)?;
//! index.save(Path::new("library.idx"))?;
//!
//! let index = Index::load(Path::new("library.idx"))?;
//! let (features, _fps) = mocap_search::load_features(Path::new("query.bvh"))?;
//! let report = index.query("query.bvh", &features, 10, Ranking::Histogram);
//! print!("{}", report.to_text());
//! # Ok::<(), mocap_search::SearchError>(())
//! ```

pub mod clips;
pub mod dtw;
pub mod error;
pub mod eval;
pub mod features;
pub mod forest;
pub mod index;
pub mod intervals;
pub mod labels;
pub mod scores;
pub mod take;

pub use clips::{load_clips, load_features, load_motion, motion_files, Clip};
pub use error::{Result, SearchError};
pub use eval::{evaluate, EvalConfig, EvalReport, SplitRule};
pub use forest::{Forest, ForestConfig, Tree, TreeConfig};
pub use index::{build_index, Index, IndexConfig, QueryReport, Ranking};
pub use labels::{LabelFile, LabelRule, NamePattern};
pub use take::{search_take, TakeMatch, TakeSearchConfig};
