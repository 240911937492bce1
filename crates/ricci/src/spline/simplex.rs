//! Bivariate simplex splines `M(u | V)` and their derivatives, evaluated for a whole family of
//! knot sets at once.
//!
//! A simplex spline of degree `p` has a knot set `V` of `p + 3` points in the plane. We use the
//! normalisation in which the degree-0 spline of a triangle `W` is `χ_[W)(u) / |det W|`
//! (`det W` = twice the signed area) and the recurrence of Micchelli carries no factor:
//!
//! ```text
//! M(u | V) = Σ_j λ_j(u | W) M(u | V \ w_j),        W = {w_0, w_1, w_2} ⊂ V affinely independent,
//! D_y M(u | V) = p Σ_j μ_j(y | W) M(u | V \ w_j),   y = Σ μ_j w_j, Σ μ_j = 0,
//! ```
//!
//! where `λ(u | W)` are the barycentric coordinates of `u` and `μ(y | W)` those of the vector `y`
//! (the linear part of `λ`). With this normalisation `∫ M(· | V) = 1 / ((p + 1)(p + 2))`, so
//! that `|det W| M(· | V)` integrates to the same value as a Bernstein polynomial of degree `p`
//! over `W` — the normalisation of the DMS basis (Dahmen–Micchelli–Seidel 1992).
//!
//! **Half-open convention.** The recurrence holds everywhere once every degree-0 spline is
//! evaluated as a one-sided limit from the same direction: a point `u` counts as inside the
//! triangle `W` when `u + ε d + ε² d⊥` is inside for all small `ε > 0`, with `d` the evaluation
//! direction given by the caller and `d⊥` its counter-clockwise rotation. Every function and
//! derivative computed here is therefore the limit from direction `d`; for the continuous ones
//! (all derivatives of order `< p` when no three knots are collinear) this is just the value.
//! Points closer to a knot line than `1e-11` times the knot set's diameter are treated as lying
//! on it, so that points computed on a line in floating point get the one-sided limit too.
//! Each knot line is tested with one canonical orientation, so the degree-0 splines of a family
//! partition every neighbourhood consistently.
//!
//! **Families.** [`SimplexFamily`] evaluates many simplex splines over one knot array (say all
//! knot sets `V_β^I` of a DMS triangle): the recurrence is unrolled once into a DAG of knot
//! subsets (memoised by bitmask), and an evaluation is one pass over the DAG, leaves first. The
//! recurrence triangle `W` of a subset is the last knot of every knot group present, completed
//! by the knot that makes it fattest, which keeps the DAG small for DMS families and the
//! barycentric coordinates well conditioned.
//!
//! **Precision.** [`SimplexFamily::eval_offset`] runs the recurrence in double precision;
//! [`SimplexFamily::eval_offset_extended`] in double-double, for partials that must not carry
//! the recurrence's rounding (it grows like `(D/r)^k` for order `k`, `r` the thinnest knot
//! cloud and `D` the knot diameter; see `spline::manifold`, *Conditioning*).

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::numeric::dd::Dd;

/// A point or vector in the plane.
pub type Point = [f64; 2];

/// Points closer than this fraction of the knot-set diameter to a knot line are on the line.
const ON_LINE_REL: f64 = 1e-11;

#[inline]
fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}
#[inline]
fn cross(a: Point, b: Point) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
/// Twice the signed area of the triangle `(a, b, c)`.
#[inline]
pub fn det3(a: Point, b: Point, c: Point) -> f64 {
    cross(sub(b, a), sub(c, a))
}

/// Number of partial derivatives `∂_x^a ∂_y^b` with `a + b ≤ order`.
#[inline]
pub const fn n_partials(order: usize) -> usize {
    (order + 1) * (order + 2) / 2
}

/// Index of `∂_x^a ∂_y^b` in the derivative layout used everywhere in `spline`: by total order
/// `k = a + b`, then by `b`: `(0,0), (1,0), (0,1), (2,0), (1,1), (0,2), (3,0), …`.
#[inline]
pub const fn partial_index(a: usize, b: usize) -> usize {
    let k = a + b;
    k * (k + 1) / 2 + b
}

/// One knot line of a leaf triangle, in canonical orientation (from the knot with the lower
/// index to the higher one). `inside` is +1 if the triangle lies on the left of the line.
#[derive(Debug, Clone, Copy)]
struct Line {
    p: Point,
    dir: Point,
    /// `|cross(dir, u - p)|` below this means "on the line".
    tol: f64,
    inside: f64,
}

