//! Bézier elements: the maximal rectangles of the domain on which the spline is **one** bicubic
//! polynomial (for an analysis-suitable T-spline, the faces of the extended T-mesh: Scott,
//! Borden, Verhoosel, Sederberg, Hughes 2011 §3; Li, Zheng, Sederberg, Hughes, Scott 2012 §3),
//! found from the Bézier patches of a finer tensor grid of cells (issue 18's export).
//!
//! The cells of a grid (a T-mesh face cut by the knot lines around it for genus 0 and 1, a
//! strip of the genus ≥ 2 domain mesh) are merged into rectangles by a predicate computed from
//! the patches themselves, so it holds whatever mesh produced them: the rectangle's patch
//! (interpolated at its 4 × 4 nodes, each from the cell that holds it) **restricted back** to
//! every cell (blossoming, [`BezierPatch::restrict`]) reproduces that cell's 16 Bézier points
//! to [`SAME_POLYNOMIAL`] of the rectangle's size (the diagonal of its control points' box).
//! A genuine knot line breaks the third derivative and misses that by many orders of magnitude
//! ([`MergeStats`] records the worst merge accepted and the nearest refused).
//!
//! Greedy maximal rectangles: from the first unassigned cell (rows bottom to top, cells left
//! to right) extend along `u` while neighbouring cells are one polynomial, then along `v`
//! while the whole next row is; when the cells' polynomial pieces tile the grid by rectangles
//! (the faces of the extended T-mesh) this finds exactly those. Every rectangle is checked
//! cell by cell before it is kept (else its cells are kept apart).

use super::bezier::{interpolate_patch, BezierPatch};
use super::domain_mesh::DomainMesh;
use serde::Serialize;

/// Relative tolerance of "one polynomial": the largest difference between a cell's Bézier
/// points and the merged patch's restricted to the cell, over the diagonal of the merged
/// patch's control-point box.
pub const SAME_POLYNOMIAL: f64 = 1e-12;

/// What merging did: cells in, elements out, and how far the predicate was from its tolerance
/// on both sides.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MergeStats {
    /// [`SAME_POLYNOMIAL`].
    pub tolerance: f64,
    /// Cells (patches) before merging.
    pub cells: usize,
    /// Bézier elements after.
    pub elements: usize,
    /// The largest relative difference of a merged cell (≤ [`SAME_POLYNOMIAL`]).
    pub worst_merged: f64,
    /// The smallest relative difference of two neighbouring cells not merged (∞: none).
    pub nearest_refused: f64,
    /// Rectangles whose cell-by-cell check failed after the pairwise one passed (kept apart).
    pub split_back: usize,
}

impl Default for MergeStats {
    fn default() -> Self {
        MergeStats {
            tolerance: SAME_POLYNOMIAL,
            cells: 0,
            elements: 0,
            worst_merged: 0.0,
            nearest_refused: f64::INFINITY,
            split_back: 0,
        }
    }
}

/// A Bézier element of a grid of `nu × nv` cells: its patch and its cells `i0..i1 × j0..j1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Element {
    pub patch: BezierPatch,
    pub cells: [usize; 4],
}

/// The diagonal of the box of the patch's control points (1 for a point).
fn size(p: &BezierPatch) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for row in &p.control {
        for c in row {
            for d in 0..3 {
                lo[d] = lo[d].min(c[d]);
                hi[d] = hi[d].max(c[d]);
            }
        }
    }
    let s = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    if s > 0.0 {
        s
    } else {
        1.0
    }
}

/// The largest difference between the Bézier points of `cell` and those of `merged` restricted
/// to the cell's rectangle, relative to `merged`'s size.
pub fn mismatch(merged: &BezierPatch, cell: &BezierPatch) -> f64 {
    let r = merged.restrict(cell.u0, cell.u1, cell.v0, cell.v1);
    let mut worst = 0.0f64;
    for i in 0..4 {
        for j in 0..4 {
            for d in 0..3 {
                worst = worst.max((r.control[i][j][d] - cell.control[i][j][d]).abs());
            }
        }
    }
    if worst.is_finite() {
        worst / size(merged)
    } else {
        f64::INFINITY
    }
}

