//! The interface the fairing and the fit ([`super::fit`]) need from a spline space,
//! [`SplineSpace`], its implementation for the planar [`DmsSpace`], and the evaluation of
//! `F = Σ c N` on any spline space ([`evaluate`]). The manifold space
//! ([`super::manifold`]) implements it too.

use crate::error::Result;

use super::dms::{evaluate_with, DmsSpace, Workspace};
use super::quadrature::quadrature_barycentric;
use super::simplex::Point;

/// What the fairing and the fit need from a spline space: the planar [`DmsSpace`] and the
/// manifold space of [`crate::spline::manifold`] both provide it. Control points are indexed
/// `triangle * per_triangle + position of β`; a *parameter point* is whatever the space uses
/// to name a point of a triangle (the domain point for [`DmsSpace`], the coordinates in the
/// face's canonical chart for a manifold space), and derivatives are taken in an orthonormal
/// frame of that parametrisation.
pub trait SplineSpace: Sync {
    fn degree(&self) -> usize;
    /// Number of triangles (control points are stored for all of them; inactive triangles
    /// carry control points that no basis function uses).
    fn n_triangles(&self) -> usize;
    fn per_triangle(&self) -> usize {
        super::dms::per_triangle(self.degree())
    }
    fn n_control_points(&self) -> usize {
        self.n_triangles() * self.per_triangle()
    }
    /// Ordered pairs `(I, J, o)` of triangles of the spline that share an edge, `o` the local
    /// index of `I`'s vertex opposite the edge (both orientations of every edge).
    fn neighbour_pairs(&self) -> Vec<(u32, u32, usize)>;
    /// Blossom weights of `J`'s control points at the blossom arguments of `I`'s control point
    /// `β` (both expressed in one coordinate system).
    fn blossom_weights_between(&self, i: u32, beta: [usize; 3], j: u32, out: &mut [f64]);
    /// All basis functions that may be non-zero at `param` in triangle `face`, with partials
    /// up to `order` (see [`DmsSpace::basis_at`]).
    fn basis_at(&self, face: u32, param: Point, order: usize, ws: &mut Workspace) -> Result<usize>;
    /// Quadrature of the thin-plate energy with `rule` on every triangle — barycentric
    /// points with weights as fractions of the triangle's area: `(face, parameter point,
    /// weight)`.
    fn quadrature_with(&self, rule: &[([f64; 3], f64)]) -> Vec<(u32, Point, f64)>;
    /// The quadrature of the fit and of [`thin_plate_energy`]:
    /// [`quadrature_with`](Self::quadrature_with) the rule [`quadrature_barycentric`].
    fn quadrature(&self) -> Vec<(u32, Point, f64)> {
        self.quadrature_with(&quadrature_barycentric())
    }
    /// Mean edge length and total area of the parameter domain (to make `λ` scale-free).
    fn domain_scale(&self) -> (f64, f64);
}

impl SplineSpace for DmsSpace {
    fn degree(&self) -> usize {
        DmsSpace::degree(self)
    }
    fn n_triangles(&self) -> usize {
        self.domain().n_faces()
    }
    fn neighbour_pairs(&self) -> Vec<(u32, u32, usize)> {
        let mesh = self.domain().mesh();
        let mut out = Vec::new();
        for h in 0..mesh.n_corners() as u32 {
            let t = mesh.he_twin(h);
            if mesh.is_boundary_halfedge(t) {
                continue;
            }
            out.push((h / 3, t / 3, (h as usize % 3 + 2) % 3));
        }
        out
    }
    fn blossom_weights_between(&self, i: u32, beta: [usize; 3], j: u32, out: &mut [f64]) {
        let args = self.triangle(i).blossom_args(beta);
        self.triangle(j).blossom_weights(&args, out);
    }
    fn basis_at(&self, face: u32, param: Point, order: usize, ws: &mut Workspace) -> Result<usize> {
        DmsSpace::basis_at(self, face, param, order, ws)
    }
    fn quadrature_with(&self, rule: &[([f64; 3], f64)]) -> Vec<(u32, Point, f64)> {
        quadrature(self, rule)
    }
    fn domain_scale(&self) -> (f64, f64) {
        let dom = self.domain();
        let mesh = dom.mesh();
        let mut hsum = 0.0;
        for e in 0..mesh.n_edges() as u32 {
            let [a, b] = mesh.edge_vertices(e).map(|v| dom.points()[v as usize]);
            hsum += (a[0] - b[0]).hypot(a[1] - b[1]);
        }
        let area: f64 = (0..dom.n_faces() as u32)
            .map(|f| {
                let [a, b, c] = dom.face_points(f);
                0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
            })
            .sum();
        (hsum / mesh.n_edges().max(1) as f64, area)
    }
}

/// `F = Σ c N` and its partials up to `order` at a parameter point of any [`SplineSpace`]
/// (`out[k * dim + d]`, see [`DmsSpace::evaluate`]).
#[allow(clippy::too_many_arguments)]
pub fn evaluate<S: SplineSpace + ?Sized>(
    space: &S,
    control: &[f64],
    dim: usize,
    face: u32,
    param: Point,
    order: usize,
    ws: &mut Workspace,
    out: &mut [f64],
) -> Result<()> {
    evaluate_with(
        control,
        dim,
        space.n_control_points(),
        order,
        ws,
        out,
        |ws| space.basis_at(face, param, order, ws),
    )
}

/// Thin-plate quadrature (`rule` on every face, equal weights). Returns
/// `(face, point, weight)`.
fn quadrature(space: &DmsSpace, rule: &[([f64; 3], f64)]) -> Vec<(u32, Point, f64)> {
    let dom = space.domain();
    let mut q = Vec::with_capacity(dom.n_faces() * rule.len());
    for f in 0..dom.n_faces() as u32 {
        let [a, b, c] = dom.face_points(f);
        let area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        for &(bary, w) in rule {
            q.push((f, dom.point_in_face(f, bary), area * w));
        }
    }
    q
}
