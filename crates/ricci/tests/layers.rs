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
//!
//! The same file checks two more rules of `docs/DESIGN.md` §2 on the workspace's non-test code
//! (`crates/*/src`): **size** — no file over [`MAX_FILE_LINES`] lines and no function over
//! [`MAX_FN_LINES`] lines, inline `#[cfg(test)]` modules not counted, except the entries of
//! [`SIZE_ALLOWED`] — and **citations** — every `docs/…` path cited anywhere under `crates/` or
//! in `.ci/` exists.

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

// ---------------------------------------------------------------------------------------------
// Size: files and functions

/// Longest non-test source file (lines).
const MAX_FILE_LINES: usize = 900;
/// Longest non-test function (lines from `fn` to its closing brace).
const MAX_FN_LINES: usize = 150;

/// Exceptions to the size rules, to be removed as the files are split: `(path from the
/// workspace root, function name or "" for the file's length, why)`. An entry names one file
/// exactly and one finding in it (a whole-file entry does not excuse the file's long
/// functions), so that a new long function or file anywhere is caught. An entry that is no
/// longer needed is printed (not a failure, so that branches that split a file do not collide
/// with the one that edits this list). Empty since session 4: every file and function is within
/// the limits.
const SIZE_ALLOWED: &[(&str, &str, &str)] = &[];

/// Byte ranges of the inline `#[cfg(test)] mod … { … }` blocks of stripped code.
fn test_modules(code: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(k) = code[i..].find("#[cfg(test)]") {
        let p = i + k;
        i = p + "#[cfg(test)]".len();
        let rest = code[i..].trim_start();
        let rest = rest.strip_prefix("pub ").unwrap_or(rest).trim_start();
        let Some(rest) = rest.strip_prefix("mod ") else {
            continue;
        };
        let (_, after) = ident_at(rest, 0);
        if !rest[after..].trim_start().starts_with('{') {
            continue; // `mod tests;` in another file
        }
        let open = i + (code[i..].len() - rest.len()) + after + rest[after..].find('{').unwrap();
        let close = matching_brace(code, open);
        out.push((p, close));
        i = close;
    }
    out
}

/// Position of the `}` matching the `{` at byte `open` (end of the text if unbalanced).
fn matching_brace(code: &str, open: usize) -> usize {
    let mut depth = 0usize;
    for (j, c) in code[open..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return open + j;
                }
            }
            _ => {}
        }
    }
    code.len()
}

/// Functions with a body outside test modules: `(name, first line, number of lines)`.
fn functions(code: &str, tests: &[(usize, usize)]) -> Vec<(String, usize, usize)> {
    let line_of = |pos: usize| code[..pos].matches('\n').count() + 1;
    let bytes = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(k) = code[i..].find("fn ") {
        let p = i + k;
        i = p + 3;
        if p > 0 && is_ident(bytes[p - 1] as char) {
            continue;
        }
        if tests.iter().any(|&(a, b)| a <= p && p <= b) {
            continue;
        }
        let (name, after) = ident_at(code, i);
        if name.is_empty() {
            continue; // `fn(u32) -> bool`, a pointer type
        }
        // The body: the first `{` outside parentheses and brackets; a `;` first means none.
        let mut depth = 0i32;
        let mut body = None;
        for (j, c) in code[after..].char_indices() {
            match c {
                '(' | '[' => depth += 1,
                ')' | ']' => depth -= 1,
                ';' if depth <= 0 => break,
                '{' if depth <= 0 => {
                    body = Some(after + j);
                    break;
                }
                _ => {}
            }
        }
        let Some(open) = body else {
            continue;
        };
        let close = matching_brace(code, open);
        let first = line_of(p);
        out.push((name.to_string(), first, line_of(close) - first + 1));
    }
    out
}

