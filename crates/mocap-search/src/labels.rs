//! Class labels of library clips: from the file name or from a label file.
//!
//! **From the file name**: a pattern is matched against the file name
//! without its extension. `{label}` marks the class, `{performer}` the actor
//! (used to split the evaluation by performer), `{*}` any other field and
//! `*` any text; everything else must match literally. Several `{label}`
//! fields are joined with `/` (to train on content and style together).
//! Built-in patterns:
//!
//! | name | pattern | example |
//! | --- | --- | --- |
//! | `bandai-content` | `dataset-*_{label}_{*}_{*}` | `dataset-2_walk-turn-left_feminine_004` -> `walk-turn-left` |
//! | `bandai-style` | `dataset-*_{*}_{label}_{*}` | ... -> `feminine` |
//! | `bandai-content-style` | `dataset-*_{label}_{label}_{*}` | ... -> `walk-turn-left/feminine` |
//! | `hdm05` | `HDM_{performer}_{label}_{*}_{*}` | `HDM_bd_walk4StepsLstart_001_120` -> `walk4StepsLstart`, performer `bd` |
//!
//! **From a label file**: one clip a line, `name,label` or
//! `name,label,performer` (commas or tabs; `#` starts a comment; a first line
//! `file,label...` is a header). `name` is the file name with or without its
//! extension, or a path ending in it.

use std::collections::HashMap;
use std::path::Path;

use regex::Regex;

use crate::error::SearchError;

/// The label (and, when known, the performer) of one clip.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClipLabel {
    pub label: String,
    pub performer: Option<String>,
}

/// How clips get their labels.
#[derive(Debug, Clone)]
pub enum LabelRule {
    FromName(NamePattern),
    FromFile(LabelFile),
}

impl LabelRule {
    /// The rule a command line asks for: a label file (`--labels FILE`) or
    /// a file-name pattern or preset (`--labels-from-name PATTERN`), with
    /// its name for reports (the file's path, or the pattern).
    pub fn from_options(
        file: Option<&Path>,
        pattern: Option<&str>,
    ) -> Result<(LabelRule, String), SearchError> {
        match (file, pattern) {
            (Some(file), _) => Ok((
                LabelRule::FromFile(LabelFile::read(file)?),
                file.display().to_string(),
            )),
            (None, Some(pattern)) => Ok((
                LabelRule::FromName(NamePattern::parse(pattern)?),
                pattern.to_string(),
            )),
            (None, None) => Err(SearchError::Invalid(
                "give --labels FILE or --labels-from-name PATTERN".into(),
            )),
        }
    }

    /// The label of the clip stored at `path`.
    pub fn label_of(&self, path: &Path) -> Result<ClipLabel, SearchError> {
        match self {
            LabelRule::FromName(p) => p.label_of(path),
            LabelRule::FromFile(f) => f.label_of(path),
        }
    }
}

/// A file-name pattern with `{label}`, `{performer}`, `{*}` and `*`.
#[derive(Debug, Clone)]
pub struct NamePattern {
    pattern: String,
    regex: Regex,
    label_fields: usize,
}

impl NamePattern {
    /// Parses a pattern or the name of a built-in one (see the module docs).
    pub fn parse(pattern: &str) -> Result<NamePattern, SearchError> {
        let expanded = match pattern {
            "bandai-content" => "dataset-*_{label}_{*}_{*}",
            "bandai-style" => "dataset-*_{*}_{label}_{*}",
            "bandai-content-style" => "dataset-*_{label}_{label}_{*}",
            "hdm05" => "HDM_{performer}_{label}_{*}_{*}",
            other => other,
        };
        let bad = |why: &str| SearchError::Labels(format!("label pattern `{pattern}`: {why}"));
        let mut regex = String::from("^");
        let mut label_fields = 0;
        let mut has_performer = false;
        let mut rest = expanded;
        while !rest.is_empty() {
            if let Some(after) = rest.strip_prefix('{') {
                let end = after
                    .find('}')
                    .ok_or_else(|| bad("a `{` is not closed by `}`"))?;
                match &after[..end] {
                    "label" => {
                        regex.push_str(&format!("(?P<label{label_fields}>.+?)"));
                        label_fields += 1;
                    }
                    "performer" if !has_performer => {
                        regex.push_str("(?P<performer>.+?)");
                        has_performer = true;
                    }
                    "performer" => return Err(bad("`{performer}` appears twice")),
                    "*" => regex.push_str(".+?"),
                    other => {
                        return Err(bad(&format!(
                        "unknown field `{{{other}}}`; expected {{label}}, {{performer}} or {{*}}"
                    )))
                    }
                }
                rest = &after[end + 1..];
            } else {
                let c = rest.chars().next().expect("rest is not empty");
                if c == '*' {
                    regex.push_str(".*?");
                } else {
                    regex.push_str(&regex::escape(&c.to_string()));
                }
                rest = &rest[c.len_utf8()..];
            }
        }
        regex.push('$');
        if label_fields == 0 {
            return Err(bad("it has no `{label}` field"));
        }
        let regex = Regex::new(&regex).map_err(|e| bad(&e.to_string()))?;
        Ok(NamePattern {
            pattern: expanded.to_string(),
            regex,
            label_fields,
        })
    }

