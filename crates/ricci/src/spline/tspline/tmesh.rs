//! Periodic T-meshes over the flat torus (Sederberg, Zheng, Bakenov, Nasri 2003 §3; Sederberg
//! et al. 2004; paper 003 §3).
//!
//! The domain is the flat torus `R² / Λ` with the lattice `Λ = Z ω₁ + Z ω₂`, `ω₁ = (W, 0)`,
//! `ω₂ = (s, H)`, `H > 0`: a point `(u, v)` is the same as `(u + W, v)` and `(u + s, v + H)`.
//! A non-rectangular lattice (`s ≠ 0`) is a rectangle `[0, W) × [0, H)` whose top side is glued
//! to the bottom side with a shift `s`. The T-mesh is a partition of that rectangle into
//! axis-aligned rectangular **faces**; the lines `u = 0` and `v = 0` are always knot lines.
//! A side of a face is an **edge**; a vertex where only three edges meet is a **T-junction**.
//!
//! **Anchors** (cubic, odd degree): the vertices of the T-mesh. The local knot vector of an
//! anchor `(u, v)` is inferred by ray casting (Sederberg et al. 2003, Fig. 4): along the line
//! `v` = const, the `u` coordinates of the next two vertical edges (or vertices) met to the
//! left and to the right give `[u₋₂, u₋₁, u, u₊₁, u₊₂]`, and likewise vertically. Rays that
//! leave the rectangle continue in the neighbouring copy (coordinates are unwrapped, so a
//! knot vector is an increasing sequence in the universal cover).
//!
//! **Analysis suitability** (Li, Zheng, Sederberg, Hughes, Scott 2012): the face extension of a
//! T-junction goes from it in the direction of its missing edge until it has crossed two
//! perpendicular edges; its edge extension goes the other way across one. A T-mesh is
//! analysis-suitable when no horizontal extension meets a vertical one; then the blending
//! functions are linearly independent and form a partition of unity (dual compatibility).
//! [`TMesh::make_analysis_suitable`] extends T-junctions face by face until that holds.

use crate::error::{Error, Result};
use crate::spline::error::SplineError;

/// The lattice of the flat torus: `(u, v) ~ (u + W, v) ~ (u + s, v + H)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    pub width: f64,
    pub height: f64,
    pub shift: f64,
}

impl Lattice {
    /// The representative of `(u, v)` in `[0, W) × [0, H)`.
    pub fn canonical(&self, u: f64, v: f64) -> (f64, f64) {
        let n = (v / self.height).floor();
        let mut v = v - n * self.height;
        let mut u = u - n * self.shift;
        if v >= self.height {
            v -= self.height;
            u -= self.shift;
        }
        if v < 0.0 {
            v = 0.0;
        }
        u -= (u / self.width).floor() * self.width;
        if u >= self.width {
            u -= self.width;
        }
        if u < 0.0 {
            u = 0.0;
        }
        (u, v)
    }
}

/// A face `[u0, u1] × [v0, v1]` of the T-mesh, inside the rectangle `[0, W] × [0, H]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Face {
    pub u0: f64,
    pub u1: f64,
    pub v0: f64,
    pub v1: f64,
}

impl Face {
    pub fn contains(&self, u: f64, v: f64) -> bool {
        u >= self.u0 && u < self.u1 && v >= self.v0 && v < self.v1
    }
}

/// A knot line: its coordinate and the merged closed intervals covered by edges.
#[derive(Debug, Clone)]
struct Line {
    c: f64,
    spans: Vec<(f64, f64)>,
}

/// A T-junction: the vertex and its missing direction (0 = +u, 1 = +v, 2 = −u, 3 = −v).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TJunction {
    pub u: f64,
    pub v: f64,
    pub missing: u8,
}

/// A T-junction extension as a segment of the universal cover: horizontal (`v` fixed,
/// `a ≤ u ≤ b`) or vertical (`u` fixed, `a ≤ v ≤ b`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extension {
    pub horizontal: bool,
    /// The fixed coordinate.
    pub at: f64,
    pub a: f64,
    pub b: f64,
    /// Index of the T-junction in [`TMesh::t_junctions`].
    pub junction: usize,
}

/// An anchor (T-mesh vertex) and its inferred local knot vectors (unwrapped coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    pub u: f64,
    pub v: f64,
    pub knots_u: [f64; 5],
    pub knots_v: [f64; 5],
}

