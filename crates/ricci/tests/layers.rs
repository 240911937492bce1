//! The dependency direction of the library's modules (issue 21): the pipeline
//!
//! `numeric < mesh < metric < flow < cut < layout ≈ analysis < atlas < spline`
//!
//! read from the sources. A module may use the modules before it in this order, never one
//! after it; `analysis` sits beside `layout` (it uses `layout`, `layout` does not use it);
//! `error` and `progress` are utilities every module may use (they use nothing). Every
//! `crate::X` path (in `use` lines, grouped `use crate::{…}`, and inline paths) and every
//! `super::…` chain that climbs to the crate root is checked; comments and string literals are
//! not. A **compatibility re-export** — a `pub use crate::X…;` whose doc comment starts with
//! "Compatibility re-export", in the `mod.rs` of the module re-exported into — is allowed
//! (it keeps old paths compiling for code written against them), nothing else is.
//!
//! A violation is reported with file and line.

use std::path::{Path, PathBuf};

/// Top-level modules in pipeline order: `(name, rank)`; equal ranks are not allowed to use
/// each other except for the pairs in [`SIDEWAYS`].
const LAYERS: &[(&str, u32)] = &[
    ("error", 0),
    ("progress", 0),
    ("numeric", 1),
    ("mesh", 2),
    ("metric", 3),
    ("flow", 4),
    ("cut", 5),
    ("layout", 6),
    ("analysis", 6),
    ("atlas", 7),
    ("param", 7),
    ("spline", 8),
];

/// Utilities every module may use.
const UTILITIES: &[&str] = &["error", "progress"];

/// Allowed uses between modules of equal rank: `(user, used)`.
const SIDEWAYS: &[(&str, &str)] = &[("analysis", "layout")];

const COMPAT_MARK: &str = "Compatibility re-export";

fn rank(m: &str) -> Option<u32> {
    LAYERS.iter().find(|(n, _)| *n == m).map(|&(_, r)| r)
}

/// Whether module `user` may refer to module `used`.
fn allowed(user: &str, used: &str) -> bool {
    if user == used || UTILITIES.contains(&used) || SIDEWAYS.contains(&(user, used)) {
        return true;
    }
    match (rank(user), rank(used)) {
        (Some(a), Some(b)) => b < a,
        _ => false,
    }
}

/// A reference from one top-level module to another.
#[derive(Debug, Clone, PartialEq)]
struct Reference {
    line: usize,
    target: String,
    /// Whether it is a marked compatibility re-export.
    compat: bool,
}

/// The source with comments and the contents of string and char literals blanked out (line
/// structure kept), so that only code is scanned.
fn strip(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    let blank = |c: u8| if c == b'\n' { b'\n' } else { b' ' };
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                out.push(b' ');
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let mut depth = 0;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    out.extend_from_slice(b"  ");
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    out.extend_from_slice(b"  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
        } else if b[i] == b'r' && (b[i..].starts_with(b"r#\"") || b[i..].starts_with(b"r\"")) {
            // Raw string r#"…"# (any number of #).
            let mut j = i + 1;
            while b[j] == b'#' {
                j += 1;
            }
            let hashes = j - i - 1;
            let mut close = vec![b'"'];
            close.extend(std::iter::repeat_n(b'#', hashes));
            out.extend(std::iter::repeat_n(b' ', j + 1 - i));
            i = j + 1;
            while i < b.len() && !b[i..].starts_with(&close) {
                out.push(blank(b[i]));
                i += 1;
            }
            out.extend(std::iter::repeat_n(b' ', close.len().min(b.len() - i)));
            i += close.len();
        } else if b[i] == b'"' {
            out.push(b' ');
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' && i + 1 < b.len() {
                    out.push(b' ');
                    i += 1;
                }
                out.push(blank(b[i]));
                i += 1;
            }
            out.push(b' ');
            i += 1;
        } else if b[i] == b'\'' && i + 2 < b.len() && (b[i + 2] == b'\'' || b[i + 1] == b'\\') {
            // A char literal ('x' or '\n', '\''); lifetimes ('a) are left alone.
            out.push(b' ');
            i += 1;
            while i < b.len() && b[i] != b'\'' {
                if b[i] == b'\\' {
                    out.push(b' ');
                    i += 1;
                }
                out.push(b' ');
                i += 1;
            }
            out.push(b' ');
            i += 1;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    out.truncate(b.len());
    String::from_utf8_lossy(&out).into_owned()
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The identifier starting at byte `i` of `s` (after white space).
fn ident_at(s: &str, i: usize) -> (&str, usize) {
    let rest = &s[i..];
    let skip = rest.len() - rest.trim_start().len();
    let rest = &rest[skip..];
    let n = rest.find(|c: char| !is_ident(c)).unwrap_or(rest.len());
    (&rest[..n], i + skip + n)
}

/// Top-level names of a `{ a::b, c, d::{e, f} }` group starting at the `{` at byte `i`.
fn group_heads(s: &str, i: usize) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    let mut depth = 0;
    let mut expect_head = true;
    let mut j = i;
    while j < s.len() {
        let c = s[j..].chars().next().unwrap();
        match c {
            '{' => {
                depth += 1;
                expect_head = depth == 1;
            }
            '}' => {
                depth -= 1;
                if depth == 0 {
                    break;
                }
            }
            ',' if depth == 1 => expect_head = true,
            c if expect_head && depth == 1 && is_ident(c) => {
                let (id, _) = ident_at(s, j);
                out.push((id.to_string(), j));
                expect_head = false;
            }
            _ => {}
        }
        j += c.len_utf8();
    }
    out
}

