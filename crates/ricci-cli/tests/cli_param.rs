//! `ricci param`: one command from a mesh to a UV map on its own faces.

use std::f64::consts::PI;
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
    // Gauss–Bonnet: 1 or 2 cones cannot flatten a sphere (curvatures sum to 4π, each < 2π);
    // 3 can.
    for k in ["1", "2", "3"] {
        let o = Command::new(bin())
            .arg("param")
            .arg(&mesh)
            .args(["--cones", k, "--json"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.success(), k == "3", "--cones {k}: {err}");
        if k != "3" {
            assert_eq!(o.status.code(), Some(1), "--cones {k}");
            assert!(err.contains("needs at least 3 cones"), "--cones {k}: {err}");
        }
    }
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

/// Corner UVs of an OBJ's faces: `uv[3f + i]` from the `vt` of corner `i` of face `f`, with
/// the `v` index of every corner.
fn obj_corner_uv(text: &str) -> (Vec<[f64; 2]>, Vec<usize>) {
    let vt: Vec<[f64; 2]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .map(|l| {
            let w: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [w[0], w[1]]
        })
        .collect();
    let (_, _, f) = obj_faces(text);
    let uv = f.iter().flat_map(|t| t.map(|(_, b)| vt[b - 1])).collect();
    let v = f.iter().flat_map(|t| t.map(|(a, _)| a)).collect();
    (uv, v)
}

/// Checks of a written UV OBJ that do not trust the program: every UV triangle has positive
/// signed area (recomputed from the `vt` lines), and every edge whose two sides have
/// different `vt` (a seam) has the same UV length on both sides (relative 1e-6 of the longer,
/// or 1e-9 of the layout's size): the two sides differ by the seam's transition, a rigid
/// motion for rigid seams, and free seams keep lengths too (`u = 0` on both sides). Returns
/// (flipped triangles, seam edges, worst length mismatch).
fn check_uv_obj(text: &str) -> (usize, usize, f64) {
    use std::collections::HashMap;
    let (uv, v) = obj_corner_uv(text);
    let nf = uv.len() / 3;
    let flipped = (0..nf)
        .filter(|&f| {
            let q = &uv[3 * f..3 * f + 3];
            let a = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
            a.is_nan() || a <= 0.0
        })
        .count();
    let len = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let mut sides: HashMap<(usize, usize), (usize, usize)> = HashMap::new();
    let (mut seams, mut worst) = (0, 0.0f64);
    for f in 0..nf {
        for i in 0..3 {
            let (c, d) = (3 * f + i, 3 * f + (i + 1) % 3);
            if let Some((c2, d2)) = sides.remove(&(v[d], v[c])) {
                // The twin runs d → c: its corners c2 (at v[d]) and d2 (at v[c]).
                if uv[c] != uv[d2] || uv[d] != uv[c2] {
                    seams += 1;
                    let (l1, l2) = (len(uv[c], uv[d]), len(uv[c2], uv[d2]));
                    let m = (l1 - l2).abs() / (l1.max(l2)).max(1e-9);
                    worst = worst.max(m);
                }
            } else {
                sides.insert((v[c], v[d]), (c, d));
            }
        }
    }
    (flipped, seams, worst)
}

/// Issue 16, "0 flipped faces, every time": the camel's maps that used to fold (its flat
/// torus — the default — and 0 or 1 rigid cones: 19–20 flipped; 3–4 cones with free seams:
/// 24 / 14; 5 rigid cones: the flow did not converge) are now recomputed with rigid seams or
/// more cones, said on stderr and in `chart_details[].fallback`; every written UV triangle
/// has positive area and the seams match (`check_uv_obj`); the stderr warning appears
/// exactly when the report counts flipped faces. Runs that were fine (6 free, 8 rigid) are
/// unchanged: no fallback.
#[test]
fn camel_maps_have_no_flipped_triangles() {
    let Some(meshes) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES not set: skipped");
        return;
    };
    let mesh = meshes.join("camel.off");
    if !mesh.exists() {
        eprintln!("{} missing: skipped", mesh.display());
        return;
    }
    for (cones, seams, fallback) in [
        (None, "rigid", true),
        (Some("0"), "free", true),
        (Some("3"), "free", true),
        (Some("4"), "free", true),
        (Some("5"), "rigid", true),
        (Some("6"), "free", false),
        (Some("8"), "rigid", false),
    ] {
        let out = tmp(&format!("camel-{cones:?}-{seams}.obj"));
        let mut cmd = Command::new(bin());
        cmd.arg("param").arg(&mesh);
        if let Some(k) = cones {
            cmd.args(["--cones", k]);
        }
        let o = cmd
            .args(["--seams", seams, "--json", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let case = format!("camel, cones {cones:?}, {seams} seams");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{case}: {err}");
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let (flipped, seam_edges, mismatch) = check_uv_obj(&std::fs::read_to_string(&out).unwrap());
        assert_eq!(
            flipped, 0,
            "{case}: {flipped} flipped UV triangles in the OBJ"
        );
        assert_eq!(v["flipped_faces"], 0, "{case}");
        assert!(seam_edges > 0, "{case}: no seam in the OBJ");
        assert!(mismatch < 1e-6, "{case}: seam length mismatch {mismatch:e}");
        assert!(!err.contains("warning:"), "{case}: {err}");
        let note = &v["chart_details"][0]["fallback"];
        assert_eq!(note.is_string(), fallback, "{case}: fallback {note}");
        assert_eq!(err.contains("note:"), fallback, "{case}: {err}");
    }
}

/// Area-weighted σ of `log(A_uv / A_3d)` over the faces of a UV OBJ, from its `v`, `vt` and
/// `f` lines.
fn log_area_sigma_of_obj(text: &str) -> f64 {
    let pos: Vec<[f64; 3]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let w: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [w[0], w[1], w[2]]
        })
        .collect();
    let (uv, v) = obj_corner_uv(text);
    let (mut w, mut s1, mut s2) = (0.0, 0.0, 0.0);
    for f in 0..uv.len() / 3 {
        let p = |i: usize| pos[v[3 * f + i] - 1];
        let (a, b) = (
            [0, 1, 2].map(|k| p(1)[k] - p(0)[k]),
            [0, 1, 2].map(|k| p(2)[k] - p(0)[k]),
        );
        let c = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let a3 = 0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        let q = &uv[3 * f..3 * f + 3];
        let auv = 0.5
            * ((q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]));
        if a3 > 0.0 && auv > 0.0 {
            let x = (auv / a3).ln();
            w += a3;
            s1 += a3 * x;
            s2 += a3 * x * x;
        }
    }
    let m = s1 / w;
    (s2 / w - m * m).max(0.0).sqrt()
}