impl Line {
    /// Is `u` (approached from direction `d`, then `dp`) on the inner side?
    #[inline]
    fn admits(&self, u: Point, d: Point, dp: Point) -> bool {
        let s = cross(self.dir, sub(u, self.p));
        if s > self.tol {
            return self.inside > 0.0;
        }
        if s < -self.tol {
            return self.inside < 0.0;
        }
        let sd = cross(self.dir, d);
        let td = 1e-12 * (self.dir[0].abs() + self.dir[1].abs()) * (d[0].abs() + d[1].abs());
        if sd > td {
            return self.inside > 0.0;
        }
        if sd < -td {
            return self.inside < 0.0;
        }
        let sp = cross(self.dir, dp);
        (sp > 0.0) == (self.inside > 0.0)
    }
}

/// A degree-0 simplex spline: `χ_[W)(u) / |det W|`.
#[derive(Debug, Clone, Copy)]
struct Leaf {
    lines: [Line; 3],
    inv_det: f64,
    /// `1 / |det W|` in double-double ([`SimplexFamily::eval_offset_extended`]).
    inv_det_dd: Dd,
}

/// One way of running the recurrence at a node: `M(V) = Σ_j λ_j(u) M(child_j)` with
/// `λ_j(u) = a_j + bx_j u_x + by_j u_y` (local coordinates).
#[derive(Debug, Clone, Copy)]
struct Variant {
    child: [u32; 3],
    /// The recurrence triangle `W` (local coordinates) and `1 / det W`.
    w: [Point; 3],
    inv_det: f64,
    /// Linear parts of `λ_j`: `μ_j(e_x)`, `μ_j(e_y)` (the derivative formula's coefficients).
    bx: [f64; 3],
    by: [f64; 3],
    /// The same in double-double, from the (exact) local knots.
    inv_det_dd: Dd,
    bx_dd: [Dd; 3],
    by_dd: [Dd; 3],
}

/// `cross(a − x, b − x)` in double-double: the differences are exact (`two_sum`), so the only
/// rounding is double-double's own (~1e-32 relative).
#[inline]
fn cross_from_dd(a: Point, b: Point, x: [Dd; 2]) -> Dd {
    let (ax, ay) = (Dd::new(a[0]) - x[0], Dd::new(a[1]) - x[1]);
    let (bx, by) = (Dd::new(b[0]) - x[0], Dd::new(b[1]) - x[1]);
    ax * by - ay * bx
}

/// Twice the signed area of `(a, b, c)` in double-double.
#[inline]
fn det3_dd(a: Point, b: Point, c: Point) -> Dd {
    cross_from_dd(b, c, [Dd::new(a[0]), Dd::new(a[1])])
}

impl Variant {
    /// [`Self::lambda`] in double-double.
    #[inline]
    fn lambda_dd(&self, x: [Dd; 2]) -> [Dd; 3] {
        let w = &self.w;
        [
            cross_from_dd(w[1], w[2], x) * self.inv_det_dd,
            cross_from_dd(w[2], w[0], x) * self.inv_det_dd,
            cross_from_dd(w[0], w[1], x) * self.inv_det_dd,
        ]
    }

    /// `λ_j(x) = det(W with w_j replaced by x) / det W`, from differences to `x` so that each
    /// coordinate carries a small relative error.
    #[inline]
    fn lambda(&self, x: Point) -> [f64; 3] {
        let d = [sub(self.w[0], x), sub(self.w[1], x), sub(self.w[2], x)];
        [
            cross(d[1], d[2]) * self.inv_det,
            cross(d[2], d[0]) * self.inv_det,
            cross(d[0], d[1]) * self.inv_det,
        ]
    }
}

/// An internal node of degree `p ≥ 1`. Knot sets drawn from two clouds have two variants
/// (the thin recurrence triangle anchored at either cloud); evaluation uses the one whose
/// barycentric coordinates at `u` are smallest, which avoids cancellation near the far end.
#[derive(Debug, Clone, Copy)]
struct Node {
    var: [Variant; 2],
    two: bool,
    degree: f64,
}

impl Node {
    /// The variant used at `x` (the one whose barycentric coordinates there are smallest) and
    /// those coordinates.
    #[inline]
    fn variant_at(&self, x: Point) -> (&Variant, [f64; 3]) {
        let lam = self.var[0].lambda(x);
        if self.two {
            let lam2 = self.var[1].lambda(x);
            let s1 = lam[0].abs() + lam[1].abs() + lam[2].abs();
            let s2 = lam2[0].abs() + lam2[1].abs() + lam2[2].abs();
            if s2 < s1 {
                return (&self.var[1], lam2);
            }
        }
        (&self.var[0], lam)
    }
}

/// The evaluation direction `d` (`[1, 0]` for a zero `dir`) and its counter-clockwise
/// rotation `d⊥` (module docs, *Half-open convention*).
#[inline]
fn limit_directions(dir: Point) -> (Point, Point) {
    let d = if dir[0] == 0.0 && dir[1] == 0.0 {
        [1.0, 0.0]
    } else {
        dir
    };
    (d, [-d[1], d[0]])
}

