//! Triangular B-splines of Dahmen–Micchelli–Seidel (DMS) over a planar triangulation.
//!
//! Follows Dahmen, Micchelli, Seidel, "Blossoming begets B-spline bases built better by
//! B-patches" (Math. Comp. 1992) and Fong–Seidel (1993); used by paper 000 §5.
//!
//! **Knots.** Every domain vertex `v` carries a knot cloud `t_{v,0} = v, t_{v,1}, …, t_{v,n}`.
//! For a domain triangle `I = (v_0, v_1, v_2)` (counter-clockwise) and `β = (β_0, β_1, β_2)`,
//! `|β| = n`, the knot set is `V_β^I = {t_{0,0..β_0}, t_{1,0..β_1}, t_{2,0..β_2}}` (`β_m + 1`
//! knots of cloud `m`, `n + 3` in all) and the normalised basis function is
//! `N_{I,β} = |d_β^I| M(· | V_β^I)`, `d_β^I = det(t_{0,β_0}, t_{1,β_1}, t_{2,β_2})` (twice the
//! signed area; [`crate::spline::simplex`] fixes the normalisation of `M`).
//!
//! **Admissibility** (checked by [`DmsSpace::new`]): every triangle `Δ_β^I = [t_{0,β_0},
//! t_{1,β_1}, t_{2,β_2}]`, `|β| ≤ n`, is positively oriented and their interiors share a point
//! (`Ω_I ≠ ∅`); no three knots of a triangle's knot array are collinear (then every basis
//! function is `C^{n−1}`); on a boundary edge `(v, w)` every knot of the clouds of `v` and `w`
//! other than `v` and `w` lies strictly outside the domain's side of the edge line. Under these
//! conditions the spline space contains every polynomial of degree `≤ n` on the domain, with
//! control points given by blossoming ([`DmsSpace::control_points_of_polynomial`]):
//! `c_{I,β} = f(t_{0,0..β_0−1}, t_{1,0..β_1−1}, t_{2,0..β_2−1})`. (Sketch of why: the
//! recurrence on `V_β^I` with `W = Δ_β^I` telescopes over `β` by the affinity of the blossom;
//! the terms that lose a vertex knot cancel between the two triangles of an interior edge,
//! which see the same knots with opposite orientation; on a boundary edge they live outside the
//! domain.) In particular the basis is a partition of unity on the whole closed domain.
//!
//! **Evaluation.** A point of the domain is given with the face it belongs to; every value and
//! derivative is the limit from inside that face (the half-open convention of
//! [`crate::spline::simplex`] with the direction towards the face's centroid). So points on
//! edges and vertices are handled exactly, and derivatives of order `n` (piecewise constant)
//! are one-sided. A chart of a manifold spline can build the same basis from knots in its own
//! coordinates with [`TriangleBasis::new`].
//!
//! **B-patch polynomial.** The control points of one triangle also define a polynomial `P^I`
//! of degree `n`, the unique one whose blossom at `t_{0,0..β_0−1}, t_{1,0..β_1−1},
//! t_{2,0..β_2−1}` is `c_{I,β}` for all `|β| = n` (the DMS B-patch). Its blossom at any
//! arguments is a fixed linear combination of the control points ([`TriangleBasis::blossom_weights`],
//! a generalised de Casteljau algorithm over the triangles `Δ_γ^I`, `|γ| < n`); the fairing of
//! paper 000 (eq. 14, Fig. 13) constrains control points by it.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::numeric::dd::Dd;

use super::poly::Polynomial;
use super::simplex::{det3, n_partials, Point, SimplexFamily};

mod basis;
mod knots;

pub(crate) use basis::blossom_weights_of;
pub use basis::TriangleBasis;
pub(crate) use knots::{convex_hull, general_position_involving, hash64, needs_shrink, unit};
pub use knots::{general_position, patch_quality, triple_quality, KnotClouds, KnotOptions};

/// Largest supported degree.
pub const MAX_DEGREE: usize = 6;

