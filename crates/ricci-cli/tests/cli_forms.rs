//! `ricci forms`: the contract keys, the modulus of a torus of revolution against its closed
//! form, the conformal net written as OBJ (its uv triangles tile a fundamental parallelogram
//! of area Im τ, positively oriented), zeros of a genus-2 form (2g − 2 = 2, one placed by
//! `--zeros`), and the exit codes for bad arguments (2) and bad input (1).

use std::path::PathBuf;
use std::process::Command;

fn ricci() -> Command {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ricci-cli-forms-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn run_json(args: &[&std::ffi::OsStr]) -> serde_json::Value {
    let o = ricci().args(args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("stdout is one JSON object")
}

/// uv triangles of an OBJ with `vt` and `f v/vt` lines: signed areas.
fn uv_areas(text: &str) -> Vec<f64> {
    let mut vt = Vec::new();
    let mut areas = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("vt") => {
                let x: f64 = it.next().unwrap().parse().unwrap();
                let y: f64 = it.next().unwrap().parse().unwrap();
                vt.push([x, y]);
            }
            Some("f") => {
                let t: Vec<[f64; 2]> = it
                    .map(|c| vt[c.split('/').nth(1).unwrap().parse::<usize>().unwrap() - 1])
                    .collect();
                areas.push(
                    0.5 * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1])
                        - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1])),
                );
            }
            _ => {}
        }
    }
    areas
}

#[test]
fn torus_modulus_and_conformal_net() {
    let mesh = scratch("torus.off");
    let o = ricci()
        .args([
            "generate", "torus", "--major", "1", "--minor", "0.4", "-n", "64", "--out",
        ])
        .arg(&mesh)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let obj = scratch("torus_net.obj");
    let png = scratch("torus_net.png");
    let v = run_json(&[
        "forms".as_ref(),
        mesh.as_os_str(),
        "--out".as_ref(),
        obj.as_os_str(),
        "--png".as_ref(),
        png.as_os_str(),
        "--json".as_ref(),
    ]);
    for key in [
        "genus",
        "period_matrix",
        "modulus",
        "zeros",
        "seconds",
        "quality",
    ] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }
    assert_eq!(v["genus"], 1);
    let im = v["modulus"][1].as_f64().unwrap();
    let want = (1.0f64 - 0.16).sqrt() / 0.4;
    assert!(
        (im - want).abs() / want < 3e-3,
        "modulus {im} vs closed form {want}"
    );
    assert_eq!(v["zero_count"], 0);
    // The net tiles the fundamental parallelogram (a-period 1, b-period τ): area Im Ω.
    let areas = uv_areas(&std::fs::read_to_string(&obj).unwrap());
    let total: f64 = areas.iter().sum();
    let im_omega = v["period_matrix"]["im"][0][0].as_f64().unwrap();
    assert!(
        (total - im_omega).abs() < 1e-9 * im_omega,
        "uv area {total} vs Im Ω {im_omega}"
    );
    assert!(areas.iter().all(|&a| a > 0.0), "a uv triangle is reversed");
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}

#[test]
fn genus2_zeros_and_placement() {
    let mesh = scratch("g2.off");
    let o = ricci()
        .args(["generate", "genus2", "--out"])
        .arg(&mesh)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = run_json(&["forms".as_ref(), mesh.as_os_str(), "--json".as_ref()]);
    assert_eq!(v["genus"], 2);
    assert_eq!(v["zero_count"], 2);
    let om = &v["period_matrix"];
    for part in ["re", "im"] {
        let a = om[part][0][1].as_f64().unwrap();
        let b = om[part][1][0].as_f64().unwrap();
        assert!((a - b).abs() < 1e-8, "Ω not symmetric: {a} vs {b}");
    }
    assert!(v["im_eigenvalues"][0].as_f64().unwrap() > 0.0);
    let v = run_json(&[
        "forms".as_ref(),
        mesh.as_os_str(),
        "--zeros".as_ref(),
        "40".as_ref(),
        "--json".as_ref(),
    ]);
    assert_eq!(v["zero_count"], 2);
    let zs: Vec<u64> = v["zeros"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|z| z["vertex"].as_u64())
        .collect();
    assert!(zs.contains(&40), "zero not placed at vertex 40: {zs:?}");
}

#[test]
fn bad_arguments_and_bad_input() {
    let mesh = scratch("g2b.off");
    let o = ricci()
        .args(["generate", "genus2", "--out"])
        .arg(&mesh)
        .output()
        .unwrap();
    assert!(o.status.success());
    let o = ricci()
        .arg("forms")
        .arg(&mesh)
        .args(["--zeros", "1,2,3", "--json"])
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["error"].as_str().unwrap().contains("at most 2"));
    let sphere = scratch("sphere.off");
    let o = ricci()
        .args(["generate", "sphere", "--out"])
        .arg(&sphere)
        .output()
        .unwrap();
    assert!(o.status.success());
    let o = ricci().arg("forms").arg(&sphere).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("genus-0"), "{err}");
}
