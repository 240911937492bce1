//! The conformal net: integration of a holomorphic 1-form on the cut mesh (paper 002 §4.2.3,
//! "global conformal parameterization"; paper 003 §2).
//!
//! `φ(p) = ∫_{x}^{p} ω` along any path inside the fundamental domain (the disk of the canonical
//! cut): `ω` is closed, so the integral does not depend on the path. `φ` is a uv coordinate
//! per cut-mesh vertex (so per corner of the input faces); across each side pair of the
//! polygon it jumps by the period of `ω` along the partner loop. Its iso-lines form the
//! conformal net (a checkerboard of squares away from the zeros).
//!
//! Quality: on each face `φ` is affine; its Jacobian (face frame → uv) has singular values
//! `σ₁ ≥ σ₂` and the quasi-conformal distortion `σ₁/σ₂` is 1 for a conformal map.

use super::cochain::on_halfedge;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use serde::Serialize;
use std::collections::VecDeque;

/// uv per cut-mesh vertex.
#[derive(Debug, Clone)]
pub struct ConformalNet {
    pub uv: Vec<[f64; 2]>,
    /// `max |φ(tip) − φ(origin) − ω(h)|` over the cut mesh's half-edges (0 up to rounding).
    pub integration_error: f64,
    pub quality: NetQuality,
}

/// Angle distortion of the net.
#[derive(Debug, Clone, Serialize)]
pub struct NetQuality {
    pub qc_mean: f64,
    pub qc_p95: f64,
    pub qc_max: f64,
    /// Faces whose uv triangle is reversed (around the zeros the net winds 2(m+1)·π).
    pub flipped_faces: usize,
}

/// Integrate `re + i im` (1-forms on the refined mesh, whose interior half-edges share their
/// ids with the cut mesh's) over the cut mesh, starting at 0 on cut vertex `start`.
pub(crate) fn integrate(
    refined: &Mesh,
    lengths: &[f64],
    cut_mesh: &Mesh,
    re: &[f64],
    im: &[f64],
) -> Result<ConformalNet> {
    let n = cut_mesh.n_vertices();
    let mut uv = vec![[f64::NAN; 2]; n];
    let mut queue = VecDeque::new();
    if n == 0 {
        return Err(Error::input("the cut mesh is empty"));
    }
    uv[0] = [0.0, 0.0];
    queue.push_back(0u32);
    while let Some(v) = queue.pop_front() {
        if cut_mesh.is_isolated(v) {
            continue;
        }
        for h in cut_mesh.outgoing(v) {
            let t = cut_mesh.he_tip(h);
            if uv[t as usize][0].is_nan() {
                let p = uv[v as usize];
                uv[t as usize] = [
                    p[0] + value(refined, cut_mesh, re, h),
                    p[1] + value(refined, cut_mesh, im, h),
                ];
                queue.push_back(t);
            }
        }
    }
    if let Some(v) = uv.iter().position(|p| p[0].is_nan()) {
        return Err(Error::topology(format!(
            "cut-mesh vertex {v} is not connected to vertex 0"
        )));
    }
    let mut err = 0.0f64;
    for h in 0..cut_mesh.n_corners() as u32 {
        let (a, b) = (cut_mesh.he_origin(h), cut_mesh.he_tip(h));
        let du = uv[b as usize][0] - uv[a as usize][0] - on_halfedge(refined, re, h);
        let dv = uv[b as usize][1] - uv[a as usize][1] - on_halfedge(refined, im, h);
        err = err.max(du.abs()).max(dv.abs());
    }
    let quality = net_quality(refined, lengths, cut_mesh, &uv);
    Ok(ConformalNet {
        uv,
        integration_error: err,
        quality,
    })
}

/// The form on cut-mesh half-edge `h` (boundary half-edges of the cut mesh: minus the value on
/// their interior twin).
fn value(refined: &Mesh, cut_mesh: &Mesh, w: &[f64], h: u32) -> f64 {
    if cut_mesh.is_boundary_halfedge(h) {
        -on_halfedge(refined, w, cut_mesh.he_twin(h))
    } else {
        on_halfedge(refined, w, h)
    }
}

fn net_quality(refined: &Mesh, lengths: &[f64], cut_mesh: &Mesh, uv: &[[f64; 2]]) -> NetQuality {
    let mut qc = Vec::with_capacity(cut_mesh.n_faces());
    let mut flipped = 0;
    for f in 0..cut_mesh.n_faces() as u32 {
        let hs = refined.face_halfedges(f);
        let [a, b, c] = hs.map(|h| lengths[refined.he_edge(h) as usize]);
        // Face frame: v0 = 0, v1 = (a, 0), v2 = (x, y).
        let x = (a * a + c * c - b * b) / (2.0 * a);
        let y = (c * c - x * x).max(0.0).sqrt();
        let [i, j, k] = cut_mesh.face(f).map(|v| uv[v as usize]);
        let (e1, e2) = ([j[0] - i[0], j[1] - i[1]], [k[0] - i[0], k[1] - i[1]]);
        if !(y > 0.0 && a > 0.0) {
            continue;
        }
        // Jacobian columns: d(uv)/dX, d(uv)/dY with e1 = J (a, 0), e2 = J (x, y).
        let jx = [e1[0] / a, e1[1] / a];
        let jy = [(e2[0] - x * jx[0]) / y, (e2[1] - x * jx[1]) / y];
        let det = jx[0] * jy[1] - jx[1] * jy[0];
        if det <= 0.0 {
            flipped += 1;
        }
        let fro = jx[0] * jx[0] + jx[1] * jx[1] + jy[0] * jy[0] + jy[1] * jy[1];
        let disc = (fro * fro - 4.0 * det * det).max(0.0).sqrt();
        let s1 = (0.5 * (fro + disc)).sqrt();
        let s2 = (0.5 * (fro - disc)).max(0.0).sqrt();
        qc.push(if s2 > 0.0 { s1 / s2 } else { f64::INFINITY });
    }
    qc.sort_by(f64::total_cmp);
    let finite: Vec<f64> = qc.iter().cloned().filter(|x| x.is_finite()).collect();
    let mean = finite.iter().sum::<f64>() / finite.len().max(1) as f64;
    let p95 = qc
        .get(((qc.len() as f64) * 0.95) as usize)
        .cloned()
        .unwrap_or(f64::NAN);
    NetQuality {
        qc_mean: mean,
        qc_p95: p95,
        qc_max: qc.last().cloned().unwrap_or(f64::NAN),
        flipped_faces: flipped,
    }
}