/// Size violations of one file (`rel`: path from the workspace root) before the allow-list:
/// `(function name or "", message)`.
fn size_findings(rel: &str, src: &str) -> Vec<(String, String)> {
    let code = strip(src);
    let tests = test_modules(&code);
    let test_lines: usize = tests
        .iter()
        .map(|&(a, b)| code[a..=b.min(code.len() - 1)].matches('\n').count() + 1)
        .sum();
    let lines = src.lines().count().saturating_sub(test_lines);
    let mut out = Vec::new();
    if lines > MAX_FILE_LINES {
        out.push((
            String::new(),
            format!("{rel}: {lines} lines outside tests (at most {MAX_FILE_LINES})"),
        ));
    }
    for (name, line, n) in functions(&code, &tests) {
        if n > MAX_FN_LINES {
            out.push((
                name.clone(),
                format!("{rel}:{line}: fn `{name}` has {n} lines (at most {MAX_FN_LINES})"),
            ));
        }
    }
    out
}

/// Whether a finding `(fn name or "" for the file's length)` in `rel` is on the allow-list
/// (same path, same name); marks the entry used.
fn size_allowed(rel: &str, name: &str, used: &mut [bool]) -> bool {
    size_allowed_in(SIZE_ALLOWED, rel, name, used)
}

/// Whether `list` excuses finding `name` ("" for the file's length) in file `rel`; marks the
/// entry used.
fn size_allowed_in(list: &[(&str, &str, &str)], rel: &str, name: &str, used: &mut [bool]) -> bool {
    for (k, &(path, func, _)) in list.iter().enumerate() {
        if rel == path && func == name {
            used[k] = true;
            return true;
        }
    }
    false
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn no_file_over_900_lines_and_no_function_over_150_lines() {
    let root = workspace_root();
    let mut files = Vec::new();
    for krate in ["ricci", "ricci-render", "ricci-cli"] {
        rust_files(&root.join("crates").join(krate).join("src"), &mut files);
    }
    assert!(files.len() > 40, "found only {} source files", files.len());
    let mut used = vec![false; SIZE_ALLOWED.len()];
    let mut violations = Vec::new();
    let mut allowed = 0;
    for path in &files {
        let rel = path
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let src = std::fs::read_to_string(path).unwrap();
        for (name, msg) in size_findings(&rel, &src) {
            if size_allowed(&rel, &name, &mut used) {
                allowed += 1;
                eprintln!("  allowed: {msg}");
            } else {
                violations.push(msg);
            }
        }
    }
    eprintln!("{allowed} size finding(s) on the allow-list");
    for (k, &(path, func, _)) in SIZE_ALLOWED.iter().enumerate() {
        if !used[k] {
            eprintln!("allow-list entry no longer needed: {path} {func}");
        }
    }
    assert!(
        violations.is_empty(),
        "{} file(s)/function(s) too long (split them along their jobs, docs/DESIGN.md §2):\n{}",
        violations.len(),
        violations.join("\n")
    );
}

#[test]
fn the_size_check_counts_functions_and_files_without_tests() {
    let mut src = String::from("//! fn in a comment { {\nfn short() -> u32 {\n    1\n}\n");
    src += "trait T {\n    fn declared(&self) -> [u8; 2];\n}\n";
    src += "pub fn long(x: &[f64; 3], f: fn(u32) -> bool) -> Vec<u32> {\n";
    for _ in 0..150 {
        src += "    let s = \"}\";\n";
    }
    src += "    vec![]\n}\n";
    src += "#[cfg(test)]\nmod tests {\n    fn also_long() {\n";
    src += &"        let _ = 1;\n".repeat(2000);
    src += "    }\n}\n";
    let code = strip(&src);
    let tests = test_modules(&code);
    assert_eq!(tests.len(), 1);
    let fns = functions(&code, &tests);
    let names: Vec<(&str, usize, usize)> =
        fns.iter().map(|(n, a, b)| (n.as_str(), *a, *b)).collect();
    assert_eq!(names, vec![("short", 2, 3), ("long", 8, 153)]);
    let found = size_findings("x.rs", &src);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].1.starts_with("x.rs:8: fn `long` has 153 lines"),
        "{found:?}"
    );
    // The test module's 2000 lines do not count; 900 lines of code do.
    let big = "fn f() {}\n".repeat(MAX_FILE_LINES + 1);
    assert_eq!(size_findings("big.rs", &big).len(), 1);
    assert!(size_findings("big.rs", &(big.clone() + &src)).len() == 2);
    // The list's semantics, on a list of its own (SIZE_ALLOWED itself is empty now).
    let list = [
        ("crates/ricci/src/a/b.rs", "", "whole file"),
        ("crates/ricci/src/a/b.rs", "long_one", "one function"),
    ];
    let mut used = vec![false; list.len()];
    assert!(size_allowed_in(
        &list,
        "crates/ricci/src/a/b.rs",
        "",
        &mut used
    ));
    // Exact entries: no directory prefix, and a file's length does not excuse its functions.
    assert!(!size_allowed_in(
        &list,
        "crates/ricci/src/a/other.rs",
        "",
        &mut used
    ));
    assert!(!size_allowed_in(
        &list,
        "crates/ricci/src/a/",
        "",
        &mut used
    ));
    assert!(!size_allowed_in(
        &list,
        "crates/ricci/src/a/b.rs",
        "new_function",
        &mut used
    ));
    assert!(size_allowed_in(
        &list,
        "crates/ricci/src/a/b.rs",
        "long_one",
        &mut used
    ));
    assert!(!size_allowed_in(
        &list,
        "crates/ricci/src/a/b.rs",
        "long",
        &mut used
    ));
    assert_eq!(used, vec![true, true]);
}