    /// The pattern, with a built-in name expanded.
    pub fn as_str(&self) -> &str {
        &self.pattern
    }

    /// The label of the clip at `path` (its file name without extension).
    pub fn label_of(&self, path: &Path) -> Result<ClipLabel, SearchError> {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let caps = self.regex.captures(&stem).ok_or_else(|| {
            SearchError::Labels(format!(
                "{}: the file name `{stem}` does not match the label pattern `{}`",
                path.display(),
                self.pattern
            ))
        })?;
        let label = (0..self.label_fields)
            .map(|k| caps[format!("label{k}").as_str()].to_string())
            .collect::<Vec<_>>()
            .join("/");
        Ok(ClipLabel {
            label,
            performer: caps.name("performer").map(|m| m.as_str().to_string()),
        })
    }
}

/// Labels read from a file: clip name -> label (and performer).
#[derive(Debug, Clone, Default)]
pub struct LabelFile {
    by_name: HashMap<String, ClipLabel>,
}

impl LabelFile {
    /// Reads a label file (see the module docs for the format).
    pub fn read(path: &Path) -> Result<LabelFile, SearchError> {
        let text = std::fs::read_to_string(path).map_err(|e| SearchError::Io {
            path: path.to_path_buf(),
            error: e,
        })?;
        LabelFile::parse(&text, path)
    }

    /// Parses label-file text; `path` is only used in error messages.
    pub fn parse(text: &str, path: &Path) -> Result<LabelFile, SearchError> {
        let mut by_name = HashMap::new();
        for (k, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let fields: Vec<&str> = line
                .split([',', '\t'])
                .map(str::trim)
                .filter(|f| !f.is_empty())
                .collect();
            if by_name.is_empty() && fields.first() == Some(&"file") {
                continue; // header
            }
            if fields.len() < 2 || fields.len() > 3 {
                return Err(SearchError::Labels(format!(
                    "{}:{}: expected `name,label` or `name,label,performer`, got `{line}`",
                    path.display(),
                    k + 1
                )));
            }
            let name = clip_key(Path::new(fields[0]));
            let label = ClipLabel {
                label: fields[1].to_string(),
                performer: fields.get(2).map(|p| p.to_string()),
            };
            if by_name.insert(name.clone(), label).is_some() {
                return Err(SearchError::Labels(format!(
                    "{}:{}: clip `{name}` is labelled twice",
                    path.display(),
                    k + 1
                )));
            }
        }
        Ok(LabelFile { by_name })
    }

    pub fn label_of(&self, path: &Path) -> Result<ClipLabel, SearchError> {
        self.by_name.get(&clip_key(path)).cloned().ok_or_else(|| {
            SearchError::Labels(format!(
                "{}: no label for this clip in the label file (looked up as `{}`)",
                path.display(),
                clip_key(path)
            ))
        })
    }

    pub fn len(&self) -> usize {
        self.by_name.len()
    }

    pub fn is_empty(&self) -> bool {
        self.by_name.is_empty()
    }
}

/// Clips are looked up by file name without extension.
fn clip_key(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn label(pattern: &str, name: &str) -> ClipLabel {
        NamePattern::parse(pattern)
            .unwrap()
            .label_of(Path::new(name))
            .unwrap()
    }

    #[test]
    fn bandai_and_hdm05_names() {
        let name = "data/dataset-2_walk-turn-left_feminine_004.bvh";
        assert_eq!(label("bandai-content", name).label, "walk-turn-left");
        assert_eq!(label("bandai-style", name).label, "feminine");
        assert_eq!(
            label("bandai-content-style", name).label,
            "walk-turn-left/feminine"
        );
        let hdm = label("hdm05", "HDM_bd_walk4StepsLstart_001_120.amc");
        assert_eq!(hdm.label, "walk4StepsLstart");
        assert_eq!(hdm.performer.as_deref(), Some("bd"));
        assert_eq!(label("clip-{label}.v*", "clip-jump.v12.bvh").label, "jump");
    }

    #[test]
    fn bad_patterns_and_names_are_clear_errors() {
        let e = NamePattern::parse("{content}_{*}").unwrap_err().to_string();
        assert!(e.contains("unknown field `{content}`"), "{e}");
        assert!(NamePattern::parse("{*}_x")
            .unwrap_err()
            .to_string()
            .contains("no `{label}`"));
        assert!(NamePattern::parse("{label").is_err());
        let e = NamePattern::parse("bandai-content")
            .unwrap()
            .label_of(Path::new("walk.bvh"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("does not match"), "{e}");
    }

    #[test]
    fn label_files() {
        let text = "file,label,performer\n# a comment\nwalk_01.bvh, walk, ann\nrun_01\trun\n";
        let f = LabelFile::parse(text, Path::new("labels.csv")).unwrap();
        assert_eq!(f.len(), 2);
        let walk = f.label_of(Path::new("/x/walk_01.bvh")).unwrap();
        assert_eq!(
            (walk.label.as_str(), walk.performer.as_deref()),
            ("walk", Some("ann"))
        );
        assert_eq!(f.label_of(Path::new("run_01.amc")).unwrap().label, "run");
        assert!(f.label_of(Path::new("jump.bvh")).is_err());
        let e = LabelFile::parse("a,b\nonly-one-field\n", Path::new("l.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("l.csv:2:"), "{e}");
    }
}
