//! What a demo stage produces — a [`Section`] with text, pictures, tables, files and a JSON
//! summary — and the static `index.html` that shows them all.
//!
//! The page needs no network: one file with inline CSS, system fonts, images as relative
//! links to the PNGs next to it (their pixel sizes are written as `width`/`height`), no
//! scripts. Every string that comes from the computation is HTML-escaped.

use serde_json::Value;
use std::fmt::Write as _;

/// How a stage ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// Everything the stage promises was computed.
    Ok,
    /// The stage ran but something is off (e.g. a flow that did not reach its tolerance).
    Warning(String),
    /// The stage failed; the sentence says why.
    Failed(String),
    /// Not run because a stage it needs did not succeed.
    Skipped(String),
}

impl Status {
    pub fn name(&self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Warning(_) => "warning",
            Status::Failed(_) => "failed",
            Status::Skipped(_) => "skipped",
        }
    }
    pub fn message(&self) -> Option<&str> {
        match self {
            Status::Ok => None,
            Status::Warning(m) | Status::Failed(m) | Status::Skipped(m) => Some(m),
        }
    }
    /// Whether later stages may use the results.
    pub fn usable(&self) -> bool {
        matches!(self, Status::Ok | Status::Warning(_))
    }
}

/// A picture in the page: a PNG (or SVG) file in the output folder with its size in pixels.
#[derive(Debug, Clone)]
pub struct Picture {
    pub file: String,
    pub caption: String,
    pub width: u32,
    pub height: u32,
    /// Other renderings of the same figure (e.g. the SVG of a PNG plot), linked below it.
    pub alternatives: Vec<String>,
}

/// A table of numbers that came out of a stage.
#[derive(Debug, Clone, Default)]
pub struct Table {
    pub caption: String,
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new(caption: &str, header: &[&str]) -> Table {
        Table {
            caption: caption.into(),
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }
    pub fn row(&mut self, cells: Vec<String>) {
        self.rows.push(cells);
    }
    /// A two-column table of (quantity, value) pairs.
    pub fn key_values(caption: &str, pairs: Vec<(&str, String)>) -> Table {
        let mut t = Table::new(caption, &["quantity", "value"]);
        for (k, v) in pairs {
            t.row(vec![k.to_string(), v]);
        }
        t
    }
}

/// One section of the report (one stage of the pipeline).
#[derive(Debug, Clone)]
pub struct Section {
    /// Anchor and JSON key (`surface`, `flow`, …).
    pub id: &'static str,
    pub title: String,
    /// Which paper section the stage follows.
    pub reference: String,
    pub status: Status,
    /// The main result in a few words, for the overview table at the top.
    pub headline: String,
    /// Plain-text paragraphs (escaped when written).
    pub paragraphs: Vec<String>,
    pub pictures: Vec<Picture>,
    pub tables: Vec<Table>,
    /// Files written by the stage: (file name in the output folder, description).
    pub files: Vec<(String, String)>,
    /// Commands that compute the same from the files in the folder.
    pub commands: Vec<String>,
    /// Per-stage summary for `--json` and `demo.json`.
    pub summary: Value,
    pub seconds: f64,
    /// CPU time of the process (all threads, user + system) during the stage, where the
    /// system reports it ([`crate::util::process_cpu_seconds`]).
    pub cpu_seconds: Option<f64>,
}

impl Section {
    pub fn new(id: &'static str, title: &str, reference: &str) -> Section {
        Section {
            id,
            title: title.into(),
            reference: reference.into(),
            status: Status::Ok,
            headline: String::new(),
            paragraphs: Vec::new(),
            pictures: Vec::new(),
            tables: Vec::new(),
            files: Vec::new(),
            commands: Vec::new(),
            summary: Value::Object(Default::default()),
            seconds: 0.0,
            cpu_seconds: None,
        }
    }
}

/// HTML-escape text for element content and attribute values.
pub fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            _ => o.push(c),
        }
    }
    o
}

/// Escaped text with `code` spans (text between backticks) set in `<code>`.
pub fn inline(s: &str) -> String {
    let mut o = String::with_capacity(s.len() + 16);
    for (i, part) in s.split('`').enumerate() {
        if i % 2 == 1 {
            o.push_str("<code>");
            o.push_str(&esc(part));
            o.push_str("</code>");
        } else {
            o.push_str(&esc(part));
        }
    }
    o
}

/// `1.234e-11`-style for small numbers, fixed otherwise.
pub fn num(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{x:.3e}")
    } else {
        format!("{x:.6}")
    }
}