/// The references to top-level modules of the crate in one file. `depth` is the number of
/// module levels of the file below the crate root (`flow/mod.rs` 1, `flow/newton.rs` 2), so
/// that `super::` chains climbing to the root are recognized.
fn references(src: &str, depth: usize) -> Vec<Reference> {
    let code = strip(src);
    let raw_lines: Vec<&str> = src.lines().collect();
    let line_of = |pos: usize| code[..pos].matches('\n').count() + 1;
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    let push = |pos: usize, name: &str, out: &mut Vec<Reference>| {
        if name.is_empty() || name == "self" || name == "super" || name == "crate" {
            return;
        }
        let line = line_of(pos);
        out.push(Reference {
            line,
            target: name.to_string(),
            compat: is_compat(&raw_lines, line),
        });
    };
    let mut i = 0;
    while let Some(k) = code[i..].find("crate::") {
        let p = i + k;
        i = p + "crate::".len();
        if p > 0 && (is_ident(bytes[p - 1] as char) || bytes[p - 1] == b'$') {
            continue;
        }
        if code[i..].trim_start().starts_with('{') {
            let b = i + code[i..].find('{').unwrap();
            for (name, pos) in group_heads(&code, b) {
                push(pos, &name, &mut out);
            }
        } else {
            let (name, _) = ident_at(&code, i);
            push(p, name, &mut out);
        }
    }
    // `super::super::…::X` reaching the root from a file `depth` levels down.
    if depth > 0 {
        let chain = "super::".repeat(depth);
        let mut i = 0;
        while let Some(k) = code[i..].find(&chain) {
            let p = i + k;
            i = p + chain.len();
            if p > 0 && is_ident(bytes[p - 1] as char)
                || code[p..].starts_with(&(chain.clone() + "super::"))
            {
                continue;
            }
            if p >= 7 && &code[p - 7..p] == "super::" {
                continue;
            }
            let (name, _) = ident_at(&code, i);
            if rank(name).is_some() {
                push(p, name, &mut out);
            }
        }
    }
    out
}

/// Whether line `line` (1-based) is a `pub use crate::…` whose doc comment (the comment lines
/// right above it) starts with [`COMPAT_MARK`].
fn is_compat(lines: &[&str], line: usize) -> bool {
    let Some(text) = lines.get(line - 1) else {
        return false;
    };
    if !text.trim_start().starts_with("pub use crate::") {
        return false;
    }
    let mut k = line - 1;
    let mut first_doc = None;
    while k > 0 && lines[k - 1].trim_start().starts_with("///") {
        first_doc = Some(lines[k - 1]);
        k -= 1;
    }
    first_doc.is_some_and(|d| {
        d.trim_start()
            .trim_start_matches('/')
            .trim_start()
            .starts_with(COMPAT_MARK)
    })
}

/// Items the crate root re-exports (`pub use error::{Error, Result};` in `lib.rs`): `(name,
/// module)`, so that `crate::Result` counts as a use of `error`.
fn root_aliases(lib: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for line in strip(lib).lines() {
        let Some(rest) = line.trim().strip_prefix("pub use ") else {
            continue;
        };
        let rest = rest.trim_end_matches(';');
        let (module, tail) = rest.split_once("::").unwrap_or((rest, ""));
        let names: Vec<&str> = if let Some(g) = tail.strip_prefix('{') {
            g.trim_end_matches('}').split(',').collect()
        } else {
            vec![tail]
        };
        for n in names {
            let n = n.trim();
            let n = n
                .rsplit(" as ")
                .next()
                .unwrap_or(n)
                .rsplit("::")
                .next()
                .unwrap_or(n);
            if !n.is_empty() {
                out.push((n.trim().to_string(), module.trim().to_string()));
            }
        }
    }
    out
}

