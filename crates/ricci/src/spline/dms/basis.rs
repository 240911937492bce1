//! The DMS basis of one triangle ([`TriangleBasis`], module docs of [`super`]): the simplex
//! splines of its knot sets, their normalisation and the blossom of the B-patch polynomial.

use super::*;

/// The DMS basis functions `N_{I,β}`, `|β| = n`, of one triangle, built from the knot clouds
/// of its three vertices (counter-clockwise) in any coordinate system — a chart of a manifold
/// spline supplies them in its own coordinates.
#[derive(Debug, Clone)]
pub struct TriangleBasis {
    pub(super) degree: usize,
    /// Clouds of the three vertices, `[m * (n+1) + k] = t_{m,k}`.
    pub(super) knots: Vec<Point>,
    pub(super) family: SimplexFamily,
    /// `|d_β|` per β (in [`multi_indices`] order).
    pub(super) scale: Vec<f64>,
    /// Bounding box of all knots (contains every support).
    pub(super) bbox: [Point; 2],
    /// Convex hull of all knots, counter-clockwise (contains every support).
    pub(super) hull: Vec<Point>,
    /// Per hull edge `i → i + 1`: the tolerance of [`Self::may_contain`]'s side test,
    /// `−1e-9 · |edge| · diameter`, computed once (it was computed at every call, two `hypot`s
    /// per hull edge and evaluation; the same expression, so the same numbers).
    pub(super) hull_tol: Vec<f64>,
    /// Affine barycentric maps of `Δ_γ`, `|γ| < n`, for the blossom: per γ (ordered by `|γ|`,
    /// then [`multi_indices`]) `[a, bx, by]` for each of the three coordinates.
    pub(super) patch: Vec<[[f64; 3]; 3]>,
    /// Smallest `det Δ_β / (longest side)²` over `|β| ≤ n`.
    pub(super) min_orientation: f64,
    /// Area of `Ω_I = ∩ Δ_β` relative to the area of `Δ_0` (the domain triangle).
    pub(super) omega_ratio: f64,
    /// [`general_position`] of the knot array.
    pub(super) general_position: f64,
}

/// The side-test tolerances of [`TriangleBasis::may_contain`], one per hull edge.
fn hull_tolerances(hull: &[Point], bbox: [Point; 2]) -> Vec<f64> {
    let k = hull.len();
    let diam = (bbox[1][0] - bbox[0][0]).max(bbox[1][1] - bbox[0][1]);
    (0..k)
        .map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % k]);
            let len = norm(sub(b, a));
            -1e-9 * len * diam
        })
        .collect()
}

impl TriangleBasis {
    /// Build the basis of a triangle whose vertices carry the clouds `clouds[m] = t_{m,0..n}`
    /// (vertices counter-clockwise). Fails if the knots violate the DMS conditions that can be
    /// checked on one triangle: a triangle `Δ_β` that is not positively oriented, an empty
    /// `Ω_I`, or three collinear knots.
    pub fn new(degree: usize, clouds: [&[Point]; 3]) -> Result<TriangleBasis> {
        let n = degree;
        if !(1..=MAX_DEGREE).contains(&n) || clouds.iter().any(|c| c.len() != n + 1) {
            return Err(Error::input(format!(
                "DMS triangle: degree {n} needs clouds of {} knots each (degree 1..={MAX_DEGREE})",
                n + 1
            )));
        }
        let mut knots = Vec::with_capacity(3 * (n + 1));
        for c in clouds {
            knots.extend_from_slice(c);
        }
        let t = |m: usize, k: usize| knots[m * (n + 1) + k];
        let (min_orientation, omega_ratio) = patch_quality(n, &knots);
        if !(min_orientation > 1e-9) {
            return Err(Error::input(format!(
                "DMS knots: a triangle Δ_β is not positively oriented (relative signed area {min_orientation:.2e}); move the knots closer to their vertices"
            )));
        }
        if !(omega_ratio > 1e-9) {
            return Err(Error::input(
                "DMS knots: the triangles Δ_β of a domain triangle have no common interior point (Ω_I is empty); move the knots closer to their vertices",
            ));
        }
        let gp = general_position(&knots);
        if !(gp > 1e-9) {
            return Err(Error::input(format!(
                "DMS knots: three knots of a triangle are collinear (relative area {gp:.1e}); the basis would lose smoothness"
            )));
        }
        let groups: Vec<u8> = (0..3 * (n + 1)).map(|i| (i / (n + 1)) as u8).collect();
        let betas = multi_indices(n);
        let mut sets = Vec::with_capacity(betas.len());
        let mut scale = Vec::with_capacity(betas.len());
        for beta in &betas {
            let mut mask = 0u64;
            for m in 0..3 {
                for k in 0..=beta[m] {
                    mask |= 1 << (m * (n + 1) + k);
                }
            }
            sets.push(mask);
            scale.push(det3(t(0, beta[0]), t(1, beta[1]), t(2, beta[2])));
        }
        let family = SimplexFamily::new(&knots, &groups, &sets)?;
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for k in &knots {
            for c in 0..2 {
                lo[c] = lo[c].min(k[c]);
                hi[c] = hi[c].max(k[c]);
            }
        }
        let mut patch = Vec::new();
        for total in 0..n {
            for g in multi_indices(total) {
                let w = [t(0, g[0]), t(1, g[1]), t(2, g[2])];
                let det = det3(w[0], w[1], w[2]);
                let mut maps = [[0.0; 3]; 3];
                for j in 0..3 {
                    let (q, r) = (w[(j + 1) % 3], w[(j + 2) % 3]);
                    maps[j] = [
                        (q[0] * r[1] - q[1] * r[0]) / det,
                        (q[1] - r[1]) / det,
                        (r[0] - q[0]) / det,
                    ];
                }
                patch.push(maps);
            }
        }
        let hull = convex_hull(&knots);
        let hull_tol = hull_tolerances(&hull, [lo, hi]);
        Ok(TriangleBasis {
            degree: n,
            general_position: gp,
            hull,
            hull_tol,
            knots,
            family,
            scale,
            bbox: [lo, hi],
            patch,
            min_orientation,
            omega_ratio,
        })
    }