/// Multi-indices `β` with `|β| = n`, in the order used for control points of a triangle:
/// `β_0` descending, then `β_1` descending (`(n,0,0), (n−1,1,0), (n−1,0,1), …, (0,0,n)`).
pub fn multi_indices(n: usize) -> Vec<[usize; 3]> {
    let mut v = Vec::with_capacity((n + 1) * (n + 2) / 2);
    for b0 in (0..=n).rev() {
        for b1 in (0..=n - b0).rev() {
            v.push([b0, b1, n - b0 - b1]);
        }
    }
    v
}

/// Position of `β` in [`multi_indices`]`(n)`.
pub fn multi_index_position(n: usize, beta: [usize; 3]) -> usize {
    let k = n - beta[0]; // rows with larger β_0 come first: 1 + 2 + … + k entries
    k * (k + 1) / 2 + (k - beta[1])
}

/// Number of control points per triangle, `(n+1)(n+2)/2`.
pub const fn per_triangle(n: usize) -> usize {
    (n + 1) * (n + 2) / 2
}

/// The edges of the control net of one degree-`n` triangle, as pairs of positions in
/// [`multi_indices`] order: `β` is joined to `β − e_a + e_b` for `(a, b)` = (0, 1), (0, 2),
/// (1, 2) — the `3n(n+1)/2` edges of the B-patch's net.
pub fn control_net_edges(n: usize) -> Vec<(usize, usize)> {
    let betas = multi_indices(n);
    let mut out = Vec::with_capacity(3 * n * (n + 1) / 2);
    for (k, b) in betas.iter().enumerate() {
        for (from, to) in [(0, 1), (0, 2), (1, 2)] {
            if b[from] == 0 {
                continue;
            }
            let mut q = *b;
            q[from] -= 1;
            q[to] += 1;
            if let Some(j) = betas.iter().position(|x| *x == q) {
                out.push((k, j));
            }
        }
    }
    out
}

#[inline]
fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}
#[inline]
fn norm(a: Point) -> f64 {
    a[0].hypot(a[1])
}

/// A planar triangulation: the parameter domain of a DMS spline.
#[derive(Debug, Clone)]
pub struct Domain {
    points: Vec<Point>,
    mesh: Mesh,
}

impl Domain {
    /// Validate and build. Triangles must be counter-clockwise with positive area and form an
    /// oriented manifold (disk-like or with holes).
    pub fn new(points: Vec<Point>, triangles: Vec<[u32; 3]>) -> Result<Domain> {
        if let Some(v) = points
            .iter()
            .position(|p| !p[0].is_finite() || !p[1].is_finite())
        {
            return Err(Error::input(format!(
                "spline domain: vertex {v} has a non-finite coordinate"
            )));
        }
        let mesh = Mesh::from_triangles(points.len(), triangles)?;
        for (f, t) in mesh.faces().iter().enumerate() {
            let [a, b, c] = t.map(|v| points[v as usize]);
            let area2 = det3(a, b, c);
            let scale = norm(sub(b, a)).max(norm(sub(c, a))).max(norm(sub(c, b)));
            if !(area2 > 1e-12 * scale * scale) {
                return Err(Error::input(format!(
                    "spline domain: face {f} ({}, {}, {}) is not counter-clockwise with positive area (signed area {:.3e})",
                    t[0],
                    t[1],
                    t[2],
                    area2 / 2.0
                )));
            }
        }
        if let Some(v) = (0..mesh.n_vertices() as u32).find(|&v| mesh.is_isolated(v)) {
            return Err(Error::input(format!(
                "spline domain: vertex {v} belongs to no triangle"
            )));
        }
        Ok(Domain { points, mesh })
    }
    pub fn points(&self) -> &[Point] {
        &self.points
    }
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }
    pub fn triangles(&self) -> &[[u32; 3]] {
        self.mesh.faces()
    }
    pub fn n_faces(&self) -> usize {
        self.mesh.n_faces()
    }
    /// The corners of face `f`.
    pub fn face_points(&self, f: u32) -> [Point; 3] {
        self.mesh.face(f).map(|v| self.points[v as usize])
    }
    /// Centroid of face `f`.
    pub fn centroid(&self, f: u32) -> Point {
        let [a, b, c] = self.face_points(f);
        [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0]
    }
    /// The point with barycentric coordinates `bary` in face `f`.
    pub fn point_in_face(&self, f: u32, bary: [f64; 3]) -> Point {
        let [a, b, c] = self.face_points(f);
        [
            bary[0] * a[0] + bary[1] * b[0] + bary[2] * c[0],
            bary[0] * a[1] + bary[1] * b[1] + bary[2] * c[1],
        ]
    }
}