// ---------------------------------------------------------------------------------------------
// Citations of `docs/`

/// The `docs/…` paths cited in a text: a `docs/` not preceded by a path or identifier
/// character, up to the first character that cannot be part of a path; a trailing `.` or `,`
/// (end of a sentence) is dropped.
fn cited_docs(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut i = 0;
        while let Some(k) = line[i..].find("docs/") {
            let p = i + k;
            i = p + "docs/".len();
            let prev = line[..p].chars().next_back();
            if prev.is_some_and(|c| is_ident(c) || c == '/' || c == '.' || c == '-') {
                continue;
            }
            let len = line[p..]
                .find(|c: char| !(is_ident(c) || matches!(c, '/' | '.' | '-')))
                .unwrap_or(line.len() - p);
            let path = line[p..p + len].trim_end_matches(['.', ',']);
            if path.len() > "docs/".len() {
                out.push((n + 1, path.to_string()));
            }
        }
    }
    out
}

/// Lines that cite the design notes by bare name (`DESIGN.md` not preceded by `docs/`): the
/// notes live in `docs/`, and the citation should say so.
fn bare_design_citations(text: &str) -> Vec<usize> {
    let name = concat!("DESIGN", ".md");
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut i = 0;
        while let Some(k) = line[i..].find(name) {
            let p = i + k;
            i = p + name.len();
            if !line[..p].ends_with("docs/") {
                out.push(n + 1);
            }
        }
    }
    out
}

/// The sections cited after each cited `docs/…` path in a text: `(line, path, "3")` for the
/// path followed by `§3`, one entry per number of a list `§2, §4` (a backtick after the path
/// is allowed).
fn cited_sections(text: &str) -> Vec<(usize, String, String)> {
    let mut out = Vec::new();
    for (line, path) in cited_docs(text) {
        let Some(row) = text.lines().nth(line - 1) else {
            continue;
        };
        let mut from = 0;
        while let Some(k) = row[from..].find(&path) {
            let mut rest = row[from + k + path.len()..].trim_start_matches('`');
            from += k + path.len();
            while let Some(r) = rest.trim_start().strip_prefix('§') {
                let len = r
                    .find(|c: char| !(c.is_ascii_digit() || c == '.'))
                    .unwrap_or(r.len());
                let num = r[..len].trim_end_matches('.');
                if !num.is_empty() {
                    out.push((line, path.clone(), num.to_string()));
                }
                rest = r[len..].strip_prefix(',').unwrap_or("");
            }
        }
    }
    out
}

