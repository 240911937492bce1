//! `ricci::param`'s least-squares conformal refinement on the input faces (`param::lscm`):
//! the same chart computed with and without it (`ParamOptions::lscm_refinement`), compared
//! by quantities measured here from positions and UVs alone:
//!
//! * every input face's UV triangle of the refined map is positively oriented;
//! * qc = σmax/σmin of every face's linear map (singular values of its 2×2 Jacobian, written
//!   here): the refined map's p95 is below the exact map's, and on face.off with 8 cones at
//!   or below Boundary First Flattening's 1.0516 (BENCHMARKS.md, session 13 "cone14", BFF
//!   6924b2f measured with `uv_obj_stats`);
//! * the cones keep their angles: the UV corner angles around a cone vertex add up to
//!   `2π − K̄` in the refined map;
//! * when both maps are on the input faces, across every seam edge the two sides' UV edge
//!   vectors differ by the same similarity in both (`d₂/d₁` unchanged to 1e-9): the seam
//!   transitions are the exact map's.
//! * camelhead with the greedy's 8 cones and their unbounded least-squares curvatures (given;
//!   the default bounds them, `param::cones::CONE_SCALE_CEILING`, and then nothing folds):
//!   the exact map folds an input face (so it is written on the common subdivision); the
//!   refined one is written on the input faces with none folded.

#[path = "ricci_meshes/mod.rs"]
mod ricci_meshes;

use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::param::cones::{free_boundary_cones, ConeBudget, CurvatureRule};
use ricci::param::{parametrize, ConeSpec, ParamOptions, Parametrization};
use ricci::progress::NoProgress;

/// qc of every face (σmax/σmin of the linear map from the 3D triangle to its UV triangle).
pub(crate) fn face_qc(s: &Surface, uv: &[[f64; 2]]) -> Vec<f64> {
    s.mesh
        .faces()
        .iter()
        .enumerate()
        .map(|(f, t)| {
            let p = |i: usize| s.positions[t[i] as usize];
            let d = |a: [f64; 3], b: [f64; 3]| [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let (e1, e2) = (d(p(0), p(1)), d(p(0), p(2)));
            let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let l1 = dot(e1, e1).sqrt();
            let x2 = dot(e1, e2) / l1;
            let y2 = (dot(e2, e2) - x2 * x2).max(0.0).sqrt();
            let q = |i: usize| uv[3 * f + i];
            let (a, b) = (
                [q(1)[0] - q(0)[0], q(1)[1] - q(0)[1]],
                [q(2)[0] - q(0)[0], q(2)[1] - q(0)[1]],
            );
            // J [l1 x2; 0 y2] = [a b]  ⇒  J = [a, (b − x2/l1 · a)/y2].
            let c0 = [a[0] / l1, a[1] / l1];
            let c1 = [(b[0] - x2 * c0[0]) / y2, (b[1] - x2 * c0[1]) / y2];
            let fro = c0[0] * c0[0] + c0[1] * c0[1] + c1[0] * c1[0] + c1[1] * c1[1];
            let det = (c0[0] * c1[1] - c0[1] * c1[0]).abs();
            let disc = (fro * fro - 4.0 * det * det).max(0.0).sqrt();
            ((fro + disc) / (fro - disc).max(1e-300)).sqrt()
        })
        .collect()
}

pub(crate) fn p95(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    x[((x.len() - 1) as f64 * 0.95).round() as usize]
}

fn map(s: &Surface, cones: ConeSpec, refine: bool) -> Parametrization {
    let opts = ParamOptions {
        cones,
        lscm_refinement: refine,
        ..ParamOptions::default()
    };
    parametrize(s, &opts, &mut NoProgress).unwrap()
}

pub(crate) fn uv_area2(q: &[[f64; 2]]) -> f64 {
    (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1])
}

