//! `ricci layout camelhead.off --target round-boundary` with the default scheme (issue 15's
//! must-show: "camelhead round … converged with the default and no refinement flags; then
//! `ricci layout` with 0 flipped faces"). Checked from the written OBJ, not from the JSON: every
//! triangle's UV area is positive, and the boundary's UVs lie on one circle (a least-squares
//! circle fit, Kåsa 1976: x² + y² + Dx + Ey + F = 0), which is what a round boundary means.
//! Needs `$RICCI_MESHES`.

use std::process::Command;

#[path = "../../ricci/tests/ricci_meshes/mod.rs"]
mod ricci_meshes;

/// Positions of `v` lines, UVs of `vt` lines, faces as (vertex, uv) index triples (0-based).
type Obj = (usize, Vec<[f64; 2]>, Vec<[(usize, usize); 3]>);

fn read_obj(text: &str) -> Obj {
    let (mut nv, mut vt, mut faces) = (0, Vec::new(), Vec::new());
    for line in text.lines() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("v") => nv += 1,
            Some("vt") => {
                let x: Vec<f64> = w.take(2).map(|s| s.parse().unwrap()).collect();
                vt.push([x[0], x[1]]);
            }
            Some("f") => {
                let c: Vec<(usize, usize)> = w
                    .map(|s| {
                        let mut p = s.split('/');
                        let v: usize = p.next().unwrap().parse().unwrap();
                        let t: usize = p.next().unwrap().parse().unwrap();
                        (v - 1, t - 1)
                    })
                    .collect();
                assert_eq!(c.len(), 3, "triangles: {line}");
                faces.push([c[0], c[1], c[2]]);
            }
            _ => {}
        }
    }
    (nv, vt, faces)
}

/// Solve the 3×3 system `m x = b` (Cramer's rule).
fn solve3(m: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(m);
    std::array::from_fn(|k| {
        let mut mk = m;
        for i in 0..3 {
            mk[i][k] = b[i];
        }
        det(mk) / d
    })
}

#[test]
fn camelhead_round_boundary_is_a_circle_with_no_flipped_face() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let out = std::env::temp_dir().join(format!("ricci-round-{}.obj", std::process::id()));
    let o = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .arg("layout")
        .arg(dir.join("camelhead.off"))
        .args(["--target", "round-boundary", "--json", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["metric"]["converged"], true, "{}", v["metric"]);
    let (nv, uv, faces) = read_obj(&std::fs::read_to_string(&out).unwrap());
    let _ = std::fs::remove_file(&out);
    // 0 flipped faces, recounted.
    let area = |f: &[(usize, usize); 3]| {
        let [a, b, c] = f.map(|(_, t)| uv[t]);
        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    };
    let flipped = faces.iter().filter(|f| area(f) <= 0.0).count();
    assert_eq!(flipped, 0, "{flipped} of {} faces flipped", faces.len());
    // Boundary edges: used by one face (vertex ids); their UVs.
    let mut count = std::collections::HashMap::new();
    for f in &faces {
        for i in 0..3 {
            let (a, b) = (f[i].0, f[(i + 1) % 3].0);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut on_boundary = vec![None; nv];
    for f in &faces {
        for i in 0..3 {
            let (a, b) = (f[i].0, f[(i + 1) % 3].0);
            if count[&(a.min(b), a.max(b))] == 1 {
                on_boundary[a] = Some(uv[f[i].1]);
                on_boundary[b] = Some(uv[f[(i + 1) % 3].1]);
            }
        }
    }
    let pts: Vec<[f64; 2]> = on_boundary.into_iter().flatten().collect();
    assert!(
        pts.len() >= 50,
        "camelhead's boundary: {} vertices",
        pts.len()
    );
    // Kåsa fit: minimise Σ (x² + y² + Dx + Ey + F)².
    let (mut m, mut r) = ([[0.0; 3]; 3], [0.0; 3]);
    for p in &pts {
        let row = [p[0], p[1], 1.0];
        let rhs = -(p[0] * p[0] + p[1] * p[1]);
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += row[i] * row[j];
            }
            r[i] += row[i] * rhs;
        }
    }
    let [d, e, f] = solve3(m, r);
    let (cx, cy) = (-0.5 * d, -0.5 * e);
    let radius = (cx * cx + cy * cy - f).sqrt();
    let worst = pts
        .iter()
        .map(|p| (((p[0] - cx).powi(2) + (p[1] - cy).powi(2)).sqrt() - radius).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "camelhead round boundary: {} boundary vertices, radius {radius:.6}, largest distance \
         from the circle {worst:.2e}",
        pts.len()
    );
    assert!(
        worst <= 1e-6 * radius,
        "the boundary is not round: {worst:e} off a circle of radius {radius}"
    );
}