/// Uniform grid of the triangles' support boxes, for finding the basis functions that may be
/// non-zero at a point.
#[derive(Debug, Clone)]
struct Grid {
    lo: Point,
    cell: f64,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    fn new(boxes: &[[Point; 2]]) -> Grid {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut mean = 0.0;
        for b in boxes {
            for c in 0..2 {
                lo[c] = lo[c].min(b[0][c]);
                hi[c] = hi[c].max(b[1][c]);
            }
            mean += (b[1][0] - b[0][0]).max(b[1][1] - b[0][1]);
        }
        mean /= boxes.len().max(1) as f64;
        let ext = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-300);
        let mut cell = mean.max(ext / 2048.0);
        if !(cell > 0.0) {
            cell = 1.0;
        }
        let nx = (((hi[0] - lo[0]) / cell).floor() as usize + 1).min(4096);
        let ny = (((hi[1] - lo[1]) / cell).floor() as usize + 1).min(4096);
        let idx =
            |x: f64, n: usize, o: f64| (((x - o) / cell).floor().max(0.0) as usize).min(n - 1);
        let mut count = vec![0u32; nx * ny + 1];
        let ranges: Vec<[usize; 4]> = boxes
            .iter()
            .map(|b| {
                [
                    idx(b[0][0], nx, lo[0]),
                    idx(b[1][0], nx, lo[0]),
                    idx(b[0][1], ny, lo[1]),
                    idx(b[1][1], ny, lo[1]),
                ]
            })
            .collect();
        for r in &ranges {
            for j in r[2]..=r[3] {
                for i in r[0]..=r[1] {
                    count[j * nx + i + 1] += 1;
                }
            }
        }
        for k in 1..count.len() {
            count[k] += count[k - 1];
        }
        let mut fillp = count.clone();
        let mut items = vec![0u32; count[nx * ny] as usize];
        for (t, r) in ranges.iter().enumerate() {
            for j in r[2]..=r[3] {
                for i in r[0]..=r[1] {
                    items[fillp[j * nx + i] as usize] = t as u32;
                    fillp[j * nx + i] += 1;
                }
            }
        }
        Grid {
            lo,
            cell,
            nx,
            ny,
            start: count,
            items,
        }
    }
    fn query(&self, u: Point) -> &[u32] {
        let fx = ((u[0] - self.lo[0]) / self.cell).floor();
        let fy = ((u[1] - self.lo[1]) / self.cell).floor();
        if !(fx >= 0.0 && fy >= 0.0) || fx as usize >= self.nx || fy as usize >= self.ny {
            return &[];
        }
        let c = fy as usize * self.nx + fx as usize;
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

/// Arithmetic of the simplex-spline recurrence in an evaluation.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// Double-double recurrence ([`SimplexFamily::eval_offset_extended`]) whenever partials
    /// are asked for (values alone use the double recurrence, which is accurate for them):
    /// partials agree between charts and between nearby points to ~1e-12 of their size. The
    /// default.
    #[default]
    Extended,
    /// Double precision (~8× faster): values to 1e-15, but an order-`k` partial carries
    /// rounding noise `~ε (D/r)^k` (`D/r` the ratio of a basis function's support to its
    /// thinnest knot cloud), up to 1e-8–1e-6 of the partial at edges and vertices of graded
    /// meshes. Enough for quadrature (the fit's Gram matrix) and tessellation.
    Double,
}

/// Scratch space for evaluations (reuse it: evaluation does not allocate once it is warm).
/// `precision` chooses the arithmetic of the manifold spline's basis evaluations
/// ([`crate::spline::manifold::ManifoldSpace`]).
#[derive(Debug, Default, Clone)]
pub struct Workspace {
    pub precision: Precision,
    pub(crate) simplex: Vec<f64>,
    pub(crate) simplex_dd: Vec<Dd>,
    pub(crate) local: Vec<f64>,
    /// Global control-point indices of the basis functions found by [`DmsSpace::basis_at`].
    pub indices: Vec<u32>,
    /// Their values and partials, `n_partials(order)` per function.
    pub values: Vec<f64>,
    /// Order-2 rotations of the manifold spline's candidate bases, one slot per candidate of
    /// the face last evaluated (`crate::spline::manifold::charts::rotate_partials2_cached`).
    pub(crate) rot2: Vec<Option<([f64; 2], [f64; 36])>>,
}

