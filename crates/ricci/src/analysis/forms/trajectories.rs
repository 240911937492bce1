//! Critical horizontal trajectories of a holomorphic 1-form (paper 002 §4.2.4, the "critical
//! trajectories through the zeros" of the conformal net; Strebel, *Quadratic differentials*,
//! ch. IV): the curves along which `ω` is real, i.e. `Im ∫ω` is constant, that leave a zero.
//!
//! On each face a discrete holomorphic form is constant, so its potential `φ = ∫ω` is affine
//! and a horizontal trajectory is the segment of the level line `Im φ = const` through the
//! face. Near a zero of order `m` (`ω ≈ z^m dz`) the level line `Im φ = Im φ(p)` leaves `p` in
//! `2(m + 1)` directions (alternately with `Re φ` increasing and decreasing), so a form with
//! zeros of orders `m_i` has `Σ 2(m_i + 1)` critical trajectories. Each is traced face by face
//! (in the face's own chart of `φ`, so the cut and the periods play no role) for a given
//! length `∫|ω|` along it, or until it runs into a vertex or a folded face.

use super::cochain::on_halfedge;
use super::HolomorphicForm;
use crate::layout::isometry::Complex;
use crate::mesh::{Mesh, NONE};

/// A point on edge `from → to` of the mesh at `(1 − t)·from + t·to` (`t = 0`: the vertex).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgePoint {
    pub from: u32,
    pub to: u32,
    pub t: f64,
}

impl EdgePoint {
    /// The point on a surface with these vertex positions.
    pub fn position(&self, pos: &[[f64; 3]]) -> [f64; 3] {
        let (a, b) = (pos[self.from as usize], pos[self.to as usize]);
        std::array::from_fn(|k| a[k] + self.t * (b[k] - a[k]))
    }
}

/// One critical horizontal trajectory: it starts at the zero `zero` (the first point) and
/// runs with `Re φ` increasing (`outgoing`) or decreasing.
#[derive(Debug, Clone)]
pub struct Trajectory {
    pub zero: u32,
    pub outgoing: bool,
    pub points: Vec<EdgePoint>,
    /// `∫|ω|` along it.
    pub length: f64,
}

/// The value of the form on half-edge `h`.
fn value(mesh: &Mesh, form: &HolomorphicForm, h: u32) -> Complex {
    Complex::new(
        on_halfedge(mesh, &form.re, h),
        on_halfedge(mesh, &form.im, h),
    )
}

/// The critical horizontal trajectories from each of the vertices `zeros` (zeros of `form`),
/// each traced for at most `length` (in `∫|ω|`) and `max_faces` faces.
pub fn critical_trajectories(
    mesh: &Mesh,
    form: &HolomorphicForm,
    zeros: &[u32],
    length: f64,
    max_faces: usize,
) -> Vec<Trajectory> {
    let mut out = Vec::new();
    for &p in zeros {
        if (p as usize) >= mesh.n_vertices() || mesh.is_isolated(p) {
            continue;
        }
        for h in mesh.outgoing(p) {
            if mesh.he_face(h) == NONE {
                continue;
            }
            // Face (p, b, c) with φ(p) = 0.
            let hn = mesh.he_next(h);
            let pb = value(mesh, form, h);
            let pc = pb + value(mesh, form, hn);
            let straddle = pb.im * pc.im;
            if straddle.is_nan() || straddle >= 0.0 {
                continue;
            }
            let s = pb.im / (pb.im - pc.im);
            let x = pb + (pc - pb) * s;
            let outgoing = x.re > 0.0;
            let start = EdgePoint {
                from: p,
                to: p,
                t: 0.0,
            };
            let first = EdgePoint {
                from: mesh.he_origin(hn),
                to: mesh.he_tip(hn),
                t: s,
            };
            let mut tr = Trajectory {
                zero: p,
                outgoing,
                points: vec![start, first],
                length: x.norm(),
            };
            trace(mesh, form, hn, s, length, max_faces, &mut tr);
            out.push(tr);
        }
    }
    out
}

