//! Triangle-quality measures shared by the generators (the vector helpers are
//! [`crate::numeric::vec3`]'s).

pub(crate) use crate::numeric::vec3::{add, cross, dist, dot, lerp, norm, scale, sub, Vec3 as P3};

/// Unnormalised normal `(b − a) × (c − a)` (twice the area vector).
#[inline]
pub(crate) fn tri_normal(a: P3, b: P3, c: P3) -> P3 {
    cross(sub(b, a), sub(c, a))
}

/// Corner angle at `a` of triangle `(a, b, c)`, radians, in `[0, π]`.
#[inline]
pub(crate) fn corner_angle(a: P3, b: P3, c: P3) -> f64 {
    let (u, w) = (sub(b, a), sub(c, a));
    norm(cross(u, w)).atan2(dot(u, w))
}

/// Smallest corner angle of triangle `(a, b, c)`, radians.
#[inline]
pub(crate) fn min_angle(a: P3, b: P3, c: P3) -> f64 {
    corner_angle(a, b, c)
        .min(corner_angle(b, c, a))
        .min(corner_angle(c, a, b))
}

/// Smallest corner angle of triangle `(a, b, c)`, or `-1` when its normal does not point into
/// the half-space of `up` by at least `cos_limit` (the triangle would be folded over).
#[inline]
pub(crate) fn oriented_min_angle(a: P3, b: P3, c: P3, up: P3, cos_limit: f64) -> f64 {
    let n = tri_normal(a, b, c);
    let nn = norm(n) * norm(up);
    if nn == 0.0 || dot(n, up) <= cos_limit * nn {
        return -1.0;
    }
    min_angle(a, b, c)
}