/// A family of simplex splines over one array of knots, evaluated together (see module docs).
#[derive(Debug, Clone)]
pub struct SimplexFamily {
    /// Knots in local coordinates (relative to `origin`).
    knots: Vec<Point>,
    origin: Point,
    leaves: Vec<Leaf>,
    /// Internal nodes; node id `leaves.len() + k` is `nodes[k]`, children always come first.
    nodes: Vec<Node>,
    /// Node id of each requested knot set.
    roots: Vec<u32>,
    /// Degree of each requested knot set.
    root_degree: Vec<usize>,
    /// Smallest `|det|` of a recurrence triangle relative to the squared knot diameter: a
    /// measure of how far the knot sets are from degenerate.
    min_relative_det: f64,
    diameter: f64,
}

impl SimplexFamily {
    /// Build the family of simplex splines `M(· | V_r)` where each `V_r` is given as a bitmask
    /// over `knots` (bit `k` = knot `k`, at most 64 knots). `groups[k]` assigns every knot to a
    /// group (for DMS: the domain vertex whose cloud it belongs to; knots are ordered inside a
    /// group by index); pass all zeros if there is no such structure.
    ///
    /// Fails if a knot set has fewer than 3 knots or is (numerically) degenerate, i.e. if some
    /// recurrence step cannot find three knots that are not collinear.
    pub fn new(knots: &[Point], groups: &[u8], sets: &[u64]) -> Result<SimplexFamily> {
        if knots.len() > 64 || groups.len() != knots.len() {
            return Err(Error::input(format!(
                "simplex spline family: {} knots and {} group labels (at most 64 knots, one label each)",
                knots.len(),
                groups.len()
            )));
        }
        if knots.iter().any(|k| !k[0].is_finite() || !k[1].is_finite()) {
            return Err(Error::input("simplex spline family: a knot is not finite"));
        }
        let n = knots.len().max(1) as f64;
        let origin = [
            knots.iter().map(|k| k[0]).sum::<f64>() / n,
            knots.iter().map(|k| k[1]).sum::<f64>() / n,
        ];
        let local: Vec<Point> = knots.iter().map(|&k| sub(k, origin)).collect();
        let mut diameter: f64 = 0.0;
        for a in &local {
            for b in &local {
                let d = sub(*a, *b);
                diameter = diameter.max(d[0].hypot(d[1]));
            }
        }
        let mut b = Builder {
            knots: &local,
            groups,
            memo: HashMap::new(),
            leaves: Vec::new(),
            nodes: Vec::new(),
            min_rel: f64::INFINITY,
            diameter,
        };
        let mut roots = Vec::with_capacity(sets.len());
        let mut root_degree = Vec::with_capacity(sets.len());
        for &s in sets {
            if s.count_ones() < 3 || (knots.len() < 64 && s >> knots.len() != 0) {
                return Err(Error::input(format!(
                    "simplex spline family: knot set {s:#x} has fewer than 3 knots or refers to a missing knot"
                )));
            }
            roots.push(b.build(s)?);
            root_degree.push(s.count_ones() as usize - 3);
        }
        // Renumber: leaves first, then internal nodes in creation order (children first).
        let nl = b.leaves.len() as u32;
        let fix = |id: u32| -> u32 {
            if id & INTERNAL != 0 {
                nl + (id & !INTERNAL)
            } else {
                id
            }
        };
        let nodes = b
            .nodes
            .iter()
            .map(|nd| {
                let mut nd = *nd;
                for v in &mut nd.var {
                    v.child = v.child.map(fix);
                }
                nd
            })
            .collect();
        let roots = roots.into_iter().map(fix).collect();
        let min_relative_det = b.min_rel;
        let leaves = b.leaves;
        Ok(SimplexFamily {
            knots: local,
            origin,
            leaves,
            nodes,
            roots,
            root_degree,
            min_relative_det,
            diameter,
        })
    }

    /// Number of knot sets (functions) in the family.
    pub fn len(&self) -> usize {
        self.roots.len()
    }
    /// True if the family has no functions.
    pub fn is_empty(&self) -> bool {
        self.roots.is_empty()
    }
    /// Number of DAG nodes (distinct knot subsets) one evaluation visits.
    pub fn n_nodes(&self) -> usize {
        self.leaves.len() + self.nodes.len()
    }
    /// Degree of function `r`.
    pub fn degree(&self, r: usize) -> usize {
        self.root_degree[r]
    }
    /// Smallest `|det W|` over all recurrence triangles, relative to the squared diameter of
    /// the knots: ≈ 0 means three knots are (nearly) collinear.
    pub fn min_relative_det(&self) -> f64 {
        self.min_relative_det
    }
    /// Knot `k` in the caller's coordinates.
    pub fn knot(&self, k: usize) -> Point {
        [
            self.knots[k][0] + self.origin[0],
            self.knots[k][1] + self.origin[1],
        ]
    }
    /// Scratch length needed by [`Self::eval`] for derivatives up to `order`.
    pub fn workspace_len(&self, order: usize) -> usize {
        // Orders ≤ 2 share one layout of six partials per node (`eval_offset_upto2`).
        self.n_nodes() * n_partials(order.max(2))
    }