/// A grid of `nu × nv` cells, `cells[j * nu + i]`, column `i` over `[u_i, u_{i+1}]` and row
/// `j` over `[v_j, v_{j+1}]` (the patches' own rectangles).
struct Grid<'a> {
    nu: usize,
    cells: &'a [BezierPatch],
}

impl Grid<'_> {
    fn cell(&self, i: usize, j: usize) -> &BezierPatch {
        &self.cells[j * self.nu + i]
    }

    /// The patch over the cells `i0..i1 × j0..j1`, interpolating at its 4 × 4 nodes the cell
    /// that holds each node (no extrapolation).
    fn merged(&self, [i0, i1, j0, j1]: [usize; 4]) -> BezierPatch {
        let (u0, u1) = (self.cell(i0, j0).u0, self.cell(i1 - 1, j0).u1);
        let (v0, v1) = (self.cell(i0, j0).v0, self.cell(i0, j1 - 1).v1);
        interpolate_patch(u0, u1, v0, v1, |u, v| {
            let i = i0 + (i0..i1 - 1).filter(|&k| self.cell(k, j0).u1 <= u).count();
            let j = j0 + (j0..j1 - 1).filter(|&k| self.cell(i0, k).v1 <= v).count();
            self.cell(i, j).point(u, v)
        })
    }

    /// The largest [`mismatch`] of the cells `r` with their merged patch, and that patch.
    fn check(&self, r: [usize; 4]) -> (f64, BezierPatch) {
        let m = self.merged(r);
        let mut worst = 0.0f64;
        for j in r[2]..r[3] {
            for i in r[0]..r[1] {
                worst = worst.max(mismatch(&m, self.cell(i, j)));
            }
        }
        (worst, m)
    }

    /// Whether two neighbouring cells are one polynomial, recording the distances.
    fn joined(&self, r: [usize; 4], stats: &mut MergeStats) -> bool {
        let (d, _) = self.check(r);
        if d <= SAME_POLYNOMIAL {
            stats.worst_merged = stats.worst_merged.max(d);
            true
        } else {
            stats.nearest_refused = stats.nearest_refused.min(d);
            false
        }
    }
}

/// The Bézier elements of a grid of `nu × nv` cells (`cells[j * nu + i]`, rows of equal
/// heights and columns of equal widths), `stats` updated.
pub fn merge_grid(
    nu: usize,
    nv: usize,
    cells: &[BezierPatch],
    stats: &mut MergeStats,
) -> Vec<Element> {
    let g = Grid { nu, cells };
    stats.cells += nu * nv;
    // one polynomial with the right and the upper neighbour
    let mut right = vec![false; nu * nv];
    let mut up = vec![false; nu * nv];
    for j in 0..nv {
        for i in 0..nu {
            if i + 1 < nu {
                right[j * nu + i] = g.joined([i, i + 2, j, j + 1], stats);
            }
            if j + 1 < nv {
                up[j * nu + i] = g.joined([i, i + 1, j, j + 2], stats);
            }
        }
    }
    let mut taken = vec![false; nu * nv];
    let mut out = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            if taken[j * nu + i] {
                continue;
            }
            let mut i1 = i + 1;
            while i1 < nu && right[j * nu + i1 - 1] && !taken[j * nu + i1] {
                i1 += 1;
            }
            let mut j1 = j + 1;
            while j1 < nv
                && (i..i1).all(|k| up[(j1 - 1) * nu + k] && !taken[j1 * nu + k])
                && (i..i1 - 1).all(|k| right[j1 * nu + k])
            {
                j1 += 1;
            }
            for jj in j..j1 {
                for ii in i..i1 {
                    taken[jj * nu + ii] = true;
                }
            }
            let r = [i, i1, j, j1];
            if i1 - i == 1 && j1 - j == 1 {
                out.push(Element {
                    patch: *g.cell(i, j),
                    cells: r,
                });
                continue;
            }
            let (d, patch) = g.check(r);
            if d <= SAME_POLYNOMIAL {
                stats.worst_merged = stats.worst_merged.max(d);
                out.push(Element { patch, cells: r });
            } else {
                stats.split_back += 1;
                for jj in j..j1 {
                    for ii in i..i1 {
                        out.push(Element {
                            patch: *g.cell(ii, jj),
                            cells: [ii, ii + 1, jj, jj + 1],
                        });
                    }
                }
            }
        }
    }
    stats.elements += out.len();
    out
}

