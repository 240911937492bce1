//! `ricci pou`: files, JSON keys, exit codes, on a generated genus-2 surface; the local
//! quadratics against constant control points (error and smoothness), a surface with boundary.

use std::path::PathBuf;
use std::process::{Command, Output};

fn ricci(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(args)
        .output()
        .expect("run ricci")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci_cli_pou_{}_{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("one JSON object on stdout")
}

fn count(obj: &str, prefix: &str) -> usize {
    obj.lines().filter(|l| l.starts_with(prefix)).count()
}

#[test]
fn genus2_writes_surface_control_points_and_report() {
    let d = tmp("g2");
    let mesh = d.join("g2.off");
    let o = ricci(&[
        "generate",
        "genus2",
        "-n",
        "16",
        "--out",
        mesh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut reports = Vec::new();
    for degree in ["0", "2"] {
        let out = d.join(format!("local{degree}"));
        let v = json(&ricci(&[
            "pou",
            mesh.to_str().unwrap(),
            "--local-degree",
            degree,
            "--samples",
            "300",
            "--continuity-edges",
            "500",
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]));
        for k in [
            "control_points",
            "rms_error_percent",
            "max_error_percent",
            "continuity",
            "chart_independence",
            "seconds",
        ] {
            assert!(v.get(k).is_some(), "key {k} missing: {v}");
        }
        // C∞ in practice: the jumps of orders 0–3 at rounding level.
        let jumps: Vec<f64> = v["continuity"]["relative_jumps"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(jumps.len(), 4);
        assert!(jumps.iter().all(|&j| j <= 1e-10), "{v}");
        // The files hold what the report says.
        let surf = std::fs::read_to_string(out.join("surface.obj")).unwrap();
        assert_eq!(
            count(&surf, "v ") as u64,
            v["tessellation"]["vertices"].as_u64().unwrap()
        );
        let cp = std::fs::read_to_string(out.join("control_points.obj")).unwrap();
        assert_eq!(
            count(&cp, "v ") as u64,
            v["control_points"].as_u64().unwrap()
        );
        let file: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("pou.json")).unwrap()).unwrap();
        assert_eq!(file["control_points"], v["control_points"]);
        reports.push(v);
    }
    // Local quadratics approximate better than constant control points (same bases, same
    // fairness): the blend reproduces quadratics instead of constants only.
    let rms = |v: &serde_json::Value| v["rms_error_percent"].as_f64().unwrap();
    assert!(
        rms(&reports[1]) < rms(&reports[0]),
        "local quadratics rms {} ≥ constants rms {}",
        rms(&reports[1]),
        rms(&reports[0])
    );
}

#[test]
fn bad_arguments_exit_2_and_a_torus_exits_1() {
    let d = tmp("bad");
    let mesh = d.join("t.off");
    let o = ricci(&[
        "generate",
        "torus",
        "-n",
        "12",
        "--out",
        mesh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m = mesh.to_str().unwrap();
    for args in [
        vec!["pou", m, "--local-degree", "3"],
        vec!["pou", m, "--radius", "0.5"],
        vec!["pou", m, "--tessellation", "0"],
    ] {
        let o = ricci(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
    }
    // A torus has no hyperbolic structure: one sentence, exit 1.
    let o = ricci(&["pou", m]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("Euler characteristic"), "{err}");
}
