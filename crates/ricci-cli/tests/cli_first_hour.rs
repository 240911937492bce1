//! A new user's first hour (issue 22, items 3–7): refusals that name the file and say what to
//! try, consistent exit codes and ranges, progress and warnings on stderr, checkerboards that
//! show checks whatever the layout's scale, and output paths that are checked.
//!
//! Runs on small generated surfaces (no `RICCI_MESHES` needed).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn ricci(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(args)
        .output()
        .expect("ricci runs")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci-first-hour-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn err(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn generate(dir: &Path, kind: &str, n: &str) -> PathBuf {
    let p = dir.join(format!("{kind}.off"));
    let o = ricci(&["generate", kind, "-n", n, "--out", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", err(&o));
    p
}

/// A vertex id out of range is a bad argument (exit 2) in every subcommand that takes one,
/// with the valid range.
#[test]
fn vertex_ids_out_of_range_exit_2_with_the_range() {
    let d = tmp("ids");
    let g = generate(&d, "genus2", "12");
    let m = g.to_str().unwrap();
    let out = d.join("o");
    let o_ = out.to_str().unwrap();
    for args in [
        vec!["atlas", m, "--singularity", "99999", "--out", o_],
        vec!["spline", m, "--singularity", "99999", "--out", o_],
        vec!["layout", m, "--base", "99999"],
        vec!["spectrum", m, "--base", "99999"],
        vec!["cut", m, "--base", "99999", "--out", "c.obj"],
    ] {
        let o = ricci(&args);
        let e = err(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains("99999") && e.contains("only"), "{args:?}: {e}");
    }
}

/// Numeric options: the real range in the message, negative values reach our own check
/// (not clap's "use '-- -1'" tip), exit 2.
#[test]
fn numeric_options_state_their_range() {
    let d = tmp("ranges");
    let g = generate(&d, "torus", "12");
    let o = ricci(&[
        "demo",
        "--resolution=-5",
        "--out",
        d.join("x").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(err(&o).contains("between 12 and 200"), "{}", err(&o));
    assert!(
        !d.join("x").exists(),
        "the demo created its folder for a refused argument"
    );
    let o = ricci(&["flow", g.to_str().unwrap(), "--tolerance", "-1"]);
    assert_eq!(o.status.code(), Some(2));
    let e = err(&o);
    assert!(e.contains("--tolerance -1 must be a positive"), "{e}");
    assert!(!e.contains("-- -1"), "{e}");
}

/// `render --out` into a folder that does not exist is refused and creates nothing; a folder
/// given as the mesh gets a sentence that says so and what to try.
#[test]
fn output_folders_and_folders_as_meshes() {
    let d = tmp("paths");
    let g = generate(&d, "torus", "12");
    let missing = d.join("no/such/dir");
    let png = missing.join("s.png");
    let o = ricci(&[
        "render",
        g.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", err(&o));
    assert!(err(&o).contains("does not exist") && err(&o).contains("try: mkdir -p"));
    assert!(
        !d.join("no").exists(),
        "render created {}",
        missing.display()
    );
    for sub in ["info", "flow", "layout"] {
        let o = ricci(&[sub, d.to_str().unwrap()]);
        let e = err(&o);
        assert_eq!(o.status.code(), Some(1), "{sub}: {e}");
        assert!(e.contains("is a folder, not a mesh file"), "{sub}: {e}");
        assert!(e.trim_end().contains("try: ricci batch"), "{sub}: {e}");
    }
}

/// Refusals name the file and end with a "try:" that works.
#[test]
fn spectrum_refusal_names_the_file_and_what_to_try() {
    let d = tmp("spectrum");
    let disk = generate(&d, "disk", "16");
    let o = ricci(&["spectrum", disk.to_str().unwrap()]);
    let e = err(&o);
    assert_eq!(o.status.code(), Some(1));
    assert!(e.contains(disk.to_str().unwrap()), "{e}");
    let try_cmd = e
        .split("try: ")
        .nth(1)
        .and_then(|t| t.split(" (").next())
        .expect("a try: line")
        .trim()
        .to_string();
    let w: Vec<&str> = try_cmd.split_whitespace().collect();
    assert_eq!(w[0], "ricci");
    let o = ricci(&w[1..]);
    assert!(o.status.success(), "`{try_cmd}` fails: {}", err(&o));
}

/// `spline` without `--out` warns that nothing was kept; progress lines go to stderr when it
/// is not a terminal; `seconds` is the whole command's time; the summary says what was written.
#[test]
fn spline_warns_reports_progress_and_total_time() {
    let d = tmp("spline");
    let disk = generate(&d, "disk", "10");
    let t0 = std::time::Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(["spline", disk.to_str().unwrap(), "--json"])
        .env("RICCI_PROGRESS_AFTER", "0")
        .output()
        .unwrap();
    let wall = t0.elapsed().as_secs_f64();
    let e = err(&o);
    assert!(o.status.success(), "{e}");
    assert!(e.contains("warning: no --out"), "{e}");
    assert!(e.contains("try: ricci spline"), "{e}");
    assert!(
        e.lines().filter(|l| l.starts_with("ricci: [")).count() >= 3,
        "no progress lines on stderr: {e}"
    );
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let s = j["seconds"].as_f64().unwrap();
    let inner = j["seconds_spline"].as_f64().unwrap();
    assert!(s >= inner, "seconds {s} < seconds_spline {inner}");
    // The process's own wall time bounds it from above; start-up is small.
    assert!(
        s <= wall && s >= 0.5 * wall - 0.2,
        "seconds {s}, wall {wall}"
    );
    let out = d.join("sp");
    let o = ricci(&[
        "spline",
        disk.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", err(&o));
    assert!(!err(&o).contains("no --out"));
    let so = String::from_utf8_lossy(&o.stdout);
    assert!(so.contains("wrote") && so.contains("surface.obj"), "{so}");
    assert!(out.join("surface.obj").exists());
}

/// `--checker N` draws N checks across the layout whatever its scale: a layout spanning ±100
/// shows black and white checks, not a grey blur of 3 200 checks per image.
#[test]
fn checkerboard_is_scaled_to_the_layout() {
    let d = tmp("checker");
    // A flat square grid of side 200 with its own vt (the layout = the positions).
    let n = 20;
    let mut obj = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (
                200.0 * i as f64 / n as f64 - 100.0,
                200.0 * j as f64 / n as f64 - 100.0,
            );
            obj.push_str(&format!("v {x} {y} 0\nvt {x} {y}\n"));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            let (b, c, e) = (a + 1, a + n + 1, a + n + 2);
            obj.push_str(&format!(
                "f {a}/{a} {b}/{b} {e}/{e}\nf {a}/{a} {e}/{e} {c}/{c}\n"
            ));
        }
    }
    let mesh = d.join("big.obj");
    std::fs::write(&mesh, obj).unwrap();
    let png = d.join("big.png");
    let o = ricci(&[
        "render",
        mesh.to_str().unwrap(),
        "--view",
        "0,0,1",
        "--checker",
        "8",
        "--size",
        "256",
        "--unlit",
        "--out",
        png.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", err(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["paint"], "checker");
    let img = ricci_render::Image::from_png(&std::fs::read(&png).unwrap()).unwrap();
    let (mut dark, mut light, mut all) = (0usize, 0usize, 0usize);
    for y in 0..img.height {
        for x in 0..img.width {
            let p = img.pixel(x, y);
            let l = (p[0] as f64 + p[1] as f64 + p[2] as f64) / (3.0 * 255.0);
            all += 1;
            if l < 0.45 {
                dark += 1;
            } else if l > 0.75 {
                light += 1;
            }
        }
    }
    let (fd, fl) = (dark as f64 / all as f64, light as f64 / all as f64);
    assert!(
        fd > 0.2 && fl > 0.2,
        "dark {fd:.2}, light {fl:.2}: no visible checks"
    );
}

/// A file without texture coordinates (a spherical layout's uv.obj) and `--checker`: a
/// sentence that says so and what to try, instead of a silent solid grey.
#[test]
fn checker_without_uvs_is_explained() {
    let d = tmp("nouv");
    let s = d.join("sphere.off");
    let o = ricci(&[
        "generate",
        "sphere",
        "--subdivisions",
        "2",
        "--out",
        s.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let uv = d.join("sphere-uv.obj");
    let o = ricci(&["layout", s.to_str().unwrap(), "--out", uv.to_str().unwrap()]);
    assert!(o.status.success(), "{}", err(&o));
    let png = d.join("s.png");
    let o = ricci(&[
        "render",
        uv.to_str().unwrap(),
        "--checker",
        "16",
        "--out",
        png.to_str().unwrap(),
    ]);
    let e = err(&o);
    assert!(!o.status.success());
    assert!(
        e.contains("no texture coordinates") && e.contains("try: ricci render"),
        "{e}"
    );
    let t = e.split("try: ").nth(1).unwrap().trim();
    let w: Vec<&str> = t.split_whitespace().collect();
    let o = ricci(&w[1..]);
    assert!(o.status.success(), "`{t}` fails: {}", err(&o));
}

/// With `--json`, every subcommand that reads a mesh answers a failure with exactly one JSON
/// object `{"error": SENTENCE}` on stdout (docs/DESIGN.md §4) — the same sentence as the
/// `error:` line on stderr — both for a refusal (exit 1: a file that does not exist) and for a
/// bad argument (exit 2).
#[test]
fn json_failures_print_one_error_object() {
    let d = tmp("json-errors");
    let missing = d.join("no-such-mesh.off");
    let m = missing.to_str().unwrap();
    let out = d.join("out");
    let o = out.to_str().unwrap();
    let png = d.join("out.png");
    let p = png.to_str().unwrap();
    let obj = d.join("out.obj");
    let c = obj.to_str().unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec!["info", m],
        vec!["cut", m, "--out", c],
        vec!["flow", m],
        vec!["layout", m],
        vec!["param", m, "--out", o],
        vec!["spectrum", m],
        vec!["forms", m],
        vec!["teichmuller", m],
        vec!["atlas", m, "--out", o],
        vec!["spline", m],
        vec!["pou", m],
        vec!["tspline", m],
        vec!["render", m, "--out", p],
    ];
    for args in cases {
        for (extra, code) in [(None, 1), (Some("--no-such-flag"), 2)] {
            let mut a = args.clone();
            a.push("--json");
            a.extend(extra);
            let r = ricci(&a);
            assert_eq!(r.status.code(), Some(code), "{a:?}: {}", err(&r));
            let text = String::from_utf8_lossy(&r.stdout);
            let v: serde_json::Value = serde_json::from_str(text.trim())
                .unwrap_or_else(|e| panic!("{a:?}: stdout is not one JSON object ({e}): {text}"));
            let e = v["error"]
                .as_str()
                .unwrap_or_else(|| panic!("{a:?}: no \"error\" string in {v}"));
            assert!(!e.is_empty(), "{a:?}");
            // Progress lines may come first on stderr; the sentence is the `error:` line.
            let stderr = err(&r);
            let first = stderr
                .lines()
                .find(|l| l.starts_with("error: "))
                .unwrap_or("")
                .to_string();
            assert!(
                first.contains(e.lines().next().unwrap()),
                "{a:?}: stderr {first:?} vs JSON {e:?}"
            );
            if code == 1 {
                assert!(e.contains("no-such-mesh.off"), "{a:?}: {e}");
            }
        }
    }
    assert!(
        !out.exists() && !png.exists() && !obj.exists(),
        "nothing written"
    );
}

/// Item 4: `ricci spectrum --count 10000` (> 120 s in the issue) says up front, on stderr and
/// before any work, that it will take long and roughly how long — whether or not stderr is a
/// terminal (here a pipe). The command is stopped as soon as the line has arrived.
#[test]
fn spectrum_with_a_large_count_estimates_its_time_up_front() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    use std::time::{Duration, Instant};
    let d = tmp("spectrum-count");
    let g = generate(&d, "genus2", "12");
    let mut child = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(["spectrum", g.to_str().unwrap(), "--count", "10000"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("ricci runs");
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let t0 = Instant::now();
    let mut estimate = None;
    while t0.elapsed() < Duration::from_secs(60) {
        match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(l) if l.contains("--count 10000") => {
                estimate = Some(l);
                break;
            }
            Ok(_) => {}
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(_) => break, // stderr closed: the command ended without the line
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    let l = estimate.expect("no estimate on stderr within 60 s of `spectrum --count 10000`");
    // "… expect roughly N s": more than the 120 s the issue measured.
    let secs: f64 = l
        .rsplit("roughly ")
        .next()
        .and_then(|t| t.split_whitespace().next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no number of seconds in: {l}"));
    assert!(secs > 120.0, "estimate {secs} s: {l}");
    let _ = std::fs::remove_dir_all(&d);
}

/// Item 4: `spectrum` prints progress lines on stderr when it is not a terminal (before, its
/// spinner drew nothing there): one per stage, and the search for closed geodesics says it is
/// running. `RICCI_PROGRESS_AFTER=0` lifts the 2 s delay so that a short run shows them too.
#[test]
fn spectrum_prints_progress_lines_when_stderr_is_not_a_terminal() {
    let d = tmp("spectrum-progress");
    let g = generate(&d, "genus2", "12");
    let o = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(["spectrum", g.to_str().unwrap(), "--json"])
        .env("RICCI_PROGRESS_AFTER", "0")
        .output()
        .unwrap();
    let e = err(&o);
    assert!(o.status.success(), "{e}");
    let lines: Vec<&str> = e.lines().filter(|l| l.starts_with("ricci: [")).collect();
    assert!(
        lines.iter().any(|l| l.contains("spectrum")),
        "no progress line of the spectrum's search on stderr: {e}"
    );
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        j["lengths"].as_array().is_some_and(|l| !l.is_empty()),
        "{j}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Item 4: a step that reports nothing while it works (the spline's fairing: one sparse
/// factorisation) still shows the command is alive — a heartbeat line `(still running)` on
/// stderr when it is not a terminal (every 10 s; here every 0.02 s, so the disk's
/// steps of ~0.1 s are long enough). Before the heartbeat the spline printed no such line.
#[test]
fn spline_heartbeat_shows_it_is_alive_during_silent_steps() {
    let d = tmp("spline-heartbeat");
    let disk = generate(&d, "disk", "24");
    let o = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(["spline", disk.to_str().unwrap(), "--json"])
        .env("RICCI_PROGRESS_AFTER", "0")
        .env("RICCI_PROGRESS_EVERY", "0.02")
        .output()
        .unwrap();
    let e = err(&o);
    assert!(o.status.success(), "{e}");
    let beats: Vec<&str> = e
        .lines()
        .filter(|l| l.starts_with("ricci: [") && l.ends_with("(still running)"))
        .collect();
    assert!(!beats.is_empty(), "no heartbeat line on stderr: {e}");
    // Each names a stage the spline reported (not an empty one).
    assert!(
        beats
            .iter()
            .all(|l| ["knots", "fairing", "fit", "fill", "measure"]
                .iter()
                .any(|s| l.contains(&format!("] {s}")))),
        "{beats:?}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Item 7: `layout` says what it wrote (file, and that it holds the input's vertices and faces,
/// which the README's `render --uv` needs) — one line, on stderr, naming the file.
#[test]
fn layout_says_what_it_wrote() {
    let d = tmp("layout-wrote");
    let t = generate(&d, "torus", "16");
    let uv = d.join("uv.obj");
    let o = ricci(&["layout", t.to_str().unwrap(), "--out", uv.to_str().unwrap()]);
    assert!(o.status.success(), "{}", err(&o));
    assert!(uv.exists());
    let said = format!("{}{}", String::from_utf8_lossy(&o.stdout), err(&o));
    let line = said
        .lines()
        .find(|l| l.contains("wrote") && l.contains(uv.to_str().unwrap()))
        .unwrap_or_else(|| panic!("no line saying it wrote {}: {said}", uv.display()));
    // The counts it states are the file's.
    let text = std::fs::read_to_string(&uv).unwrap();
    let nv = text.lines().filter(|l| l.starts_with("v ")).count();
    let nf = text.lines().filter(|l| l.starts_with("f ")).count();
    assert!(line.contains(&format!("{nv} vertices")), "{line} ({nv} v)");
    assert!(line.contains(&format!("{nf} faces")), "{line} ({nf} f)");
    let _ = std::fs::remove_dir_all(&d);
}