/// A Bézier element of the genus ≥ 2 domain mesh: its patch (in the exported parameters,
/// [`DomainMesh::export_offsets`]), its strip and the strip's cells `i0..i1 × j0..j1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DomainElement {
    pub patch: BezierPatch,
    pub strip: usize,
    pub cells: [usize; 4],
}

impl DomainElement {
    /// The cells' sides it covers along `u` (exported parameters, `offsets` from
    /// [`DomainMesh::export_offsets`]) and along `v`, its first and last parameters included.
    pub fn breaks(&self, mesh: &DomainMesh, offsets: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let r = &mesh.rects[self.strip];
        let [i0, i1, j0, j1] = self.cells;
        let us = (i0..=i1).map(|i| offsets[self.strip] + r.x(i)).collect();
        let vs = (j0..=j1).map(|j| r.y(j)).collect();
        (us, vs)
    }
}

/// Per strip, its cells by `(i, j)`: `ids[strip][j * m + i]`.
pub fn strip_cells(mesh: &DomainMesh) -> Vec<Vec<u32>> {
    let mut ids: Vec<Vec<u32>> = mesh
        .rects
        .iter()
        .map(|r| vec![u32::MAX; r.m * r.n])
        .collect();
    for (c, &(r, i, j)) in mesh.cell_at.iter().enumerate() {
        let m = mesh.rects[r as usize].m;
        ids[r as usize][j as usize * m + i as usize] = c as u32;
    }
    ids
}

/// The Bézier elements of the domain mesh's spline for the control points `control`: the
/// cells of every strip (a tensor grid) merged where they are one polynomial.
pub fn domain_elements(
    mesh: &DomainMesh,
    control: &[[f64; 3]],
) -> (Vec<DomainElement>, MergeStats) {
    let offsets = mesh.export_offsets();
    let ids = strip_cells(mesh);
    let mut stats = MergeStats::default();
    let mut out = Vec::with_capacity(mesh.n_cells());
    for (s, r) in mesh.rects.iter().enumerate() {
        let cells: Vec<BezierPatch> = ids[s]
            .iter()
            .map(|&c| mesh.patch(c, control, offsets[s], 0.0))
            .collect();
        for e in merge_grid(r.m, r.n, &cells, &mut stats) {
            out.push(DomainElement {
                patch: e.patch,
                strip: s,
                cells: e.cells,
            });
        }
    }
    (out, stats)
}

/// The spline's point at `(u, v)` (exported parameters) of strip `strip`, from the blending
/// functions of the cell there ([`DomainMesh::point`]), not from any patch; `ids` from
/// [`strip_cells`].
pub fn spline_point(
    mesh: &DomainMesh,
    ids: &[Vec<u32>],
    offsets: &[f64],
    strip: usize,
    (u, v): (f64, f64),
    control: &[[f64; 3]],
) -> [f64; 3] {
    let r = &mesh.rects[strip];
    let (i, s) = r.column(u - offsets[strip]);
    let (j, t) = r.row(v);
    mesh.point(ids[strip][j * r.m + i], s, t, control)
}
