//! `ricci param`: one command from a mesh to a UV map on its own faces.

use std::path::PathBuf;
use std::process::Command;

#[path = "../../ricci/tests/ricci_meshes/mod.rs"]
mod ricci_meshes;

fn bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_ricci"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci-cli-param-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn generate(kind: &str, file: &str) -> PathBuf {
    let p = tmp(file);
    let st = Command::new(bin())
        .args(["generate", kind, "--out"])
        .arg(&p)
        .status()
        .unwrap();
    assert!(st.success());
    p
}

/// Faces and `f v/vt` triples of an OBJ.
fn obj_faces(text: &str) -> (usize, usize, Vec<[(usize, usize); 3]>) {
    let (mut v, mut vt, mut f) = (0, 0, Vec::new());
    for l in text.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        match w.first() {
            Some(&"v") => v += 1,
            Some(&"vt") => vt += 1,
            Some(&"f") => {
                let c: Vec<(usize, usize)> = w[1..]
                    .iter()
                    .map(|x| {
                        let mut it = x.split('/');
                        let a = it.next().unwrap().parse().unwrap();
                        let b = it.next().and_then(|b| b.parse().ok()).unwrap_or(0);
                        (a, b)
                    })
                    .collect();
                f.push([c[0], c[1], c[2]]);
            }
            _ => {}
        }
    }
    (v, vt, f)
}

/// A torus: the OBJ keeps the input's vertices and faces, seams show as extra `vt`, the JSON
/// reports 0 flipped faces and no cones.
#[test]
fn torus_uv_obj_is_on_the_input_faces() {
    let mesh = generate("torus", "torus.obj");
    let out = tmp("torus-uv.obj");
    let svg = tmp("torus-uv.svg");
    let o = Command::new(bin())
        .arg("param")
        .arg(&mesh)
        .arg("--out")
        .arg(&out)
        .arg("--svg")
        .arg(&svg)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["flipped_faces"], 0);
    assert_eq!(v["uv_faces"], "input");
    assert_eq!(v["cone_count"], 0);
    assert!(v["qc_p95"].as_f64().unwrap() < 1.5);
    let (nv_in, _, f_in) = obj_faces(&std::fs::read_to_string(&mesh).unwrap());
    let (nv, nvt, f) = obj_faces(&std::fs::read_to_string(&out).unwrap());
    assert_eq!(nv, nv_in);
    assert_eq!(f.len(), f_in.len());
    for (a, b) in f.iter().zip(&f_in) {
        assert_eq!([a[0].0, a[1].0, a[2].0], [b[0].0, b[1].0, b[2].0]);
    }
    assert!(nvt > nv, "seams need extra vt ({nvt} vt, {nv} v)");
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
}

/// Cones given by vertex and angle on a sphere; a bad cone list is a usage error; --sphere
/// maps onto the unit sphere.
#[test]
fn given_cones_usage_errors_and_sphere() {
    let mesh = generate("sphere", "sphere.obj");
    let o = Command::new(bin())
        .arg("param")
        .arg(&mesh)
        .args(["--cones", "0=pi,1=pi,2=pi,3=pi", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["cone_count"], 4);
    assert_eq!(v["flipped_faces"], 0);
    let bad = Command::new(bin())
        .arg("param")
        .arg(&mesh)
        .args(["--cones", "0=banana", "--json"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let s = Command::new(bin())
        .arg("param")
        .arg(&mesh)
        .args(["--sphere", "--json"])
        .output()
        .unwrap();
    assert!(s.status.success(), "{}", String::from_utf8_lossy(&s.stderr));
    let v: serde_json::Value = serde_json::from_slice(&s.stdout).unwrap();
    assert_eq!(v["mode"], "sphere");
    assert_eq!(v["flipped_faces"], 0);
}

/// `--seams free` on a genus-2 surface: the JSON says which seams (top level and per chart),
/// the OBJ keeps the input's faces with seams as extra `vt`, no face flips; the default is
/// `rigid`; an unknown value is a usage error.
#[test]
fn free_seams_are_reported_and_written_on_the_input_faces() {
    let mesh = generate("genus2", "genus2.obj");
    let out = tmp("genus2-free.obj");
    let o = Command::new(bin())
        .arg("param")
        .arg(&mesh)
        .args(["--cones", "6", "--seams", "free", "--json", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["seams"], "free");
    assert_eq!(v["chart_details"][0]["seams"], "free");
    assert_eq!(v["flipped_faces"], 0);
    assert_eq!(v["cone_count"], 6);
    if v["uv_faces"] == "input" {
        let (nv_in, _, f_in) = obj_faces(&std::fs::read_to_string(&mesh).unwrap());
        let (nv, nvt, f) = obj_faces(&std::fs::read_to_string(&out).unwrap());
        assert_eq!((nv, f.len()), (nv_in, f_in.len()));
        assert!(nvt > nv, "seams need extra vt ({nvt} vt, {nv} v)");
    }
    let d = Command::new(bin())
        .arg("param")
        .arg(&mesh)
        .args(["--cones", "6", "--json"])
        .output()
        .unwrap();
    assert!(d.status.success(), "{}", String::from_utf8_lossy(&d.stderr));
    let v: serde_json::Value = serde_json::from_slice(&d.stdout).unwrap();
    assert_eq!(v["seams"], "rigid");
    let bad = Command::new(bin())
        .arg("param")
        .arg(&mesh)
        .args(["--seams", "loose", "--json"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown seams 'loose'"));
}

/// A map with flipped triangles is never written silently: stderr warns exactly when the
/// report counts flipped faces (camel with three cones and free seams has had some: its scale
/// factors span ~e^±10), and says nothing of flips otherwise.
#[test]
fn flipped_triangles_are_warned_on_stderr() {
    let Some(meshes) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES not set: skipped");
        return;
    };
    let mesh = meshes.join("camel.off");
    if !mesh.exists() {
        eprintln!("{} missing: skipped", mesh.display());
        return;
    }
    for (cones, seams) in [("3", "free"), ("8", "rigid")] {
        let out = tmp(&format!("camel-{cones}-{seams}.obj"));
        let o = Command::new(bin())
            .arg("param")
            .arg(&mesh)
            .args(["--cones", cones, "--seams", seams, "--json", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let flipped = v["flipped_faces"].as_u64().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        let warned = err.contains("flipped triangle");
        assert_eq!(
            warned,
            flipped > 0,
            "{cones} cones, {seams} seams: {flipped} flipped, stderr: {err}"
        );
    }
}