/// Whether a markdown text has a heading numbered `section` (`## 3. Title` for "3").
fn has_section(markdown: &str, section: &str) -> bool {
    markdown.lines().any(|l| {
        let t = l.trim_start();
        t.starts_with('#')
            && t.trim_start_matches('#')
                .split_whitespace()
                .next()
                .is_some_and(|num| num.trim_end_matches('.') == section)
    })
}

fn all_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let name = p.file_name().unwrap_or_default().to_string_lossy();
        if name.starts_with('.') && name != ".ci" || name == "target" {
            continue;
        }
        if p.is_dir() {
            all_files(&p, out);
        } else if p
            .extension()
            .is_some_and(|e| ["rs", "py", "toml", "md"].contains(&e.to_str().unwrap_or("")))
            || p.parent()
                .and_then(Path::file_name)
                .is_some_and(|n| n == ".ci")
        {
            out.push(p);
        }
    }
}

#[test]
fn every_docs_path_cited_in_the_code_exists() {
    let root = workspace_root();
    let mut files = Vec::new();
    all_files(&root.join("crates"), &mut files);
    all_files(&root.join(".ci"), &mut files);
    let mut cited = 0;
    let mut missing = Vec::new();
    for path in &files {
        let Ok(text) = std::fs::read_to_string(path) else {
            continue;
        };
        let rel = path.strip_prefix(&root).unwrap_or(path);
        for (line, doc) in cited_docs(&text) {
            cited += 1;
            if !root.join(&doc).exists() {
                missing.push(format!(
                    "{}:{line}: cites {doc}, which is not there",
                    rel.display()
                ));
            }
        }
        for (line, doc, section) in cited_sections(&text) {
            let Ok(md) = std::fs::read_to_string(root.join(&doc)) else {
                continue; // reported above
            };
            if !has_section(&md, &section) {
                missing.push(format!(
                    "{}:{line}: cites {doc} §{section}, which has no such section",
                    rel.display()
                ));
            }
        }
        if path.ends_with("tests/layers.rs") {
            continue; // this file names the rule
        }
        for line in bare_design_citations(&text) {
            missing.push(format!(
                "{}:{line}: cites {} without its folder; write docs/{}",
                rel.display(),
                concat!("DESIGN", ".md"),
                concat!("DESIGN", ".md")
            ));
        }
    }
    assert!(
        cited > 0,
        "no docs/ citation found under {}",
        root.display()
    );
    assert!(
        missing.is_empty(),
        "{} citation(s) of missing docs:\n{}",
        missing.len(),
        missing.join("\n")
    );
}

#[test]
fn the_citation_check_reads_paths_and_leaves_other_words() {
    let d = concat!("do", "cs/");
    let text = format!(
        "//! see {d}DESIGN.md §3, and ({d}notes/wave2-arch.md).\n// not a citation: mydocs/x.md, ../{d}y\nlet s = \"{d}a-b_c.md,\";\n"
    );
    let got: Vec<(usize, String)> = cited_docs(&text);
    let want = [
        (1, format!("{d}DESIGN.md")),
        (1, format!("{d}notes/wave2-arch.md")),
        (3, format!("{d}a-b_c.md")),
    ];
    assert_eq!(got, want.to_vec());
    // Sections after a cited path, also in lists and after a backtick; other § are not.
    let n = concat!("DESIGN", ".md");
    let text = format!("see `{d}{n}` §2, §4.1. and {d}x.md §3; not §9\n");
    let want = [
        (1, format!("{d}{n}"), "2".to_string()),
        (1, format!("{d}{n}"), "4.1".to_string()),
        (1, format!("{d}x.md"), "3".to_string()),
    ];
    assert_eq!(cited_sections(&text), want.to_vec());
    let md = "# T\n## 1. A\n### 4.1 B\n## 12. C\n";
    assert!(has_section(md, "1") && has_section(md, "4.1") && has_section(md, "12"));
    assert!(!has_section(md, "2") && !has_section(md, "4"));
    // A bare name is a finding; one with its folder is not.
    let text = format!("a {n} §3\nb {d}{n} §3\nc ({n})\n");
    assert_eq!(bare_design_citations(&text), vec![1, 3]);
}

