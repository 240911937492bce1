//! T-junctions on the domain mesh (issue 18; T-splines: Sederberg, Zheng, Bakenov, Nasri 2003
//! §3, local knot vectors by ray casting; analysis-suitable T-meshes: Li, Zheng, Sederberg,
//! Hughes, Scott 2012 §3–4). The grading at the zeros ([`DomainMesh::graded`]) adds mesh
//! lines through whole strips; here each of those lines is kept only where it is needed —
//! from the zero through its corner block and `margin` cells beyond — and ends there in a
//! **T-junction** inside the strip. The lines of the corner blocks, the strip sides and every
//! line of the ungraded mesh stay whole.
//!
//! **The spline.** One control point per vertex of the T-mesh (its *anchors*). An anchor's
//! blending function is the product of two cubic B-splines whose five knots are the first two
//! mesh lines the rays from the anchor meet in each direction (continuing across strip
//! gluings by the translations). Every knot of the T-mesh is a knot of the full graded mesh,
//! so by knot insertion ([`knot_insertion`], Boehm 1980) every blending function is a
//! combination of the full mesh's tensor-product B-splines; the full mesh's Bézier extraction
//! is reused unchanged, and the T-spline is the subspace of its nets spanned by those
//! combinations. It is folded into [`DomainMesh::reduction`]: a net expanded from the free
//! values is a T-spline net (and, with the G¹ conditions, G¹ at the zeros). The anchors whose
//! four rays meet only lines of the full mesh have the full mesh's blending function: among
//! them every vertex near a zero, so the zeros' rules and G¹ conditions apply unchanged.
//!
//! **Analysis-suitable by construction.** A graded line ends only where it leaves a gap of at
//! least two intervals (else it stays whole). The T-junctions on lines along `v` sit `L + 2 +
//! margin` rows from the strip's bottom or top (`L` the levels), on the first `L` columns
//! from a side; those on lines along `u` the same number of columns from a side, on the first
//! `L` rows from the bottom or top. A T-junction's extension (two faces ahead, one edge behind)
//! of a line along `v` stays within those `L` columns and at least `L + 1` rows from the
//! bottom and top; one along `u` within the `L` rows: no extension along `u` meets one along
//! `v` (the test checks it from the mesh lines, independently). Hence the blending functions
//! are linearly independent and sum to one (Li et al. 2012, Theorems 4.8, 6.2).

use super::blocks::FINE;
use super::*;

/// The T-mesh of a graded domain mesh: which graded lines end in T-junctions, and its anchors.
#[derive(Debug, Clone, Default)]
pub struct TJunctions {
    /// Cells beyond a corner block (the first `L + 2` columns or rows from a zero) through
    /// which a graded line continues before it ends.
    pub margin: usize,
    /// Per control point of the T-spline: its vertex of the full mesh, and its free value in
    /// [`DomainMesh::reduction`] (`u32::MAX` if the G¹ conditions fix it).
    pub anchors: Vec<(u32, u32)>,
    /// Anchors whose blending function is not the full mesh's (their rays skip a graded line).
    pub modified: usize,
    /// The T-junctions: strip, `(i, j)` (the point `(x(i), y(j))` of the strip) and whether
    /// the line that ends there runs along `v`.
    pub junctions: Vec<(u32, u32, u32, bool)>,
}

/// Whether knot `b` of `k` intervals (of the graded mesh) is one of the grading's.
fn graded(b: usize, k: usize, levels: usize) -> bool {
    (1..=levels).contains(&b) || (b + levels >= k && b < k)
}

impl Rect {
    /// Whether column line `i` is one of the grading's (module doc of the parent).
    fn graded_u(&self, i: usize) -> bool {
        let h = self.u_fine[i];
        h.is_multiple_of(FINE) && graded(h / FINE, self.base_m, self.levels)
    }

