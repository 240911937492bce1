//! Error-driven local refinement away from the zeros (issue 18; paper 003 §3.3: "insert
//! control points — local knot insertion, T-junctions — where the error exceeds the
//! tolerance"). A **block** is a box of cells of one strip of the graded mesh whose cells are
//! split 2×2: new lines at the midpoints of its columns, kept in the T-mesh from one row below
//! the box to one row above it, and at the midpoints of its rows, kept across its columns;
//! the new lines end in T-junctions (inside the strip, or on its sides). In the full mesh
//! ([`DomainMesh::refined`]) the same knots run through the whole chain of strips glued top to
//! bottom (columns) or the whole cylinder (rows): it stays a per-strip tensor grid, its Bézier
//! extraction unchanged, and the T-spline is written in it by knot insertion exactly as for the
//! graded lines ([`super::tjunctions`]; the T-mesh is [`DomainMesh::on_line_u`] /
//! [`DomainMesh::on_line_v`]).
//!
//! **The zeros.** Only columns and rows at least [`CLEAR`] intervals from the strip's ends are
//! split: the two intervals next to every zero keep their size (its rules and the G¹
//! conditions unchanged), and an anchor whose ray meets a zero — it keeps the full mesh's
//! blending function, whose knots reach two intervals past its second crossing — meets no
//! block's knot in the full mesh that the T-mesh lacks. A box at a strip's side splits only
//! across it (the rows at a vertical side, the columns at a horizontal one).
//!
//! **Analysis-suitable** (Li, Zheng, Sederberg, Hughes, Scott 2012 §3). Within a block the lines
//! along `v` run one row beyond the box and those along `u` stop at its sides, so their
//! extensions (two crossings ahead, one back) do not meet: the extension of a line along `v`
//! ends one row beyond the box, where no line along `u` of the block reaches (had both stopped
//! at the box's sides, the extensions of its first column and row lines would meet at its first
//! inner point). Boxes of one strip closer than [`GAP`] cells in both directions are merged into
//! their bounding box, repeatedly (the closure of [`place_blocks`]), so the extensions of two
//! blocks stay apart too. Near the strip sides and the graded lines the fit checks the whole
//! T-mesh ([`DomainMesh::extensions_meet`]) and refines the spacing instead if it is not.

use super::*;

/// A box of cells of strip `rect` of the graded mesh — columns `i0..i1`, rows `j0..j1`, in the
/// indices of [`DomainMesh::graded`] — split 2×2 where it is [`CLEAR`] of the strip's ends
/// (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Block {
    pub rect: usize,
    pub i0: usize,
    pub i1: usize,
    pub j0: usize,
    pub j1: usize,
}

/// Boxes of one strip closer than this many cells along `u` and along `v` are merged.
pub const GAP: isize = 3;

/// The intervals at each end of a strip side that no block splits (module doc).
pub const CLEAR: usize = 4;

/// The part of `lo..hi` at least [`CLEAR`] from both ends of `0..len` (maybe empty).
fn clear_of_ends(lo: usize, hi: usize, len: usize) -> std::ops::Range<usize> {
    let lo = lo.max(CLEAR);
    lo..hi.min(len.saturating_sub(CLEAR)).max(lo)
}

impl Block {
    fn contains(&self, i: usize, j: usize) -> bool {
        (self.i0..self.i1).contains(&i) && (self.j0..self.j1).contains(&j)
    }

    /// The columns it splits, of a strip of `m` columns.
    pub fn split_u(&self, m: usize) -> std::ops::Range<usize> {
        clear_of_ends(self.i0, self.i1, m)
    }

    /// The rows it splits, of a strip of `n` rows.
    pub fn split_v(&self, n: usize) -> std::ops::Range<usize> {
        clear_of_ends(self.j0, self.j1, n)
    }

    /// The cells of the box.
    pub fn cells(&self) -> usize {
        (self.i1 - self.i0) * (self.j1 - self.j0)
    }
}

/// The knots with the midpoints of the intervals `split` inserted, and per knot twice its index
/// in `knots` (plus one for a midpoint).
fn interleave(knots: &[f64], split: &[bool]) -> (Vec<f64>, Vec<usize>) {
    let (mut xs, mut half) = (Vec::new(), Vec::new());
    for (b, &x) in knots.iter().enumerate() {
        xs.push(x);
        half.push(2 * b);
        if split.get(b).copied().unwrap_or(false) {
            xs.push(0.5 * (x + knots[b + 1]));
            half.push(2 * b + 1);
        }
    }
    (xs, half)
}

/// Give every strip its knots — the graded mesh's, with the midpoints of every column split by
/// a block of its chain of strips glued top to bottom (`top`) and of every row split by a block
/// of its cylinder — and number the cells strip by strip; the number of cells, or why not.
pub(super) fn split_knots(
    rects: &mut [Rect],
    top: &[usize],
    blocks: &[Block],
) -> Result<usize, String> {
    let nr = rects.len();
    for r in rects.iter_mut() {
        r.base_m = r.m;
        r.base_n = r.n;
    }
    let mut split_u: Vec<Vec<bool>> = rects.iter().map(|r| vec![false; r.m]).collect();
    let mut split_v: Vec<Vec<bool>> = rects.iter().map(|r| vec![false; r.n]).collect();
    for b in blocks {
        let ok = b.rect < nr
            && b.i0 < b.i1
            && b.i1 <= rects[b.rect].m
            && b.j0 < b.j1
            && b.j1 <= rects[b.rect].n;
        if !ok {
            return Err(format!("block {b:?} is not a box of cells of a strip"));
        }
        let (su, sv) = (b.split_u(rects[b.rect].m), b.split_v(rects[b.rect].n));
        let mut r = b.rect;
        for _ in 0..nr {
            split_u[r][su.clone()].iter_mut().for_each(|x| *x = true);
            r = top[r];
            if r == b.rect {
                break;
            }
        }
        let c = rects[b.rect].cylinder;
        for (r, rc) in rects.iter().enumerate() {
            if rc.cylinder == c {
                split_v[r][sv.clone()].iter_mut().for_each(|x| *x = true);
            }
        }
    }
    let mut cells = 0;
    for (r, rc) in rects.iter_mut().enumerate() {
        let (bu, bv) = rc.base_knots();
        (rc.xs, rc.u_half) = interleave(&bu, &split_u[r]);
        (rc.ys, rc.v_half) = interleave(&bv, &split_v[r]);
        rc.m = rc.xs.len() - 1;
        rc.n = rc.ys.len() - 1;
        rc.first_cell = cells;
        cells += rc.m * rc.n;
    }
    Ok(cells)
}

