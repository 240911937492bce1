//! Isometries of the three model spaces, as types (paper 001 §V Step 4, paper 002 §6.2.2.3).
//!
//! * [`RigidMotion`] — orientation-preserving rigid motions of the plane, `z ↦ e^{iθ} z + t`
//!   (deck transformations of flat tori are the special case θ = 0; flat metrics with cone
//!   points have rotations too).
//! * [`Mobius`] — orientation-preserving isometries of the Poincaré disk,
//!   `z ↦ (a z + b)/(b̄ z + ā)` with `|a|² − |b|² = 1` (the group SU(1,1); the matrices `±M`
//!   act identically, comparisons take the sign into account).
//! * [`Rotation`] — rotations of the unit sphere (3×3 orthogonal matrices of determinant 1).
//!
//! Each implements [`Isometry`]: identity, composition, inverse, application, the map taking
//! one pair of points to another (`(p0, q0) ↦ (p1, q1)`, the τ₁⁻¹∘τ₀ construction of paper 001
//! §V, made symmetric so that a small disagreement of the two distances is split evenly),
//! least-squares fitting from many point pairs, and a distance between two isometries used by
//! tests and accuracy reports.
//!
//! The real projective structure (paper 002 §6.2.4) is given by [`Mobius::klein_matrix`]: the
//! same isometry as an SO(2,1) matrix acting on homogeneous Klein coordinates
//! `(X₁, X₂, X₀)` (Klein point `(X₁/X₀, X₂/X₀)`), derived from the action `Q ↦ g Q g†` of
//! SU(1,1) on the Hermitian matrices `Q(z) = (z, 1)ᵀ(z̄, 1)/(1 − |z|²)`, whose coordinates
//! `X₀ = (1 + |z|²)/(1 − |z|²)`, `X₁ + iX₂ = 2z/(1 − |z|²)` are the hyperboloid model.

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::error::{Error, Result};
use num_complex::Complex64 as C;

/// A point of the plane or of the Poincaré disk.
pub type Complex = C;

/// What layouts, deck groups and tilings need from an isometry group.
pub trait Isometry: Copy + Clone + std::fmt::Debug + Send + Sync + 'static {
    /// A point of the model space.
    type Point: Copy + std::fmt::Debug + Send + Sync + 'static;
    fn identity() -> Self;
    fn apply(&self, p: Self::Point) -> Self::Point;
    /// `self ∘ other` (apply `other` first).
    fn compose(&self, other: &Self) -> Self;
    fn inverse(&self) -> Self;
    /// The isometry taking `p0 ↦ p1` and the geodesic direction from `p0` towards `q0` onto
    /// the one from `p1` towards `q1`. If `d(p0, q0) ≠ d(p1, q1)` (numerical noise), the
    /// mismatch is split evenly between the two ends.
    fn from_pairs(p0: Self::Point, q0: Self::Point, p1: Self::Point, q1: Self::Point) -> Self;
    /// Least-squares fit of `x_i ↦ y_i` (sum of squared distances in the model, measured with
    /// the metric of the space at `y_i`). Fails with fewer than two distinct points.
    fn fit(pairs: &[(Self::Point, Self::Point)]) -> Result<Self>;
    /// A distance between two isometries (documented per type), zero iff they are equal.
    fn distance(&self, other: &Self) -> f64;
    /// Re-project onto the group (remove accumulated rounding).
    fn normalized(&self) -> Self;
    /// A lower bound of the displacement `d(g(x), x)` over all points `x` (0 if unknown).
    fn displacement_bound(&self) -> f64 {
        0.0
    }
    /// Size of the isometry as a matrix (Frobenius norm for Möbius maps and rotations,
    /// `1 + |t|` for rigid motions): rounding in a product of isometries is bounded by the
    /// machine epsilon times the product of these sizes.
    fn size(&self) -> f64;
}

// ---------------------------------------------------------------------------------------------
// Plane

/// `z ↦ rot · z + t` with `|rot| = 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidMotion {
    pub rot: C,
    pub t: C,
}

