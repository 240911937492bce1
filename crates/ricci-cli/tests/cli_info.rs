//! `ricci info` as a user runs it: exit codes, one-line errors on stderr, the JSON contract.

use std::path::PathBuf;
use std::process::{Command, Output};

fn ricci(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(args)
        .output()
        .expect("the ricci binary runs")
}

fn temp_file(name: &str, content: &[u8]) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci-cli-info-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, content).unwrap();
    p
}

fn meshes() -> Option<PathBuf> {
    let d = ricci_meshes()?;
    d.is_dir().then_some(d)
}

/// Exit code 1, nothing on stdout, exactly one line on stderr; returns that line.
fn refused(path: &str, json: bool) -> String {
    let mut args = vec!["info", path];
    if json {
        args.push("--json");
    }
    let out = ricci(&args);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "{path}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{path}: {stderr}");
    if json {
        // `{"error": sentence}` on stdout, the same sentence as on stderr.
        let v: serde_json::Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|_| panic!("{path}: stdout is not one JSON object"));
        assert_eq!(
            format!("error: {}", v["error"].as_str().unwrap_or("")),
            stderr.trim(),
            "{path}"
        );
    } else {
        assert!(out.stdout.is_empty(), "{path}: stdout not empty");
    }
    stderr
}

const CONTRACT: [&str; 10] = [
    "vertices",
    "edges",
    "faces",
    "components",
    "boundary_loops",
    "euler_characteristic",
    "genus",
    "orientable",
    "manifold",
    "min_angle_deg",
];

fn info_json(path: &str) -> serde_json::Value {
    let out = ricci(&["info", path, "--json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("stdout is one JSON value");
    for k in CONTRACT {
        assert!(v.get(k).is_some(), "missing key {k}");
    }
    v
}

#[test]
fn json_report_of_a_square_pyramid() {
    // A square pyramid: a quad base (triangulated) and four triangles: V=5, F=6, E=9, χ=2.
    let off = "OFF\n5 5 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n";
    let p = temp_file("pyramid.off", off.as_bytes());
    let v = info_json(p.to_str().unwrap());
    assert_eq!(v["vertices"], 5);
    assert_eq!(v["faces"], 6);
    assert_eq!(v["edges"], 9);
    assert_eq!(v["euler_characteristic"], 2);
    assert_eq!(v["genus"], 0);
    assert_eq!(v["boundary_loops"], 0);
    assert_eq!(v["components"], 1);
    assert_eq!(v["orientable"], true);
    assert_eq!(v["manifold"], true);
    assert_eq!(v["triangulated_polygons"], 1);
    // The base's right angles are split by the diagonal into 45° angles; the apex angles of
    // the side faces are 2·atan(0.5/√1.25) = 48.19°: so the minimum is 45°.
    let min = v["min_angle_deg"].as_f64().unwrap();
    assert!((min - 45.0).abs() < 1e-9, "{min}");
    assert_eq!(v["per_component"].as_array().unwrap().len(), 1);
    // Text output works too and prints nothing on stderr.
    let out = ricci(&["info", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stderr.is_empty());
    assert!(String::from_utf8_lossy(&out.stdout).contains("5 vertices"));
}

#[test]
fn bad_files_exit_1_with_one_line() {
    let p = temp_file("bad.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n");
    let e = refused(p.to_str().unwrap(), false);
    assert!(
        e.contains("bad.off") && e.contains("line 6") && e.contains("vertex 5"),
        "{e}"
    );
    let e = refused(p.to_str().unwrap(), true);
    assert!(e.contains("vertex 5"), "{e}");
    let p = temp_file("empty.ply", b"");
    let e = refused(p.to_str().unwrap(), true);
    assert!(e.contains("empty"), "{e}");
    let e = refused("/nonexistent/dir/mesh.obj", false);
    assert!(e.contains("mesh.obj"), "{e}");
}

#[test]
fn real_negative_examples_are_refused() {
    let Some(dir) = meshes() else {
        eprintln!("note: RICCI_MESHES is not set; skipping cow.obj / moebius.obj");
        return;
    };
    let cow = dir.join("cow.obj");
    let e = refused(cow.to_str().unwrap(), false);
    assert!(
        e.contains("cow.obj") && e.contains("non-manifold vertex"),
        "{e}"
    );
    let moebius = dir.join("moebius.obj");
    let e = refused(moebius.to_str().unwrap(), true);
    assert!(
        e.contains("moebius.obj") && e.contains("not orientable"),
        "{e}"
    );
}

#[test]
fn multi_component_teapot_is_reported_per_component() {
    let Some(dir) = meshes() else {
        eprintln!("note: RICCI_MESHES is not set; skipping teapot.obj");
        return;
    };
    let v = info_json(dir.join("teapot.obj").to_str().unwrap());
    assert_eq!(v["components"], 5);
    let per = v["per_component"].as_array().unwrap();
    assert_eq!(per.len(), 5);
    // The parts add up to the whole (SOURCES.md: V 1202, F 2256, E 3456, b 8, χ 2).
    let sum = |k: &str| per.iter().map(|c| c[k].as_i64().unwrap()).sum::<i64>();
    assert_eq!(sum("vertices"), 1202);
    assert_eq!(sum("faces"), 2256);
    assert_eq!(sum("edges"), 3456);
    assert_eq!(sum("boundary_loops"), 8);
    assert_eq!(sum("euler_characteristic"), 2);
    for c in per {
        let b = c["boundary_loop_lengths"].as_array().unwrap().len() as i64;
        assert_eq!(b, c["boundary_loops"].as_i64().unwrap());
        // χ = 2 − 2g − b per component.
        assert_eq!(
            c["euler_characteristic"].as_i64().unwrap(),
            2 - 2 * c["genus"].as_i64().unwrap() - b
        );
    }
}

#[test]
fn bad_arguments_exit_2() {
    for args in [
        &["info"][..],
        &["info", "a.obj", "--bogus"][..],
        &["nonsense-command"][..],
    ] {
        let out = ricci(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}

#[path = "../../ricci/tests/ricci_meshes/mod.rs"]
mod ricci_meshes;
use ricci_meshes::ricci_meshes;