/// Violations of the layer order in one file of module `module` (path `file` for messages,
/// `is_mod_root` for `X/mod.rs` or `X.rs`); `aliases` from [`root_aliases`].
fn check_file(
    file: &str,
    module: &str,
    is_mod_root: bool,
    src: &str,
    depth: usize,
    aliases: &[(String, String)],
) -> Vec<String> {
    let mut out = Vec::new();
    if rank(module).is_none() {
        out.push(format!(
            "{file}: top-level module `{module}` has no place in the layer order (add it to LAYERS in tests/layers.rs)"
        ));
        return out;
    }
    for mut r in references(src, depth) {
        if let Some((_, m)) = aliases.iter().find(|(n, _)| *n == r.target) {
            r.target = m.clone();
        }
        if allowed(module, &r.target) {
            continue;
        }
        if r.compat && is_mod_root {
            continue;
        }
        let why = match rank(&r.target) {
            None => format!("`{}` is not a known top-level module", r.target),
            Some(_) if r.compat => "a compatibility re-export outside the module's mod.rs".into(),
            Some(_) => format!("`{}` comes after `{module}` in the pipeline", r.target),
        };
        out.push(format!(
            "{file}:{}: `{module}` refers to `crate::{}` ({why})",
            r.line, r.target
        ));
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("read src")
        .map(|e| e.expect("dir entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn no_module_uses_a_later_stage_of_the_pipeline() {
    // `RICCI_LAYERS_SRC` points the check at another tree (e.g. an old revision, to compare).
    let src = std::env::var_os("RICCI_LAYERS_SRC")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(files.len() > 20, "found only {} source files", files.len());
    let aliases = root_aliases(&std::fs::read_to_string(src.join("lib.rs")).expect("lib.rs"));
    assert!(
        aliases.iter().any(|(n, m)| n == "Result" && m == "error"),
        "lib.rs re-exports {aliases:?}"
    );
    let mut violations = Vec::new();
    let mut edges = std::collections::BTreeSet::new();
    for path in &files {
        let rel = path.strip_prefix(&src).unwrap();
        let parts: Vec<String> = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        if parts == ["lib.rs"] {
            continue;
        }
        let module = parts[0].trim_end_matches(".rs").to_string();
        let is_mod_root = parts.len() == 1 || (parts.len() == 2 && parts[1] == "mod.rs");
        // Module depth: `x.rs` and `x/mod.rs` are 1, `x/y.rs` is 2, `x/y/mod.rs` is 2, …
        let depth = parts.len() - usize::from(parts.last().unwrap() == "mod.rs");
        let text = std::fs::read_to_string(path).unwrap();
        let file = format!("crates/ricci/src/{}", rel.display());
        violations.extend(check_file(
            &file,
            &module,
            is_mod_root,
            &text,
            depth,
            &aliases,
        ));
        for r in references(&text, depth) {
            let target = aliases
                .iter()
                .find(|(n, _)| *n == r.target)
                .map_or(r.target, |(_, m)| m.clone());
            if target != module {
                edges.insert((module.clone(), target, r.compat));
            }
        }
    }
    eprintln!("module dependencies (user → used):");
    for (a, b, compat) in &edges {
        let note = if *compat {
            " (compatibility re-export)"
        } else {
            ""
        };
        eprintln!("  {a} → {b}{note}");
    }
    assert!(
        violations.is_empty(),
        "{} import(s) against the layer order:\n{}",
        violations.len(),
        violations.join("\n")
    );
}

#[test]
fn the_check_flags_backward_imports_and_spares_comments_strings_and_marked_re_exports() {
    let fake = r#"//! Docs may mention [`crate::spline`] freely.
use crate::Result;
use crate::numeric::dd::Dd;
use crate::spline::fit;
use crate::{error::Error, layout::dd::Cdd, metric::{Geometry, Scheme}};
fn f() -> Result<()> {
    let s = "crate::atlas::mentioned_in_a_string";
    let x = crate::flow::ricci_flow(); // crate::cut in a comment
    super::super::atlas::thing();
    Ok(())
}

/// Compatibility re-export: moved.
pub use crate::cut::slice;

pub use crate::analysis::spectrum;
"#;
    let aliases =
        root_aliases("pub mod error;\npub use error::{Error, Result};\npub use numeric::simd;\n");
    assert_eq!(
        aliases,
        [("Error", "error"), ("Result", "error"), ("simd", "numeric")]
            .map(|(a, b)| (a.to_string(), b.to_string()))
    );
    let v = check_file("fake/mod.rs", "metric", true, fake, 2, &aliases);
    let lines: Vec<&str> = v.iter().map(|s| s.split(": ").next().unwrap()).collect();
    assert_eq!(
        lines,
        vec![
            "fake/mod.rs:4",  // crate::spline
            "fake/mod.rs:5",  // layout in a group
            "fake/mod.rs:8",  // crate::flow inline
            "fake/mod.rs:16", // unmarked re-export of analysis
            "fake/mod.rs:9",  // super::super::atlas from depth 2
        ],
        "{v:#?}"
    );
    // The marked re-export is allowed only in the module's mod.rs.
    let v = check_file("fake/other.rs", "metric", false, fake, 2, &aliases);
    assert!(
        v.iter().any(|s| s.starts_with("fake/other.rs:14:")),
        "{v:#?}"
    );
    // Same stage and earlier stages are fine; unknown top-level modules are not.
    assert!(check_file("a.rs", "spline", true, fake, 1, &aliases).is_empty());
    assert_eq!(
        check_file("new/mod.rs", "newstage", true, "", 1, &aliases).len(),
        1
    );
    assert!(allowed("analysis", "layout") && !allowed("layout", "analysis"));
    assert!(allowed("numeric", "error") && !allowed("numeric", "mesh"));
    assert!(!allowed("error", "numeric"));
}
