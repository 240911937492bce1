//! `ricci spline`: files, JSON keys, exit codes, on a generated genus-2 surface (both chart
//! providers) and a generated torus.

use std::path::PathBuf;
use std::process::{Command, Output};

fn ricci(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(args)
        .output()
        .expect("run ricci")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci_cli_spline_{}_{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn generate(kind: &str, res: &str, path: &std::path::Path) {
    let o = ricci(&["generate", kind, "-n", res, "--out", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("one JSON object on stdout")
}

#[test]
fn genus2_writes_the_surface_net_boundaries_and_report() {
    let d = tmp("g2");
    let mesh = d.join("g2.off");
    generate("genus2", "16", &mesh);
    for charts in ["local", "atlas"] {
        let out = d.join(charts);
        let o = ricci(&[
            "spline",
            mesh.to_str().unwrap(),
            "--charts",
            charts,
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]);
        let v = json(&o);
        for k in [
            "degree",
            "fairness",
            "control_points",
            "domain_faces",
            "rms_error_percent",
            "max_error_percent",
            "continuity",
            "seconds",
        ] {
            assert!(v.get(k).is_some(), "{charts}: key {k} missing");
        }
        assert_eq!(v["degree"], 3);
        assert_eq!(v["genus"], 2);
        assert!(v["singular_vertex"].is_u64());
        let c = &v["continuity"];
        assert_eq!(c["smoothness"], 2, "{charts}: {c}");
        assert!(c["max_seam_normal_jump_deg"].as_f64().unwrap() <= 0.5);
        // Error against the input mesh: a cubic spline of a 16-segment surface stays within a
        // few percent of the diagonal.
        assert!(
            v["max_error_percent"].as_f64().unwrap() < 5.0,
            "{charts}: {v}"
        );
        // The files, and the OBJ's vertex count matches the side JSON.
        let obj = std::fs::read_to_string(out.join("surface.obj")).unwrap();
        let nv = obj.lines().filter(|l| l.starts_with("v ")).count();
        assert!(obj.contains("g fill"));
        let side: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join("surface_vertices.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(side["face"].as_array().unwrap().len(), nv);
        assert_eq!(side["chart"].as_array().unwrap().len(), nv);
        // One closed mesh: every edge in two triangles. Spline triangles use vertices of
        // the spline (face and chart ≥ 0); the fill's own vertices are −1 and only in the fill.
        let (mut group, mut edges) = ("", std::collections::HashMap::new());
        let mut in_spline = vec![false; nv];
        for l in obj.lines() {
            if let Some(g) = l.strip_prefix("g ") {
                group = if g == "fill" { "fill" } else { "spline" };
            } else if let Some(f) = l.strip_prefix("f ") {
                let f: Vec<usize> = f
                    .split(' ')
                    .map(|x| x.parse::<usize>().unwrap() - 1)
                    .collect();
                for k in 0..3 {
                    let (a, b) = (f[k], f[(k + 1) % 3]);
                    *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                    if group == "spline" {
                        in_spline[a] = true;
                    }
                }
            }
        }
        assert!(
            edges.values().all(|&c| c == 2),
            "{charts}: the surface is not closed"
        );
        for (v, &s) in in_spline.iter().enumerate() {
            let (f, c) = (
                side["face"][v].as_i64().unwrap(),
                side["chart"][v].as_i64().unwrap(),
            );
            assert_eq!(s, f >= 0, "{charts}: vertex {v} face {f}");
            assert_eq!(f >= 0, c >= 0, "{charts}: vertex {v} face {f} chart {c}");
        }
        let net = std::fs::read_to_string(out.join("control_net.obj")).unwrap();
        assert_eq!(
            net.lines().filter(|l| l.starts_with("v ")).count() as u64,
            v["control_points"].as_u64().unwrap()
        );
        assert!(std::fs::read_to_string(out.join("boundaries.obj"))
            .unwrap()
            .contains("\nl "));
        let rep: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("spline.json")).unwrap())
                .unwrap();
        assert_eq!(rep["control_points"], v["control_points"]);
    }
}

#[test]
fn torus_has_no_extraordinary_point() {
    let d = tmp("torus");
    let mesh = d.join("t.off");
    generate("torus", "24", &mesh);
    let v = json(&ricci(&[
        "spline",
        mesh.to_str().unwrap(),
        "--degree",
        "2",
        "--fairness",
        "0",
        "--json",
    ]));
    assert_eq!(v["genus"], 1);
    assert!(v["singular_vertex"].is_null());
    assert_eq!(v["active_faces"], v["domain_faces"]);
    assert_eq!(v["continuity"]["smoothness"], 1);
    assert!(v["continuity"]["seams"].as_array().unwrap().is_empty());
}

#[test]
fn bad_arguments_and_bad_input() {
    let d = tmp("bad");
    let mesh = d.join("t.off");
    generate("torus", "12", &mesh);
    let m = mesh.to_str().unwrap();
    for args in [
        vec!["spline", m, "--degree", "7"],
        vec!["spline", m, "--fairness", "3"],
        vec!["spline", m, "--singularity", "x"],
        vec!["spline", m, "--charts", "nope"],
    ] {
        let o = ricci(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(e.trim().lines().count(), 1, "{e}");
    }
    // A sphere has no flat metric with at most one cone: bad input, exit 1, one sentence.
    let s = d.join("s.off");
    let o = ricci(&[
        "generate",
        "sphere",
        "--subdivisions",
        "1",
        "--out",
        s.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let o = ricci(&["spline", s.to_str().unwrap(), "--charts", "local"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&o.stderr).trim().lines().count(), 1);
    let o = ricci(&["spline", d.join("missing.off").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
}