    fn graded_v(&self, j: usize) -> bool {
        let h = self.v_fine[j];
        h.is_multiple_of(FINE) && graded(h / FINE, self.base_n, self.levels)
    }
}

/// Coefficients of the cubic B-spline with the knots `xi` in the B-splines of the finer knots
/// `t` (increasing, from `xi[0]` to `xi[4]`, with `new[k]` true for the knots not in `xi`):
/// the one with knots `t[k..k + 5]` gets `out[k]`. One knot at a time (Boehm 1980).
pub fn knot_insertion(xi: [f64; 5], t: &[f64], new: &[bool]) -> Vec<f64> {
    let span = xi[4] - xi[0];
    // three padding knots at each end: the B-splines over them have coefficient 0
    let mut tau: Vec<f64> = (1..=3).rev().map(|k| xi[0] - k as f64 * span).collect();
    tau.extend(xi);
    tau.extend((1..=3).map(|k| xi[4] + k as f64 * span));
    let mut c = vec![0.0; tau.len() - 4];
    c[3] = 1.0;
    for (&x, _) in t.iter().zip(new).filter(|p| *p.1) {
        let k = tau.iter().rposition(|&y| y <= x).unwrap_or(0);
        let next: Vec<f64> = (0..=c.len())
            .map(|j| {
                if j + 3 <= k {
                    c[j]
                } else if j > k {
                    c[j - 1]
                } else {
                    let a = (x - tau[j]) / (tau[j + 3] - tau[j]);
                    a * c[j] + (1.0 - a) * c[j - 1]
                }
            })
            .collect();
        tau.insert(k + 1, x);
        c = next;
    }
    c[3..3 + t.len().saturating_sub(4)].to_vec()
}

/// One step of a ray along the full mesh: the signed distance from the anchor, the cell whose
/// lower-left corner is the vertex reached, and whether the T-mesh has a line across there.
type RayStep = (f64, u32, bool);

impl DomainMesh {
    /// The reach of the graded lines from a strip's end (`None`: no T-junctions).
    fn reach(&self, r: usize) -> Option<usize> {
        let t = self.tjunctions.as_ref()?;
        Some(self.rects[r].levels + 2 + t.margin)
    }

    /// Whether the T-mesh has a line along `v` through the point `(x(i), y(j))` of strip `r`.
    pub fn on_line_v(&self, r: usize, i: usize, j: usize) -> bool {
        let rc = &self.rects[r];
        let Some(k) = self.reach(r) else {
            return true;
        };
        if let Some(on) = self.block_line_v(r, i, j) {
            return on;
        }
        // a gap of at least two intervals, else the line stays whole (indices of the graded
        // mesh, in units of `1 / FINE`: blocks split some intervals)
        let (h, n) = (rc.v_fine[j], rc.base_n);
        !rc.graded_u(i) || 2 * k + 2 > n || h <= FINE * k || h >= FINE * (n - k)
    }

    /// Whether the T-mesh has a line along `u` through the point `(x(i), y(j))` of strip `r`.
    pub fn on_line_u(&self, r: usize, i: usize, j: usize) -> bool {
        let rc = &self.rects[r];
        let Some(k) = self.reach(r) else {
            return true;
        };
        if let Some(on) = self.block_line_u(r, i, j) {
            return on;
        }
        let (h, m) = (rc.u_fine[i], rc.base_m);
        !rc.graded_v(j) || 2 * k + 2 > m || h <= FINE * k || h >= FINE * (m - k)
    }

    /// Whether the vertex at the lower-left corner of cell `c` has a T-mesh line across
    /// `axis` (a line along the other direction) through it.
    pub(super) fn crossed(&self, c: u32, axis: Axis) -> bool {
        let (r, i, j) = self.cell_at[c as usize];
        let (r, i, j) = (r as usize, i as usize, j as usize);
        match axis {
            Axis::U => self.on_line_v(r, i, j),
            Axis::V => self.on_line_u(r, i, j),
        }
    }

