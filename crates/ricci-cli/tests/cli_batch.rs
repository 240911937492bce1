//! `ricci batch` as a user runs it: one line per mesh with the command's own JSON or its
//! refusal sentence, a rerun that does nothing, and a batch killed half-way that a rerun
//! completes without redoing what was done.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn ricci(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(args)
        .output()
        .expect("the ricci binary runs")
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci-cli-batch-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn summary(out: &Output) -> Value {
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the batch prints its summary as JSON")
}

fn lines(dir: &Path) -> Vec<Value> {
    std::fs::read_to_string(dir.join("results.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The error sentence `ricci COMMAND MESH` prints on its own (stderr, after "error: ").
fn own_sentence(args: &[&str]) -> String {
    let out = ricci(args);
    assert_ne!(out.status.code(), Some(0));
    let e = String::from_utf8_lossy(&out.stderr);
    e.lines()
        .rev()
        .find_map(|l| l.strip_prefix("error: "))
        .unwrap()
        .to_string()
}

const NON_MANIFOLD: &str =
    "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n";

#[test]
fn batch_records_results_and_refusals_and_a_rerun_does_nothing() {
    let d = temp_dir("small");
    let torus = d.join("torus.off");
    let disk = d.join("disk.obj");
    let bad = d.join("bad.off");
    assert!(
        ricci(&["generate", "torus", "--out", torus.to_str().unwrap()])
            .status
            .success()
    );
    assert!(
        ricci(&["generate", "disk", "--out", disk.to_str().unwrap()])
            .status
            .success()
    );
    std::fs::write(&bad, NON_MANIFOLD).unwrap();
    let manifest = d.join("manifest.txt");
    std::fs::write(
        &manifest,
        "# relative to the manifest\ntorus.off\n\ndisk.obj\nbad.off\nmissing.off\n",
    )
    .unwrap();
    let out = d.join("out");
    let (m, o) = (manifest.to_str().unwrap(), out.to_str().unwrap());
    let args = [
        "batch",
        m,
        "--out",
        o,
        "--jobs",
        "2",
        "--json",
        "--",
        "flow",
        "--target",
        "free-boundary",
        "--out",
        "{out}/metrics/{stem}.json",
    ];
    let s = summary(&ricci(&args));
    assert_eq!(s["meshes"], 4);
    assert_eq!(s["ran"], 4);
    assert_eq!(s["ok"], 1, "{s}"); // the torus has no boundary: free-boundary refuses it
    assert_eq!(s["failed"], 3);
    let l = lines(&out);
    assert_eq!(l.len(), 4);
    // Manifest order, paths relative to the manifest's folder.
    let names: Vec<&str> = l.iter().map(|x| x["mesh"].as_str().unwrap()).collect();
    assert!(names[0].ends_with("torus.off") && names[3].ends_with("missing.off"));
    // Each line's result is what the command prints on its own, each error its sentence.
    for x in &l {
        let mesh = x["mesh"].as_str().unwrap();
        let alone = ricci(&["flow", mesh, "--target", "free-boundary", "--json"]);
        if x["status"] == "ok" {
            assert!(mesh.ends_with("disk.obj"));
            let own: Value = serde_json::from_slice(&alone.stdout).unwrap();
            for key in [
                "max_curvature_error",
                "iterations",
                "gauss_bonnet_error",
                "area",
            ] {
                assert_eq!(x["result"][key], own[key], "{key}");
            }
            assert!(x["error"].is_null());
            // {out} and {stem} were substituted: the metric file exists.
            let metric = x["result"]["out"].as_str().unwrap();
            assert!(metric.starts_with(o) && Path::new(metric).is_file());
        } else {
            assert_eq!(x["status"], "error");
            assert_eq!(x["exit_code"], 1);
            assert!(x["result"].is_null());
            let sentence = own_sentence(&["flow", mesh, "--target", "free-boundary"]);
            assert_eq!(x["error"].as_str().unwrap(), sentence);
        }
    }
    assert!(l[2]["error"]
        .as_str()
        .unwrap()
        .contains("non-manifold edge"));
    // A second run does nothing and leaves the same lines.
    let before = std::fs::read_to_string(out.join("results.jsonl")).unwrap();
    let s = summary(&ricci(&args));
    assert_eq!(
        (s["ran"].as_u64(), s["skipped"].as_u64()),
        (Some(0), Some(4))
    );
    assert_eq!(
        std::fs::read_to_string(out.join("results.jsonl")).unwrap(),
        before
    );
    // --retry-failed runs the three refused meshes again, and only those.
    let mut retry = args.to_vec();
    retry.insert(6, "--retry-failed");
    let s = summary(&ricci(&retry));
    assert_eq!(
        (s["ran"].as_u64(), s["skipped"].as_u64()),
        (Some(3), Some(1))
    );
}

#[test]
fn a_batch_killed_half_way_is_completed_by_a_rerun() {
    let d = temp_dir("kill");
    let g2 = d.join("g2.off");
    assert!(ricci(&[
        "generate",
        "genus",
        "--genus",
        "2",
        "-n",
        "100",
        "--out",
        g2.to_str().unwrap()
    ])
    .status
    .success());
    // Eight different paths (results are per path), each a hyperbolic flow of ~0.2 s.
    let n = 8;
    let mut manifest = String::new();
    for i in 0..n {
        let p = d.join(format!("copy{i}.off"));
        std::fs::copy(&g2, &p).unwrap();
        manifest.push_str(&format!("copy{i}.off\n"));
    }
    std::fs::write(d.join("manifest.txt"), manifest).unwrap();
    let out = d.join("out");
    let results = out.join("results");
    let (m, o) = (
        d.join("manifest.txt").display().to_string(),
        out.display().to_string(),
    );
    let args = [
        "batch",
        &m,
        "--out",
        &o,
        "--jobs",
        "1",
        "--json",
        "--",
        "flow",
        "--geometry",
        "hyperbolic",
    ];
    let count = || {
        std::fs::read_dir(&results)
            .map(|r| {
                r.flatten()
                    .filter(|e| e.file_name().to_string_lossy().ends_with(".json"))
                    .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
                    .count()
            })
            .unwrap_or(0)
    };
    let mut child = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while count() < 2 && t0.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL: no clean-up of any kind
    child.wait().unwrap();
    let k = count();
    assert!(
        (2..n).contains(&k),
        "killed after {k} of {n} results (expected half-way)"
    );
    // Every result left behind is whole JSON.
    for e in std::fs::read_dir(&results).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.ends_with(".json") && !name.starts_with('.') {
            let v: Value = serde_json::from_slice(&std::fs::read(e.path()).unwrap()).unwrap();
            assert_eq!(v["status"], "ok");
        }
    }
    let s = summary(&ricci(&args));
    assert_eq!(s["skipped"].as_u64(), Some(k as u64));
    assert_eq!(s["ran"].as_u64(), Some((n - k) as u64));
    assert_eq!(s["ok"].as_u64(), Some(n as u64), "{s}");
    let l = lines(&out);
    assert_eq!(l.len(), n);
    for (i, x) in l.iter().enumerate() {
        assert!(x["mesh"]
            .as_str()
            .unwrap()
            .ends_with(&format!("copy{i}.off")));
        assert_eq!(x["result"]["converged"], true);
        // All copies are the same surface: the same metric, to the last digit.
        assert_eq!(
            x["result"]["max_curvature_error"],
            l[0]["result"]["max_curvature_error"]
        );
    }
    // No temporary file is left.
    let leftovers = std::fs::read_dir(&results)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .count();
    assert_eq!(leftovers, 0);
}

#[test]
fn a_timeout_and_bad_arguments_are_recorded_not_fatal() {
    let d = temp_dir("timeout");
    let g2 = d.join("g2.off");
    assert!(ricci(&[
        "generate",
        "genus",
        "--genus",
        "2",
        "-n",
        "100",
        "--out",
        g2.to_str().unwrap()
    ])
    .status
    .success());
    let out = d.join("out");
    let (m, o) = (d.display().to_string(), out.display().to_string());
    // A time limit far below one flow: status `timeout`, and the batch goes on.
    let s = summary(&ricci(&[
        "batch",
        &m,
        "--out",
        &o,
        "--timeout",
        "0.001",
        "--json",
        "--",
        "layout",
    ]));
    assert_eq!(s["meshes"], 1);
    let l = lines(&out);
    assert_eq!(l[0]["status"], "timeout");
    assert!(l[0]["error"].as_str().unwrap().contains("time limit"));
    // An option the command does not know: status `error` with exit code 2 and clap's line.
    let out2 = d.join("out2");
    let s = summary(&ricci(&[
        "batch",
        &m,
        "--out",
        out2.to_str().unwrap(),
        "--json",
        "--",
        "info",
        "--no-such-option",
    ]));
    assert_eq!(s["failed"], 1);
    let l = lines(&out2);
    assert_eq!(l[0]["exit_code"], 2);
    assert!(l[0]["error"].as_str().unwrap().contains("--no-such-option"));
}

#[test]
fn batch_over_the_shared_meshes_with_flow() {
    let Some(meshes) = ricci_meshes() else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let d = temp_dir("shared");
    let o = d.join("out").display().to_string();
    let dir = meshes.display().to_string();
    let args = [
        "batch",
        &dir,
        "--out",
        &o,
        "--jobs",
        "2",
        "--timeout",
        "600",
        "--json",
        "--",
        "flow",
    ];
    let s = summary(&ricci(&args));
    let files = std::fs::read_dir(&meshes)
        .unwrap()
        .flatten()
        .filter(|e| {
            let n = e.file_name().to_string_lossy().to_lowercase();
            [".obj", ".off", ".ply", ".stl"]
                .iter()
                .any(|x| n.ends_with(x))
        })
        .count();
    assert_eq!(s["meshes"].as_u64(), Some(files as u64));
    assert_eq!(s["ran"], s["meshes"]);
    assert!(s["ok"].as_u64().unwrap() >= 1, "{s}");
    let l = lines(&d.join("out"));
    assert_eq!(l.len(), files);
    let by_name = |n: &str| {
        l.iter()
            .find(|x| x["mesh"].as_str().unwrap().ends_with(n))
            .unwrap()
    };
    // Refused meshes carry the library's sentence, the same as running the command alone.
    for (name, words) in [
        ("cow.obj", "non-manifold vertex"),
        ("moebius.obj", "not orientable"),
        ("teapot.obj", "components"),
    ] {
        let x = by_name(name);
        if !Path::new(x["mesh"].as_str().unwrap()).exists() {
            continue;
        }
        assert_eq!(x["status"], "error", "{name}");
        let e = x["error"].as_str().unwrap();
        assert!(e.contains(words), "{name}: {e}");
        assert_eq!(e, own_sentence(&["flow", x["mesh"].as_str().unwrap()]));
    }
    // genus3 (genus 3): hyperbolic by default (the surface chooses its geometry).
    let g = by_name("genus3.off");
    if Path::new(g["mesh"].as_str().unwrap()).exists() {
        assert_eq!(g["status"], "ok", "{g}");
        assert_eq!(g["result"]["geometry"], "hyperbolic");
    }
    // Kitten (genus 1): a flat metric, as the command reports alone.
    let k = by_name("kitten.nf20k.off");
    assert_eq!(k["status"], "ok");
    assert_eq!(k["result"]["converged"], true);
    for x in &l {
        assert!(
            ["ok", "error"].contains(&x["status"].as_str().unwrap()),
            "{x}"
        );
        assert_eq!(x["status"] == "ok", x["error"].is_null());
    }
    // Issue 22 item 2: `ricci flow MESH` without flags chooses its geometry and boundary
    // condition and converges on every shared mesh that `ricci layout` accepts: every mesh the
    // flow did not converge on (or refused) is refused by `layout` too.
    for x in &l {
        let mesh = x["mesh"].as_str().unwrap();
        if x["status"] == "ok" {
            assert_eq!(x["result"]["converged"], true, "{mesh}: {x}");
            assert!(
                x["result"]["gauss_bonnet_error"].as_f64().unwrap() < 1e-6,
                "{mesh}: {x}"
            );
        } else if !x["error"].as_str().unwrap_or("").contains("time limit") {
            let o = Command::new(env!("CARGO_BIN_EXE_ricci"))
                .args(["layout", mesh])
                .output()
                .unwrap();
            assert!(
                !o.status.success(),
                "{mesh}: layout succeeds but flow failed: {}",
                x["error"]
            );
        }
    }
    // The second run does nothing.
    let s = summary(&ricci(&args));
    assert_eq!(
        (s["ran"].as_u64(), s["skipped"].as_u64()),
        (Some(0), Some(files as u64))
    );
}

/// `$RICCI_MESHES` as a folder (a relative path is taken from the workspace root, as CI
/// gives it).
fn ricci_meshes() -> Option<PathBuf> {
    ricci_meshes_dir::ricci_meshes().filter(|d| d.is_dir())
}

#[path = "../../ricci/tests/ricci_meshes/mod.rs"]
mod ricci_meshes_dir;