// ---------------------------------------------------------------------------------------------
// The metric as one value at the stage fronts (issue 21: the intrinsic-metric type is what "the
// flow produces and the cut, layout, atlas and spline consume").

/// The stages whose public functions take a metric as one `IntrinsicMetric` (geometry,
/// lengths and their double-double tail together), never as a bare slice of lengths.
const METRIC_STAGES: &[&str] = &["cut", "layout", "atlas", "param", "spline", "analysis"];

/// Parameter names that mean "a metric given as bare numbers".
const BARE_METRIC_PARAMS: &[&str] = &["lengths", "lengths_lo", "input_lengths"];

/// Public functions that still take bare lengths: `(file under crates/ricci/src, function,
/// why)`. An entry no longer needed is printed, not a failure (as for [`SIZE_ALLOWED`]).
const BARE_METRIC_ALLOWED: &[(&str, &str, &str)] = &[
    (
        "spline/manifold/charts.rs",
        "face_side_lengths",
        "a per-face kernel (like metric::corner_angles), called in the charts' inner loops \
         with the lengths the charts hold",
    ),
    (
        "spline/manifold/charts.rs",
        "star_frame",
        "a per-vertex kernel (like metric::corner_angles), called in the charts' inner loops \
         with the lengths the charts hold",
    ),
];

/// Split a parameter list at its top-level commas.
fn split_params(params: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let (mut depth, mut start) = (0i32, 0);
    for (j, c) in params.char_indices() {
        let arrow = c == '>' && params[..j].ends_with('-');
        match c {
            '(' | '[' | '<' | '{' => depth += 1,
            '>' if arrow => {}
            ')' | ']' | '>' | '}' => depth -= 1,
            ',' if depth == 0 => {
                out.push(&params[start..j]);
                start = j + 1;
            }
            _ => {}
        }
    }
    out.push(&params[start..]);
    out.into_iter().filter(|p| !p.trim().is_empty()).collect()
}

/// Public functions (`pub fn`, not `pub(crate)`/`pub(super)`, outside inline test modules)
/// with a parameter named in [`BARE_METRIC_PARAMS`] of a type of `f64`s: `(function, line,
/// parameter)`. Comments and strings are not read.
fn bare_metric_params(src: &str) -> Vec<(String, usize, String)> {
    let code = strip(src);
    let tests = test_modules(&code);
    let line_of = |pos: usize| code[..pos].matches('\n').count() + 1;
    let bytes = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(k) = code[i..].find("pub fn ") {
        let p = i + k;
        i = p + "pub fn ".len();
        if p > 0 && is_ident(bytes[p - 1] as char) || tests.iter().any(|&(a, b)| a <= p && p <= b) {
            continue;
        }
        let (name, after) = ident_at(&code, i);
        // The parameter list: the first `(` outside the generics `<…>`.
        let mut angle = 0i32;
        let mut open = None;
        for (j, c) in code[after..].char_indices() {
            match c {
                '<' => angle += 1,
                '>' if !code[..after + j].ends_with('-') => angle -= 1,
                '(' if angle == 0 => {
                    open = Some(after + j);
                    break;
                }
                _ => {}
            }
        }
        let Some(open) = open else {
            continue;
        };
        let mut depth = 0i32;
        let mut close = code.len();
        for (j, c) in code[open..].char_indices() {
            match c {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        close = open + j;
                        break;
                    }
                }
                _ => {}
            }
        }
        for param in split_params(&code[open + 1..close]) {
            let Some((pname, ty)) = param.split_once(':') else {
                continue;
            };
            let pname = pname.trim().trim_start_matches("mut ").trim();
            if BARE_METRIC_PARAMS.contains(&pname) && ty.contains("f64") {
                let ty = ty.split_whitespace().collect::<Vec<_>>().join(" ");
                out.push((name.to_string(), line_of(p), format!("{pname}: {ty}")));
            }
        }
    }
    out
}