impl RigidMotion {
    pub fn new(theta: f64, t: C) -> Self {
        RigidMotion {
            rot: C::from_polar(1.0, theta),
            t,
        }
    }
    pub fn translation(t: C) -> Self {
        RigidMotion {
            rot: C::new(1.0, 0.0),
            t,
        }
    }
    /// Rotation angle θ in (−π, π].
    pub fn angle(&self) -> f64 {
        self.rot.arg()
    }
}

impl Isometry for RigidMotion {
    type Point = C;
    fn identity() -> Self {
        RigidMotion::translation(C::new(0.0, 0.0))
    }
    #[inline]
    fn apply(&self, p: C) -> C {
        self.rot * p + self.t
    }
    fn compose(&self, o: &Self) -> Self {
        RigidMotion {
            rot: self.rot * o.rot,
            t: self.rot * o.t + self.t,
        }
    }
    fn inverse(&self) -> Self {
        let r = self.rot.conj();
        RigidMotion {
            rot: r,
            t: -(r * self.t),
        }
    }
    fn from_pairs(p0: C, q0: C, p1: C, q1: C) -> Self {
        let d0 = q0 - p0;
        let d1 = q1 - p1;
        let r = d1 * d0.conj();
        let rot = if r.norm() > 0.0 {
            r / r.norm()
        } else {
            C::new(1.0, 0.0)
        };
        // Midpoint to midpoint: splits a length mismatch evenly.
        let m0 = 0.5 * (p0 + q0);
        let m1 = 0.5 * (p1 + q1);
        RigidMotion {
            rot,
            t: m1 - rot * m0,
        }
    }
    fn fit(pairs: &[(C, C)]) -> Result<Self> {
        if pairs.len() < 2 {
            return Err(Error::numerical(
                "a rigid motion needs at least two point pairs to be fitted",
            ));
        }
        let n = pairs.len() as f64;
        let c0 = pairs.iter().map(|p| p.0).sum::<C>() / n;
        let c1 = pairs.iter().map(|p| p.1).sum::<C>() / n;
        let s: C = pairs.iter().map(|(x, y)| (x - c0).conj() * (y - c1)).sum();
        if !(s.norm() > 0.0) || !s.norm().is_finite() {
            return Err(Error::numerical(
                "cannot fit a rigid motion: the points coincide or are not finite",
            ));
        }
        let rot = s / s.norm();
        Ok(RigidMotion {
            rot,
            t: c1 - rot * c0,
        })
    }
    /// `|rot₁ − rot₂| + |t₁ − t₂|`.
    fn distance(&self, o: &Self) -> f64 {
        (self.rot - o.rot).norm() + (self.t - o.t).norm()
    }
    fn size(&self) -> f64 {
        1.0 + self.t.norm()
    }
    fn normalized(&self) -> Self {
        let n = self.rot.norm();
        RigidMotion {
            rot: if n > 0.0 { self.rot / n } else { self.rot },
            t: self.t,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Poincaré disk

/// `z ↦ (a z + b)/(b̄ z + ā)`, the SU(1,1) matrix `[[a, b], [b̄, ā]]` with `|a|² − |b|² = 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mobius {
    pub a: C,
    pub b: C,
}

impl Mobius {
    /// From unnormalized coefficients (scaled so that `|a|² − |b|² = 1`). `None` if
    /// `|a| ≤ |b|` (not an isometry of the disk).
    pub fn new(a: C, b: C) -> Option<Self> {
        let det = a.norm_sqr() - b.norm_sqr();
        if !(det > 0.0) || !det.is_finite() {
            return None;
        }
        let s = det.sqrt();
        Some(Mobius { a: a / s, b: b / s })
    }
    /// The map `z ↦ (z − p)/(1 − p̄ z)` taking `p` to the origin (`|p| < 1`).
    pub fn to_origin(p: C) -> Self {
        let s = (1.0 - p.norm_sqr()).max(f64::MIN_POSITIVE).sqrt();
        Mobius {
            a: C::new(1.0 / s, 0.0),
            b: -p / s,
        }
    }
    /// The rotation `z ↦ e^{iφ} z`.
    pub fn rotation(phi: f64) -> Self {
        Mobius {
            a: C::from_polar(1.0, 0.5 * phi),
            b: C::new(0.0, 0.0),
        }
    }
    /// Hyperbolic translation by distance `d` along the real diameter (towards +1 for d > 0).
    pub fn real_translation(d: f64) -> Self {
        Mobius {
            a: C::new((0.5 * d).cosh(), 0.0),
            b: C::new((0.5 * d).sinh(), 0.0),
        }
    }
    /// The paper's parameters (paper 001 Eq. 14, paper 002 §6.2.4): `M(z) = e^{iθ}(z − z₀)/(1 − z̄₀ z)`.
    pub fn theta_center(&self) -> (f64, C) {
        let theta = (self.a / self.a.conj()).arg();
        (theta, -self.b / self.a)
    }
    /// Inverse of [`Mobius::theta_center`].
    pub fn from_theta_center(theta: f64, z0: C) -> Self {
        Mobius::rotation(theta).compose(&Mobius::to_origin(z0))
    }
    /// Trace `a + ā = 2 Re a` of the normalized matrix (defined up to sign).
    pub fn trace(&self) -> f64 {
        2.0 * self.a.re
    }
    /// Translation length `2 acosh(|tr|/2)` for a hyperbolic element, 0 for elliptic and
    /// parabolic ones (|tr| ≤ 2).
    pub fn translation_length(&self) -> f64 {
        let h = self.a.re.abs();
        if h > 1.0 {
            2.0 * h.acosh()
        } else {
            0.0
        }
    }
    /// The two fixed points on the unit circle of a hyperbolic element, (repelling,
    /// attracting); `None` if the element is not hyperbolic.
    pub fn fixed_points(&self) -> Option<(C, C)> {
        // Fixed points of (a z + b)/(b̄ z + ā): b̄ z² + (ā − a) z − b = 0.
        let h = self.a.re;
        if h.abs() <= 1.0 || self.b.norm() == 0.0 {
            return None;
        }
        let bb = self.b.conj();
        let disc = (h * h - 1.0).sqrt(); // ((ā − a)² + 4|b|²)/4 = (Re a)² − 1
        let im = C::new(0.0, self.a.im); // (a − ā)/2
        let z1 = (im + disc) / bb;
        let z2 = (im - disc) / bb;
        // The attracting fixed point has |derivative| < 1: |b̄ z + ā|⁻² < 1.
        let der = |z: C| 1.0 / (bb * z + self.a.conj()).norm_sqr();
        if der(z1) < der(z2) {
            Some((z2, z1))
        } else {
            Some((z1, z2))
        }
    }
    /// The same isometry acting on homogeneous Klein coordinates `(X₁, X₂, X₀)` (an SO(2,1)
    /// matrix preserving `X₁² + X₂² − X₀²`), paper 002 §6.2.4.
    pub fn klein_matrix(&self) -> [[f64; 3]; 3] {
        let (a, b) = (self.a, self.b);
        let s = a * a + b * b;
        let d = a * a - b * b;
        let ab = a * b;
        let abc = a * b.conj();
        [
            [s.re, -d.im, 2.0 * ab.re],
            [s.im, d.re, 2.0 * ab.im],
            [2.0 * abc.re, -2.0 * abc.im, a.norm_sqr() + b.norm_sqr()],
        ]
    }
}

/// Poincaré disk → Klein disk: `k = 2z/(1 + |z|²)`.
pub fn poincare_to_klein(z: C) -> C {
    2.0 * z / (1.0 + z.norm_sqr())
}
/// Klein disk → Poincaré disk: `z = k/(1 + √(1 − |k|²))`.
pub fn klein_to_poincare(k: C) -> C {
    k / (1.0 + (1.0 - k.norm_sqr()).max(0.0).sqrt())
}
/// Hyperboloid coordinates `(X₁, X₂, X₀)` of a point of the Poincaré disk.
pub fn poincare_to_hyperboloid(z: C) -> [f64; 3] {
    let d = 1.0 - z.norm_sqr();
    [2.0 * z.re / d, 2.0 * z.im / d, (1.0 + z.norm_sqr()) / d]
}

/// Hyperbolic distance between two points of the Poincaré disk,
/// `2 asinh(|p − q| / √((1 − |p|²)(1 − |q|²)))` (accurate for close points).
#[inline]
pub fn disk_distance(p: C, q: C) -> f64 {
    let den = ((1.0 - p.norm_sqr()) * (1.0 - q.norm_sqr()))
        .max(0.0)
        .sqrt();
    if den <= 0.0 {
        return f64::INFINITY;
    }
    2.0 * ((p - q).norm() / den).asinh()
}

/// `|p − q|² / ((1 − |p|²)(1 − |q|²))` (∞ outside the disk), `sinh²` of half the
/// [`disk_distance`] with the same denominator: ordering by it orders by that distance.
#[inline]
pub fn disk_distance_key(p: C, q: C) -> f64 {
    let den = ((1.0 - p.norm_sqr()) * (1.0 - q.norm_sqr())).max(0.0);
    if den <= 0.0 {
        return f64::INFINITY;
    }
    (p - q).norm_sqr() / den
}

impl Isometry for Mobius {
    type Point = C;
    /// The translation length `2 acosh(|Re a| / √(|a|² − |b|²))` of a hyperbolic map (0 for
    /// elliptic and parabolic ones): no point of the disk moves less.
    fn displacement_bound(&self) -> f64 {
        let det = self.a.norm_sqr() - self.b.norm_sqr();
        if !(det > 0.0) {
            return 0.0;
        }
        let t = self.a.re.abs() / det.sqrt();
        if t > 1.0 {
            2.0 * t.acosh()
        } else {
            0.0
        }
    }
    fn identity() -> Self {
        Mobius {
            a: C::new(1.0, 0.0),
            b: C::new(0.0, 0.0),
        }
    }
    #[inline]
    fn apply(&self, z: C) -> C {
        (self.a * z + self.b) / (self.b.conj() * z + self.a.conj())
    }
    fn compose(&self, o: &Self) -> Self {
        Mobius {
            a: self.a * o.a + self.b * o.b.conj(),
            b: self.a * o.b + self.b * o.a.conj(),
        }
    }
    fn inverse(&self) -> Self {
        Mobius {
            a: self.a.conj(),
            b: -self.b,
        }
    }
    /// τ₁⁻¹ ∘ τ₀ (paper 001 §V): τ maps p to 0 and q to the positive real axis; a hyperbolic
    /// translation along the real axis by half the length mismatch is inserted in between.
    fn from_pairs(p0: C, q0: C, p1: C, q1: C) -> Self {
        let frame = |p: C, q: C| -> (Mobius, f64) {
            let t = Mobius::to_origin(p);
            let w = t.apply(q);
            let r = w.norm();
            let rot = if r > 0.0 {
                Mobius::rotation(-w.arg())
            } else {
                Mobius::identity()
            };
            (rot.compose(&t), 2.0 * r.min(1.0 - f64::EPSILON).atanh())
        };
        let (t0, d0) = frame(p0, q0);
        let (t1, d1) = frame(p1, q1);
        let shift = Mobius::real_translation(0.5 * (d1 - d0));
        t1.inverse().compose(&shift).compose(&t0).normalized()
    }
    /// Gauss–Newton on `Σ w_i² |M(x_i) − y_i|²` with `w_i = 2/(1 − |y_i|²)` (the disk metric at
    /// `y_i`), started from [`Isometry::from_pairs`] on the two most distant pairs; steps in
    /// the Lie algebra su(1,1). Stops when the step is below 1e-15 or after 30 iterations.
    fn fit(pairs: &[(C, C)]) -> Result<Self> {
        if pairs.len() < 2 {
            return Err(Error::numerical(
                "a Möbius transformation needs at least two point pairs to be fitted",
            ));
        }
        // Start from the first pair and the pair farthest from it.
        let (x0, y0) = pairs[0];
        let far = pairs
            .iter()
            .max_by(|p, q| disk_distance(x0, p.0).total_cmp(&disk_distance(x0, q.0)))
            .copied()
            .unwrap_or(pairs[1]);
        if !(disk_distance(x0, far.0) > 0.0) {
            return Err(Error::numerical(
                "cannot fit a Möbius transformation: the points coincide",
            ));
        }
        let mut m = Mobius::from_pairs(x0, far.0, y0, far.1);
        for _ in 0..30 {
            // Residual r_i = w (M x − y); Jacobian columns: the su(1,1) vector fields at M x:
            // ∂α: 2i w, ∂β_r: 1 − w², ∂β_i: i(1 + w²).
            let mut jtj = [[0.0f64; 3]; 3];
            let mut jtr = [0.0f64; 3];
            for &(x, y) in pairs {
                let w = m.apply(x);
                let wt = 2.0 / (1.0 - y.norm_sqr()).max(1e-300);
                let r = (w - y) * wt;
                let cols = [
                    C::new(0.0, 2.0) * w * wt,
                    (C::new(1.0, 0.0) - w * w) * wt,
                    C::new(0.0, 1.0) * (C::new(1.0, 0.0) + w * w) * wt,
                ];
                for i in 0..3 {
                    jtr[i] += cols[i].re * r.re + cols[i].im * r.im;
                    for j in 0..3 {
                        jtj[i][j] += cols[i].re * cols[j].re + cols[i].im * cols[j].im;
                    }
                }
            }
            let xi = solve3(jtj, [-jtr[0], -jtr[1], -jtr[2]])?;
            let step = Mobius::exp_algebra(xi[0], C::new(xi[1], xi[2]));
            m = step.compose(&m).normalized();
            if xi.iter().map(|v| v.abs()).fold(0.0, f64::max) < 1e-15 {
                break;
            }
        }
        Ok(m)
    }
    /// Frobenius norm of `M₁ − M₂` or of `M₁ + M₂`, whichever is smaller (±M act alike).
    fn distance(&self, o: &Self) -> f64 {
        let d1 = (self.a - o.a).norm_sqr() + (self.b - o.b).norm_sqr();
        let d2 = (self.a + o.a).norm_sqr() + (self.b + o.b).norm_sqr();
        (2.0 * d1.min(d2)).sqrt()
    }
    fn normalized(&self) -> Self {
        Mobius::new(self.a, self.b).unwrap_or(*self)
    }
    fn size(&self) -> f64 {
        (2.0 * (self.a.norm_sqr() + self.b.norm_sqr())).sqrt()
    }
}

impl Mobius {
    /// `exp([[iα, β], [β̄, −iα]])`, using `X² = (|β|² − α²) I`.
    pub(crate) fn exp_algebra(alpha: f64, beta: C) -> Self {
        let s2 = beta.norm_sqr() - alpha * alpha;
        let (c, sh) = if s2.abs() < 1e-8 {
            // Series: cosh √s2 ≈ 1 + s2/2, sinh √s2 / √s2 ≈ 1 + s2/6.
            (
                1.0 + 0.5 * s2 + s2 * s2 / 24.0,
                1.0 + s2 / 6.0 + s2 * s2 / 120.0,
            )
        } else if s2 > 0.0 {
            let s = s2.sqrt();
            (s.cosh(), s.sinh() / s)
        } else {
            let s = (-s2).sqrt();
            (s.cos(), s.sin() / s)
        };
        Mobius {
            a: C::new(c, sh * alpha),
            b: beta * sh,
        }
        .normalized()
    }
}

/// Solve a 3×3 system with faer's LU (partial pivoting).
pub(crate) fn solve3(m: [[f64; 3]; 3], rhs: [f64; 3]) -> Result<[f64; 3]> {
    use faer::linalg::solvers::Solve;
    let a = faer::Mat::<f64>::from_fn(3, 3, |i, j| m[i][j]);
    let b = faer::Mat::<f64>::from_fn(3, 1, |i, _| rhs[i]);
    let x = a.partial_piv_lu().solve(&b);
    let out = [x[(0, 0)], x[(1, 0)], x[(2, 0)]];
    if out.iter().all(|v| v.is_finite()) {
        Ok(out)
    } else {
        Err(Error::numerical(
            "singular least-squares system while fitting an isometry (points in degenerate position)",
        ))
    }
}

// ---------------------------------------------------------------------------------------------
// Sphere

/// A rotation of the unit sphere, `p ↦ R p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation {
    pub m: [[f64; 3]; 3],
}

pub(crate) use crate::numeric::vec3::{cross as cross3, dot as dot3};
pub(crate) fn normalize3(a: [f64; 3]) -> [f64; 3] {
    let n = dot3(a, a).sqrt();
    if n > 0.0 {
        [a[0] / n, a[1] / n, a[2] / n]
    } else {
        a
    }
}
pub(crate) fn det3(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    dot3(a, cross3(b, c))
}
/// Great-circle distance, `2 asin(|p − q|/2)` for unit vectors (accurate for close points).
pub fn sphere_distance(p: [f64; 3], q: [f64; 3]) -> f64 {
    let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let c = 0.5 * dot3(d, d).sqrt();
    if c >= 1.0 {
        std::f64::consts::PI
    } else {
        2.0 * c.asin()
    }
}

impl Rotation {
    /// Orthonormal frame `(p, t, p × t)` with `t` the unit tangent at `p` towards `q`.
    fn frame(p: [f64; 3], q: [f64; 3]) -> [[f64; 3]; 3] {
        let p = normalize3(p);
        let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let k = dot3(d, p);
        let t = normalize3([d[0] - k * p[0], d[1] - k * p[1], d[2] - k * p[2]]);
        [p, t, cross3(p, t)]
    }
    fn transpose(&self) -> Self {
        let m = self.m;
        Rotation {
            m: [
                [m[0][0], m[1][0], m[2][0]],
                [m[0][1], m[1][1], m[2][1]],
                [m[0][2], m[1][2], m[2][2]],
            ],
        }
    }
}

impl Isometry for Rotation {
    type Point = [f64; 3];
    fn identity() -> Self {
        Rotation {
            m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }
    #[inline]
    fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.m;
        [dot3(m[0], p), dot3(m[1], p), dot3(m[2], p)]
    }
    fn compose(&self, o: &Self) -> Self {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = (0..3).map(|k| self.m[i][k] * o.m[k][j]).sum();
            }
        }
        Rotation { m }
    }
    fn inverse(&self) -> Self {
        self.transpose()
    }
    /// Frames `(p, t, p × t)` at both ends; the tangent directions match exactly, the points
    /// `p0 ↦ p1` up to the rotation that splits a length mismatch (rotating about `p × t`).
    fn from_pairs(p0: [f64; 3], q0: [f64; 3], p1: [f64; 3], q1: [f64; 3]) -> Self {
        let half = 0.5 * (sphere_distance(p1, q1) - sphere_distance(p0, q0));
        let f0 = Rotation::frame(p0, q0);
        let f1 = Rotation::frame(p1, q1);
        // Columns of F are the frame vectors: R = F1 · S · F0ᵀ with S the rotation by `half`
        // in the (p, t) plane taking p towards t.
        let (s, c) = half.sin_cos();
        let sm = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let f0t = Rotation { m: f0 }; // rows = frame vectors = F0ᵀ
        let f1c = Rotation { m: f1 }.transpose(); // columns = frame vectors = F1
        f1c.compose(&Rotation { m: sm }).compose(&f0t)
    }
    /// Kabsch: SVD of `Σ y_i x_iᵀ` (faer), with the determinant fixed to +1.
    fn fit(pairs: &[(Self::Point, Self::Point)]) -> Result<Self> {
        if pairs.len() < 2 {
            return Err(Error::numerical(
                "a rotation needs at least two point pairs to be fitted",
            ));
        }
        let mut h = [[0.0f64; 3]; 3];
        for (x, y) in pairs {
            for i in 0..3 {
                for j in 0..3 {
                    h[i][j] += y[i] * x[j];
                }
            }
        }
        let mat = faer::Mat::<f64>::from_fn(3, 3, |i, j| h[i][j]);
        let svd = mat
            .svd()
            .map_err(|_| Error::numerical("SVD failed while fitting a rotation"))?;
        let (u, v) = (svd.U(), svd.V());
        let mut uv = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                uv[i][j] = (0..3).map(|k| u[(i, k)] * v[(j, k)]).sum();
            }
        }
        let d = det3(uv[0], uv[1], uv[2]).signum();
        let mut m = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = u[(i, 0)] * v[(j, 0)] + u[(i, 1)] * v[(j, 1)] + d * u[(i, 2)] * v[(j, 2)];
            }
        }
        let r = Rotation { m };
        if m.iter().flatten().all(|x| x.is_finite()) {
            Ok(r)
        } else {
            Err(Error::numerical("cannot fit a rotation: non-finite points"))
        }
    }
    /// Frobenius norm of `R₁ − R₂`.
    fn distance(&self, o: &Self) -> f64 {
        let mut s = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                s += (self.m[i][j] - o.m[i][j]).powi(2);
            }
        }
        s.sqrt()
    }
    fn size(&self) -> f64 {
        3f64.sqrt()
    }
    /// Gram–Schmidt on the rows.
    fn normalized(&self) -> Self {
        let r0 = normalize3(self.m[0]);
        let k = dot3(self.m[1], r0);
        let r1 = normalize3([
            self.m[1][0] - k * r0[0],
            self.m[1][1] - k * r0[1],
            self.m[1][2] - k * r0[2],
        ]);
        Rotation {
            m: [r0, r1, cross3(r0, r1)],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rng(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64) / ((1u64 << 53) as f64)
    }
    fn disk_point(s: &mut u64) -> C {
        C::from_polar(0.9 * rng(s).sqrt(), std::f64::consts::TAU * rng(s))
    }

    #[test]
    fn mobius_group_laws_and_pair_fit() {
        let mut s = 7;
        for _ in 0..50 {
            let m1 = Mobius::from_theta_center(3.0 * rng(&mut s), disk_point(&mut s));
            let m2 = Mobius::from_theta_center(-2.0 * rng(&mut s), disk_point(&mut s));
            let z = disk_point(&mut s);
            // Composition = application in sequence; inverse undoes.
            let a = m1.compose(&m2).apply(z);
            let b = m1.apply(m2.apply(z));
            assert!((a - b).norm() < 1e-12);
            assert!((m1.inverse().apply(m1.apply(z)) - z).norm() < 1e-12);
            // Isometry: distances preserved (hyperbolic distance formula).
            let w = disk_point(&mut s);
            assert!((disk_distance(m1.apply(z), m1.apply(w)) - disk_distance(z, w)).abs() < 1e-10);
            // theta/centre round trip.
            let (th, z0) = m1.theta_center();
            assert!(Mobius::from_theta_center(th, z0).distance(&m1) < 1e-12);
            // The map between two pairs at equal distance is recovered exactly.
            let (p0, q0) = (z, w);
            let (p1, q1) = (m1.apply(p0), m1.apply(q0));
            let fit = Mobius::from_pairs(p0, q0, p1, q1);
            assert!(fit.distance(&m1) < 1e-9, "{fit:?} vs {m1:?}");
            // Least squares from many pairs with no noise.
            let pairs: Vec<(C, C)> = (0..6)
                .map(|_| {
                    let x = disk_point(&mut s);
                    (x, m1.apply(x))
                })
                .collect();
            let lsq = Mobius::fit(&pairs).unwrap();
            assert!(lsq.distance(&m1) < 1e-9, "{lsq:?} vs {m1:?}");
        }
    }

    #[test]
    fn mobius_translation_length_matches_displacement_on_axis() {
        // A hyperbolic translation by d along the real axis, conjugated by a random isometry:
        // trace gives 2 acosh(|tr|/2) = d, and its fixed points are the conjugated ±1.
        let mut s = 3;
        for &d in &[0.1, 1.0, 3.5] {
            let g = Mobius::from_theta_center(1.3, disk_point(&mut s));
            let t = g
                .compose(&Mobius::real_translation(d))
                .compose(&g.inverse());
            assert!((t.translation_length() - d).abs() < 1e-10);
            let (rep, att) = t.fixed_points().unwrap();
            assert!((att - g.apply(C::new(1.0, 0.0))).norm() < 1e-9);
            assert!((rep - g.apply(C::new(-1.0, 0.0))).norm() < 1e-9);
            // A point on the axis moves by exactly d.
            let p = g.apply(C::new(0.3, 0.0));
            assert!((disk_distance(p, t.apply(p)) - d).abs() < 1e-10);
        }
    }

    #[test]
    fn klein_matrices_preserve_lorentz_form_and_agree_with_mobius_action() {
        let mut s = 11;
        for _ in 0..30 {
            let m = Mobius::from_theta_center(6.0 * rng(&mut s), disk_point(&mut s));
            let k = m.klein_matrix();
            // Kᵀ J K = J, J = diag(1, 1, −1).
            let j = [1.0, 1.0, -1.0];
            for a in 0..3 {
                for b in 0..3 {
                    let v: f64 = (0..3).map(|c| k[c][a] * j[c] * k[c][b]).sum();
                    let want = if a == b { j[a] } else { 0.0 };
                    assert!((v - want).abs() < 1e-9, "{a}{b}: {v}");
                }
            }
            // Acting on the Klein image of z gives the Klein image of M z.
            let z = disk_point(&mut s);
            let kz = poincare_to_klein(z);
            let h = [kz.re, kz.im, 1.0];
            let r: Vec<f64> = (0..3).map(|i| dot3(k[i], h)).collect();
            let img = C::new(r[0] / r[2], r[1] / r[2]);
            assert!((img - poincare_to_klein(m.apply(z))).norm() < 1e-10);
            assert!((klein_to_poincare(img) - m.apply(z)).norm() < 1e-9);
            // Composition is matrix multiplication.
            let m2 = Mobius::from_theta_center(1.0, disk_point(&mut s));
            let k12 = m.compose(&m2).klein_matrix();
            let k2 = m2.klein_matrix();
            for a in 0..3 {
                for b in 0..3 {
                    let v: f64 = (0..3).map(|c| k[a][c] * k2[c][b]).sum();
                    assert!((v - k12[a][b]).abs() < 1e-9 * (1.0 + v.abs()));
                }
            }
        }
    }

    #[test]
    fn rigid_motion_fits() {
        let mut s = 5;
        for _ in 0..20 {
            let m = RigidMotion::new(6.0 * rng(&mut s), C::new(rng(&mut s), rng(&mut s)));
            let pts: Vec<(C, C)> = (0..5)
                .map(|_| {
                    let x = C::new(rng(&mut s), rng(&mut s));
                    (x, m.apply(x))
                })
                .collect();
            assert!(RigidMotion::fit(&pts).unwrap().distance(&m) < 1e-12);
            let f = RigidMotion::from_pairs(pts[0].0, pts[1].0, pts[0].1, pts[1].1);
            assert!(f.distance(&m) < 1e-12);
            assert!(m.compose(&m.inverse()).distance(&RigidMotion::identity()) < 1e-14);
        }
    }

    #[test]
    fn rotation_fits() {
        let mut s = 9;
        let unit = |s: &mut u64| normalize3([rng(s) - 0.5, rng(s) - 0.5, rng(s) - 0.5]);
        for _ in 0..20 {
            let r = Rotation::from_pairs(unit(&mut s), unit(&mut s), unit(&mut s), unit(&mut s));
            // Orthogonal with determinant one.
            assert!(r.compose(&r.inverse()).distance(&Rotation::identity()) < 1e-12);
            assert!((det3(r.m[0], r.m[1], r.m[2]) - 1.0).abs() < 1e-12);
            let pts: Vec<_> = (0..4)
                .map(|_| {
                    let x = unit(&mut s);
                    (x, r.apply(x))
                })
                .collect();
            assert!(Rotation::fit(&pts).unwrap().distance(&r) < 1e-12);
            let f = Rotation::from_pairs(pts[0].0, pts[1].0, pts[0].1, pts[1].1);
            assert!(f.distance(&r) < 1e-12);
            let p = unit(&mut s);
            let q = unit(&mut s);
            assert!(
                (sphere_distance(r.apply(p), r.apply(q)) - sphere_distance(p, q)).abs() < 1e-12
            );
        }
    }
}
