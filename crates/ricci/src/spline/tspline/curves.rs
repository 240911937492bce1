//! The T-mesh drawn on the surface (paper 003 Fig. 1(d), 5 and 7: "the red curves on the
//! manifold T-spline surface are the images of the edges on the domain manifold"): every
//! T-mesh edge mapped through the T-spline `S : R²/Λ → R³`, and the T-junctions as small loops
//! around their images, plus the closed lattice-grid tessellation used to draw the surface.

use super::surface::TSpline;

/// Images of the T-mesh's face sides (`per_edge` segments per side; a side shared by two
/// faces is drawn twice, which draws the same curve) and small loops around the images of the
/// T-junctions (parameter circles of `marker` times the smallest side of the faces at the
/// junction, 12 segments).
#[derive(Debug, Clone, Default)]
pub struct TMeshCurves {
    pub edges: Vec<Vec<[f64; 3]>>,
    pub t_junctions: Vec<Vec<[f64; 3]>>,
}

/// See [`TMeshCurves`].
pub fn tmesh_on_surface(ts: &TSpline, per_edge: usize, marker: f64) -> TMeshCurves {
    let k = per_edge.max(1);
    let mesh = &ts.basis.mesh;
    let mut edges = Vec::with_capacity(4 * mesh.faces().len());
    for f in mesh.faces() {
        let corners = [(f.u0, f.v0), (f.u1, f.v0), (f.u1, f.v1), (f.u0, f.v1)];
        for s in 0..4 {
            let (a, b) = (corners[s], corners[(s + 1) % 4]);
            edges.push(
                (0..=k)
                    .map(|i| {
                        let t = i as f64 / k as f64;
                        ts.point(a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
                    })
                    .collect(),
            );
        }
    }
    let lat = mesh.lattice;
    let mean = (lat.width * lat.height / mesh.faces().len().max(1) as f64).sqrt();
    let tol = 1e-9 * lat.width.max(lat.height);
    let t_junctions = mesh
        .t_junctions()
        .iter()
        .map(|t| {
            // the smallest side of the faces touching the junction (the conformal factor
            // makes face sizes vary by orders of magnitude); the mean face size if none is
            // found (a junction on the glued sides)
            let side = mesh
                .faces()
                .iter()
                .filter(|f| {
                    t.u >= f.u0 - tol && t.u <= f.u1 + tol && t.v >= f.v0 - tol && t.v <= f.v1 + tol
                })
                .map(|f| (f.u1 - f.u0).min(f.v1 - f.v0))
                .fold(f64::INFINITY, f64::min);
            let r = marker * if side.is_finite() { side } else { mean };
            (0..12)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / 12.0;
                    ts.point(t.u + r * a.cos(), t.v + r * a.sin())
                })
                .collect()
        })
        .collect();
    TMeshCurves { edges, t_junctions }
}

/// The T-spline on the lattice grid `p(i, j) = (i/n) ω₁ + (j/m) ω₂` of the flat torus: one
/// closed, welded triangle mesh (`n m` vertices, `2 n m` triangles, a torus).
pub fn torus_tessellation(ts: &TSpline, n: usize, m: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let (n, m) = (n.max(3), m.max(3));
    let lat = ts.basis.mesh.lattice;
    let mut positions = Vec::with_capacity(n * m);
    for j in 0..m {
        for i in 0..n {
            let (a, b) = (i as f64 / n as f64, j as f64 / m as f64);
            positions.push(ts.point(a * lat.width + b * lat.shift, b * lat.height));
        }
    }
    let id = |i: usize, j: usize| ((j % m) * n + (i % n)) as u32;
    let mut triangles = Vec::with_capacity(2 * n * m);
    for j in 0..m {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    (positions, triangles)
}