/// The transitions across the seams of a UV OBJ: for every seam edge (input vertices `a < b`
/// as 0-based `v` indices), the rotation angle `θ ∈ (−π, π]` taking the edge on one side to
/// the other and the rotation's centre (`None` for a translation).
fn seam_transitions(text: &str) -> Vec<([usize; 2], f64, Option<[f64; 2]>)> {
    use std::collections::HashMap;
    let (uv, v) = obj_corner_uv(text);
    let mut sides: HashMap<(usize, usize), (usize, usize)> = HashMap::new();
    let mut out = Vec::new();
    for f in 0..uv.len() / 3 {
        for i in 0..3 {
            let (c, d) = (3 * f + i, 3 * f + (i + 1) % 3);
            let Some((c2, d2)) = sides.remove(&(v[d], v[c])) else {
                sides.insert((v[c], v[d]), (c, d));
                continue;
            };
            if uv[c] == uv[d2] && uv[d] == uv[c2] {
                continue;
            }
            // Side 1: uv[c] → uv[d]; side 2: uv[d2] → uv[c2] (same vertices v[c] → v[d]).
            let e1 = [uv[d][0] - uv[c][0], uv[d][1] - uv[c][1]];
            let e2 = [uv[c2][0] - uv[d2][0], uv[c2][1] - uv[d2][1]];
            let th = (e1[0] * e2[1] - e1[1] * e2[0]).atan2(e1[0] * e2[0] + e1[1] * e2[1]);
            // Centre z of the rotation R with R(p − z) + z = q, p = uv[c], q = uv[d2].
            let (p, q) = (uv[c], uv[d2]);
            let (co, si) = (th.cos(), th.sin());
            let rhs = [
                q[0] - (co * p[0] - si * p[1]),
                q[1] - (si * p[0] + co * p[1]),
            ];
            let (m00, m01, m10, m11) = (1.0 - co, si, -si, 1.0 - co);
            let det = m00 * m11 - m01 * m10;
            let centre = (det.abs() > 1e-12).then(|| {
                [
                    (rhs[0] * m11 - m01 * rhs[1]) / det,
                    (m00 * rhs[1] - m10 * rhs[0]) / det,
                ]
            });
            let (a, b) = (v[c] - 1, v[d] - 1);
            out.push(([a.min(b), a.max(b)], th, centre));
        }
    }
    out
}