impl DomainMesh {
    /// Strip and cell `(i, j)` of the graded mesh (before the blocks) that contains cell `c`.
    pub fn base_cell(&self, c: u32) -> (usize, usize, usize) {
        let (r, i, j) = self.cell_at[c as usize];
        let rc = &self.rects[r as usize];
        (
            r as usize,
            rc.u_half[i as usize] / 2,
            rc.v_half[j as usize] / 2,
        )
    }

    /// `None` if column knot `i` of strip `r` is the graded mesh's; else whether the T-mesh has
    /// that block line at row knot `j` (from one row below its block to one row above).
    pub(super) fn block_line_v(&self, r: usize, i: usize, j: usize) -> Option<bool> {
        let rc = &self.rects[r];
        let a = rc.u_half[i];
        if a.is_multiple_of(2) {
            return None;
        }
        let (col, y) = (a / 2, rc.v_half[j]);
        Some(self.blocks.iter().any(|b| {
            b.rect == r
                && b.split_u(rc.base_m).contains(&col)
                && y + 2 >= 2 * b.j0
                && y <= 2 * b.j1 + 2
        }))
    }

    /// `None` if row knot `j` of strip `r` is the graded mesh's; else whether the T-mesh has
    /// that block line at column knot `i` (across its block's columns).
    pub(super) fn block_line_u(&self, r: usize, i: usize, j: usize) -> Option<bool> {
        let rc = &self.rects[r];
        let a = rc.v_half[j];
        if a.is_multiple_of(2) {
            return None;
        }
        let (row, x) = (a / 2, rc.u_half[i]);
        Some(self.blocks.iter().any(|b| {
            b.rect == r && b.split_v(rc.base_n).contains(&row) && x >= 2 * b.i0 && x <= 2 * b.i1
        }))
    }
}

/// Whether two boxes `[i0, i1, j0, j1]` are closer than [`GAP`] cells along both directions.
fn close(a: [usize; 4], b: [usize; 4]) -> bool {
    let gap = |lo0: usize, hi0: usize, lo1: usize, hi1: usize| {
        (lo1 as isize - hi0 as isize).max(lo0 as isize - hi1 as isize)
    };
    gap(a[0], a[1], b[0], b[1]) < GAP && gap(a[2], a[3], b[2], b[3]) < GAP
}

/// The blocks that split the cells `marked` of `mesh` (and their neighbours) with those it
/// has, closed (module doc), in the indices of `mesh`'s graded mesh; or why a block cannot be
/// placed: a marked cell is in a block already, or no column or row of it can be split.
pub fn place_blocks(mesh: &DomainMesh, marked: &[u32]) -> Result<Vec<Block>, String> {
    let nr = mesh.rects.len();
    let mut boxes: Vec<Vec<[usize; 4]>> = vec![Vec::new(); nr];
    for b in &mesh.blocks {
        boxes[b.rect].push([b.i0, b.i1, b.j0, b.j1]);
    }
    let mut seen = std::collections::HashSet::new();
    for &c in marked {
        let (r, i, j) = mesh.base_cell(c);
        if !seen.insert((r, i, j)) {
            continue;
        }
        let rc = &mesh.rects[r];
        let (m, n) = (rc.base_m, rc.base_n);
        let at = || {
            format!(
                "cell ({i}, {j}) of strip {} of cylinder {} ({m} × {n} cells)",
                rc.strip, rc.cylinder
            )
        };
        if mesh.blocks.iter().any(|b| b.rect == r && b.contains(i, j)) {
            return Err(format!("{} is split already", at()));
        }
        let clear = |k: usize, len: usize| k >= CLEAR && k + CLEAR < len;
        if !clear(i, m) && !clear(j, n) {
            return Err(format!("{} is within {CLEAR} cells of two sides", at()));
        }
        // the cell and its neighbours
        boxes[r].push([
            i.saturating_sub(1),
            (i + 2).min(m),
            j.saturating_sub(1),
            (j + 2).min(n),
        ]);
    }
    let mut out = Vec::new();
    for (r, mut bs) in boxes.into_iter().enumerate() {
        // every merge removes a box: at most `bs.len()` rounds
        for _ in 0..bs.len() {
            let pair = (0..bs.len())
                .flat_map(|a| (a + 1..bs.len()).map(move |b| (a, b)))
                .find(|&(a, b)| close(bs[a], bs[b]));
            let Some((a, b)) = pair else {
                break;
            };
            let (x, y) = (bs[a], bs[b]);
            bs[a] = [
                x[0].min(y[0]),
                x[1].max(y[1]),
                x[2].min(y[2]),
                x[3].max(y[3]),
            ];
            bs.swap_remove(b);
        }
        out.extend(bs.into_iter().map(|x| Block {
            rect: r,
            i0: x[0],
            i1: x[1],
            j0: x[2],
            j1: x[3],
        }));
    }
    Ok(out)
}
