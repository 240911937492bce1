//! Zeros of a holomorphic 1-form (paper 002 §4.2.4): where the gradient field of its real
//! part vanishes, located at vertices by the discrete Poincaré–Hopf index.
//!
//! A harmonic 1-form is constant on each face (a vector `w_f` in the face's plane). Going once
//! counter-clockwise around vertex `v`, the vector turns by `Σ δ` (each `δ ∈ (−π, π]` the turn
//! from one face to the next, measured after unfolding the two faces across their common
//! edge), while the frame turns by the cone angle `Σ θ = 2π − K_v`; the index is
//! `ind_v = (Σ δ + K_v) / 2π`, an integer. The turns across an edge seen from its two end
//! points cancel, so `Σ_v ind_v = Σ K_v / 2π = χ = 2 − 2g` for every field. Near a zero of
//! order `m`, `ω ≈ z^m dz` and `Re ω` has a saddle with `2(m + 1)` sectors, index `−m`; a
//! holomorphic form has no poles, so the zeros, counted with multiplicity, number `2g − 2`,
//! and a discrete form is faithful when no vertex has a positive index.

use super::cochain::on_halfedge;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use serde::Serialize;
use std::f64::consts::PI;

/// A zero of a holomorphic 1-form at a vertex.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct Zero {
    pub vertex: u32,
    /// Order of the zero (`−index`).
    pub multiplicity: u32,
}

/// The singularities of the real part of a 1-form.
#[derive(Debug, Clone, Serialize)]
pub struct ZeroSet {
    /// Vertices of negative index (zeros of the holomorphic form).
    pub zeros: Vec<Zero>,
    /// Vertices of positive index (impossible for a holomorphic form: discretization
    /// artefacts), as (vertex, index).
    pub spurious: Vec<(u32, i64)>,
    /// `Σ multiplicity` of the zeros.
    pub count: u32,
    /// `Σ_v ind_v` (= χ).
    pub total_index: i64,
}

/// The vector of the constant 1-form with values `a1` on `v0→v1` and `a2` on `v1→v2` in the
/// frame of a triangle with `v0 = (0, 0)`, `v1 = (l01, 0)`, `v2 = p2`; the three edge
/// directions `v0→v1, v1→v2, v2→v0`.
fn face_frame(l: [f64; 3]) -> Option<[[f64; 2]; 3]> {
    // l = [|v0v1|, |v1v2|, |v2v0|]
    let [a, b, c] = l;
    let x = (a * a + c * c - b * b) / (2.0 * a);
    let y2 = c * c - x * x;
    if y2.is_nan() || y2 <= 0.0 || a.is_nan() || a <= 0.0 {
        return None;
    }
    let p2 = [x, y2.sqrt()];
    Some([[a, 0.0], [p2[0] - a, p2[1]], [-p2[0], -p2[1]]])
}

/// The vector field of `w` on face `f` (in its frame) and the frame's edge directions.
pub(super) fn face_vector(
    mesh: &Mesh,
    lengths: &[f64],
    w: &[f64],
    f: u32,
) -> Option<([f64; 2], [[f64; 2]; 3])> {
    let hs = mesh.face_halfedges(f);
    let l = hs.map(|h| lengths[mesh.he_edge(h) as usize]);
    let d = face_frame(l)?;
    let a1 = on_halfedge(mesh, w, hs[0]);
    let a2 = on_halfedge(mesh, w, hs[1]);
    // w·d0 = a1, w·(d0 + d1) = a1 + a2.
    let e2 = [d[0][0] + d[1][0], d[0][1] + d[1][1]];
    let wx = a1 / d[0][0];
    let wy = (a1 + a2 - wx * e2[0]) / e2[1];
    Some(([wx, wy], d))
}

pub(super) fn angle_between(d: [f64; 2], w: [f64; 2]) -> f64 {
    (d[0] * w[1] - d[1] * w[0]).atan2(d[0] * w[0] + d[1] * w[1])
}

pub(super) fn wrap(x: f64) -> f64 {
    let mut y = x % (2.0 * PI);
    if y > PI {
        y -= 2.0 * PI;
    } else if y <= -PI {
        y += 2.0 * PI;
    }
    y
}

/// The Poincaré–Hopf index of the face-constant field of the closed 1-form `w` at every
/// vertex of a closed mesh (Euclidean lengths).
pub(crate) fn vertex_indices(mesh: &Mesh, lengths: &[f64], w: &[f64]) -> Result<Vec<i64>> {
    let nf = mesh.n_faces();
    let mut vec = Vec::with_capacity(nf);
    for f in 0..nf as u32 {
        vec.push(face_vector(mesh, lengths, w, f).ok_or_else(|| {
            Error::numerical(format!("face {f} is degenerate; its field is undefined"))
        })?);
    }
    // Angle of the field relative to half-edge h (leaving its corner) and the corner angle.
    let rel = |h: u32| {
        let (w, d) = vec[(h / 3) as usize];
        angle_between(d[(h % 3) as usize], w)
    };
    let corner = |h: u32| {
        let (_, d) = vec[(h / 3) as usize];
        let a = d[(h % 3) as usize];
        let p = d[((h + 2) % 3) as usize];
        let b = [-p[0], -p[1]];
        angle_between(a, b)
    };
    let mut ind = vec![0i64; mesh.n_vertices()];
    for v in 0..mesh.n_vertices() as u32 {
        if mesh.is_isolated(v) || mesh.is_boundary_vertex(v) {
            continue;
        }
        let h0 = mesh.vertex_halfedge(v);
        let (mut h, mut turn, mut cone) = (h0, 0.0, 0.0);
        let budget = mesh.valence(v) + 1;
        for _ in 0..budget {
            let next = mesh.he_twin(mesh.he_prev(h));
            let th = corner(h);
            turn += wrap(rel(next) + th - rel(h));
            cone += th;
            h = next;
            if h == h0 {
                break;
            }
        }
        ind[v as usize] = ((turn + 2.0 * PI - cone) / (2.0 * PI)).round() as i64;
    }
    Ok(ind)
}

/// The zeros of the holomorphic form whose real part is `w` (module docs).
pub(crate) fn zeros(mesh: &Mesh, lengths: &[f64], w: &[f64]) -> Result<ZeroSet> {
    let ind = vertex_indices(mesh, lengths, w)?;
    let mut zs = Vec::new();
    let mut spurious = Vec::new();
    for (v, &i) in ind.iter().enumerate() {
        if i < 0 {
            zs.push(Zero {
                vertex: v as u32,
                multiplicity: (-i) as u32,
            });
        } else if i > 0 {
            spurious.push((v as u32, i));
        }
    }
    Ok(ZeroSet {
        count: zs.iter().map(|z| z.multiplicity).sum(),
        zeros: zs,
        spurious,
        total_index: ind.iter().sum(),
    })
}
