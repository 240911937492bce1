//! The univariate cubic B-spline over five knots `t0 ≤ t1 ≤ t2 ≤ t3 ≤ t4` (the local knot
//! vector of a T-spline anchor, Sederberg et al. 2003 §3), with its first and second
//! derivatives.
//!
//! Cox–de Boor: `N_{i,0}(t) = 1` on the half-open interval `[t_i, t_{i+1})`,
//! `N_{i,k} = (t − t_i)/(t_{i+k} − t_i) N_{i,k−1} + (t_{i+k+1} − t)/(t_{i+k+1} − t_{i+1}) N_{i+1,k−1}`
//! (0/0 = 0), and `N'_{i,k} = k (N_{i,k−1}/(t_{i+k} − t_i) − N_{i+1,k−1}/(t_{i+k+1} − t_{i+1}))`.

/// `[N, N', N'']` of the cubic B-spline with knots `t` at `x` (zero outside `[t0, t4)`).
pub fn cubic(t: &[f64; 5], x: f64) -> [f64; 3] {
    if !(x >= t[0] && x < t[4]) {
        return [0.0; 3];
    }
    let q = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
    // degree 0
    let mut n0 = [0.0; 4];
    for i in 0..4 {
        if x >= t[i] && x < t[i + 1] {
            n0[i] = 1.0;
        }
    }
    // degree 1
    let mut n1 = [0.0; 3];
    for i in 0..3 {
        n1[i] =
            q(x - t[i], t[i + 1] - t[i]) * n0[i] + q(t[i + 2] - x, t[i + 2] - t[i + 1]) * n0[i + 1];
    }
    // degree 2
    let mut n2 = [0.0; 2];
    for i in 0..2 {
        n2[i] =
            q(x - t[i], t[i + 2] - t[i]) * n1[i] + q(t[i + 3] - x, t[i + 3] - t[i + 1]) * n1[i + 1];
    }
    let n3 = q(x - t[0], t[3] - t[0]) * n2[0] + q(t[4] - x, t[4] - t[1]) * n2[1];
    let d1 = 3.0 * (q(n2[0], t[3] - t[0]) - q(n2[1], t[4] - t[1]));
    // second derivative: derivative of the degree-2 functions
    let d2_0 = 2.0 * (q(n1[0], t[2] - t[0]) - q(n1[1], t[3] - t[1]));
    let d2_1 = 2.0 * (q(n1[1], t[3] - t[1]) - q(n1[2], t[4] - t[2]));
    let d2 = 3.0 * (q(d2_0, t[3] - t[0]) - q(d2_1, t[4] - t[1]));
    [n3, d1, d2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_cubic_matches_closed_form_and_finite_differences() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        // closed form of the uniform cubic B-spline on [1,2): (−3s³+3s²+3s+1)/6, s = x−1
        for &x in &[1.1, 1.5, 1.9] {
            let s = x - 1.0;
            let want = (-3.0 * s * s * s + 3.0 * s * s + 3.0 * s + 1.0) / 6.0;
            assert!((cubic(&t, x)[0] - want).abs() < 1e-14);
        }
        let t = [0.0, 0.3, 1.1, 1.2, 2.5];
        for &x in &[0.1, 0.5, 1.15, 1.7, 2.2] {
            let h = 1e-6;
            let v = cubic(&t, x);
            let fd1 = (cubic(&t, x + h)[0] - cubic(&t, x - h)[0]) / (2.0 * h);
            let fd2 = (cubic(&t, x + h)[1] - cubic(&t, x - h)[1]) / (2.0 * h);
            assert!((v[1] - fd1).abs() < 1e-7, "{x}: {} vs {fd1}", v[1]);
            assert!((v[2] - fd2).abs() < 1e-6, "{x}: {} vs {fd2}", v[2]);
        }
    }
}
