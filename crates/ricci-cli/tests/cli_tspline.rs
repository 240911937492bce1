//! `ricci tspline` fit flags (issue 18): `--correction-gain`, `--rms-marks`, `--area-weights`
//! reach the library (echoed in the JSON, and they change the fit the way their definitions
//! say), bad values are refused with exit code 2, on a generated torus (no `RICCI_MESHES`);
//! and the genus-2 default (the domain-mesh spline) against the input's topology.

use std::path::PathBuf;
use std::process::{Command, Output};

fn ricci(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(args)
        .output()
        .expect("run ricci")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci_cli_tspline_{}_{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("one JSON object on stdout")
}

fn torus() -> PathBuf {
    let d = tmp("mesh");
    let mesh = d.join("torus.off");
    // a thick torus: the vertex areas differ by a factor 3 between the outer and inner rings
    let o = ricci(&[
        "generate",
        "torus",
        "--major",
        "1",
        "--minor",
        "0.5",
        "-n",
        "24",
        "--out",
        mesh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    mesh
}

fn last_step_rms(v: &serde_json::Value) -> f64 {
    v["steps"].as_array().unwrap().last().unwrap()["rms_error_percent"]
        .as_f64()
        .unwrap()
}

/// One fit over the same T-mesh (`--max-iterations 1`, no correction): the area-weighted fit
/// has the smaller area-weighted rms, the plain fit the smaller vertex rms (each minimises its
/// own sum of squares; the fairness weight is 1e-5 of the data term). With `--area-weights`
/// the steps' rms is the weighted one: it equals the report's area-weighted rms, computed by
/// another function; the report's `rms_error_percent` stays the vertex rms.
#[test]
fn area_weights_fit_the_area_weighted_sum_and_the_report_keeps_the_vertex_rms() {
    let mesh = torus();
    let m = mesh.to_str().unwrap();
    let base = [
        "tspline",
        m,
        "--tolerance",
        "0.01%",
        "--max-iterations",
        "1",
        "--initial-faces",
        "16",
        "--max-points-per-face",
        "0",
        "--json",
    ];
    let plain = json(&ricci(&base));
    let mut args = base.to_vec();
    args.push("--area-weights");
    let weighted = json(&ricci(&args));
    assert_eq!(weighted["area_weights"], true);
    assert_eq!(plain["area_weights"], false);
    assert_eq!(plain["control_points"], weighted["control_points"]);
    let f = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    let (pv, pa) = (
        f(&plain, "rms_error_percent"),
        f(&plain, "rms_error_percent_area_weighted"),
    );
    let (wv, wa) = (
        f(&weighted, "rms_error_percent"),
        f(&weighted, "rms_error_percent_area_weighted"),
    );
    assert!((last_step_rms(&plain) - pv).abs() <= 1e-12 * pv, "{plain}");
    assert!(
        (last_step_rms(&weighted) - wa).abs() <= 1e-9 * wa,
        "{weighted}"
    );
    assert!(
        wa < pa,
        "area-weighted rms: weighted fit {wa} vs plain fit {pa}"
    );
    assert!(pv < wv, "vertex rms: plain fit {pv} vs weighted fit {wv}");
}

/// `--correction-gain` and `--rms-marks` are echoed and act: with a rms target and
/// `--rms-marks 1`, each refit of the rms phase splits one face (so the control points grow
/// by a few per iteration, not by the θ rule's many), and a gain of 0.9 stops every correction
/// after its first round (a different fit from the full rounds).
#[test]
fn correction_gain_and_rms_marks_reach_the_fit() {
    let mesh = torus();
    let m = mesh.to_str().unwrap();
    let run = |gain: &str, marks: &str| {
        json(&ricci(&[
            "tspline",
            m,
            "--tolerance",
            "1%",
            "--rms-tolerance",
            "0.001%",
            "--max-iterations",
            "4",
            "--parameter-correction",
            "3",
            "--correction-gain",
            gain,
            "--rms-marks",
            marks,
            "--json",
        ]))
    };
    let greedy = run("0", "1");
    assert_eq!(greedy["rms_marks"], 1);
    assert_eq!(greedy["correction_gain"], 0.0);
    let steps = greedy["steps"].as_array().unwrap();
    let cps: Vec<u64> = steps
        .iter()
        .map(|s| s["control_points"].as_u64().unwrap())
        .collect();
    let theta = run("0", "0");
    let theta_cps: Vec<u64> = theta["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["control_points"].as_u64().unwrap())
        .collect();
    assert!(
        cps.last() < theta_cps.last(),
        "one split per refit {cps:?} vs the θ rule {theta_cps:?}"
    );
    let stopped = run("0.9", "1");
    assert_eq!(stopped["correction_gain"], 0.9);
    assert_ne!(
        stopped["rms_error_percent"], greedy["rms_error_percent"],
        "the gain did not change the fit"
    );
}

#[test]
fn bad_fit_flags_are_refused_with_exit_code_2() {
    for (flag, value) in [
        ("--correction-gain", "1"),
        ("--correction-gain", "-0.1"),
        ("--rms-marks", "1000000"),
    ] {
        let arg = format!("{flag}={value}");
        let o = ricci(&["tspline", "no-such.off", &arg, "--json"]);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(flag), "{flag} {value}: {e}");
    }
}

/// Genus 2, the default: one spline on the quad mesh of the glued strips. Checked against the
/// topology of the input (generated genus 2, χ = −2): the quad mesh is closed, so control
/// points − cells = χ; 2g − 2 = 2 simple zeros, each a vertex of valence 8, so 16 cell sides
/// with a zero at an end; those sides C¹ in the translation chart (G¹: the fit keeps the
/// conditions at the zeros), all the others C². The per-cylinder
/// fit stays reachable by `--per-cylinder`.
#[test]
fn genus_two_default_is_the_domain_mesh_spline_and_per_cylinder_is_an_option() {
    let d = tmp("genus2");
    let mesh = d.join("genus2.off");
    let o = ricci(&[
        "generate",
        "genus",
        "--genus",
        "2",
        "--out",
        mesh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m = mesh.to_str().unwrap();
    let out = d.join("out");
    let v = json(&ricci(&[
        "tspline",
        m,
        "--tolerance",
        "2%",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert_eq!(v["spline"], "domain_mesh", "{v}");
    for key in [
        "control_points",
        "rms_error_percent",
        "max_error_percent",
        "iterations",
        "continuity",
        "seconds",
    ] {
        assert!(!v[key].is_null(), "no {key}: {v}");
    }
    let n = |k: &str| v[k].as_i64().unwrap();
    assert_eq!(n("control_points") - n("cells"), -2, "{v}");
    assert_eq!(n("bezier_patches"), n("cells"));
    let c = &v["continuity"];
    assert_eq!(c["extraordinary_points"], 2);
    assert_eq!(c["at_zeros"]["sides"], 16, "{c}");
    assert_eq!(c["at_zeros"]["class"], "C1", "{c}");
    for k in ["one_interval_from_zeros", "elsewhere"] {
        assert!(c[k]["class"] == "C2" || c[k]["class"] == "C3", "{k}: {c}");
    }
    assert_eq!(v["converged"], true, "{v}");
    assert!(v["max_error_percent"].as_f64().unwrap() <= 2.0, "{v}");
    for f in [
        "tspline.step",
        "tspline.igs",
        "surface.obj",
        "samples.json",
        "tspline.json",
    ] {
        assert!(out.join(f).is_file(), "{f} not written");
    }
    let p = json(&ricci(&[
        "tspline",
        m,
        "--tolerance",
        "2%",
        "--json",
        "--per-cylinder",
    ]));
    assert_eq!(p["spline"], "per_cylinder", "{p}");
    assert!(p["cylinders"].as_array().is_some_and(|c| !c.is_empty()));
}