impl Workspace {
    /// An empty workspace whose evaluations use `precision`.
    pub fn with_precision(precision: Precision) -> Workspace {
        Workspace {
            precision,
            ..Workspace::default()
        }
    }
}

/// Quality of the knot configuration, as measured by [`DmsSpace::new`].
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct KnotReport {
    /// Smallest relative signed area of a `Δ_β^I` (> 0 required).
    pub min_orientation: f64,
    /// Smallest `|Ω_I| / |I|` (> 0 required).
    pub min_omega_ratio: f64,
    /// Smallest sine-like measure of collinearity of three knots of one triangle.
    pub min_general_position: f64,
    /// Largest number of simplex-spline nodes of one triangle.
    pub max_nodes: usize,
}

/// The DMS spline space of a planar triangulation: domain, knots and the basis of every
/// triangle. Control points are indexed `face * (n+1)(n+2)/2 + position of β`.
#[derive(Debug, Clone)]
pub struct DmsSpace {
    domain: Domain,
    clouds: KnotClouds,
    bases: Vec<TriangleBasis>,
    grid: Grid,
    report: KnotReport,
}

impl DmsSpace {
    /// Build the space and check the DMS conditions (module docs); the error names the face
    /// or vertex at fault.
    pub fn new(domain: Domain, clouds: KnotClouds) -> Result<DmsSpace> {
        let n = clouds.degree();
        let mesh = domain.mesh();
        if clouds.n_vertices() != mesh.n_vertices() {
            return Err(Error::input(format!(
                "knot clouds for {} vertices, domain has {}",
                clouds.n_vertices(),
                mesh.n_vertices()
            )));
        }
        for v in 0..mesh.n_vertices() as u32 {
            if clouds.cloud(v)[0] != domain.points[v as usize] {
                return Err(Error::input(format!(
                    "knot t_(v,0) of vertex {v} is not the vertex itself"
                )));
            }
        }
        // Boundary condition: knots of boundary vertices outside their boundary edges.
        for h in mesh.n_corners() as u32..mesh.n_halfedges() as u32 {
            // interior twin a → b has the domain on its left
            let hi = mesh.he_twin(h);
            let (a, b) = (mesh.he_origin(hi), mesh.he_tip(hi));
            let (pa, pb) = (domain.points[a as usize], domain.points[b as usize]);
            for &v in &[a, b] {
                for (k, t) in clouds.cloud(v).iter().enumerate().skip(1) {
                    if !(det3(pa, pb, *t) < 0.0) {
                        return Err(Error::input(format!(
                            "DMS knots: knot {k} of boundary vertex {v} is not outside the boundary edge ({a}, {b}); polynomial reproduction would fail near it"
                        )));
                    }
                }
            }
        }
        use rayon::prelude::*;
        let bases: Vec<TriangleBasis> = mesh
            .faces()
            .par_iter()
            .enumerate()
            .map(|(f, t)| {
                TriangleBasis::new(n, t.map(|v| clouds.cloud(v)))
                    .map_err(|e| Error::input(format!("face {f}: {e}")))
            })
            .collect::<Result<_>>()?;
        let mut report = KnotReport {
            min_orientation: f64::INFINITY,
            min_omega_ratio: f64::INFINITY,
            min_general_position: f64::INFINITY,
            max_nodes: 0,
        };
        for b in &bases {
            report.min_orientation = report.min_orientation.min(b.min_orientation);
            report.min_omega_ratio = report.min_omega_ratio.min(b.omega_ratio);
            report.min_general_position = report.min_general_position.min(b.general_position);
            report.max_nodes = report.max_nodes.max(b.n_nodes());
        }
        let boxes: Vec<[Point; 2]> = bases.iter().map(|b| b.bbox).collect();
        let grid = Grid::new(&boxes);
        Ok(DmsSpace {
            domain,
            clouds,
            bases,
            grid,
            report,
        })
    }