    /// Evaluate all functions of the family and their partial derivatives up to `order` at `u`,
    /// as limits from direction `dir` (see module docs; `dir` must not be zero).
    ///
    /// `out[r * n_partials(order) + partial_index(a, b)] = ∂_x^a ∂_y^b M(u | V_r)`.
    /// `work` is resized as needed (no allocation once it is large enough).
    pub fn eval(&self, u: Point, dir: Point, order: usize, work: &mut Vec<f64>, out: &mut [f64]) {
        self.eval_offset(sub(u, self.origin), dir, order, work, out);
    }

    /// The centroid of the knots, relative to which [`Self::eval_offset`] takes its point.
    pub fn origin(&self) -> Point {
        self.origin
    }

    /// [`Self::eval`] at the point `origin() + x`, given by its offset `x` from the knots'
    /// centroid: a caller that knows the point relative to nearby geometry (a face's corners)
    /// keeps its full precision, instead of rounding it to the caller's coordinates first
    /// (`ε |u|`, large against the knot spacing when the coordinates are far from the origin).
    pub fn eval_offset(
        &self,
        x: Point,
        dir: Point,
        order: usize,
        work: &mut Vec<f64>,
        out: &mut [f64],
    ) {
        let np = n_partials(order);
        debug_assert!(out.len() >= self.roots.len() * np);
        let need = self.n_nodes() * np;
        if work.len() < need {
            work.resize(need, 0.0);
        }
        let (d, dp) = limit_directions(dir);
        if order <= 2 {
            self.eval_offset_upto2(x, d, dp, order, work, out);
            return;
        }
        let nl = self.leaves.len();
        for (i, leaf) in self.leaves.iter().enumerate() {
            let inside = leaf.lines.iter().all(|l| l.admits(x, d, dp));
            let w = &mut work[i * np..(i + 1) * np];
            w.fill(0.0);
            if inside {
                w[0] = leaf.inv_det;
            }
        }
        for (k, nd) in self.nodes.iter().enumerate() {
            let (v, lam) = nd.variant_at(x);
            let (done, rest) = work.split_at_mut((nl + k) * np);
            let me = &mut rest[..np];
            let c = [
                v.child[0] as usize * np,
                v.child[1] as usize * np,
                v.child[2] as usize * np,
            ];
            me[0] = lam[0] * done[c[0]] + lam[1] * done[c[1]] + lam[2] * done[c[2]];
            // A simplex spline of degree p is piecewise of degree p: partials of higher order
            // vanish (and are not computed).
            let top = order.min(nd.degree as usize);
            me[n_partials(top)..].fill(0.0);
            for ord in 1..=top {
                for b in 0..=ord {
                    let a = ord - b;
                    let idx = partial_index(a, b);
                    // Peel one x-derivative if there is one, else one y-derivative.
                    let (coef, from) = if a > 0 {
                        (&v.bx, partial_index(a - 1, b))
                    } else {
                        (&v.by, partial_index(a, b - 1))
                    };
                    me[idx] = nd.degree
                        * (coef[0] * done[c[0] + from]
                            + coef[1] * done[c[1] + from]
                            + coef[2] * done[c[2] + from]);
                }
            }
        }
        for (r, &id) in self.roots.iter().enumerate() {
            out[r * np..(r + 1) * np]
                .copy_from_slice(&work[id as usize * np..(id as usize + 1) * np]);
        }
    }