    /// The ray along `axis` (forward or back) from the vertex at the lower-left corner of cell
    /// `c`: every vertex of the full mesh up to the second the T-mesh has a line through;
    /// `None` when it meets a zero first.
    fn ray(&self, c: u32, axis: Axis, forward: bool) -> Result<Option<Vec<RayStep>>, String> {
        let (back, ahead) = axis.sides();
        let (mut cell, mut at) = (c, 0.0);
        let mut out = Vec::new();
        let budget = self.n_cells();
        while out.iter().filter(|s: &&RayStep| s.2).count() < 2 {
            if out.len() > budget {
                return Err(format!(
                    "the ray from the vertex of cell {c} does not close"
                ));
            }
            if forward {
                at += self.len(cell, axis);
                cell = self.nb(cell, ahead);
            } else {
                cell = self.nb(cell, back);
                at -= self.len(cell, axis);
            }
            if self.is_zero(self.corners[cell as usize][0]) {
                return Ok(None);
            }
            out.push((at, cell, self.crossed(cell, axis)));
        }
        Ok(Some(out))
    }

    /// The full mesh's knots (with their cells) along `axis` through the anchor at the lower-left
    /// of cell `c`, from its fifth T-mesh knot back to its fifth ahead; `None` if a ray meets
    /// a zero.
    /// The anchor's index in the list comes with it.
    fn knots_through(&self, c: u32, axis: Axis) -> Result<Option<(Vec<RayStep>, usize)>, String> {
        let (Some(mut back), Some(ahead)) = (self.ray(c, axis, false)?, self.ray(c, axis, true)?)
        else {
            return Ok(None);
        };
        back.reverse();
        let at = back.len();
        back.push((0.0, c, true));
        back.extend(ahead);
        Ok(Some((back, at)))
    }

    /// The anchor at the lower-left of cell `c` as a combination of the full mesh's vertices,
    /// or `None` if its blending function is the full mesh's.
    fn anchor_column(&self, c: u32) -> Result<Option<Combination>, String> {
        if self.is_zero(self.corners[c as usize][0]) {
            return Ok(None);
        }
        let (Some((ku, _)), Some((kv, iv))) = (
            self.knots_through(c, Axis::U)?,
            self.knots_through(c, Axis::V)?,
        ) else {
            return Ok(None);
        };
        if ku.iter().chain(&kv).all(|s| s.2) {
            return Ok(None);
        }
        let coefficients = |k: &[RayStep]| {
            let t: Vec<f64> = k.iter().map(|s| s.0).collect();
            let new: Vec<bool> = k.iter().map(|s| !s.2).collect();
            let xi: Vec<f64> = k.iter().filter(|s| s.2).map(|s| s.0).collect();
            knot_insertion([xi[0], xi[1], xi[2], xi[3], xi[4]], &t, &new)
        };
        let (a, b) = (coefficients(&ku), coefficients(&kv));
        // B-spline k of the full knots is centred at knot k + 2
        let mut out = Combination::new();
        for (p, &x) in a.iter().enumerate() {
            for (q, &y) in b.iter().enumerate() {
                if x * y == 0.0 {
                    continue;
                }
                // from the anchor: along u to the column, then along v
                let mut cell = ku[p + 2].1;
                let steps = q as isize + 2 - iv as isize;
                for _ in 0..steps.unsigned_abs() {
                    cell = self.nb(cell, if steps > 0 { TOP } else { BOTTOM });
                }
                let v = self.corners[cell as usize][0];
                if self.is_zero(v) {
                    return Err(format!(
                        "a T-junction's blending function reaches the zero at vertex {v}"
                    ));
                }
                add(&mut out, v, x * y);
            }
        }
        Ok(Some(out))
    }