/// Faces by cells of a uniform grid over `[0, W) × [0, H)` (see [`TMesh::face_grid`]).
pub struct FaceGrid<'a> {
    mesh: &'a TMesh,
    nx: usize,
    ny: usize,
    /// Per cell, the faces meeting it, in increasing order.
    cells: Vec<Vec<u32>>,
}

impl FaceGrid<'_> {
    /// The face containing the point: the first of the faces in increasing order, as
    /// [`TMesh::locate`].
    pub fn locate(&self, u: f64, v: f64) -> Option<usize> {
        let lat = self.mesh.lattice;
        let (cu, cv) = lat.canonical(u, v);
        let ix = ((cu / lat.width * self.nx as f64).floor().max(0.0) as usize).min(self.nx - 1);
        let iy = ((cv / lat.height * self.ny as f64).floor().max(0.0) as usize).min(self.ny - 1);
        self.cells[iy * self.nx + ix]
            .iter()
            .map(|&k| k as usize)
            .find(|&k| self.mesh.faces[k].contains(cu, cv))
    }
}

/// A T-mesh over the flat torus.
#[derive(Debug, Clone)]
pub struct TMesh {
    pub lattice: Lattice,
    faces: Vec<Face>,
    vlines: Vec<Line>,
    hlines: Vec<Line>,
    /// Coordinates closer than this are the same knot line.
    tol: f64,
    /// Offset used to look at one side of a vertex (a small fraction of the smallest face).
    delta: f64,
}

fn merge(mut spans: Vec<(f64, f64)>, tol: f64) -> Vec<(f64, f64)> {
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(spans.len());
    for s in spans {
        match out.last_mut() {
            Some(l) if s.0 <= l.1 + tol => l.1 = l.1.max(s.1),
            _ => out.push(s),
        }
    }
    out
}

fn group_lines(mut items: Vec<(f64, (f64, f64))>, tol: f64) -> Vec<Line> {
    items.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut lines: Vec<Line> = Vec::new();
    let mut pending: Vec<(f64, f64)> = Vec::new();
    let mut cur: Option<f64> = None;
    for (c, s) in items {
        match cur {
            Some(c0) if (c - c0).abs() <= tol => pending.push(s),
            _ => {
                if let Some(c0) = cur {
                    lines.push(Line {
                        c: c0,
                        spans: merge(std::mem::take(&mut pending), tol),
                    });
                }
                cur = Some(c);
                pending.push(s);
            }
        }
    }
    if let Some(c0) = cur {
        lines.push(Line {
            c: c0,
            spans: merge(pending, tol),
        });
    }
    lines
}

impl TMesh {
    /// The tensor-product mesh with column coordinates `us` (`0 = us[0] < … < W`) and row
    /// coordinates `vs` (`0 = vs[0] < … < H`).
    pub fn grid(lattice: Lattice, us: &[f64], vs: &[f64]) -> Result<TMesh> {
        if !(lattice.width > 0.0 && lattice.height > 0.0 && lattice.shift.is_finite()) {
            return Err(Error::input(format!(
                "the torus lattice needs W > 0 and H > 0 (got W = {}, H = {}, s = {})",
                lattice.width, lattice.height, lattice.shift
            )));
        }
        let ok = |xs: &[f64], end: f64| {
            !xs.is_empty()
                && xs[0] == 0.0
                && xs.windows(2).all(|w| w[0] < w[1])
                && xs[xs.len() - 1] < end
        };
        if !ok(us, lattice.width) || !ok(vs, lattice.height) {
            return Err(Error::input(
                "T-mesh grid lines must start at 0, increase strictly and stay below the period",
            ));
        }
        let mut faces = Vec::new();
        for j in 0..vs.len() {
            let v1 = if j + 1 < vs.len() {
                vs[j + 1]
            } else {
                lattice.height
            };
            for i in 0..us.len() {
                let u1 = if i + 1 < us.len() {
                    us[i + 1]
                } else {
                    lattice.width
                };
                faces.push(Face {
                    u0: us[i],
                    u1,
                    v0: vs[j],
                    v1,
                });
            }
        }
        let mut m = TMesh {
            lattice,
            faces,
            vlines: Vec::new(),
            hlines: Vec::new(),
            tol: 1e-10 * lattice.width.max(lattice.height),
            delta: 0.0,
        };
        m.rebuild();
        Ok(m)
    }

