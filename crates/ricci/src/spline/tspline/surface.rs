//! Cubic T-spline blending functions over a periodic T-mesh and T-spline surfaces
//! (Sederberg et al. 2003 eq. (2); paper 003 §3, eq. (1)).
//!
//! The blending function of anchor `i` is `B_i(u, v) = N[u⃗_i](u) N[v⃗_i](v)` with the cubic
//! B-splines of its local knot vectors ([`super::basis::cubic`]); on the torus a point sees
//! every lattice translate of every support, `B̃_i(p) = Σ_{λ ∈ Λ} B_i(p − λ)`. The surface is
//! `S(p) = Σ_i P_i B̃_i(p)` (non-rational: all weights 1, so analysis-suitable meshes give a
//! partition of unity and `S` is affine invariant).

use super::basis::cubic;
use super::tmesh::{Anchor, TMesh};
use crate::error::Result;

/// Value and partial derivatives `[B, B_u, B_v, B_uu, B_uv, B_vv]`.
pub type Jet = [f64; 6];

/// The blending functions of a T-mesh with a bucket grid for point queries.
#[derive(Debug, Clone)]
pub struct TBasis {
    pub mesh: TMesh,
    pub anchors: Vec<Anchor>,
    /// Cell size and counts of the bucket grid over `[0, W) × [0, H)`.
    nx: usize,
    ny: usize,
    /// For every cell, `(anchor, du, dv)`: the anchor's support translated by `(du, dv)`
    /// (a lattice vector) meets the cell.
    cells: Vec<Vec<(u32, f64, f64)>>,
}

impl TBasis {
    pub fn new(mesh: TMesh) -> Result<TBasis> {
        let anchors = mesh.anchors()?;
        let lat = mesh.lattice;
        let (w, h) = (lat.width, lat.height);
        let n = anchors.len().max(1);
        let side = (w * h / n as f64).sqrt().max(1e-300);
        let nx = ((w / side).ceil() as usize).clamp(1, 512);
        let ny = ((h / side).ceil() as usize).clamp(1, 512);
        let mut cells = vec![Vec::new(); nx * ny];
        for (i, a) in anchors.iter().enumerate() {
            let (u0, u1) = (a.knots_u[0], a.knots_u[4]);
            let (v0, v1) = (a.knots_v[0], a.knots_v[4]);
            // translates (m W + n s, n H) with the support box meeting [0,W]×[0,H]
            let n0 = ((-v1) / h).floor() as i64;
            let n1 = ((h - v0) / h).ceil() as i64;
            for nn in n0..=n1 {
                let dv = nn as f64 * h;
                let (b0, b1) = ((v0 + dv).max(0.0), (v1 + dv).min(h));
                if b0 >= b1 {
                    continue;
                }
                let su = nn as f64 * lat.shift;
                let m0 = ((-(u1 + su)) / w).floor() as i64;
                let m1 = ((w - (u0 + su)) / w).ceil() as i64;
                for mm in m0..=m1 {
                    let du = su + mm as f64 * w;
                    let (a0, a1) = ((u0 + du).max(0.0), (u1 + du).min(w));
                    if a0 >= a1 {
                        continue;
                    }
                    let (ix0, ix1) = (cell(a0, w, nx), cell(a1, w, nx));
                    let (iy0, iy1) = (cell(b0, h, ny), cell(b1, h, ny));
                    for iy in iy0..=iy1 {
                        for ix in ix0..=ix1 {
                            cells[iy * nx + ix].push((i as u32, du, dv));
                        }
                    }
                }
            }
        }
        Ok(TBasis {
            mesh,
            anchors,
            nx,
            ny,
            cells,
        })
    }

    pub fn len(&self) -> usize {
        self.anchors.len()
    }

    pub fn is_empty(&self) -> bool {
        self.anchors.is_empty()
    }

    /// The nonzero blending functions at `(u, v)` (any representative) with their jets,
    /// translates of one anchor summed. `out` is cleared first.
    pub fn eval(&self, u: f64, v: f64, out: &mut Vec<(usize, Jet)>) {
        out.clear();
        let (u, v) = self.mesh.lattice.canonical(u, v);
        let lat = self.mesh.lattice;
        let c = &self.cells[cell(v, lat.height, self.ny) * self.nx + cell(u, lat.width, self.nx)];
        for &(i, du, dv) in c {
            let a = &self.anchors[i as usize];
            let (x, y) = (u - du, v - dv);
            if !(x >= a.knots_u[0] && x < a.knots_u[4] && y >= a.knots_v[0] && y < a.knots_v[4]) {
                continue;
            }
            let nu = cubic(&a.knots_u, x);
            let nv = cubic(&a.knots_v, y);
            let j = [
                nu[0] * nv[0],
                nu[1] * nv[0],
                nu[0] * nv[1],
                nu[2] * nv[0],
                nu[1] * nv[1],
                nu[0] * nv[2],
            ];
            if j.iter().all(|&x| x == 0.0) {
                continue;
            }
            match out.iter_mut().find(|(k, _)| *k == i as usize) {
                Some((_, acc)) => {
                    for (s, t) in acc.iter_mut().zip(j) {
                        *s += t;
                    }
                }
                None => out.push((i as usize, j)),
            }
        }
    }

    /// The translates `(anchor, du, dv)` registered in the cells meeting `[u0,u1]×[v0,v1]`
    /// (a rectangle inside `[0, W] × [0, H]`), each once.
    pub(crate) fn candidates_in(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> Vec<(u32, f64, f64)> {
        let lat = self.mesh.lattice;
        let mut out = Vec::new();
        for iy in cell(v0, lat.height, self.ny)..=cell(v1, lat.height, self.ny) {
            for ix in cell(u0, lat.width, self.nx)..=cell(u1, lat.width, self.nx) {
                out.extend_from_slice(&self.cells[iy * self.nx + ix]);
            }
        }
        out.sort_by(|a, b| {
            a.0.cmp(&b.0)
                .then(a.1.total_cmp(&b.1))
                .then(a.2.total_cmp(&b.2))
        });
        out.dedup();
        out
    }
}

fn cell(x: f64, len: f64, n: usize) -> usize {
    ((x / len * n as f64).floor().max(0.0) as usize).min(n - 1)
}

/// A cubic T-spline surface in R³.
#[derive(Debug, Clone)]
pub struct TSpline {
    pub basis: TBasis,
    pub control: Vec<[f64; 3]>,
}

impl TSpline {
    /// `[S, S_u, S_v, S_uu, S_uv, S_vv]` at `(u, v)`.
    pub fn jet(&self, u: f64, v: f64) -> [[f64; 3]; 6] {
        let mut buf = Vec::new();
        self.basis.eval(u, v, &mut buf);
        let mut out = [[0.0; 3]; 6];
        for (i, j) in &buf {
            let p = self.control[*i];
            for k in 0..6 {
                for d in 0..3 {
                    out[k][d] += j[k] * p[d];
                }
            }
        }
        out
    }

    pub fn point(&self, u: f64, v: f64) -> [f64; 3] {
        self.jet(u, v)[0]
    }
}