    /// The mesh with every graded line ending `margin` cells beyond its corner blocks (module
    /// doc): the same Bézier extraction, the T-spline's nets as [`Self::reduction`]; or why
    /// not.
    pub fn with_t_junctions(mut self, margin: usize) -> Result<Self, String> {
        self.tjunctions = Some(TJunctions {
            margin,
            ..TJunctions::default()
        });
        let nv = self.n_vertices();
        let mut lower_left = vec![u32::MAX; nv];
        for (c, q) in self.corners.iter().enumerate() {
            if lower_left[q[0] as usize] == u32::MAX {
                lower_left[q[0] as usize] = c as u32;
            }
        }
        // per full vertex: its value as a combination of anchors
        let mut rows: Vec<Combination> = vec![Combination::new(); nv];
        let mut anchors: Vec<u32> = Vec::new();
        let mut modified = 0;
        let mut junctions = Vec::new();
        for v in 0..nv as u32 {
            let c = lower_left[v as usize];
            if !(self.crossed(c, Axis::U) && self.crossed(c, Axis::V)) {
                continue;
            }
            if let Some(along_v) = self.t_junction(c) {
                let (r, i, j) = self.cell_at[c as usize];
                junctions.push((r, i, j, along_v));
            }
            let a = anchors.len() as u32;
            anchors.push(v);
            match self.anchor_column(c)? {
                None => add(&mut rows[v as usize], a, 1.0),
                Some(col) => {
                    modified += 1;
                    for (x, w) in col {
                        add(&mut rows[x as usize], a, w);
                    }
                }
            }
        }
        // with the G¹ reduction: anchor a is the combination of free values of its vertex
        let old = std::mem::take(&mut self.reduction);
        let mut renumber = vec![u32::MAX; old.free];
        let mut free = 0u32;
        let mut number = |f: u32| {
            if renumber[f as usize] == u32::MAX {
                renumber[f as usize] = free;
                free += 1;
            }
            renumber[f as usize]
        };
        let mut anchor_free = Vec::with_capacity(anchors.len());
        for &v in &anchors {
            let e = &old.expand[v as usize];
            anchor_free.push(match e.as_slice() {
                [(f, w)] if *w == 1.0 => (v, number(*f)),
                _ => (v, u32::MAX),
            });
        }
        let mut expand = Vec::with_capacity(nv);
        for row in &rows {
            let mut comb = Combination::new();
            for &(a, w) in row {
                for &(f, x) in &old.expand[anchors[a as usize] as usize] {
                    add(&mut comb, number(f), w * x);
                }
            }
            expand.push(comb);
        }
        self.reduction = Reduction {
            free: free as usize,
            expand,
        };
        self.tjunctions = Some(TJunctions {
            margin,
            anchors: anchor_free,
            modified,
            junctions,
        });
        Ok(self)
    }

    /// The control points of the spline: the T-mesh's anchors, or every vertex.
    pub fn n_control_points(&self) -> usize {
        self.tjunctions
            .as_ref()
            .map_or(self.n_vertices(), |t| t.anchors.len())
    }

    /// Whether cell `c` lies beside a graded line where it is cut (past its T-junction): an
    /// error there asks for longer lines, not for a finer mesh.
    pub fn past_t_junction(&self, c: u32) -> bool {
        let (r, i, j) = self.base_cell(c);
        let Some(k) = self.reach(r) else {
            return false;
        };
        let rc = &self.rects[r];
        let (l, m, n) = (rc.levels, rc.base_m, rc.base_n);
        let band_u = (i <= l || i + l + 1 >= m) && 2 * k + 2 <= n && j >= k && j + k < n;
        let band_v = (j <= l || j + l + 1 >= n) && 2 * k + 2 <= m && i >= k && i + k < m;
        band_u || band_v
    }

    /// The number of T-junctions (0 on a conforming mesh).
    pub fn n_t_junctions(&self) -> usize {
        self.tjunctions.as_ref().map_or(0, |t| t.junctions.len())
    }
}