    /// Uniform `nu × nv` grid.
    pub fn uniform(lattice: Lattice, nu: usize, nv: usize) -> Result<TMesh> {
        let us: Vec<f64> = (0..nu.max(1))
            .map(|i| lattice.width * i as f64 / nu as f64)
            .collect();
        let vs: Vec<f64> = (0..nv.max(1))
            .map(|j| lattice.height * j as f64 / nv as f64)
            .collect();
        TMesh::grid(lattice, &us, &vs)
    }

    pub fn faces(&self) -> &[Face] {
        &self.faces
    }

    fn rebuild(&mut self) {
        let (w, h) = (self.lattice.width, self.lattice.height);
        let mut vi = Vec::with_capacity(2 * self.faces.len());
        let mut hi = Vec::with_capacity(2 * self.faces.len());
        let mut min_side = f64::INFINITY;
        for f in &self.faces {
            min_side = min_side.min(f.u1 - f.u0).min(f.v1 - f.v0);
            vi.push((f.u0, (f.v0, f.v1)));
            let u1 = if (f.u1 - w).abs() <= self.tol {
                0.0
            } else {
                f.u1
            };
            vi.push((u1, (f.v0, f.v1)));
            hi.push((f.v0, (f.u0, f.u1)));
            if (f.v1 - h).abs() > self.tol {
                hi.push((f.v1, (f.u0, f.u1)));
            }
        }
        self.vlines = group_lines(vi, self.tol);
        self.hlines = group_lines(hi, self.tol);
        self.delta = 1e-4 * min_side;
    }

    fn find_line(lines: &[Line], c: f64, tol: f64) -> Option<&Line> {
        let i = lines.partition_point(|l| l.c < c - tol);
        lines.get(i).filter(|l| (l.c - c).abs() <= tol)
    }

    fn covered(line: &Line, x: f64) -> bool {
        line.spans.iter().any(|&(a, b)| x >= a && x <= b)
    }

    /// Is there a vertical edge through the (generic, not on a row) point `(u, v)`?
    fn vedge(&self, u: f64, v: f64) -> bool {
        let (cu, cv) = self.lattice.canonical(u, v);
        let w = self.lattice.width;
        [cu, cu - w, cu + w]
            .iter()
            .filter_map(|&c| Self::find_line(&self.vlines, c, self.tol))
            .any(|l| Self::covered(l, cv))
    }

    /// Is there a horizontal edge through the (generic, not on a column) point `(u, v)`?
    fn hedge(&self, u: f64, v: f64) -> bool {
        let (cu, cv) = self.lattice.canonical(u, v);
        let (w, h) = (self.lattice.width, self.lattice.height);
        let line = Self::find_line(&self.hlines, cv, self.tol)
            .or_else(|| Self::find_line(&self.hlines, cv - h, self.tol));
        match line {
            Some(l) => Self::covered(l, cu) || Self::covered(l, cu + w) || Self::covered(l, cu - w),
            None => false,
        }
    }

    /// Does a vertical edge pass through the point `(u, v)` (closed: end points count)?
    fn vertical_through(&self, u: f64, v: f64) -> bool {
        self.vedge(u, v + self.delta) || self.vedge(u, v - self.delta)
    }

    fn horizontal_through(&self, u: f64, v: f64) -> bool {
        self.hedge(u + self.delta, v) || self.hedge(u - self.delta, v)
    }