/// Continue `tr` from the point at parameter `s` on half-edge `e` (whose face was just
/// crossed) into the faces beyond.
fn trace(
    mesh: &Mesh,
    form: &HolomorphicForm,
    mut e: u32,
    mut s: f64,
    length: f64,
    max_faces: usize,
    tr: &mut Trajectory,
) {
    let dir = if tr.outgoing { 1.0 } else { -1.0 };
    for _ in 0..max_faces {
        if tr.length >= length {
            return;
        }
        let t = mesh.he_twin(e);
        if mesh.he_face(t) == NONE {
            return; // a boundary
        }
        // Face (c, b, d) entered across t = c → b at parameter 1 − s; φ(c) = 0.
        let tn = mesh.he_next(t);
        let cb = value(mesh, form, t);
        let cd = cb + value(mesh, form, tn);
        let x = cb * (1.0 - s);
        // The level in this face's chart (φ differs by a constant from the previous chart;
        // the entry point carries the level over).
        let level = x.im;
        let (vb, vd) = (cb.im - level, cd.im - level);
        let vc = -level;
        // Exit on b → d or on d → c.
        let (exit_he, s_exit, y) = if vb * vd < 0.0 {
            let r = vb / (vb - vd);
            (tn, r, cb + (cd - cb) * r)
        } else if vd * vc < 0.0 {
            let r = vd / (vd - vc);
            (mesh.he_next(tn), r, cd * (1.0 - r))
        } else {
            // Through the vertex d (or a degenerate face): stop there.
            if vd.abs() <= 1e-12 * (cb.norm() + cd.norm()) {
                tr.points.push(EdgePoint {
                    from: mesh.he_tip(tn),
                    to: mesh.he_tip(tn),
                    t: 0.0,
                });
            }
            return;
        };
        if (y.re - x.re) * dir <= 0.0 {
            return; // a folded face: the level line turns back
        }
        tr.length += (y - x).norm();
        tr.points.push(EdgePoint {
            from: mesh.he_origin(exit_he),
            to: mesh.he_tip(exit_he),
            t: s_exit,
        });
        e = exit_he;
        s = s_exit;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a flat square grid with ω = e^{iα} dz (no zeros inside), the level line traced from
    /// a vertex is the straight line of direction e^{−iα}: every point satisfies
    /// Im(e^{iα} z) = Im(e^{iα} z₀).
    #[test]
    fn horizontal_lines_of_a_constant_form_are_straight() {
        let n = 12usize;
        let mut pos = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                pos.push([i as f64, j as f64, 0.0]);
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let mesh = Mesh::from_triangles(pos.len(), faces).unwrap();
        let w = Complex::from_polar(1.0, 0.3);
        let mut form = HolomorphicForm {
            re: vec![0.0; mesh.n_edges()],
            im: vec![0.0; mesh.n_edges()],
        };
        for e in 0..mesh.n_edges() as u32 {
            let h = mesh.edge_halfedge(e);
            let (a, b) = (
                pos[mesh.he_origin(h) as usize],
                pos[mesh.he_tip(h) as usize],
            );
            let v = w * Complex::new(b[0] - a[0], b[1] - a[1]);
            form.re[e as usize] = v.re;
            form.im[e as usize] = v.im;
        }
        // A regular point has two horizontal directions (m = 0).
        let p = id(6, 6);
        let trs = critical_trajectories(&mesh, &form, &[p], 4.0, 1000);
        assert_eq!(trs.len(), 2, "{trs:?}");
        assert!(trs[0].outgoing != trs[1].outgoing);
        let z0 = Complex::new(6.0, 6.0);
        for tr in &trs {
            assert!(tr.points.len() > 4 && tr.length >= 4.0 - 1e-9, "{tr:?}");
            for q in &tr.points {
                let x = q.position(&pos);
                let z = Complex::new(x[0], x[1]);
                assert!(((w * (z - z0)).im).abs() < 1e-12, "{z} off the line");
            }
            let end = tr.points.last().unwrap().position(&pos);
            let u = (w * (Complex::new(end[0], end[1]) - z0)).re;
            assert!(if tr.outgoing { u > 0.0 } else { u < 0.0 });
        }
    }
}