/// Issue 16, cones on a surface with boundary: face.off with 4 greedy cones and the free
/// boundary (BFF's `--nCones=4`). Recounted from the OBJ: every UV triangle has positive
/// area; every seam edge has the same UV length on both sides, and the transitions are rigid
/// motions, one per arc of the cut (four cone paths to the boundary: at most 7 distinct
/// rotations; a non-rigid seam gives one per edge); at a cone that ends its path, the
/// rotation is the cone's curvature (the holonomy around a cone, JSON's `cones`); σ(log area)
/// recomputed from the OBJ is below the 0-cone map's. `--boundary round` with the same cones
/// is a map too (session 15; its geometry is checked in `ricci`'s `param_boundary_cones`).
#[test]
fn face_with_four_cones_and_the_free_boundary() {
    let Some(meshes) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES not set: skipped");
        return;
    };
    let mesh = meshes.join("face.off");
    if !mesh.exists() {
        eprintln!("{} missing: skipped", mesh.display());
        return;
    }
    let run = |cones: &[&str], out: &std::path::Path| {
        let o = Command::new(bin())
            .arg("param")
            .arg(&mesh)
            .args(cones)
            .args(["--json", "--out"])
            .arg(out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        (v, std::fs::read_to_string(out).unwrap())
    };
    let (v4, t4) = run(&["--cones", "4"], &tmp("face-4.obj"));
    let (_, t0) = run(&[], &tmp("face-0.obj"));
    assert_eq!(v4["cone_count"], 4, "{v4}");
    let (flipped, seams, mismatch) = check_uv_obj(&t4);
    assert_eq!(flipped, 0, "{flipped} flipped UV triangles in the OBJ");
    assert!(seams > 0, "no seam in the OBJ");
    assert!(mismatch < 1e-6, "seam length mismatch {mismatch:e}");
    // Distinct rigid motions among the seam edges' transitions.
    let tr = seam_transitions(&t4);
    let mut motions: Vec<(f64, Option<[f64; 2]>)> = Vec::new();
    for &(_, th, centre) in &tr {
        let same = |m: &(f64, Option<[f64; 2]>)| {
            (m.0.abs() - th.abs()).abs() < 1e-6
                && match (m.1, centre) {
                    (Some(a), Some(b)) => (a[0] - b[0]).hypot(a[1] - b[1]) < 1e-4,
                    (None, None) => true,
                    _ => false,
                }
        };
        if !motions.iter().any(same) {
            motions.push((th, centre));
        }
    }
    assert!(
        (1..=7).contains(&motions.len()),
        "{} distinct seam transitions over {} seam edges",
        motions.len(),
        tr.len()
    );
    if v4["uv_faces"] == "input" {
        let mut leaves = 0;
        for c in v4["cones"].as_array().unwrap() {
            let cv = c["vertex"].as_u64().unwrap() as usize;
            let k = c["curvature"].as_f64().unwrap();
            let at: Vec<f64> = tr
                .iter()
                .filter(|(e, _, _)| e.contains(&cv))
                .map(|x| x.1)
                .collect();
            if at.len() == 1 {
                leaves += 1;
                let wrapped = k - 2.0 * PI * (k / (2.0 * PI)).round();
                assert!(
                    (at[0].abs() - wrapped.abs()).abs() < 1e-6,
                    "cone {cv}: curvature {k}, seam rotation {}",
                    at[0]
                );
            }
        }
        assert!(leaves > 0, "no cone ends a cut path");
    }
    let (s4, s0) = (log_area_sigma_of_obj(&t4), log_area_sigma_of_obj(&t0));
    assert!(s4 < s0, "σ(log area) 4 cones {s4}, no cone {s0}");
    let round = Command::new(bin())
        .arg("param")
        .arg(&mesh)
        .args(["--cones", "4", "--boundary", "round", "--json", "--out"])
        .arg(tmp("face-4-round.obj"))
        .output()
        .unwrap();
    assert!(
        round.status.success(),
        "{}",
        String::from_utf8_lossy(&round.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&round.stdout).unwrap();
    assert_eq!(v["cone_count"], 4, "{v}");
}