    /// The `count` next vertical edges met by the ray from `(u, v)` in direction `dir = ±1`
    /// along `v` = const (unwrapped `u` coordinates).
    pub fn ray_u(&self, u: f64, v: f64, dir: f64, count: usize) -> Vec<f64> {
        let w = self.lattice.width;
        // the columns met on this row, in [0, W)
        let mut cand: Vec<f64> = self.vlines.iter().map(|l| l.c).collect();
        let cv = self.lattice.canonical(u, v).1;
        if cv <= self.tol || cv >= self.lattice.height - self.tol {
            // on the glued row, the columns of the strip below arrive shifted by −s
            for l in &self.vlines {
                cand.push(self.lattice.canonical(l.c - self.lattice.shift, 0.0).0);
            }
            cand.sort_by(f64::total_cmp);
            cand.dedup_by(|a, b| (*a - *b).abs() <= self.tol);
        }
        let cols: Vec<f64> = cand
            .into_iter()
            .filter(|&c| self.vertical_through(c, v))
            .collect();
        let mut out = Vec::with_capacity(count);
        if cols.is_empty() {
            return out;
        }
        let base = (u / w).floor() * w;
        let mut copy = 0i64;
        // walk the periodic sequence of columns
        'outer: for _ in 0..(count + 2) * 2 + 4 {
            let off = base + copy as f64 * w;
            let iter: Box<dyn Iterator<Item = &f64>> = if dir > 0.0 {
                Box::new(cols.iter())
            } else {
                Box::new(cols.iter().rev())
            };
            for &c in iter {
                let x = c + off;
                let beyond = if dir > 0.0 {
                    x > u + self.tol
                } else {
                    x < u - self.tol
                };
                if beyond {
                    out.push(x);
                    if out.len() == count {
                        break 'outer;
                    }
                }
            }
            copy += if dir > 0.0 { 1 } else { -1 };
        }
        out
    }

    /// The `count` next horizontal edges met by the ray from `(u, v)` in direction `dir = ±1`
    /// along `u` = const (unwrapped `v` coordinates; the ray crosses the glued sides).
    pub fn ray_v(&self, u: f64, v: f64, dir: f64, count: usize) -> Vec<f64> {
        let h = self.lattice.height;
        let mut out = Vec::with_capacity(count);
        // the rows of the strip [0, H); row 0 (= H) is a full knot line
        let rows: Vec<f64> = self.hlines.iter().map(|l| l.c).collect();
        let strip = (v / h).floor();
        let mut k = strip as i64;
        for _ in 0..(count + 2) * (rows.len() + 2) {
            let off = k as f64 * h;
            let mut hit_any = false;
            let seq: Box<dyn Iterator<Item = &f64>> = if dir > 0.0 {
                Box::new(rows.iter())
            } else {
                Box::new(rows.iter().rev())
            };
            for &r in seq {
                let y = r + off;
                let beyond = if dir > 0.0 {
                    y > v + self.tol
                } else {
                    y < v - self.tol
                };
                if beyond && self.horizontal_through(u, y) {
                    out.push(y);
                    hit_any = true;
                    if out.len() == count {
                        return out;
                    }
                }
            }
            let _ = hit_any;
            k += if dir > 0.0 { 1 } else { -1 };
        }
        out
    }

    /// The vertices of the T-mesh (canonical representatives, each once).
    pub fn vertices(&self) -> Vec<(f64, f64)> {
        let mut pts = Vec::with_capacity(4 * self.faces.len());
        for f in &self.faces {
            for &(u, v) in &[(f.u0, f.v0), (f.u1, f.v0), (f.u0, f.v1), (f.u1, f.v1)] {
                pts.push(self.snap(u, v));
            }
        }
        pts.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.total_cmp(&b.0)));
        pts.dedup_by(|a, b| (a.0 - b.0).abs() <= self.tol && (a.1 - b.1).abs() <= self.tol);
        pts
    }

    /// Canonical representative snapped onto the stored line coordinates.
    fn snap(&self, u: f64, v: f64) -> (f64, f64) {
        let (w, h) = (self.lattice.width, self.lattice.height);
        let (mut cu, mut cv) = if (v - h).abs() <= self.tol {
            self.lattice.canonical(u - self.lattice.shift, 0.0)
        } else {
            self.lattice.canonical(u, v)
        };
        if (cu - w).abs() <= self.tol {
            cu = 0.0;
        }
        if (cv - h).abs() <= self.tol {
            cv = 0.0;
        }
        if let Some(l) = Self::find_line(&self.vlines, cu, self.tol) {
            cu = l.c;
        }
        if let Some(l) = Self::find_line(&self.hlines, cv, self.tol) {
            cv = l.c;
        }
        (cu, cv)
    }

    /// The anchors with their inferred local knot vectors.
    pub fn anchors(&self) -> Result<Vec<Anchor>> {
        let mut out = Vec::new();
        for (u, v) in self.vertices() {
            let r = self.ray_u(u, v, 1.0, 2);
            let l = self.ray_u(u, v, -1.0, 2);
            let t = self.ray_v(u, v, 1.0, 2);
            let b = self.ray_v(u, v, -1.0, 2);
            if r.len() < 2 || l.len() < 2 || t.len() < 2 || b.len() < 2 {
                return Err(Error::numerical(format!(
                    "the knot rays of the T-mesh vertex ({u}, {v}) did not meet two edges on every side"
                )));
            }
            out.push(Anchor {
                u,
                v,
                knots_u: [l[1], l[0], u, r[0], r[1]],
                knots_v: [b[1], b[0], v, t[0], t[1]],
            });
        }
        Ok(out)
    }

    /// The T-junctions: vertices where exactly three edges meet.
    pub fn t_junctions(&self) -> Vec<TJunction> {
        let d = self.delta;
        let mut out = Vec::new();
        for (u, v) in self.vertices() {
            let dirs = [
                self.hedge(u + d, v),
                self.vedge(u, v + d),
                self.hedge(u - d, v),
                self.vedge(u, v - d),
            ];
            let n = dirs.iter().filter(|&&x| x).count();
            if n == 3 {
                let missing = dirs.iter().position(|&x| !x).unwrap_or(0) as u8;
                out.push(TJunction { u, v, missing });
            }
        }
        out
    }

    /// The face and edge extensions of every T-junction (cubic: the face extension crosses two
    /// perpendicular edges, the edge extension one).
    pub fn extensions(&self) -> Vec<Extension> {
        let tj = self.t_junctions();
        let mut out = Vec::with_capacity(tj.len());
        for (i, t) in tj.iter().enumerate() {
            let dir = if t.missing < 2 { 1.0 } else { -1.0 };
            if t.missing.is_multiple_of(2) {
                let face = self.ray_u(t.u, t.v, dir, 2);
                let edge = self.ray_u(t.u, t.v, -dir, 1);
                if face.len() == 2 && edge.len() == 1 {
                    let (a, b) = if dir > 0.0 {
                        (edge[0], face[1])
                    } else {
                        (face[1], edge[0])
                    };
                    out.push(Extension {
                        horizontal: true,
                        at: t.v,
                        a,
                        b,
                        junction: i,
                    });
                }
            } else {
                let face = self.ray_v(t.u, t.v, dir, 2);
                let edge = self.ray_v(t.u, t.v, -dir, 1);
                if face.len() == 2 && edge.len() == 1 {
                    let (a, b) = if dir > 0.0 {
                        (edge[0], face[1])
                    } else {
                        (face[1], edge[0])
                    };
                    out.push(Extension {
                        horizontal: false,
                        at: t.u,
                        a,
                        b,
                        junction: i,
                    });
                }
            }
        }
        out
    }

    /// Does the horizontal extension `h` meet the vertical extension `x` (or one of its
    /// lattice translates)? Closed segments.
    fn extensions_meet(&self, h: &Extension, x: &Extension) -> bool {
        let Lattice {
            width: w,
            height: ht,
            shift: s,
        } = self.lattice;
        let tol = self.tol;
        // vertical segment u = x.at + m W + n s, v ∈ [x.a + n H, x.b + n H] must contain h.at
        let n0 = ((h.at - x.b - tol) / ht).ceil() as i64;
        let n1 = ((h.at - x.a + tol) / ht).floor() as i64;
        for n in n0..=n1 {
            let c = x.at + n as f64 * s;
            let m0 = ((h.a - c - tol) / w).ceil() as i64;
            let m1 = ((h.b - c + tol) / w).floor() as i64;
            if m0 <= m1 {
                return true;
            }
        }
        false
    }

    /// The pairs (horizontal extension, vertical extension) that meet; empty = analysis-suitable.
    pub fn intersecting_extensions(&self) -> Vec<(Extension, Extension)> {
        let ext = self.extensions();
        let (hs, vs): (Vec<Extension>, Vec<Extension>) = ext.iter().partition(|e| e.horizontal);
        let mut out = Vec::new();
        for h in &hs {
            for x in &vs {
                if self.extensions_meet(h, x) {
                    out.push((*h, *x));
                }
            }
        }
        out
    }

    pub fn is_analysis_suitable(&self) -> bool {
        self.intersecting_extensions().is_empty()
    }

    fn face_at(&self, u: f64, v: f64) -> Option<usize> {
        let (cu, cv) = self.lattice.canonical(u, v);
        self.faces.iter().position(|f| f.contains(cu, cv))
    }

    /// Index of the face containing the point (half-open faces).
    pub fn locate(&self, u: f64, v: f64) -> Option<usize> {
        self.face_at(u, v)
    }

    /// A bucket grid over the faces: [`FaceGrid::locate`] answers what [`TMesh::locate`] does
    /// without scanning every face.
    pub fn face_grid(&self) -> FaceGrid<'_> {
        let (w, h) = (self.lattice.width, self.lattice.height);
        let side = (w * h / self.faces.len().max(1) as f64).sqrt().max(1e-300);
        let nx = ((w / side).ceil() as usize).clamp(1, 1024);
        let ny = ((h / side).ceil() as usize).clamp(1, 1024);
        let cell = |x: f64, len: f64, n: usize| {
            ((x / len * n as f64).floor().max(0.0) as usize).min(n - 1)
        };
        let mut cells = vec![Vec::new(); nx * ny];
        for (k, f) in self.faces.iter().enumerate() {
            for iy in cell(f.v0, h, ny)..=cell(f.v1, h, ny) {
                for ix in cell(f.u0, w, nx)..=cell(f.u1, w, nx) {
                    cells[iy * nx + ix].push(k as u32);
                }
            }
        }
        FaceGrid {
            mesh: self,
            nx,
            ny,
            cells,
        }
    }

    fn split_vertical(&mut self, f: usize, c: f64) -> bool {
        let face = self.faces[f];
        if !(c > face.u0 + self.tol && c < face.u1 - self.tol) {
            return false;
        }
        self.faces[f].u1 = c;
        self.faces.push(Face { u0: c, ..face });
        true
    }

    fn split_horizontal(&mut self, f: usize, c: f64) -> bool {
        let face = self.faces[f];
        if !(c > face.v0 + self.tol && c < face.v1 - self.tol) {
            return false;
        }
        self.faces[f].v1 = c;
        self.faces.push(Face { v0: c, ..face });
        true
    }

    /// Split face `f` into four (`quad`) or into two across its longer side.
    pub fn refine_face(&mut self, f: usize, quad: bool) {
        let face = self.faces[f];
        let (mu, mv) = (0.5 * (face.u0 + face.u1), 0.5 * (face.v0 + face.v1));
        if quad {
            let n = self.faces.len();
            if self.split_vertical(f, mu) {
                self.split_horizontal(n, mv);
            }
            self.split_horizontal(f, mv);
        } else if face.u1 - face.u0 >= face.v1 - face.v0 {
            self.split_vertical(f, mu);
        } else {
            self.split_horizontal(f, mv);
        }
        self.rebuild();
    }

    /// Refine several faces at once (indices into [`TMesh::faces`] before the call).
    pub fn refine_faces(&mut self, faces: &[(usize, bool)]) {
        for &(f, quad) in faces {
            let face = self.faces[f];
            let (mu, mv) = (0.5 * (face.u0 + face.u1), 0.5 * (face.v0 + face.v1));
            if quad {
                let n = self.faces.len();
                if self.split_vertical(f, mu) {
                    self.split_horizontal(n, mv);
                }
                self.split_horizontal(f, mv);
            } else if face.u1 - face.u0 >= face.v1 - face.v0 {
                self.split_vertical(f, mu);
            } else {
                self.split_horizontal(f, mv);
            }
        }
        self.rebuild();
    }

    /// Continue the T-junction's missing edge across the face beyond it.
    fn extend_junction(&mut self, t: &TJunction) -> bool {
        let d = self.delta;
        let (pu, pv) = match t.missing {
            0 => (t.u + d, t.v),
            1 => (t.u, t.v + d),
            2 => (t.u - d, t.v),
            _ => (t.u, t.v - d),
        };
        let (cu, cv) = self.lattice.canonical(pu, pv);
        let Some(f) = self.faces.iter().position(|f| f.contains(cu, cv)) else {
            return false;
        };
        let done = if t.missing.is_multiple_of(2) {
            // horizontal edge at the T-junction's row, in the face's copy
            let c = if (cv - t.v).abs() < 2.0 * d { t.v } else { cv };
            self.split_horizontal(f, c)
        } else {
            let c = if (cu - t.u).abs() < 2.0 * d { t.u } else { cu };
            self.split_vertical(f, c)
        };
        if done {
            self.rebuild();
        }
        done
    }

    /// Extend T-junctions until no horizontal extension meets a vertical one, at most `budget`
    /// face splits. Returns the number of splits.
    pub fn make_analysis_suitable(&mut self, budget: usize) -> Result<usize> {
        let mut splits = 0;
        loop {
            let bad = self.intersecting_extensions();
            if bad.is_empty() {
                return Ok(splits);
            }
            if splits >= budget {
                let remaining = bad.len();
                return Err(SplineError::NotAnalysisSuitable { budget, remaining }.into());
            }
            let tj = self.t_junctions();
            let mut progressed = false;
            // extend the horizontal T-junction of the first pair, else the vertical one
            for (h, x) in bad.iter().take(1) {
                for e in [h, x] {
                    if self.extend_junction(&tj[e.junction]) {
                        splits += 1;
                        progressed = true;
                        break;
                    }
                }
            }
            if !progressed {
                return Err(Error::numerical(
                    "a T-junction extension could not be continued across its face",
                ));
            }
        }
    }
}