#[test]
fn stage_fronts_take_the_metric_as_one_value() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut used = vec![false; BARE_METRIC_ALLOWED.len()];
    let (mut violations, mut files) = (Vec::new(), 0);
    for stage in METRIC_STAGES {
        let mut paths = Vec::new();
        rust_files(&src.join(stage), &mut paths);
        let root_file = src.join(format!("{stage}.rs"));
        if root_file.exists() {
            paths.push(root_file);
        }
        for path in paths {
            files += 1;
            let rel = path
                .strip_prefix(&src)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            let text = std::fs::read_to_string(&path).unwrap();
            for (name, line, param) in bare_metric_params(&text) {
                if size_allowed_in(BARE_METRIC_ALLOWED, &rel, &name, &mut used) {
                    eprintln!("  allowed: crates/ricci/src/{rel}:{line}: `{name}` takes `{param}`");
                } else {
                    violations.push(format!(
                        "crates/ricci/src/{rel}:{line}: pub fn `{name}` takes `{param}`"
                    ));
                }
            }
        }
    }
    assert!(files > 60, "found only {files} source files of the stages");
    for (k, &(path, func, _)) in BARE_METRIC_ALLOWED.iter().enumerate() {
        if !used[k] {
            eprintln!("allow-list entry no longer needed: {path} {func}");
        }
    }
    assert!(
        violations.is_empty(),
        "{} public function(s) take a metric as bare lengths; take one \
         `&ricci::metric::IntrinsicMetric` instead (or make the function pub(crate)):\n{}",
        violations.len(),
        violations.join("\n")
    );
}

#[test]
fn the_metric_check_flags_bare_lengths_of_public_functions_only() {
    let src = r#"//! pub fn in_a_doc(lengths: &[f64]) {}
use crate::metric::IntrinsicMetric;
pub fn bare(mesh: &Mesh, lengths: &[f64]) -> f64 {
    lengths[0] + "pub fn in_a_string(lengths: &[f64]) {}".len() as f64
}
pub(crate) fn internal(mesh: &Mesh, lengths: &[f64]) {}
pub fn whole(mesh: &Mesh, metric: &IntrinsicMetric, u: &[f64]) {}
pub fn generic<S: Space<Point = C>, F: Fn(u32) -> f64>(
    f: F,
    mut lengths: Vec<f64>,
    seed: Option<u32>,
) {}
impl X {
    pub fn tail(&self, x: u32, lengths_lo: Option<&[f64]>) {}
    pub fn count(&self, lengths: usize) {}
}
// pub fn commented(lengths: &[f64]) {}
#[cfg(test)]
mod tests {
    pub fn helper(lengths: &[f64]) {}
}
"#;
    let found = bare_metric_params(src);
    let names: Vec<(&str, usize)> = found.iter().map(|(n, l, _)| (n.as_str(), *l)).collect();
    assert_eq!(
        names,
        [("bare", 3), ("generic", 8), ("tail", 14)],
        "{found:?}"
    );
    assert_eq!(found[0].2, "lengths: &[f64]");
    assert_eq!(found[1].2, "lengths: Vec<f64>");
    assert_eq!(found[2].2, "lengths_lo: Option<&[f64]>");
    assert_eq!(
        split_params(" a: u32, b: HashMap<u32, f64>, c: fn(u8) -> u8, d: (u8, u8),\n"),
        [
            " a: u32",
            " b: HashMap<u32, f64>",
            " c: fn(u8) -> u8",
            " d: (u8, u8)"
        ]
    );
}