    pub fn degree(&self) -> usize {
        self.degree
    }
    /// Number of basis functions, `(n+1)(n+2)/2`.
    pub fn len(&self) -> usize {
        self.scale.len()
    }
    pub fn is_empty(&self) -> bool {
        self.scale.is_empty()
    }
    /// Knot `t_{m,k}` (vertex `m` of the triangle).
    pub fn knot(&self, m: usize, k: usize) -> Point {
        self.knots[m * (self.degree + 1) + k]
    }
    /// Bounding box of the knots, which contains the support of every basis function.
    pub fn bbox(&self) -> [Point; 2] {
        self.bbox
    }
    /// Could `u` be in the support of a basis function (inside or on the convex hull of the
    /// knots, with a small tolerance)?
    #[inline]
    pub fn may_contain(&self, u: Point) -> bool {
        if !(u[0] >= self.bbox[0][0]
            && u[0] <= self.bbox[1][0]
            && u[1] >= self.bbox[0][1]
            && u[1] <= self.bbox[1][1])
        {
            return false;
        }
        let k = self.hull.len();
        for i in 0..k {
            let (a, b) = (self.hull[i], self.hull[(i + 1) % k]);
            if det3(a, b, u) < self.hull_tol[i] {
                return false;
            }
        }
        true
    }
    /// Smallest relative signed area of the triangles `Δ_β`, `|β| ≤ n`.
    pub fn min_orientation(&self) -> f64 {
        self.min_orientation
    }
    /// Area of `Ω_I` over the area of the triangle.
    pub fn omega_ratio(&self) -> f64 {
        self.omega_ratio
    }
    /// How far the knots are from having three on a line ([`general_position`]).
    pub fn general_position(&self) -> f64 {
        self.general_position
    }
    /// Smallest relative determinant of the recurrence triangles.
    pub fn min_relative_det(&self) -> f64 {
        self.family.min_relative_det()
    }
    /// Number of simplex-spline nodes one evaluation computes.
    pub fn n_nodes(&self) -> usize {
        self.family.n_nodes()
    }
    /// Scratch length for [`Self::eval`] with derivatives up to `order`.
    pub fn workspace_len(&self, order: usize) -> usize {
        self.family.workspace_len(order)
    }

    /// Evaluate all `N_{I,β}` and their partials up to `order` at `u` as limits from direction
    /// `dir`: `out[b * n_partials(order) + partial_index(a, c)]` for β number `b`.
    pub fn eval(&self, u: Point, dir: Point, order: usize, work: &mut Vec<f64>, out: &mut [f64]) {
        self.family.eval(u, dir, order, work, out);
        self.apply_scale(order, out);
    }

    /// The centroid of the knots: the origin of [`Self::eval_offset`].
    pub fn origin(&self) -> Point {
        self.family.origin()
    }

    /// Simplex splines → `N_{I,β} = |d_β| M(· | V_β)` (values and partials, in place).
    fn apply_scale(&self, order: usize, out: &mut [f64]) {
        let np = n_partials(order);
        for (b, s) in self.scale.iter().enumerate() {
            for v in &mut out[b * np..(b + 1) * np] {
                *v *= s;
            }
        }
    }

