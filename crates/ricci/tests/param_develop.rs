//! `ricci::param` on camel (closed, genus 1, 8 greedy cones, free seams): no cut on the input
//! edges the flat triangulation kept reaches every cone, so the exact map is written on the
//! common subdivision; with the refinement (`param::develop`) it is developed along a cut on
//! any input edges and written on the input faces. Checked from positions and UVs alone:
//!
//! * every input face's UV triangle is positively oriented;
//! * the cones keep their angles: the UV corner angles around a cone add up to `2π − K̄`
//!   (to 1e-6; to 1e-3 for a cone where the exact map itself is off by more than 1e-6: cone
//!   1139, a hoof tip whose least-squares curvature −0.45 shrinks its leg by e^{−19} in the
//!   map, below what f64 UVs of size 1 resolve — docs/notes/wave2-s16-cq16.md);
//! * across the seam edges of the cut through the cones (`Chart::seam_edges` of them) the two
//!   sides' UV edge vectors differ by a rotation (`|d₂/d₁| = 1`) whose angle is the holonomy
//!   of a set of cones, `±Σ_{c∈S} K̄_c mod 2π`: to 1e-9 (rotation) / 1e-6 (angle, the flow's
//!   tolerance) on at least 98 % of them, to 1e-4 on all (the arc from that cone, where the
//!   exact map is itself off by ~1e-4);
//! * qc p95 (`param_lscm`'s own 2×2 formula) is below the common subdivision's, and at or
//!   below Boundary First Flattening's 1.4702 (BENCHMARKS.md, session 14 "qc16", BFF
//!   `--nCones=8` measured with `uv_obj_stats`).

#[path = "ricci_meshes/mod.rs"]
mod ricci_meshes;

use crate::param_lscm::{face_qc, p95, seam_ratio, uv_area2};
use ricci::mesh::Surface;
use ricci::param::{parametrize, ConeSpec, ParamOptions, Parametrization, SeamMode};
use ricci::progress::NoProgress;
use std::f64::consts::PI;

fn camel_map(s: &Surface, refine: bool) -> Parametrization {
    let opts = ParamOptions {
        cones: ConeSpec::Count(8),
        seams: SeamMode::Free,
        lscm_refinement: refine,
        ..ParamOptions::default()
    };
    parametrize(s, &opts, &mut NoProgress).unwrap()
}

/// Sum of the UV corner angles at every vertex.
fn corner_angle_sums(faces: &[[u32; 3]], uv: &[[f64; 2]], n: usize) -> Vec<f64> {
    let mut sum = vec![0.0; n];
    for (f, t) in faces.iter().enumerate() {
        let q = &uv[3 * f..3 * f + 3];
        for i in 0..3 {
            let (a, b, c) = (q[i], q[(i + 1) % 3], q[(i + 2) % 3]);
            let u = [b[0] - a[0], b[1] - a[1]];
            let v = [c[0] - a[0], c[1] - a[1]];
            sum[t[i] as usize] += (u[0] * v[1] - u[1] * v[0]).atan2(u[0] * v[0] + u[1] * v[1]);
        }
    }
    sum
}

/// Distance of the angle `a` from `b` on the circle.
fn circle_distance(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(2.0 * PI);
    d.min(2.0 * PI - d)
}

#[test]
fn camel_is_developed_on_its_input_faces() {
    let Some(dir) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let s = ricci::mesh::io::read_surface(&dir.join("camel.off"))
        .unwrap()
        .0;
    let m = &s.mesh;
    let exact = camel_map(&s, false);
    assert_eq!(exact.uv_on(), "common_subdivision");
    let new = camel_map(&s, true);
    assert_eq!(new.uv_on(), "input");
    assert!(new.charts[0].lscm_refined);
    for f in 0..m.n_faces() {
        let a = uv_area2(&new.corner_uv[3 * f..3 * f + 3]);
        assert!(a > 0.0, "camel: face {f} has UV area {a}");
    }
    // Cone angles, measured in the UVs; a cone in a part shrunk below the UVs' resolution
    // only as close as the exact map on the subdivision keeps it.
    let cones = &new.charts[0].cones;
    assert_eq!(cones.len(), 8);
    let sub = exact.subdivision.as_ref().unwrap();
    let new_angles = corner_angle_sums(m.faces(), &new.corner_uv, m.n_vertices());
    let sub_angles = corner_angle_sums(sub.mesh.faces(), &sub.corner_uv, sub.positions.len());
    for c in cones {
        let want = 2.0 * PI - c.curvature;
        let angle = new_angles[c.vertex as usize];
        let exact_error = (sub_angles[sub.input_vertex[c.vertex as usize] as usize] - want).abs();
        let tol = if exact_error < 1e-6 { 1e-6 } else { 1e-3 };
        eprintln!(
            "camel: cone {} angle error {:.1e} (exact map {exact_error:.1e})",
            c.vertex,
            (angle - want).abs()
        );
        assert!(
            (angle - want).abs() < tol,
            "camel: cone {} has UV angle {angle} vs 2π − K̄ = {want}",
            c.vertex
        );
    }
    // Seam transitions: rotations by the holonomy of a set of cones.
    let holonomies: Vec<f64> = (0..1u32 << cones.len())
        .map(|set| {
            cones
                .iter()
                .enumerate()
                .filter(|(i, _)| set >> i & 1 == 1)
                .map(|(_, c)| c.curvature)
                .sum()
        })
        .collect();
    // (rigid, a holonomy) to 1e-9 / 1e-6 and, looser, to 1e-4 / 1e-4.
    let (mut seams, mut strict, mut loose) = (0, 0, 0);
    for e in 0..m.n_edges() as u32 {
        if !new.seam[e as usize] || m.is_boundary_edge(e) {
            continue;
        }
        seams += 1;
        let r = seam_ratio(m, &new.corner_uv, e);
        let scale_error = (r[0].hypot(r[1]) - 1.0).abs();
        let angle = r[1].atan2(r[0]);
        let angle_error = holonomies
            .iter()
            .map(|&k| circle_distance(angle, k).min(circle_distance(angle, -k)))
            .fold(f64::INFINITY, f64::min);
        if scale_error < 1e-9 && angle_error < 1e-6 {
            strict += 1;
        }
        if scale_error < 1e-4 && angle_error < 1e-4 {
            loose += 1;
        }
    }
    let cone_cut = new.charts[0].seam_edges;
    eprintln!(
        "camel: {seams} seam edges; rotations by a cone holonomy: {strict} to 1e-9, {loose} to \
         1e-4; cut through the cones {cone_cut}"
    );
    assert!(cone_cut > 0);
    // The free homology seams are not rigid; the cut through the cones is. Near the shrunk
    // cone the exact map itself is flat only to ~1e-4 (its cone angle above).
    assert!(
        loose >= cone_cut && strict as f64 >= 0.98 * cone_cut as f64,
        "camel: {strict} (1e-9) / {loose} (1e-4) seam edges are rotations by a cone \
         holonomy, the cut through the cones has {cone_cut}"
    );
    // Quality: below the subdivision's qc p95 and BFF's.
    let sub_surface = Surface::new(sub.positions.clone(), sub.mesh.faces().to_vec()).unwrap();
    let q0 = p95(face_qc(&sub_surface, &sub.corner_uv));
    let q1 = p95(face_qc(&s, &new.corner_uv));
    eprintln!("camel: qc p95 {q0:.4} (common subdivision) → {q1:.4} (input faces)");
    assert!(q1 < q0, "camel: qc p95 {q0} → {q1}");
    assert!(q1 <= 1.4702, "camel: qc p95 {q1} above BFF's 1.4702");
}