    /// [`Self::eval_offset`] for partials up to order 2 (values, gradients, Hessians: the fit's
    /// thin-plate quadrature and the tessellation), the same recurrence with the same operations
    /// in the same order — so the same numbers — written out for six partials per node: one
    /// fixed-size block per node and child instead of the general loops over partial indices
    /// and their bounds checks (profile of `ricci demo`: this function was 23 % of the run).
    fn eval_offset_upto2(
        &self,
        x: Point,
        d: Point,
        dp: Point,
        order: usize,
        work: &mut Vec<f64>,
        out: &mut [f64],
    ) {
        const S: usize = 6;
        #[inline(always)]
        fn block(s: &[f64], at: usize) -> [f64; S] {
            let mut b = [0.0; S];
            b.copy_from_slice(&s[at..at + S]);
            b
        }
        let np = n_partials(order);
        let need = self.n_nodes() * S;
        if work.len() < need {
            work.resize(need, 0.0);
        }
        let nl = self.leaves.len();
        // Which nodes are not identically zero near `x` (a bit per node, when they fit): a node
        // whose children all vanish (under every variant) vanishes too and is skipped — most
        // of a family's knot subsets do not contain a given point.
        let mut live = [0u64; LIVE_WORDS];
        let track = self.n_nodes() <= 64 * LIVE_WORDS;
        let is_live =
            |live: &[u64; LIVE_WORDS], id: u32| live[id as usize / 64] >> (id % 64) & 1 == 1;
        for (i, leaf) in self.leaves.iter().enumerate() {
            let inside = leaf.lines.iter().all(|l| l.admits(x, d, dp));
            let v = if inside { leaf.inv_det } else { 0.0 };
            if inside && track {
                live[i / 64] |= 1 << (i % 64);
            }
            work[i * S..(i + 1) * S].copy_from_slice(&[v, 0.0, 0.0, 0.0, 0.0, 0.0]);
        }
        for (k, nd) in self.nodes.iter().enumerate() {
            if track {
                let any = |v: &Variant| v.child.iter().any(|&c| is_live(&live, c));
                if !(any(&nd.var[0]) || (nd.two && any(&nd.var[1]))) {
                    // All children are zero: so are the value and partials (the arithmetic
                    // below would give ±0).
                    work[(nl + k) * S..(nl + k + 1) * S].fill(0.0);
                    continue;
                }
                live[(nl + k) / 64] |= 1 << ((nl + k) % 64);
            }
            let (v, lam) = nd.variant_at(x);
            let (done, rest) = work.split_at_mut((nl + k) * S);
            let a = block(done, v.child[0] as usize * S);
            let b = block(done, v.child[1] as usize * S);
            let c = block(done, v.child[2] as usize * S);
            let mut me = [0.0; S];
            me[0] = lam[0] * a[0] + lam[1] * b[0] + lam[2] * c[0];
            // Partials of order above the node's degree vanish (see `eval_offset`).
            let top = order.min(nd.degree as usize);
            if top >= 1 {
                let p = nd.degree;
                let (bx, by) = (&v.bx, &v.by);
                // ∂x from the children's values, ∂y likewise.
                me[1] = p * (bx[0] * a[0] + bx[1] * b[0] + bx[2] * c[0]);
                me[2] = p * (by[0] * a[0] + by[1] * b[0] + by[2] * c[0]);
                if top >= 2 {
                    // ∂xx from ∂x, ∂xy from ∂y (peeling the x-derivative), ∂yy from ∂y.
                    me[3] = p * (bx[0] * a[1] + bx[1] * b[1] + bx[2] * c[1]);
                    me[4] = p * (bx[0] * a[2] + bx[1] * b[2] + bx[2] * c[2]);
                    me[5] = p * (by[0] * a[2] + by[1] * b[2] + by[2] * c[2]);
                }
            }
            rest[..S].copy_from_slice(&me);
        }
        for (r, &id) in self.roots.iter().enumerate() {
            let at = id as usize * S;
            out[r * np..(r + 1) * np].copy_from_slice(&work[at..at + np]);
        }
    }

    /// [`Self::eval_offset`] in double-double arithmetic (~32 digits), rounded to double at
    /// the end: the point's offset `xd` (double-double) and the knots are taken as exact,
    /// every barycentric coordinate and every sum of the recurrence is carried in
    /// double-double.
    ///
    /// Why: the derivative recurrence `D_y M(V) = p Σ μ_j M(V \ w_j)` cancels — the `μ_j` of
    /// a thin recurrence triangle (two knots from one cloud, one from another) are `~1/r`, `r`
    /// the cloud's radius — so in double precision an order-`k` partial carries a rounding
    /// error `~ε (D/r)^k` relative to its own size (`D` the knot diameter). That noise is not
    /// smooth in `u`: two evaluations at points one ulp apart, or at the same surface point
    /// reached from two charts, differ by it. In double-double it is `~1e-32 (D/r)^k`, below
    /// the final rounding. About 8× the cost of [`Self::eval_offset`].
    pub fn eval_offset_extended(
        &self,
        xd: [Dd; 2],
        dir: Point,
        order: usize,
        work: &mut Vec<Dd>,
        out: &mut [f64],
    ) {
        let np = n_partials(order);
        debug_assert!(out.len() >= self.roots.len() * np);
        let need = self.n_nodes() * np;
        if work.len() < need {
            work.resize(need, Dd::ZERO);
        }
        let (d, dp) = limit_directions(dir);
        let x = [xd[0].f64(), xd[1].f64()];
        let nl = self.leaves.len();
        for (i, leaf) in self.leaves.iter().enumerate() {
            let inside = leaf.lines.iter().all(|l| l.admits(x, d, dp));
            let w = &mut work[i * np..(i + 1) * np];
            w.fill(Dd::ZERO);
            if inside {
                w[0] = leaf.inv_det_dd;
            }
        }
        for (k, nd) in self.nodes.iter().enumerate() {
            let (v, _) = nd.variant_at(x);
            let (done, rest) = work.split_at_mut((nl + k) * np);
            let me = &mut rest[..np];
            let c = [
                v.child[0] as usize * np,
                v.child[1] as usize * np,
                v.child[2] as usize * np,
            ];
            // A child that vanishes identically near `u` (all partials zero) contributes
            // nothing; skipping it saves most of the double-double products at a point.
            let live = |ci: usize| done[ci..ci + np].iter().any(|z| z.hi != 0.0);
            let on = [live(c[0]), live(c[1]), live(c[2])];
            if !(on[0] || on[1] || on[2]) {
                me.fill(Dd::ZERO);
                continue;
            }
            let lam = v.lambda_dd(xd);
            let degree = Dd::new(nd.degree);
            let mut acc = Dd::ZERO;
            for j in 0..3 {
                if on[j] {
                    acc = acc + lam[j] * done[c[j]];
                }
            }
            me[0] = acc;
            let top = order.min(nd.degree as usize);
            me[n_partials(top)..].fill(Dd::ZERO);
            for ord in 1..=top {
                for b in 0..=ord {
                    let a = ord - b;
                    let idx = partial_index(a, b);
                    let (coef, from) = if a > 0 {
                        (&v.bx_dd, partial_index(a - 1, b))
                    } else {
                        (&v.by_dd, partial_index(a, b - 1))
                    };
                    let mut acc = Dd::ZERO;
                    for j in 0..3 {
                        if on[j] {
                            acc = acc + coef[j] * done[c[j] + from];
                        }
                    }
                    me[idx] = degree * acc;
                }
            }
        }
        for (r, &id) in self.roots.iter().enumerate() {
            for (o, z) in out[r * np..(r + 1) * np]
                .iter_mut()
                .zip(&work[id as usize * np..(id as usize + 1) * np])
            {
                *o = z.f64();
            }
        }
    }

