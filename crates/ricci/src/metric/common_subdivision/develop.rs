//! Breadth-first layouts of an intrinsic triangulation, one position per corner, in the plane
//! (E²) and in the Poincaré disk (H²), for checking and benchmarking the common subdivision.

use super::Tri;
use crate::error::{Error, Result};
use crate::mesh::NONE;

/// Breadth-first layout of `T` in the plane from its lengths at vertex scaling `u` (E²), one
/// position per corner (`3f + i`). Faces are placed across the edges of a spanning tree of the
/// dual graph, so the layout is continuous across those edges (across all edges for a flat
/// disk). `Err` if a triangle inequality fails.
pub fn layout_euclidean(tri: &Tri, u: &[f64]) -> Result<Vec<[f64; 2]>> {
    let nf = tri.n_faces();
    let len = |h: u32| (0.5 * tri.scaled_lambda(tri.edge[h as usize], u)).exp();
    let mut uv = vec![[f64::NAN; 2]; 3 * nf];
    let mut placed = vec![false; nf];
    let mut queue = std::collections::VecDeque::new();
    for root in 0..nf as u32 {
        if placed[root as usize] {
            continue;
        }
        let h = 3 * root;
        uv[h as usize] = [0.0, 0.0];
        uv[Tri::next(h) as usize] = [len(h), 0.0];
        place_third(&mut uv, h, len(Tri::next(h)), len(Tri::prev(h)))?;
        placed[root as usize] = true;
        queue.push_back(root);
        while let Some(f) = queue.pop_front() {
            for j in 0..3u32 {
                let h = 3 * f + j;
                let t = tri.twin[h as usize];
                if t == NONE || placed[(t / 3) as usize] {
                    continue;
                }
                // t runs tip(h) → origin(h).
                uv[t as usize] = uv[Tri::next(h) as usize];
                uv[Tri::next(t) as usize] = uv[h as usize];
                place_third(&mut uv, t, len(Tri::next(t)), len(Tri::prev(t)))?;
                placed[(t / 3) as usize] = true;
                queue.push_back(t / 3);
            }
        }
    }
    Ok(uv)
}

/// Place the corner opposite `h` to the left of origin(h) → tip(h): `a` = |tip − third|,
/// `b` = |third − origin|.
fn place_third(uv: &mut [[f64; 2]], h: u32, a: f64, b: f64) -> Result<()> {
    let p = uv[h as usize];
    let q = uv[Tri::next(h) as usize];
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    let c = dx.hypot(dy);
    let along = (b * b + c * c - a * a) / (2.0 * c);
    let h2 = b * b - along * along;
    if !(h2 > 0.0) {
        return Err(Error::numerical(format!(
            "face {} violates the triangle inequality (sides {a}, {b}, {c})",
            h / 3
        )));
    }
    let hgt = h2.sqrt();
    let (ux, uy) = (dx / c, dy / c);
    uv[Tri::prev(h) as usize] = [p[0] + along * ux - hgt * uy, p[1] + along * uy + hgt * ux];
    Ok(())
}

type Cx = (f64, f64);
#[inline]
fn cmul(a: Cx, b: Cx) -> Cx {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}
#[inline]
fn cdiv(a: Cx, b: Cx) -> Cx {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

/// Breadth-first layout of `T` in the Poincaré disk from its hyperbolic lengths at vertex
/// scaling `u` (H², `sinh(l/2) = e^{λ̃/2}`), one position per corner, like
/// [`layout_euclidean`]. Each new corner is placed in the frame where the shared edge starts
/// at the origin (a Möbius map of the disk), by the hyperbolic law of cosines.
pub fn layout_hyperbolic(tri: &Tri, u: &[f64]) -> Result<Vec<[f64; 2]>> {
    let nf = tri.n_faces();
    let len = |h: u32| {
        2.0 * (0.5 * tri.scaled_lambda(tri.edge[h as usize], u))
            .exp()
            .asinh()
    };
    let mut uv = vec![[f64::NAN; 2]; 3 * nf];
    let mut placed = vec![false; nf];
    let mut queue = std::collections::VecDeque::new();
    for root in 0..nf as u32 {
        if placed[root as usize] {
            continue;
        }
        let h = 3 * root;
        uv[h as usize] = [0.0, 0.0];
        uv[Tri::next(h) as usize] = [(0.5 * len(h)).tanh(), 0.0];
        place_third_hyperbolic(&mut uv, h, len(h), len(Tri::next(h)), len(Tri::prev(h)))?;
        placed[root as usize] = true;
        queue.push_back(root);
        while let Some(f) = queue.pop_front() {
            for j in 0..3u32 {
                let h = 3 * f + j;
                let t = tri.twin[h as usize];
                if t == NONE || placed[(t / 3) as usize] {
                    continue;
                }
                uv[t as usize] = uv[Tri::next(h) as usize];
                uv[Tri::next(t) as usize] = uv[h as usize];
                place_third_hyperbolic(&mut uv, t, len(t), len(Tri::next(t)), len(Tri::prev(t)))?;
                placed[(t / 3) as usize] = true;
                queue.push_back(t / 3);
            }
        }
    }
    Ok(uv)
}

/// Place the corner opposite `h` (side lengths: `c` of `h`, `a` = tip → third, `b` = third →
/// origin) to the left of origin(h) → tip(h) in the Poincaré disk.
fn place_third_hyperbolic(uv: &mut [[f64; 2]], h: u32, c: f64, a: f64, b: f64) -> Result<()> {
    let p = uv[h as usize];
    let q = uv[Tri::next(h) as usize];
    let pc: Cx = (p[0], p[1]);
    let pbar: Cx = (p[0], -p[1]);
    // T(z) = (z − p)/(1 − p̄ z) takes p to 0.
    let tq = cdiv(
        (q[0] - pc.0, q[1] - pc.1),
        (
            1.0 - cmul(pbar, (q[0], q[1])).0,
            -cmul(pbar, (q[0], q[1])).1,
        ),
    );
    let theta = tq.1.atan2(tq.0);
    let cos_alpha = (b.cosh() * c.cosh() - a.cosh()) / (b.sinh() * c.sinh());
    if !(cos_alpha.abs() < 1.0) {
        return Err(Error::numerical(format!(
            "face {} violates the hyperbolic triangle inequality (sides {a}, {b}, {c})",
            h / 3
        )));
    }
    let alpha = cos_alpha.acos();
    let r = (0.5 * b).tanh();
    let w: Cx = (r * (theta + alpha).cos(), r * (theta + alpha).sin());
    // T⁻¹(w) = (w + p)/(1 + p̄ w).
    let num = (w.0 + pc.0, w.1 + pc.1);
    let pw = cmul(pbar, w);
    let z = cdiv(num, (1.0 + pw.0, pw.1));
    uv[Tri::prev(h) as usize] = [z.0, z.1];
    Ok(())
}
