//! `ricci layout` on a disk whose own flow stalls (issue 15: the boundary faces split
//! off-centre): the fallback route through the flow on the double, reported as
//! `"route": "double"`, and the written common subdivision checked from the file alone — its
//! 3D area is the input's, every UV triangle is positively oriented.

use ricci::mesh::{generate, io::write_surface};
use std::path::PathBuf;
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci-cli-layout-double-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn area(p: [[f64; 3]; 3]) -> f64 {
    let (a, b) = (
        [0, 1, 2].map(|i| p[1][i] - p[0][i]),
        [0, 1, 2].map(|i| p[2][i] - p[0][i]),
    );
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
}

#[test]
fn a_split_disk_is_laid_out_through_the_double() {
    let s = generate::bumpy_split_disk(120, 7, 0.75, true).unwrap();
    let input_area: f64 = (0..s.mesh.n_faces() as u32)
        .map(|f| area(s.mesh.face(f).map(|v| s.positions[v as usize])))
        .sum();
    let (mesh, obj) = (tmp("split_disk.obj"), tmp("uv.obj"));
    write_surface(&mesh, &s).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .arg("layout")
        .arg(&mesh)
        .arg("--json")
        .arg("--out")
        .arg(&obj)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["route"], "double", "{j}");
    // Why: the surface's own flow did not converge (the reason is a sentence in the JSON).
    let reason = j["route_reason"].as_str().unwrap();
    assert!(reason.contains("converge"), "{reason}");
    assert_eq!(j["metric"]["converged"], true);
    assert!(j["metric"]["max_curvature_error"].as_f64().unwrap() <= 1e-10);
    assert!(j["metric"]["boundary_edges_flipped"].as_u64().unwrap() > 0);
    assert_eq!(j["uv"]["on"], "common_subdivision");
    assert_eq!(j["flipped_faces"], 0);
    check_obj(&obj, input_area, s.mesh.n_faces(), false);
}

/// The OBJ written at `obj` from the file alone: more faces than the input's `n_faces`, their
/// 3D area the input's (`input_area`, 1e-9), every UV triangle positively oriented, and when
/// `unit_square` every UV in `[0, 1]²`.
fn check_obj(obj: &PathBuf, input_area: f64, n_faces: usize, unit_square: bool) {
    let text = std::fs::read_to_string(obj).unwrap();
    let (mut v, mut vt, mut f) = (Vec::new(), Vec::new(), Vec::new());
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"v") => v.push([1, 2, 3].map(|i| w[i].parse::<f64>().unwrap())),
            Some(&"vt") => vt.push([1, 2].map(|i| w[i].parse::<f64>().unwrap())),
            Some(&"f") => f.push([1, 2, 3].map(|i| {
                let mut it = w[i].split('/').map(|x| x.parse::<usize>().unwrap() - 1);
                (it.next().unwrap(), it.next().unwrap())
            })),
            _ => {}
        }
    }
    assert!(f.len() > n_faces, "{} faces", f.len());
    let sub_area: f64 = f.iter().map(|t| area(t.map(|c| v[c.0]))).sum();
    assert!(
        (sub_area - input_area).abs() <= 1e-9 * input_area,
        "area {sub_area} vs {input_area}"
    );
    let flipped = f
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|c| vt[c.1]);
            let o = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            o.is_nan() || o <= 0.0
        })
        .count();
    assert_eq!(flipped, 0, "flipped UV triangles in the file");
    if unit_square {
        assert!(
            vt.iter().flatten().all(|&x| (0.0..=1.0).contains(&x)),
            "a UV outside [0, 1]²"
        );
    }
}

/// `ricci param` takes the same route (issue 15, session 11): the split disk's own flow does
/// not converge, the map comes from the flow on the double — `"route": "double"`, the common
/// subdivision written with UVs in [0, 1]², its area the input's, 0 flipped UV triangles.
#[test]
fn a_split_disk_is_parametrized_through_the_double() {
    let s = generate::bumpy_split_disk(120, 7, 0.75, true).unwrap();
    let input_area: f64 = (0..s.mesh.n_faces() as u32)
        .map(|f| area(s.mesh.face(f).map(|v| s.positions[v as usize])))
        .sum();
    let (mesh, obj) = (tmp("split_disk_param.obj"), tmp("param_uv.obj"));
    write_surface(&mesh, &s).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .arg("param")
        .arg(&mesh)
        .arg("--json")
        .arg("--out")
        .arg(&obj)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["route"], "double", "{j}");
    assert!(!j["route_reason"].as_str().unwrap().is_empty());
    assert_eq!(j["metric"]["converged"], true);
    assert!(j["metric"]["max_curvature_error"].as_f64().unwrap() <= 1e-10);
    assert_eq!(j["uv"]["on"], "common_subdivision");
    assert_eq!(j["uv_faces"], "common_subdivision");
    assert_eq!(j["flipped_faces"], 0);
    check_obj(&obj, input_area, s.mesh.n_faces(), true);
}

/// Two disks in one file: not a disk, so the failing flow is refused (one sentence, exit 1)
/// and not routed through the double.
#[test]
fn two_split_disks_in_one_file_are_refused_not_routed() {
    let s = generate::bumpy_split_disk(120, 7, 0.75, true).unwrap();
    let nv = s.mesh.n_vertices();
    let mut text = String::new();
    for shift in [0.0, 10.0] {
        for p in &s.positions {
            text += &format!("v {:e} {:e} {:e}\n", p[0] + shift, p[1], p[2]);
        }
    }
    for k in 0..2 {
        for f in 0..s.mesh.n_faces() as u32 {
            let [a, b, c] = s.mesh.face(f).map(|v| v as usize + 1 + k * nv);
            text += &format!("f {a} {b} {c}\n");
        }
    }
    let mesh = tmp("two_disks.obj");
    std::fs::write(&mesh, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .arg("layout")
        .arg(&mesh)
        .arg("--json")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(j["error"].as_str().is_some_and(|e| !e.is_empty()), "{j}");
    assert!(j.get("route").is_none(), "{j}");
}