    /// Diameter of the knot array.
    pub fn diameter(&self) -> f64 {
        self.diameter
    }
}

const INTERNAL: u32 = 1 << 31;

/// Words of the live-node bitset of [`SimplexFamily::eval_offset_upto2`] (families of up to
/// 1024 nodes skip their vanishing nodes; larger ones evaluate every node).
const LIVE_WORDS: usize = 16;

struct Builder<'a> {
    knots: &'a [Point],
    groups: &'a [u8],
    memo: HashMap<u64, u32>,
    leaves: Vec<Leaf>,
    nodes: Vec<Node>,
    min_rel: f64,
    diameter: f64,
}

impl Builder<'_> {
    fn build(&mut self, mask: u64) -> Result<u32> {
        if let Some(&id) = self.memo.get(&mask) {
            return Ok(id);
        }
        let ws = self.choose_triangles(mask)?;
        for w in &ws {
            let det = det3(self.knots[w[0]], self.knots[w[1]], self.knots[w[2]]);
            self.min_rel = self
                .min_rel
                .min(det.abs() / (self.diameter * self.diameter));
        }
        let id = if mask.count_ones() == 3 {
            let w = ws[0];
            let det = det3(self.knots[w[0]], self.knots[w[1]], self.knots[w[2]]);
            let (w, det) = if det > 0.0 {
                (w, det)
            } else {
                ([w[0], w[2], w[1]], -det)
            };
            let tol_len = ON_LINE_REL * self.diameter;
            let mut lines = [Line {
                p: [0.0; 2],
                dir: [0.0; 2],
                tol: 0.0,
                inside: 1.0,
            }; 3];
            for e in 0..3 {
                let (i, j) = (w[e], w[(e + 1) % 3]);
                // Counter-clockwise edge i → j has the triangle on its left.
                let (lo, hi, inside) = if i < j { (i, j, 1.0) } else { (j, i, -1.0) };
                let dir = sub(self.knots[hi], self.knots[lo]);
                lines[e] = Line {
                    p: self.knots[lo],
                    dir,
                    tol: tol_len * dir[0].hypot(dir[1]),
                    inside,
                };
            }
            let det_dd = det3_dd(self.knots[w[0]], self.knots[w[1]], self.knots[w[2]]);
            self.leaves.push(Leaf {
                lines,
                inv_det: 1.0 / det,
                inv_det_dd: Dd::ONE / det_dd,
            });
            (self.leaves.len() - 1) as u32
        } else {
            let mut var = [Variant {
                child: [0; 3],
                w: [[0.0; 2]; 3],
                inv_det: 0.0,
                bx: [0.0; 3],
                by: [0.0; 3],
                inv_det_dd: Dd::ZERO,
                bx_dd: [Dd::ZERO; 3],
                by_dd: [Dd::ZERO; 3],
            }; 2];
            for (vi, w) in ws.iter().enumerate() {
                let mut child = [0u32; 3];
                for j in 0..3 {
                    child[j] = self.build(mask & !(1u64 << w[j]))?;
                }
                let pts = [self.knots[w[0]], self.knots[w[1]], self.knots[w[2]]];
                let det = det3(pts[0], pts[1], pts[2]);
                // λ_j(u) = det(W with w_j replaced by u) / det(W), affine in u:
                // det(u, q, r) = cross(q, r) + u_x (q_y − r_y) + u_y (r_x − q_x).
                let det_dd = det3_dd(pts[0], pts[1], pts[2]);
                let mut v = Variant {
                    child,
                    w: pts,
                    inv_det: 1.0 / det,
                    bx: [0.0; 3],
                    by: [0.0; 3],
                    inv_det_dd: Dd::ONE / det_dd,
                    bx_dd: [Dd::ZERO; 3],
                    by_dd: [Dd::ZERO; 3],
                };
                for j in 0..3 {
                    let q = pts[(j + 1) % 3];
                    let r = pts[(j + 2) % 3];
                    v.bx[j] = (q[1] - r[1]) / det;
                    v.by[j] = (r[0] - q[0]) / det;
                    v.bx_dd[j] = (Dd::new(q[1]) - Dd::new(r[1])) / det_dd;
                    v.by_dd[j] = (Dd::new(r[0]) - Dd::new(q[0])) / det_dd;
                }
                var[vi] = v;
            }
            self.nodes.push(Node {
                var,
                two: ws.len() == 2,
                degree: (mask.count_ones() - 3) as f64,
            });
            (self.nodes.len() - 1) as u32 | INTERNAL
        };
        self.memo.insert(mask, id);
        Ok(id)
    }

    /// The recurrence triangles of a knot set (module docs): one or two choices.
    fn choose_triangles(&self, mask: u64) -> Result<Vec<[usize; 3]>> {
        let ks: Vec<usize> = (0..self.knots.len())
            .filter(|&k| mask >> k & 1 == 1)
            .collect();
        let mut present: Vec<u8> = ks.iter().map(|&k| self.groups[k]).collect();
        present.sort_unstable();
        present.dedup();
        let last = |g: u8, skip: usize| -> Option<usize> {
            ks.iter()
                .rev()
                .filter(|&&k| self.groups[k] == g)
                .nth(skip)
                .copied()
        };
        let tiny = 1e-14 * self.diameter * self.diameter;
        let ok = |w: &[usize; 3]| {
            det3(self.knots[w[0]], self.knots[w[1]], self.knots[w[2]]).abs() > tiny
        };
        let mut out = Vec::with_capacity(2);
        match present.len() {
            0..=1 => {}
            2 => {
                let (l0, l1) = (last(present[0], 0), last(present[1], 0));
                if let (Some(l0), Some(l1)) = (l0, l1) {
                    for &g in &present {
                        if let Some(x) = last(g, 1) {
                            let w = [l0, l1, x];
                            if ok(&w) {
                                out.push(w);
                            }
                        }
                    }
                }
            }
            _ => {
                let k = present.len();
                let w = [
                    last(present[k - 3], 0).unwrap_or(0),
                    last(present[k - 2], 0).unwrap_or(0),
                    last(present[k - 1], 0).unwrap_or(0),
                ];
                if ok(&w) {
                    out.push(w);
                }
            }
        }
        if !out.is_empty() {
            return Ok(out);
        }
        // One cloud (or a degenerate choice): the fattest triangle of the set.
        let mut best = (0.0, [0usize; 3]);
        for i in 0..ks.len() {
            for j in i + 1..ks.len() {
                for l in j + 1..ks.len() {
                    let (a, b, c) = (self.knots[ks[i]], self.knots[ks[j]], self.knots[ks[l]]);
                    let s = cross(sub(b, a), sub(b, a))
                        .max(0.0)
                        .max(sub(b, a)[0].hypot(sub(b, a)[1]))
                        .max(sub(c, a)[0].hypot(sub(c, a)[1]))
                        .max(sub(c, b)[0].hypot(sub(c, b)[1]));
                    let d = det3(a, b, c).abs() / (s * s);
                    if d > best.0 {
                        best = (d, [ks[i], ks[j], ks[l]]);
                    }
                }
            }
        }
        if ok(&best.1) {
            Ok(vec![best.1])
        } else {
            Err(Error::numerical(format!(
                "simplex spline: the knots of set {mask:#x} are collinear (no triangle to run the recurrence on)"
            )))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Degree-1 simplex spline with 4 knots: its integral is 1/6 and it sums with the
    /// half-open convention.
    #[test]
    fn integral_of_simplex_splines() {
        let knots = [
            [0.0, 0.0],
            [1.0, 0.1],
            [0.2, 0.9],
            [0.7, 0.6],
            [0.3, -0.2],
            [1.1, 0.8],
        ];
        for m in 3..=6usize {
            let set = (1u64 << m) - 1;
            let fam = SimplexFamily::new(&knots[..m], &vec![0; m], &[set]).unwrap();
            // Midpoint rule on a fine grid.
            let (lo, hi) = ([-0.3, -0.3], [1.2, 1.0]);
            let nn = 600;
            let (hx, hy) = ((hi[0] - lo[0]) / nn as f64, (hi[1] - lo[1]) / nn as f64);
            let mut work = Vec::new();
            let mut out = [0.0];
            let mut s = 0.0;
            for i in 0..nn {
                for j in 0..nn {
                    let u = [lo[0] + (i as f64 + 0.5) * hx, lo[1] + (j as f64 + 0.5) * hy];
                    fam.eval(u, [1.0, 0.3], 0, &mut work, &mut out);
                    s += out[0] * hx * hy;
                }
            }
            let p = (m - 3) as f64;
            let want = 1.0 / ((p + 1.0) * (p + 2.0));
            assert!(
                (s - want).abs() < 2e-3 * want.max(0.05),
                "m={m}: {s} vs {want}"
            );
        }
    }

    /// Thin knot sets of degree ≥ 3 (two clouds of radius 1e-3 one unit apart, a far knot):
    /// the double-double recurrence agrees with the double one (to the latter's rounding), and
    /// its order-2 partials are smooth at the ulp scale: moving the point by ±1e-15 changes
    /// them antisymmetrically, `|P(x + δ) + P(x − δ) − 2 P(x)| ≤ 1e-13` of their size (the
    /// second-order term is ~1e-18). Rounding noise is not antisymmetric: the double
    /// recurrence's measure is more than ten times larger.
    #[test]
    fn extended_recurrence_is_smooth_at_the_ulp_scale() {
        let r = 1e-3;
        let knots = [
            [0.0, 0.0],
            [0.7 * r, 0.4 * r],
            [-0.3 * r, 0.9 * r],
            [1.0, 0.0],
            [1.0 - 0.5 * r, 0.8 * r],
            [1.0 + 0.6 * r, -0.2 * r],
            [0.45, 0.8],
        ];
        let groups = [0, 0, 0, 1, 1, 1, 2];
        let sets = [0b111_1111u64, 0b011_1111, 0b101_1111, 0b111_1011];
        let fam = SimplexFamily::new(&knots, &groups, &sets).unwrap();
        let order = 2;
        let np = n_partials(order);
        let (mut w, mut wd) = (Vec::new(), Vec::new());
        let (mut a, mut b, mut c, mut e) = (
            vec![0.0; 4 * np],
            vec![0.0; 4 * np],
            vec![0.0; 4 * np],
            vec![0.0; 4 * np],
        );
        let o = fam.origin();
        let mut worst_move: f64 = 0.0;
        let mut worst_double: f64 = 0.0;
        let mut double_move: f64 = 0.0;
        for k in 0..200 {
            let t = (k as f64 + 0.5) / 200.0;
            let u = [0.02 + 0.96 * t, 0.3 * r * (13.0 * t).sin()];
            let x = [u[0] - o[0], u[1] - o[1]];
            let dir = [0.3, 1.0];
            let xd = [Dd::new(x[0]), Dd::new(x[1])];
            let step = [Dd::new(1e-15), Dd::new(-0.7e-15)];
            fam.eval_offset_extended(xd, dir, order, &mut wd, &mut a);
            fam.eval_offset_extended(
                [xd[0] + step[0], xd[1] + step[1]],
                dir,
                order,
                &mut wd,
                &mut b,
            );
            fam.eval_offset_extended(
                [xd[0] - step[0], xd[1] - step[1]],
                dir,
                order,
                &mut wd,
                &mut c,
            );
            fam.eval_offset(x, dir, order, &mut w, &mut e);
            let (mut e1, mut e2) = (vec![0.0; 4 * np], vec![0.0; 4 * np]);
            fam.eval_offset([x[0] + 1e-15, x[1] - 0.7e-15], dir, order, &mut w, &mut e1);
            fam.eval_offset([x[0] - 1e-15, x[1] + 0.7e-15], dir, order, &mut w, &mut e2);
            for f in 0..4 {
                let s = (3..6).map(|i| a[f * np + i].abs()).fold(0.0, f64::max);
                if s == 0.0 {
                    continue;
                }
                for i in 3..6 {
                    let j = f * np + i;
                    worst_move = worst_move.max((b[j] + c[j] - 2.0 * a[j]).abs() / s);
                    worst_double = worst_double.max((a[j] - e[j]).abs() / s);
                    double_move = double_move.max((e1[j] + e2[j] - 2.0 * e[j]).abs() / s);
                }
            }
        }
        eprintln!(
            "ulp-scale asymmetry {worst_move:.2e} (double {double_move:.2e}), double vs extended {worst_double:.2e}"
        );
        assert!(
            worst_move < 0.1 * double_move,
            "{worst_move:.2e} vs {double_move:.2e}"
        );
        assert!(
            worst_move < 1e-13,
            "extended partials are not smooth: {worst_move:.2e}"
        );
        assert!(
            worst_double < 1e-5,
            "double and extended differ by {worst_double:.2e}"
        );
    }
}
