//! Issue 22 item 3: every refusal a user can hit names the file, is one sentence on one line of
//! stderr (`error: …`), ends with one `try: …` and exits with code 1 — and the suggested `ricci`
//! command parses (`RICCI_PARSE_ONLY`), the cheap ones run successfully.
//!
//! One bad input per kind of refusal: a missing file, an unknown format, a malformed line, an
//! index out of range, a non-finite coordinate, a non-manifold edge, a topology a command does
//! not support (atlas, spline, pou, forms, tspline, spectrum on a sphere), a geometry that
//! violates Gauss–Bonnet, a UV file of another mesh, the spline's budget. Small files made here
//! (no `RICCI_MESHES` needed).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn ricci(dir: &Path, args: &[&str], parse_only: bool) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ricci"));
    c.current_dir(dir).args(args);
    if parse_only {
        c.env("RICCI_PARSE_ONLY", "1");
    }
    c.output().expect("ricci runs")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci-refusals-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let files: [(&str, &str); 7] = [
        (
            "tetra.off",
            "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n",
        ),
        (
            "nonmanifold.off",
            "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 -1 0\n3 0 1 2\n3 0 1 3\n3 0 1 4\n",
        ),
        ("truncated.off", "OFF\n3 1 0\n0 0 0\n1 0\n"),
        ("badindex.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
        ("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n"),
        ("notes.txt", "hello\n"),
        // Two triangles: a UV file whose faces are not the tetrahedron's.
        (
            "square.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
        ),
    ];
    for (name, text) in files {
        std::fs::write(d.join(name), text).unwrap();
    }
    d
}

#[test]
fn every_refusal_names_the_file_and_ends_with_a_working_try() {
    let d = scratch("all");
    let g = ricci(
        &d,
        &["generate", "genus2", "-n", "12", "--out", "g2.off"],
        false,
    );
    assert!(g.status.success(), "{}", String::from_utf8_lossy(&g.stderr));
    // (arguments, the file the message must name, run the suggestion for real)
    let cases: Vec<(Vec<&str>, &str, bool)> = vec![
        (vec!["info", "missing.off"], "missing.off", true),
        (vec!["info", "notes.txt"], "notes.txt", true),
        (vec!["info", "truncated.off"], "truncated.off", true),
        (vec!["info", "badindex.off"], "badindex.off", true),
        (vec!["flow", "nan.off"], "nan.off", true),
        (vec!["layout", "nonmanifold.off"], "nonmanifold.off", true),
        (vec!["atlas", "tetra.off", "--out", "at"], "tetra.off", true),
        (vec!["spline", "tetra.off"], "tetra.off", true),
        (vec!["pou", "tetra.off"], "tetra.off", true),
        (vec!["forms", "tetra.off"], "tetra.off", true),
        (vec!["tspline", "tetra.off"], "tetra.off", true),
        (vec!["spectrum", "tetra.off"], "tetra.off", true),
        (
            vec!["layout", "tetra.off", "--geometry", "hyperbolic"],
            "tetra.off",
            true,
        ),
        (
            vec![
                "render",
                "tetra.off",
                "--uv",
                "square.obj",
                "--checker",
                "8",
                "--out",
                "t.png",
            ],
            "square.obj",
            true,
        ),
        // The budget: the suggestion raises it (parsed, not run: it is the long computation).
        (
            vec!["spline", "g2.off", "--budget", "0.01"],
            "g2.off",
            false,
        ),
    ];
    for (args, file, run) in cases {
        let o = ricci(&d, &args, false);
        let e = String::from_utf8_lossy(&o.stderr).into_owned();
        assert_eq!(o.status.code(), Some(1), "{args:?}: {e}");
        let lines: Vec<&str> = e.lines().filter(|l| !l.trim().is_empty()).collect();
        assert_eq!(lines.len(), 1, "{args:?}: one line on stderr, got {e}");
        let line = lines[0];
        assert!(line.starts_with("error: "), "{args:?}: {line}");
        assert!(
            line.contains(file),
            "{args:?}: does not name {file}: {line}"
        );
        assert_eq!(line.matches("try: ").count(), 1, "{args:?}: {line}");
        let suggestion = line.split("try: ").nth(1).unwrap();
        // The command, without the explanation in parentheses.
        let cmd = suggestion.split(" (").next().unwrap().trim();
        assert!(!cmd.contains(';'), "{args:?}: the try: is not last: {line}");
        let w: Vec<&str> = cmd.split_whitespace().collect();
        if w[0] != "ricci" {
            // A shell command (ls, file, sed): it runs.
            let o = Command::new(w[0]).current_dir(&d).args(&w[1..]).output();
            let o = o.unwrap_or_else(|_| panic!("{args:?}: `{cmd}` does not start"));
            assert!(o.status.success(), "{args:?}: `{cmd}` fails");
            continue;
        }
        let p = ricci(&d, &w[1..], true);
        assert!(p.status.success(), "{args:?}: `{cmd}` does not parse");
        if run {
            let o = ricci(&d, &w[1..], false);
            assert!(
                o.status.success(),
                "{args:?}: `{cmd}` fails: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// `pou` without `--out` says that nothing was written (as `spline` does), with a working
/// `try:`; with `--out` it does not.
#[test]
fn pou_without_out_warns() {
    let d = scratch("pou");
    let g = ricci(
        &d,
        &["generate", "genus2", "-n", "12", "--out", "g2.off"],
        false,
    );
    assert!(g.status.success());
    let o = ricci(&d, &["pou", "g2.off", "--json"], false);
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("no --out") && e.contains("try: ricci pou g2.off --out"),
        "{e}"
    );
    let o = ricci(&d, &["pou", "g2.off", "--out", "p"], false);
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success() && !e.contains("no --out"), "{e}");
    assert!(d.join("p/surface.obj").is_file());
    let _ = std::fs::remove_dir_all(&d);
}