    /// [`Self::eval`] at `origin() + x`, the point given by its offset from the knots'
    /// centroid (see [`SimplexFamily::eval_offset`]).
    pub fn eval_offset(
        &self,
        x: Point,
        dir: Point,
        order: usize,
        work: &mut Vec<f64>,
        out: &mut [f64],
    ) {
        self.family.eval_offset(x, dir, order, work, out);
        self.apply_scale(order, out);
    }

    /// [`Self::eval_offset`] with the recurrence in double-double
    /// ([`SimplexFamily::eval_offset_extended`]).
    pub fn eval_offset_extended(
        &self,
        x: [Dd; 2],
        dir: Point,
        order: usize,
        work: &mut Vec<Dd>,
        out: &mut [f64],
    ) {
        self.family.eval_offset_extended(x, dir, order, work, out);
        self.apply_scale(order, out);
    }

    /// The arguments `t_{0,0..β_0−1}, t_{1,0..β_1−1}, t_{2,0..β_2−1}` at which the blossom gives
    /// the control point of β.
    pub fn blossom_args(&self, beta: [usize; 3]) -> Vec<Point> {
        let mut a = Vec::with_capacity(self.degree);
        for (m, &bm) in beta.iter().enumerate() {
            for k in 0..bm {
                a.push(self.knot(m, k));
            }
        }
        a
    }

    /// Weights `w_β` with `blossom of P^I at args = Σ_β w_β c_{I,β}`, where `P^I` is the B-patch
    /// polynomial of this triangle's control points (module docs); `args.len()` must be `n`.
    /// Generalised de Casteljau: start from weight 1 on `γ = 0` and, for each argument in
    /// turn, split the weight of every `γ` among `γ + e_m` by the barycentric coordinates of
    /// the argument in `Δ_γ = [t_{0,γ_0}, t_{1,γ_1}, t_{2,γ_2}]`.
    pub fn blossom_weights(&self, args: &[Point], out: &mut [f64]) {
        let n = self.degree;
        assert_eq!(args.len(), n);
        // weights per level in a dense (n+1)² array indexed by (γ_0, γ_1).
        let w = n + 1;
        let mut cur = vec![0.0; w * w];
        let mut next = vec![0.0; w * w];
        cur[0] = 1.0;
        let mut pidx = 0;
        for (s, x) in args.iter().enumerate() {
            next.fill(0.0);
            for g in multi_indices(s) {
                let maps = &self.patch[pidx];
                pidx += 1;
                let wt = cur[g[0] * w + g[1]];
                if wt == 0.0 {
                    continue;
                }
                let lam = maps.map(|m| m[0] + m[1] * x[0] + m[2] * x[1]);
                next[(g[0] + 1) * w + g[1]] += wt * lam[0];
                next[g[0] * w + g[1] + 1] += wt * lam[1];
                next[g[0] * w + g[1]] += wt * lam[2];
            }
            std::mem::swap(&mut cur, &mut next);
        }
        for (b, beta) in multi_indices(n).iter().enumerate() {
            out[b] = cur[beta[0] * w + beta[1]];
        }
    }
}

/// [`TriangleBasis::blossom_weights`] for the knot array `knots` (`[m * (n+1) + k] = t_{m,k}`)
/// given directly, in any coordinate system: the barycentric coordinates of each argument in
/// `Δ_γ` are formed from differences to the argument, so a frame local to the triangle keeps
/// them to rounding of the triangle's size.
pub(crate) fn blossom_weights_of(n: usize, knots: &[Point], args: &[Point], out: &mut [f64]) {
    let t = |m: usize, k: usize| knots[m * (n + 1) + k];
    let w = n + 1;
    let mut cur = vec![0.0; w * w];
    let mut next = vec![0.0; w * w];
    cur[0] = 1.0;
    for (s, x) in args.iter().enumerate() {
        next.fill(0.0);
        for g in multi_indices(s) {
            let wt = cur[g[0] * w + g[1]];
            if wt == 0.0 {
                continue;
            }
            let d = [
                sub(t(0, g[0]), *x),
                sub(t(1, g[1]), *x),
                sub(t(2, g[2]), *x),
            ];
            let det = det3(t(0, g[0]), t(1, g[1]), t(2, g[2]));
            let cr = |a: Point, b: Point| a[0] * b[1] - a[1] * b[0];
            let lam = [
                cr(d[1], d[2]) / det,
                cr(d[2], d[0]) / det,
                cr(d[0], d[1]) / det,
            ];
            next[(g[0] + 1) * w + g[1]] += wt * lam[0];
            next[g[0] * w + g[1] + 1] += wt * lam[1];
            next[g[0] * w + g[1]] += wt * lam[2];
        }
        std::mem::swap(&mut cur, &mut next);
    }
    for (b, beta) in multi_indices(n).iter().enumerate() {
        out[b] = cur[beta[0] * w + beta[1]];
    }
}