    /// Convenience: place knots with [`KnotClouds::place`] and build the space.
    pub fn with_placed_knots(
        domain: Domain,
        degree: usize,
        opts: &KnotOptions,
    ) -> Result<DmsSpace> {
        let clouds = KnotClouds::place(&domain, degree, opts)?;
        DmsSpace::new(domain, clouds)
    }

    pub fn degree(&self) -> usize {
        self.clouds.degree()
    }
    pub fn domain(&self) -> &Domain {
        &self.domain
    }
    pub fn clouds(&self) -> &KnotClouds {
        &self.clouds
    }
    pub fn report(&self) -> KnotReport {
        self.report
    }
    /// The basis of face `f`.
    pub fn triangle(&self, f: u32) -> &TriangleBasis {
        &self.bases[f as usize]
    }
    /// Control points per triangle.
    pub fn per_triangle(&self) -> usize {
        per_triangle(self.degree())
    }
    /// Total number of control points (basis functions).
    pub fn n_control_points(&self) -> usize {
        self.bases.len() * self.per_triangle()
    }
    /// Global index of control point `β` of face `f`.
    pub fn control_index(&self, f: u32, beta: [usize; 3]) -> usize {
        f as usize * self.per_triangle() + multi_index_position(self.degree(), beta)
    }

    /// Find a face containing `u` (closed triangles; `None` outside the domain).
    pub fn locate(&self, u: Point) -> Option<u32> {
        let mut best: Option<(f64, u32)> = None;
        for &f in self.grid.query(u) {
            let [a, b, c] = self.domain.face_points(f);
            let area = det3(a, b, c);
            let m = det3(u, b, c).min(det3(a, u, c)).min(det3(a, b, u)) / area;
            if m >= -1e-12 && best.is_none_or(|(s, _)| m > s) {
                best = Some((m, f));
            }
        }
        best.map(|(_, f)| f)
    }

    /// All basis functions that may be non-zero at `u` in face `face` (values and partials up
    /// to `order`, as limits from inside `face`), written to `ws.indices` / `ws.values`.
    /// Returns the number of functions.
    pub fn basis_at(&self, face: u32, u: Point, order: usize, ws: &mut Workspace) -> Result<usize> {
        if face as usize >= self.bases.len() || !u[0].is_finite() || !u[1].is_finite() {
            return Err(Error::input(format!(
                "spline evaluation at ({}, {}) in face {face}: the domain has {} faces and the point must be finite",
                u[0],
                u[1],
                self.bases.len()
            )));
        }
        let np = n_partials(order);
        let nb = self.per_triangle();
        let c = self.domain.centroid(face);
        let mut dir = sub(c, u);
        if dir[0] == 0.0 && dir[1] == 0.0 {
            dir = [1.0, 0.0];
        }
        ws.indices.clear();
        ws.values.clear();
        if ws.local.len() < nb * np {
            ws.local.resize(nb * np, 0.0);
        }
        for &t in self.grid.query(u) {
            let basis = &self.bases[t as usize];
            if !basis.may_contain(u) {
                continue;
            }
            match ws.precision {
                Precision::Extended if order > 0 => {
                    // `u − origin` is exact in double-double.
                    let o = basis.origin();
                    let x = [Dd::new(u[0]) - Dd::new(o[0]), Dd::new(u[1]) - Dd::new(o[1])];
                    basis.eval_offset_extended(x, dir, order, &mut ws.simplex_dd, &mut ws.local)
                }
                _ => basis.eval(u, dir, order, &mut ws.simplex, &mut ws.local),
            }
            for b in 0..nb {
                ws.indices.push((t as usize * nb + b) as u32);
            }
            ws.values.extend_from_slice(&ws.local[..nb * np]);
        }
        Ok(ws.indices.len())
    }

