//! Small helpers for vectors of R³ (`[f64; 3]`) and Kahan's stable form of Heron's formula.

/// A point or vector of R³.
pub type Vec3 = [f64; 3];

#[inline]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline]
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
/// Euclidean norm.
#[inline]
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}
/// Euclidean distance.
#[inline]
pub fn dist(a: Vec3, b: Vec3) -> f64 {
    norm(sub(a, b))
}
/// `a + t (b − a)`.
#[inline]
pub fn lerp(a: Vec3, b: Vec3, t: f64) -> Vec3 {
    [
        a[0] + t * (b[0] - a[0]),
        a[1] + t * (b[1] - a[1]),
        a[2] + t * (b[2] - a[2]),
    ]
}

/// Area of a Euclidean triangle from its side lengths, by Kahan's stable form of Heron's
/// formula (W. Kahan, *Miscalculating Area and Angles of a Needle-like Triangle*, 2014): with
/// the sides sorted `a ≥ b ≥ c`,
/// `A = ¼ √((a + (b + c))(c − (a − b))(c + (a − b))(a + (b − c)))`, accurate to a few ulps
/// also for needles. Sides that violate the triangle inequality (and NaN) give 0.
pub fn heron(l: [f64; 3]) -> f64 {
    let mut s = l;
    s.sort_by(|a, b| b.total_cmp(a));
    let [a, b, c] = s;
    let p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
    if p > 0.0 {
        0.25 * p.sqrt()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heron_matches_the_cross_product_area_and_survives_needles() {
        // Area from coordinates, ½|AB × AC|, for a generic triangle.
        let (p, q, r) = ([0.3, -1.2, 0.5], [2.0, 0.4, -0.7], [-0.6, 1.1, 1.9]);
        let want = 0.5 * norm(cross(sub(q, p), sub(r, p)));
        let got = heron([dist(q, r), dist(p, r), dist(p, q)]);
        assert!((got - want).abs() < 1e-14 * want, "{got} vs {want}");
        // Kahan's needle: a = b = 1, c = 1e-12: area = ½ c √(1 − c²/4) ≈ 5e-13; the naive
        // formula s(s−a)(s−b)(s−c) loses every digit here.
        let c: f64 = 1e-12;
        let want = 0.5 * c * (1.0 - c * c / 4.0).sqrt();
        let got = heron([1.0, 1.0, c]);
        assert!((got - want).abs() < 1e-15 * want, "{got} vs {want}");
        // Degenerate and impossible triangles have zero area; order does not matter.
        assert_eq!(heron([1.0, 2.0, 3.0]), 0.0);
        assert_eq!(heron([1.0, 1.0, 3.0]), 0.0);
        assert_eq!(heron([f64::NAN, 1.0, 1.0]), 0.0);
        assert_eq!(heron([3.0, 4.0, 5.0]), 6.0);
        assert_eq!(heron([5.0, 3.0, 4.0]), 6.0);
    }
}