const CSS: &str = r#"
:root { --ink:#1d232b; --muted:#5b6573; --line:#d9dee5; --paper:#ffffff; --band:#f4f6f9;
        --accent:#2f5d8a; --ok:#2c7a3f; --warn:#a86b00; --bad:#b3261e; }
* { box-sizing: border-box; }
body { margin:0; color:var(--ink); background:var(--band);
       font: 16px/1.55 -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial, sans-serif; }
header { background:#1f2f45; color:#fff; padding:28px 0 22px; }
header h1 { margin:0 0 6px; font-weight:600; font-size:28px; letter-spacing:.2px; }
header p { margin:0; color:#c9d5e3; }
.wrap { max-width:1080px; margin:0 auto; padding:0 24px; }
nav { background:#fff; border-bottom:1px solid var(--line); position:sticky; top:0; z-index:2; }
nav ol { margin:0; padding:10px 0; list-style:none; display:flex; flex-wrap:wrap; gap:6px 18px; }
nav a { color:var(--accent); text-decoration:none; font-size:14px; }
section { background:var(--paper); margin:22px 0; padding:22px 26px 18px; border:1px solid var(--line);
          border-radius:8px; }
h2 { margin:0 0 4px; font-size:22px; font-weight:600; }
h2 .n { color:var(--muted); font-weight:400; margin-right:6px; }
.ref { color:var(--muted); font-size:13px; margin:0 0 12px; }
table.overview .badge { margin-left:0; }
table.overview a { color:var(--accent); text-decoration:none; }
.badge { display:inline-block; font-size:12px; font-weight:600; padding:1px 8px; border-radius:10px;
         margin-left:10px; vertical-align:middle; color:#fff; }
.badge.ok { background:var(--ok); } .badge.warning { background:var(--warn); }
.badge.failed { background:var(--bad); } .badge.skipped { background:#7b8491; }
.status { border-left:4px solid var(--bad); background:#fbeeee; padding:8px 12px; margin:10px 0; }
.status.warning { border-color:var(--warn); background:#fdf5e6; }
.status.skipped { border-color:#7b8491; background:#f1f2f4; }
.figs { display:flex; flex-wrap:wrap; gap:18px; margin:14px 0; }
figure { margin:0; flex:1 1 300px; max-width:100%; }
figure img { width:100%; height:auto; border:1px solid var(--line); border-radius:4px; background:#fff; }
figcaption { font-size:14px; color:var(--muted); margin-top:4px; }
figcaption a { color:var(--accent); }
table { border-collapse:collapse; margin:10px 0 16px; font-size:14px; }
caption { text-align:left; font-weight:600; padding:4px 0; color:var(--ink); }
th, td { padding:4px 12px 4px 0; border-bottom:1px solid var(--line); text-align:left; vertical-align:top; }
th { color:var(--muted); font-weight:600; }
td.num { font-variant-numeric: tabular-nums; font-family: ui-monospace, "SF Mono", Menlo, Consolas, monospace; font-size:13px; }
.tables { display:flex; flex-wrap:wrap; gap:0 36px; align-items:flex-start; }
ul.files { font-size:14px; padding-left:18px; }
ul.files a { color:var(--accent); font-family: ui-monospace, Menlo, Consolas, monospace; }
.placeholder { color:var(--muted); border:1px dashed var(--line); border-radius:8px; padding:14px 20px; margin:22px 0; }
footer { color:var(--muted); font-size:13px; padding:8px 0 40px; }
pre { background:var(--band); border:1px solid var(--line); border-radius:4px; padding:8px 12px;
      overflow-x:auto; font: 13px/1.5 ui-monospace, "SF Mono", Menlo, Consolas, monospace; }
.cmd-title { font-size:14px; color:var(--muted); margin:12px 0 4px; }
code { font-family: ui-monospace, Menlo, Consolas, monospace; font-size:13px; }
"#;

/// Whether a table cell looks numeric (right font, no wrapping surprises).
fn numeric(s: &str) -> bool {
    !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_digit() || "+-.eE ×·−%,[]()".contains(c))
}

fn write_table(h: &mut String, t: &Table) {
    let _ = writeln!(h, "<table>");
    if !t.caption.is_empty() {
        let _ = writeln!(h, "<caption>{}</caption>", esc(&t.caption));
    }
    if !t.header.is_empty() {
        h.push_str("<tr>");
        for c in &t.header {
            let _ = write!(h, "<th>{}</th>", esc(c));
        }
        h.push_str("</tr>\n");
    }
    for r in &t.rows {
        h.push_str("<tr>");
        for c in r {
            if numeric(c) {
                let _ = write!(h, "<td class=\"num\">{}</td>", esc(c));
            } else {
                let _ = write!(h, "<td>{}</td>", esc(c));
            }
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
}

/// Everything the page shows besides the sections.
pub struct Page<'a> {
    pub title: &'a str,
    pub subtitle: String,
    pub sections: &'a [Section],
    /// Stages that are announced but not built yet: (title, sentence).
    pub placeholders: &'a [(&'a str, &'a str)],
    pub total_seconds: f64,
    pub command: String,
    /// Files of the whole run (not owned by one stage).
    pub files: Vec<(String, String)>,
}

/// The whole page as a string.
pub fn index_html(p: &Page) -> String {
    let mut h = String::with_capacity(32 * 1024);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{CSS}</style>\n</head>\n<body>\n",
        esc(p.title)
    );
    let _ = writeln!(
        h,
        "<header><div class=\"wrap\"><h1>{}</h1><p>{}</p></div></header>",
        esc(p.title),
        esc(&p.subtitle)
    );
    h.push_str("<nav><div class=\"wrap\"><ol>");
    for (i, s) in p.sections.iter().enumerate() {
        let _ = write!(
            h,
            "<li><a href=\"#{}\">{}. {}</a></li>",
            s.id,
            i + 1,
            esc(&s.title)
        );
    }
    h.push_str("</ol></div></nav>\n<main class=\"wrap\">\n");
    // Overview: one line per stage.
    h.push_str("<section id=\"overview\">\n<h2>At a glance</h2>\n<table class=\"overview\">\n");
    h.push_str("<tr><th>stage</th><th>status</th><th>result</th><th>time (s)</th></tr>\n");
    for (i, s) in p.sections.iter().enumerate() {
        let st = s.status.name();
        let text = if s.headline.is_empty() {
            s.status.message().unwrap_or("").to_string()
        } else {
            s.headline.clone()
        };
        let _ = writeln!(
            h,
            "<tr><td><a href=\"#{}\">{}. {}</a></td><td><span class=\"badge {st}\">{st}</span></td>\
             <td>{}</td><td class=\"num\">{:.2}</td></tr>",
            s.id,
            i + 1,
            esc(&s.title),
            inline(&text),
            s.seconds
        );
    }
    let _ = writeln!(
        h,
        "<tr><td>total</td><td></td><td></td><td class=\"num\">{:.2}</td></tr>\n</table>\n</section>",
        p.total_seconds
    );
    for (i, s) in p.sections.iter().enumerate() {
        let st = s.status.name();
        let _ = writeln!(
            h,
            "<section id=\"{}\">\n<h2><span class=\"n\">{}.</span>{}<span class=\"badge {st}\">{st}</span></h2>",
            s.id,
            i + 1,
            esc(&s.title)
        );
        let _ = writeln!(
            h,
            "<p class=\"ref\">{} · {:.2} s</p>",
            esc(&s.reference),
            s.seconds
        );
        if let Some(m) = s.status.message() {
            let _ = writeln!(h, "<div class=\"status {st}\">{}</div>", esc(m));
        }
        for para in &s.paragraphs {
            let _ = writeln!(h, "<p>{}</p>", inline(para));
        }
        if !s.pictures.is_empty() {
            h.push_str("<div class=\"figs\">\n");
            for f in &s.pictures {
                let _ = write!(
                    h,
                    "<figure><a href=\"{0}\"><img src=\"{0}\" width=\"{1}\" height=\"{2}\" alt=\"{3}\"></a>\
                     <figcaption>{3}",
                    esc(&f.file),
                    f.width,
                    f.height,
                    esc(&f.caption)
                );
                // One alternative: its format ("SVG"); several: their file names, so that two
                // links never read the same ("SVG · SVG" said nothing of which is which).
                for alt in &f.alternatives {
                    let label = if f.alternatives.len() == 1 {
                        alt.rsplit('.').next().unwrap_or("file").to_uppercase()
                    } else {
                        alt.clone()
                    };
                    let _ = write!(h, " · <a href=\"{}\">{}</a>", esc(alt), esc(&label));
                }
                h.push_str("</figcaption></figure>\n");
            }
            h.push_str("</div>\n");
        }
        if !s.tables.is_empty() {
            h.push_str("<div class=\"tables\">\n");
            for t in &s.tables {
                write_table(&mut h, t);
            }
            h.push_str("</div>\n");
        }
        if !s.files.is_empty() {
            h.push_str("<ul class=\"files\">\n");
            for (f, d) in &s.files {
                let _ = writeln!(
                    h,
                    "<li><a href=\"{0}\">{0}</a> — {1}</li>",
                    esc(f),
                    inline(d)
                );
            }
            h.push_str("</ul>\n");
        }
        if !s.commands.is_empty() {
            h.push_str(
                "<p class=\"cmd-title\">The same from the command line, in this folder:</p>\n<pre>",
            );
            for c in &s.commands {
                let _ = writeln!(h, "{}", esc(c));
            }
            h.push_str("</pre>\n");
        }
        h.push_str("</section>\n");
    }
    for (title, sentence) in p.placeholders {
        let _ = writeln!(
            h,
            "<div class=\"placeholder\"><strong>{}</strong> — {}</div>",
            esc(title),
            esc(sentence)
        );
    }
    h.push_str("</main>\n<footer><div class=\"wrap\">");
    let _ = write!(
        h,
        "<p>Total time {:.2} s. Produced by <code>{}</code>.",
        p.total_seconds,
        esc(&p.command)
    );
    for (f, d) in &p.files {
        let _ = write!(h, " <a href=\"{0}\">{0}</a>: {1}.", esc(f), esc(d));
    }
    h.push_str("</p></div></footer>\n</body>\n</html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_and_numbers() {
        assert_eq!(esc("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        assert_eq!(num(1.5e-12), "1.500e-12");
        assert_eq!(num(0.0), "0");
        assert_eq!(num(2.0), "2.000000");
        assert_eq!(inline("run `a<b` now"), "run <code>a&lt;b</code> now");
    }
}