    /// Evaluate `F = Σ c N` and its partials up to `order` at `u` in `face`:
    /// `out[k * dim + d]` is partial `k` (layout of [`crate::spline::simplex::partial_index`])
    /// of coordinate `d`. `control` holds `dim` numbers per control point.
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &self,
        control: &[f64],
        dim: usize,
        face: u32,
        u: Point,
        order: usize,
        ws: &mut Workspace,
        out: &mut [f64],
    ) -> Result<()> {
        let n = self.domain().n_faces() * per_triangle(self.degree());
        evaluate_with(control, dim, n, order, ws, out, |ws| {
            self.basis_at(face, u, order, ws)
        })
    }

    /// Control points (`dim` = 1) of a polynomial of degree `≤ n` by blossoming: the spline
    /// with these control points equals the polynomial on the whole domain.
    pub fn control_points_of_polynomial(&self, p: &Polynomial) -> Result<Vec<f64>> {
        let n = self.degree();
        if p.degree() > n {
            return Err(Error::input(format!(
                "a polynomial of degree {} is not in the spline space of degree {n}",
                p.degree()
            )));
        }
        let mut c = Vec::with_capacity(self.n_control_points());
        for basis in &self.bases {
            for beta in multi_indices(n) {
                c.push(p.blossom(&basis.blossom_args(beta)));
            }
        }
        Ok(c)
    }

    /// Initial control points of paper 000 §5 step (i): the degree-`n` uniform subdivision of
    /// every domain triangle mapped by its own linear interpolation of `positions` (one point of
    /// dimension `dim` per domain vertex): `c_{I,β} = Σ_m β_m P_{v_m} / n`.
    pub fn subdivision_control_points(&self, positions: &[f64], dim: usize) -> Result<Vec<f64>> {
        let n = self.degree();
        let nv = self.domain.mesh().n_vertices();
        if positions.len() != nv * dim {
            return Err(Error::input(format!(
                "{} coordinates given for {nv} domain vertices of dimension {dim}",
                positions.len()
            )));
        }
        let mut c = Vec::with_capacity(self.n_control_points() * dim);
        for t in self.domain.triangles() {
            for beta in multi_indices(n) {
                for d in 0..dim {
                    let mut s = 0.0;
                    for m in 0..3 {
                        s += beta[m] as f64 * positions[t[m] as usize * dim + d];
                    }
                    c.push(s / n as f64);
                }
            }
        }
        Ok(c)
    }
}

/// `F = Σ c N` and its partials up to `order` (`out[k * dim + d]`) for a spline space with
/// `n_control_points` control points, `basis` filling `ws` with the basis functions at the
/// point ([`DmsSpace::evaluate`], [`super::space::evaluate`]).
pub(crate) fn evaluate_with(
    control: &[f64],
    dim: usize,
    n_control_points: usize,
    order: usize,
    ws: &mut Workspace,
    out: &mut [f64],
    basis: impl FnOnce(&mut Workspace) -> Result<usize>,
) -> Result<()> {
    let np = n_partials(order);
    if control.len() != n_control_points * dim || out.len() < np * dim {
        return Err(Error::input(format!(
            "spline evaluation: {} control numbers for {} control points of dimension {dim}, output of {} for {} numbers",
            control.len(),
            n_control_points,
            out.len(),
            np * dim
        )));
    }
    let m = basis(ws)?;
    combine(control, dim, m, np, ws, out);
    Ok(())
}

/// `out = Σ_i c_{indices[i]} values[i]` over the first `m` basis functions of `ws`, summed as
/// `c_0 + Σ_i (c_i − c_0) values[i]` (partials: without the `c_0` term), `c_0` the first
/// function's control point: equal by the partition of unity (`Σ N = 1`, `Σ ∂^α N = 0`), but
/// the terms are of the size of the spline's support instead of its distance from the origin.
/// A face's second partials are sums of terms up to 10⁶ × their result; in the plain form
/// their rounding (`ε |c|`) alone reached 1e-10 of `∂²F`.
pub(crate) fn combine(
    control: &[f64],
    dim: usize,
    m: usize,
    np: usize,
    ws: &Workspace,
    out: &mut [f64],
) {
    out[..np * dim].fill(0.0);
    if m == 0 {
        return;
    }
    let g0 = ws.indices[0] as usize;
    let c0 = &control[g0 * dim..(g0 + 1) * dim];
    for i in 0..m {
        let g = ws.indices[i] as usize;
        let vals = &ws.values[i * np..(i + 1) * np];
        let c = &control[g * dim..(g + 1) * dim];
        for k in 0..np {
            let v = vals[k];
            if v != 0.0 {
                for d in 0..dim {
                    out[k * dim + d] += v * (c[d] - c0[d]);
                }
            }
        }
    }
    for d in 0..dim {
        out[d] += c0[d];
    }
}
