//! `ricci::param` on camelhead (a disk, 8 greedy cones, free boundary): the least-squares cone
//! curvatures with the cones' linearised log scale bounded above
//! (`param::cones::CONE_SCALE_CEILING`) give a map whose qc p95 by face count and σ(log area)
//! are at or below Boundary First Flattening's (1.0979 and 0.572: BFF 6924b2f `--nCones=8
//! --normalizeUVs`, BENCHMARKS.md session 14 "qc16", measured with `uv_obj_stats`). Checked
//! from the 3D positions and UVs alone (`param_lscm`'s own 2×2 qc formula, the σ of
//! log(A_uv/A_3d) weighted by 3D area computed here): every face positively oriented, cone
//! angles `2π − K̄` to 1e-9, qc p95 and σ at or below BFF's. The same cone positions with the
//! unbounded least-squares curvatures (given as cones) exceed BFF's qc p95, so the check can
//! fail.

#[path = "ricci_meshes/mod.rs"]
mod ricci_meshes;

use crate::param_lscm::{face_qc, p95, uv_area2};
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::param::cones::{free_boundary_cones, ConeBudget, CurvatureRule};
use ricci::param::{parametrize, ConeSpec, ParamOptions, Parametrization};
use ricci::progress::NoProgress;
use std::f64::consts::PI;

/// BFF's qc p95 and σ(log area) on camelhead with 8 cones.
const BFF_QC_P95: f64 = 1.0979;
const BFF_SIGMA: f64 = 0.572;

/// Area-weighted standard deviation of log(A_uv / A_3d) over the faces.
fn log_area_sigma(s: &Surface, uv: &[[f64; 2]]) -> f64 {
    let (mut w, mut m1, mut m2) = (0.0, 0.0, 0.0);
    for (f, t) in s.mesh.faces().iter().enumerate() {
        let p = |i: usize| s.positions[t[i] as usize];
        let (a, b) = (
            [p(1)[0] - p(0)[0], p(1)[1] - p(0)[1], p(1)[2] - p(0)[2]],
            [p(2)[0] - p(0)[0], p(2)[1] - p(0)[1], p(2)[2] - p(0)[2]],
        );
        let c = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let a3 = 0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        let r = (0.5 * uv_area2(&uv[3 * f..3 * f + 3]) / a3).ln();
        w += a3;
        m1 += a3 * r;
        m2 += a3 * r * r;
    }
    let mean = m1 / w;
    (m2 / w - mean * mean).max(0.0).sqrt()
}

fn map(s: &Surface, cones: ConeSpec) -> Parametrization {
    let opts = ParamOptions {
        cones,
        ..ParamOptions::default()
    };
    parametrize(s, &opts, &mut NoProgress).unwrap()
}

#[test]
fn camelhead_cones_with_bounded_scale_beat_bff() {
    let Some(dir) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let s = ricci::mesh::io::read_surface(&dir.join("camelhead.off"))
        .unwrap()
        .0;
    let m = &s.mesh;
    let p = map(&s, ConeSpec::Count(8));
    assert_eq!(p.uv_on(), "input");
    let cones = &p.charts[0].cones;
    assert_eq!(cones.len(), 8);
    let mut angle = vec![0.0; m.n_vertices()];
    for (f, t) in m.faces().iter().enumerate() {
        let q = &p.corner_uv[3 * f..3 * f + 3];
        assert!(uv_area2(q) > 0.0, "camelhead: face {f} folds");
        for i in 0..3 {
            let (a, b, c) = (q[i], q[(i + 1) % 3], q[(i + 2) % 3]);
            let u = [b[0] - a[0], b[1] - a[1]];
            let v = [c[0] - a[0], c[1] - a[1]];
            angle[t[i] as usize] += (u[0] * v[1] - u[1] * v[0]).atan2(u[0] * v[0] + u[1] * v[1]);
        }
    }
    for c in cones {
        let err = (angle[c.vertex as usize] - (2.0 * PI - c.curvature)).abs();
        assert!(
            err < 1e-9,
            "camelhead: cone {} angle off by {err:.2e}",
            c.vertex
        );
    }
    let qc = p95(face_qc(&s, &p.corner_uv));
    let sigma = log_area_sigma(&s, &p.corner_uv);
    // The same positions with the unbounded least-squares curvatures.
    let metric = IntrinsicMetric::euclidean(s.edge_lengths());
    let free = free_boundary_cones(
        m,
        &metric,
        ConeBudget::Count(8),
        CurvatureRule::LeastSquares,
        None,
    )
    .unwrap();
    let at: Vec<u32> = cones.iter().map(|c| c.vertex).collect();
    assert_eq!(free.cones.iter().map(|c| c.0).collect::<Vec<_>>(), at);
    let unbounded = map(&s, ConeSpec::Given(free.cones.clone()));
    let qc_unbounded = p95(face_qc(&s, &unbounded.corner_uv));
    let sigma_unbounded = log_area_sigma(&s, &unbounded.corner_uv);
    eprintln!(
        "camelhead: qc p95 {qc:.4}, σ {sigma:.4} (unbounded least squares {qc_unbounded:.4}, \
         {sigma_unbounded:.4}; BFF {BFF_QC_P95}, {BFF_SIGMA})"
    );
    assert!(
        qc <= BFF_QC_P95,
        "camelhead: qc p95 {qc} above BFF's {BFF_QC_P95}"
    );
    assert!(
        sigma <= BFF_SIGMA,
        "camelhead: σ {sigma} above BFF's {BFF_SIGMA}"
    );
    assert!(
        qc_unbounded > BFF_QC_P95,
        "the unbounded curvatures should not meet BFF's qc p95 ({qc_unbounded})"
    );
}
