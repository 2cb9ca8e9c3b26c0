//! The report folder: `index.html` (numbers, pictures, files and viewer
//! commands of every stage) and `report.json` (the [`DemoReport`]).

use std::fmt::Write as _;

use mocap_core::io::atomic::write_bytes_atomically;
use mocap_core::{Error, Result};

use crate::{DemoReport, StageStatus};

/// Escapes text for HTML.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A number with as many digits as it deserves.
fn format_value(value: f64) -> String {
    if value == value.trunc() && value.abs() < 1e9 {
        format!("{value:.0}")
    } else if value.abs() >= 100.0 {
        format!("{value:.1}")
    } else if value.abs() >= 1.0 {
        format!("{value:.2}")
    } else {
        format!("{value:.3}")
    }
}

/// A relative path as a URL (forward slashes, each part escaped).
fn link(path: &std::path::Path) -> String {
    path.components()
        .map(|c| escape(&c.as_os_str().to_string_lossy()))
        .collect::<Vec<_>>()
        .join("/")
}

/// The HTML page.
pub fn html(report: &DemoReport) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>mocap demo</title><style>\
         body{{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}}\
         table{{border-collapse:collapse;margin:.5em 0}}td,th{{border:1px solid #ccc;padding:.25em .6em;text-align:left}}\
         td.n{{text-align:right;font-variant-numeric:tabular-nums}}\
         .ran{{color:#176c2f}}.model_missing,.not_available{{color:#9a6700}}.failed{{color:#b42318}}\
         code,pre{{background:#f4f4f2;padding:.15em .3em}}pre{{padding:.6em;overflow-x:auto}}\
         img{{max-width:100%;border:1px solid #ddd;margin:.3em 0}}\
         </style></head><body>\n<h1>mocap demo</h1>\n"
    );
    let _ = writeln!(
        h,
        "<p>Sample: <code>{}</code>. Whole demo: {:.1} s. Each stage below ran on its own; \
         a stage whose model is missing or that failed says so and has no numbers.</p>",
        escape(&report.sample.display().to_string()),
        report.seconds
    );
    h.push_str("<table><tr><th>stage</th><th>status</th><th>seconds</th></tr>\n");
    for s in &report.stages {
        let _ = writeln!(
            h,
            "<tr><td><a href=\"#{}\">{}</a></td><td class=\"{}\">{}</td><td class=\"n\">{:.2}</td></tr>",
            escape(&s.name),
            escape(&s.title),
            status_class(s.status),
            s.status.label(),
            s.seconds
        );
    }
    h.push_str("</table>\n");
    chain_table(&mut h, report);
    for s in &report.stages {
        let _ = writeln!(
            h,
            "<h2 id=\"{}\">{} <span class=\"{}\">({})</span></h2>",
            escape(&s.name),
            escape(&s.title),
            status_class(s.status),
            s.status.label()
        );
        if let Some(m) = &s.message {
            let _ = writeln!(
                h,
                "<p class=\"{}\">{}</p>",
                status_class(s.status),
                escape(m)
            );
        }
        if !s.numbers.is_empty() {
            h.push_str("<table><tr><th>number</th><th>value</th><th>unit</th><th>what</th></tr>\n");
            for n in &s.numbers {
                let _ = writeln!(
                    h,
                    "<tr><td><code>{}</code></td><td class=\"n\">{}</td><td>{}</td><td>{}</td></tr>",
                    escape(&n.name),
                    format_value(n.value),
                    escape(&n.unit),
                    escape(&n.description)
                );
            }
            h.push_str("</table>\n");
        }
        if !s.facts.is_empty() {
            h.push_str("<table>\n");
            for (k, v) in &s.facts {
                let _ = writeln!(h, "<tr><th>{}</th><td>{}</td></tr>", escape(k), escape(v));
            }
            h.push_str("</table>\n");
        }
        for p in &s.pictures {
            let _ = writeln!(
                h,
                "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
                link(&p.path),
                escape(&p.description),
                escape(&p.description)
            );
        }
        if !s.outputs.is_empty() {
            h.push_str("<ul>\n");
            for o in &s.outputs {
                let _ = writeln!(
                    h,
                    "<li><a href=\"{}\"><code>{}</code></a>: {}</li>",
                    link(&o.path),
                    escape(&o.path.display().to_string()),
                    escape(&o.description)
                );
            }
            h.push_str("</ul>\n");
        }
        if let Some(c) = &s.viewer_command {
            let _ = writeln!(h, "<p>Play them:</p><pre>{}</pre>", escape(c));
        }
        if !s.notes.is_empty() {
            h.push_str("<ul>\n");
            for n in &s.notes {
                let _ = writeln!(h, "<li>{}</li>", escape(n));
            }
            h.push_str("</ul>\n");
        }
    }
    h.push_str(
        "<p>Data: Bandai Namco Research Motion Dataset (Kobayashi et al., 2023, arXiv:2306.08861), \
         CC BY-NC 4.0; see <code>samples/README.md</code>.</p>\n</body></html>\n",
    );
    h
}

/// The take after each stage of the chain against the sample, one row a
/// stage (`-` where the stage did not run).
const CHAIN_ROWS: &[(&str, &str, &str, &str)] = &[
    (
        "fused, on the sample's rig",
        "fuse",
        "on_rig_position_error_mm",
        "on_rig_jitter",
    ),
    (
        "cleaned",
        "clean",
        "position_error_cleaned_mm",
        "jitter_cleaned",
    ),
    (
        "feet planted",
        "feet",
        "position_error_after_mm",
        "jitter_after",
    ),
];

fn chain_table(h: &mut String, report: &DemoReport) {
    let value = |stage: &str, number: &str| {
        report
            .stage(stage)
            .and_then(|s| s.value(number))
            .map_or_else(|| "-".to_string(), format_value)
    };
    h.push_str(
        "<h2 id=\"chain\">The take through the chain</h2>\n<p>Each stage works on the output of the \
         stage before it; errors against the sample, at the same instants.</p>\n<table><tr><th>take</th>\
         <th>position error (mm)</th><th>jitter (mm/frame³)</th></tr>\n",
    );
    for (label, stage, position, jitter) in CHAIN_ROWS {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
            escape(label),
            value(stage, position),
            value(stage, jitter)
        );
    }
    let _ = writeln!(
        h,
        "<tr><td>the sample</td><td class=\"n\">0</td><td class=\"n\">{}</td></tr>\n</table>",
        value("fuse", "sample_jitter")
    );
    let _ = writeln!(
        h,
        "<p>Planted-foot sliding (cm/s): {} before the feet stage, {} after, {} in the sample.</p>",
        value("feet", "sliding_before_cm_s"),
        value("feet", "sliding_after_cm_s"),
        value("feet", "sliding_sample_cm_s")
    );
}

fn status_class(status: StageStatus) -> &'static str {
    match status {
        StageStatus::Ran => "ran",
        StageStatus::ModelMissing => "model_missing",
        StageStatus::NotAvailable => "not_available",
        StageStatus::Failed => "failed",
    }
}

/// Writes `index.html` and `report.json` (atomically).
pub fn write(report: &DemoReport) -> Result<()> {
    write_bytes_atomically(&report.index_html, html(report).as_bytes())?;
    let json = serde_json::to_vec_pretty(report)
        .map_err(|e| Error::Invalid(format!("cannot serialise the demo report: {e}")))?;
    write_bytes_atomically(&report.out.join("report.json"), &json)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup_and_formats_numbers() {
        assert_eq!(
            escape("<a href=\"x\">&'"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
        assert_eq!(format_value(195.0), "195");
        assert_eq!(format_value(31.456), "31.46");
        assert_eq!(format_value(0.01234), "0.012");
        assert_eq!(format_value(1234.56), "1234.6");
    }
}