/// The exact and the refined map; returns (qc p95 exact, qc p95 refined), the exact one
/// from its own faces (input, or the common subdivision's pieces).
fn compare(name: &str, s: &Surface, cones: ConeSpec) -> (f64, f64) {
    let exact = map(s, cones.clone(), false);
    let refined = map(s, cones, true);
    let m = &s.mesh;
    assert_eq!(refined.uv_on(), "input", "{name}");
    for f in 0..m.n_faces() {
        let a = uv_area2(&refined.corner_uv[3 * f..3 * f + 3]);
        assert!(a > 0.0, "{name}: face {f} has UV area {a}");
    }
    assert!(refined.charts[0].lscm_refined, "{name}: not refined");
    assert!(!exact.charts[0].lscm_refined);
    // Same cones, and their angle measured in the refined UVs.
    let (c0, c1) = (&exact.charts[0].cones, &refined.charts[0].cones);
    assert_eq!(c0.len(), c1.len());
    let mut sum = vec![0.0; m.n_vertices()];
    for (f, t) in m.faces().iter().enumerate() {
        let q = &refined.corner_uv[3 * f..3 * f + 3];
        for i in 0..3 {
            let (a, b, c) = (q[i], q[(i + 1) % 3], q[(i + 2) % 3]);
            let u = [b[0] - a[0], b[1] - a[1]];
            let v = [c[0] - a[0], c[1] - a[1]];
            sum[t[i] as usize] += (u[0] * v[1] - u[1] * v[0]).atan2(u[0] * v[0] + u[1] * v[1]);
        }
    }
    for (a, b) in c0.iter().zip(c1) {
        assert_eq!(
            (a.vertex, a.curvature.to_bits()),
            (b.vertex, b.curvature.to_bits())
        );
        let angle = sum[b.vertex as usize];
        assert!(
            (angle - b.angle).abs() < 1e-6,
            "{name}: cone {} has UV angle {angle} vs 2π − K̄ = {}",
            b.vertex,
            b.angle
        );
    }
    let q1 = p95(face_qc(s, &refined.corner_uv));
    let Some(sub) = &exact.subdivision else {
        check_seams(name, s, &exact, &refined);
        let q0 = p95(face_qc(s, &exact.corner_uv));
        eprintln!("{name}: qc p95 {q0:.4} → {q1:.4}");
        return (q0, q1);
    };
    // The exact map on the common subdivision: its input faces fold.
    assert!(exact.charts[0].input_flipped_faces > 0, "{name}");
    let sub_surface = Surface::new(sub.positions.clone(), sub.mesh.faces().to_vec()).unwrap();
    let q0 = p95(face_qc(&sub_surface, &sub.corner_uv));
    eprintln!("{name}: qc p95 {q0:.4} (common subdivision) → {q1:.4} (input faces)");
    (q0, q1)
}

/// `d₂/d₁` of the two sides' UV edge vectors across the interior edge `e` (complex).
pub(crate) fn seam_ratio(m: &ricci::mesh::Mesh, uv: &[[f64; 2]], e: u32) -> [f64; 2] {
    let h = m.edge_halfedge(e);
    let g = m.he_twin(h);
    let (pa, pb) = (uv[h as usize], uv[m.he_next(h) as usize]);
    let (qb, qa) = (uv[g as usize], uv[m.he_next(g) as usize]);
    let d1 = [pb[0] - pa[0], pb[1] - pa[1]];
    let d2 = [qb[0] - qa[0], qb[1] - qa[1]];
    let n = d1[0] * d1[0] + d1[1] * d1[1];
    [
        (d2[0] * d1[0] + d2[1] * d1[1]) / n,
        (d2[1] * d1[0] - d2[0] * d1[1]) / n,
    ]
}

/// Across every seam edge: `d₂/d₁` of the two sides' UV edge vectors, the same in both maps
/// (global similarities of the packing cancel in the ratio).
fn check_seams(name: &str, s: &Surface, exact: &Parametrization, refined: &Parametrization) {
    let m = &s.mesh;
    assert_eq!(exact.seam, refined.seam, "{name}: same cut");
    let ratio = |uv: &[[f64; 2]], e: u32| seam_ratio(m, uv, e);
    let (mut worst, mut seam_edges) = (0.0f64, 0);
    for e in 0..m.n_edges() as u32 {
        if !exact.seam[e as usize] || m.is_boundary_edge(e) {
            continue;
        }
        seam_edges += 1;
        let (r0, r1) = (ratio(&exact.corner_uv, e), ratio(&refined.corner_uv, e));
        worst = worst.max((r0[0] - r1[0]).hypot(r0[1] - r1[1]) / r0[0].hypot(r0[1]));
    }
    eprintln!("{name}: {seam_edges} seam edges, transitions kept to {worst:.1e}");
    assert!(seam_edges > 0, "{name}: no seam");
    assert!(
        worst < 1e-9,
        "{name}: a seam transition changed by {worst:e}"
    );
}

/// kitten (genus 1, no cones: every transition a translation), face (boundary, 8 cones) and
/// camelhead (boundary, 8 cones with the unbounded least-squares curvatures; the exact map
/// folds an input face).
#[test]
fn refinement_lowers_qc_and_keeps_cones_and_seams() {
    let Some(dir) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let read = |f: &str| ricci::mesh::io::read_surface(&dir.join(f)).unwrap().0;
    let kitten = read("kitten.nf20k.off");
    let (q0, q1) = compare("kitten", &kitten, ConeSpec::Default);
    assert!(q1 < q0, "kitten: qc p95 {q0} → {q1}");
    let face = read("face.off");
    let (q0, q1) = compare("face", &face, ConeSpec::Count(8));
    assert!(q1 < q0, "face: qc p95 {q0} → {q1}");
    assert!(q1 <= 1.0516, "face: qc p95 {q1} above BFF's 1.0516");
    let camelhead = read("camelhead.off");
    let metric = IntrinsicMetric::euclidean(camelhead.edge_lengths());
    let budget = ConeBudget::Count(8);
    let rule = CurvatureRule::LeastSquares;
    let cones = free_boundary_cones(&camelhead.mesh, &metric, budget, rule, None).unwrap();
    let (q0, q1) = compare("camelhead", &camelhead, ConeSpec::Given(cones.cones));
    assert!(q1 < q0, "camelhead: qc p95 {q0} → {q1}");
}
