//! `ricci atlas`: one JSON object with the contract keys, the files in --out DIR (atlas.json
//! whose charts reproduce the reported counts, one SVG per chart), exit code 2 for bad
//! arguments and 1 for bad input.

use std::path::PathBuf;
use std::process::Command;

fn ricci() -> Command {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ricci-cli-atlas-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn generate(kind: &str, file: &str, extra: &[&str]) -> PathBuf {
    let mesh = scratch(file);
    let o = ricci()
        .args(["generate", kind])
        .args(extra)
        .arg("--out")
        .arg(&mesh)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    mesh
}

#[test]
fn atlas_of_a_generated_genus2_surface() {
    let mesh = generate("genus2", "g2.off", &["-n", "24"]);
    let out = scratch("g2-atlas");
    let o = ricci()
        .arg("atlas")
        .arg(&mesh)
        .args(["--singularity", "auto", "--out"])
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for k in [
        "singular_vertex",
        "charts",
        "max_transition_error",
        "area_distortion",
        "flipped_faces",
        "seconds",
    ] {
        assert!(v.get(k).is_some(), "missing key {k}");
    }
    assert!(v["singular_vertex"].is_u64());
    assert_eq!(v["flipped_faces"], 0);
    assert!(v["max_transition_error"].as_f64().unwrap() <= 1e-9);
    assert!(v["flow"]["converged"].as_bool().unwrap());
    let charts = v["charts"].as_u64().unwrap() as usize;
    assert!(charts >= 2);
    // The file holds the charts: every face in the central chart, home charts in range.
    let f: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("atlas.json")).unwrap()).unwrap();
    let list = f["chart_faces"].as_array().unwrap();
    assert_eq!(list.len(), charts);
    let nf = f["triangles"].as_array().unwrap().len();
    assert_eq!(list[0]["faces"].as_array().unwrap().len(), nf);
    let homes = f["home_chart"].as_array().unwrap();
    assert_eq!(homes.len(), nf);
    assert!(homes
        .iter()
        .all(|h| h.is_null() || (h.as_u64().unwrap() as usize) < charts));
    for c in 0..charts {
        let svg = std::fs::read_to_string(out.join(format!("chart-{c}.svg"))).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    }
    assert!(out.join("overview.svg").is_file());
}

#[test]
fn atlas_of_a_disk_has_no_singular_vertex() {
    let mesh = generate("disk", "disk.off", &["-n", "24"]);
    let out = scratch("disk-atlas");
    let o = ricci()
        .arg("atlas")
        .arg(&mesh)
        .arg("--out")
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["singular_vertex"].is_null());
    assert_eq!(v["singular_vertices"].as_array().unwrap().len(), 0);
    assert_eq!(v["charts"], 1);
}

#[test]
fn bad_arguments_and_bad_input() {
    let mesh = generate("genus2", "g2b.off", &["-n", "16"]);
    let out = scratch("bad");
    for args in [
        vec!["--singularity", "middle"],
        vec!["--singularity", "99999999"],
        vec!["--cones", "1=abc"],
        vec!["--scheme", "nonsense"],
    ] {
        let o = ricci()
            .arg("atlas")
            .arg(&mesh)
            .args(&args)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(!String::from_utf8_lossy(&o.stderr).trim().is_empty());
    }
    // Cones violating Gauss–Bonnet: bad input, exit 1, one sentence, nothing written.
    let o = ricci()
        .arg("atlas")
        .arg(&mesh)
        .args(["--cones", "1=-pi", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("Gauss–Bonnet"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.join("atlas.json").exists());
    let missing = scratch("missing.off");
    let o = ricci()
        .arg("atlas")
        .arg(&missing)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
}
