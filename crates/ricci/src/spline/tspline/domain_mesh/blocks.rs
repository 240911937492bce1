//! Error-driven local refinement away from the zeros (issue 18; paper 003 §3.3: "insert
//! control points — local knot insertion, T-junctions — where the error exceeds the
//! tolerance"). A **block** of level `ℓ ≥ 1` is a box of cells of the level-`ℓ − 1` mesh of one
//! strip (level 0: the graded mesh; level `ℓ`: its intervals halved `ℓ` times) whose cells are
//! split 2×2: new lines at the midpoints of its columns, kept in the T-mesh from one row below
//! the box to one row above it, and at the midpoints of its rows, kept across its columns;
//! the new lines end in T-junctions (inside the strip, or on its sides). A block of level
//! `ℓ ≥ 2` is **nested**: it lies in the split part of a block of level `ℓ − 1`, one cell of its
//! level in from every side (its lines along `v` end on that block's lines along `u`, and the
//! extensions of that block's T-junctions, one crossing back, miss its lines), and the
//! fit places it where an error remains in cells split already. In the full mesh
//! ([`DomainMesh::refined`]) the same knots run through the whole chain of strips glued top to
//! bottom (columns) or the whole cylinder (rows): it stays a per-strip tensor grid — every knot
//! is a dyadic point of a graded interval, at `Rect::u_fine` / `Rect::v_fine` in units of
//! `1 / FINE` of it — its Bézier extraction unchanged, and the T-spline is written in it by knot
//! insertion exactly as for the graded lines ([`super::tjunctions`]; the T-mesh is
//! [`DomainMesh::on_line_u`] / [`DomainMesh::on_line_v`]). Nesting keeps this design: a level
//! only adds knots, and a knot's level is read off its dyadic position.
//!
//! **The zeros.** Only columns and rows at least [`CLEAR`] graded intervals from the strip's
//! ends are split: the two intervals next to every zero keep their size (its rules and the G¹
//! conditions unchanged), and an anchor whose ray meets a zero — it keeps the full mesh's
//! blending function, whose knots reach two intervals past its second crossing — meets no
//! block's knot in the full mesh that the T-mesh lacks. A box at a strip's side splits only
//! across it (the rows at a vertical side, the columns at a horizontal one), and so does the
//! part of a box within [`CLEAR`] of an end; a box nested where its parent splits one direction
//! only ([`Block::split`]) takes the parent's whole extent along the other and halves only that
//! one again, its lines ending where the parent's do.
//!
//! **Analysis-suitable** (Li, Zheng, Sederberg, Hughes, Scott 2012 §3). Within a block the lines
//! along `v` run one row beyond the box and those along `u` stop at its sides, so their
//! extensions (two crossings ahead, one back) do not meet: the extension of a line along `v`
//! ends one row beyond the box, where no line along `u` of the block reaches (had both stopped
//! at the box's sides, the extensions of its first column and row lines would meet at its first
//! inner point). Inside a block the mesh of its level is uniform, so a nested block sees what a
//! first-level one sees. Boxes of one strip, one level and one parent closer than [`GAP`] cells
//! (of their level) in both directions are merged into their bounding box, repeatedly (the
//! closure of [`place_blocks`]), so the extensions of two blocks stay apart too. Near the strip
//! sides, the graded lines and a parent's sides the fit checks the whole T-mesh
//! ([`DomainMesh::extensions_meet`]) and refines the spacing instead if it is not.
//!
//! **Monotone refinement** (session 19). A marked cell in the first or last row or column of the
//! split part of its deepest block — where no block can nest — asks for a box of that block's
//! level around it in the block's parent, which the closure merges into the block: the block
//! **grows**, and the cell nests at the next step (before, no block was placed there and the
//! spacing shrank everywhere, every block dropped). When the spacing does shrink, the blocks are
//! **carried over** ([`carry_blocks`]): each becomes the box of its level on the new graded mesh
//! that covers its region, nested in its carried parent as [`place_blocks`] nests a box, so every
//! region stays split at least as finely. The nesting goes [`MAX_BLOCK_LEVEL`] = 8 deep (6
//! before: on fertility at 0.5 % a cell nested 6 times made the spacing shrink).

use super::*;

/// A box of cells of strip `rect` of the level-`level − 1` mesh — columns `i0..i1`, rows
/// `j0..j1`, in the indices of [`DomainMesh::graded`] with every interval halved `level − 1`
/// times — split 2×2 where it is [`CLEAR`] of the strip's ends (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Block {
    pub rect: usize,
    pub i0: usize,
    pub i1: usize,
    pub j0: usize,
    pub j1: usize,
    /// 1 for a box of graded cells; `ℓ` for a box inside a block of level `ℓ − 1`.
    pub level: usize,
    /// Whether it splits its columns (along `u`) and its rows (along `v`): both for a block of
    /// level 1 and one nested where its parent splits both; one for a block nested where its
    /// parent splits only that one (module doc).
    pub split: [bool; 2],
}

/// Boxes of one strip closer than this many cells along `u` and along `v` are merged.
pub const GAP: isize = 3;

/// The graded intervals at each end of a strip side that no block splits (module doc).
pub const CLEAR: usize = 4;

/// The most levels of blocks (each halves the intervals of the cells it splits); 8: a cell of
/// the graded mesh split into at most `256 × 256` (measured against 6: `docs/notes/wave2-s19-kb21.md`).
pub const MAX_BLOCK_LEVEL: usize = 8;

/// A graded interval in units of the finest blocks' knots: `Rect::u_fine` and `Rect::v_fine`
/// count in `1 / FINE` of it.
pub const FINE: usize = 1 << MAX_BLOCK_LEVEL;

/// The level of a knot at `a` (units of `1 / FINE` of a graded interval): 0 for the graded
/// mesh's, `ℓ` for the midpoint of an interval of the level-`ℓ − 1` mesh.
pub fn knot_level(a: usize) -> usize {
    if a.is_multiple_of(FINE) {
        0
    } else {
        MAX_BLOCK_LEVEL - a.trailing_zeros() as usize
    }
}

impl Block {
    /// The size of a cell of its box (a cell of the level-`level − 1` mesh) in units of
    /// `1 / FINE` of a graded interval.
    pub fn cell_fine(&self) -> usize {
        FINE >> (self.level - 1)
    }

    /// The columns it splits, of a strip of `m` graded columns (in its level's indices).
    pub fn split_u(&self, m: usize) -> std::ops::Range<usize> {
        let r = self.clear_of_ends(self.i0, self.i1, m);
        if self.split[0] {
            r
        } else {
            r.start..r.start
        }
    }

    /// The rows it splits, of a strip of `n` graded rows (in its level's indices).
    pub fn split_v(&self, n: usize) -> std::ops::Range<usize> {
        let r = self.clear_of_ends(self.j0, self.j1, n);
        if self.split[1] {
            r
        } else {
            r.start..r.start
        }
    }

    /// The part of `lo..hi` at least [`CLEAR`] graded intervals from both ends of a side of
    /// `len` graded intervals, in its level's indices (maybe empty).
    fn clear_of_ends(&self, lo: usize, hi: usize, len: usize) -> std::ops::Range<usize> {
        let k = self.level - 1;
        let lo = lo.max(CLEAR << k);
        lo..hi.min((len << k).saturating_sub(CLEAR << k)).max(lo)
    }

    /// Whether the cell `[u0, u1, v0, v1]` (units of `1 / FINE` of a graded interval) of a strip
    /// of `m × n` graded cells lies in its box, in columns it splits (`.0`) and in rows it
    /// splits (`.1`).
    fn splits(&self, cell: [usize; 4], m: usize, n: usize) -> (bool, bool) {
        let s = self.cell_fine();
        let inside = |lo: usize, hi: usize, r: std::ops::Range<usize>| {
            !r.is_empty() && r.start * s <= lo && hi <= r.end * s
        };
        let in_box = inside(cell[0], cell[1], self.i0..self.i1)
            && inside(cell[2], cell[3], self.j0..self.j1);
        (
            in_box && inside(cell[0], cell[1], self.split_u(m)),
            in_box && inside(cell[2], cell[3], self.split_v(n)),
        )
    }

    /// The cells of the box (of its level).
    pub fn cells(&self) -> usize {
        (self.i1 - self.i0) * (self.j1 - self.j0)
    }

    /// The same block in the indices of a graded mesh with `d` more levels at the zeros (one
    /// more graded column and row at each end per level).
    pub fn shifted(&self, d: usize) -> Block {
        let d = d << (self.level - 1);
        Block {
            i0: self.i0 + d,
            i1: self.i1 + d,
            j0: self.j0 + d,
            j1: self.j1 + d,
            ..*self
        }
    }
}

/// The knots at the dyadic positions `at` (units of `1 / FINE` of the intervals of `knots`,
/// increasing).
fn knots_at(knots: &[f64], at: &[usize]) -> Vec<f64> {
    at.iter()
        .map(|&a| {
            let (b, f) = (a / FINE, (a % FINE) as f64 / FINE as f64);
            if f == 0.0 {
                knots[b]
            } else {
                knots[b] + f * (knots[b + 1] - knots[b])
            }
        })
        .collect()
}

/// Give every strip its knots — the graded mesh's, with the midpoints of every column split by
/// a block of its chain of strips glued top to bottom (`top`) and of every row split by a block
/// of its cylinder — and number the cells strip by strip; the number of cells, or why not.
pub(super) fn split_knots(
    rects: &mut [Rect],
    top: &[usize],
    blocks: &[Block],
) -> Result<usize, String> {
    use std::collections::BTreeSet;
    let nr = rects.len();
    for r in rects.iter_mut() {
        r.base_m = r.m;
        r.base_n = r.n;
    }
    let mut at_u: Vec<BTreeSet<usize>> = rects
        .iter()
        .map(|r| (0..=r.m).map(|b| b * FINE).collect())
        .collect();
    let mut at_v: Vec<BTreeSet<usize>> = rects
        .iter()
        .map(|r| (0..=r.n).map(|b| b * FINE).collect())
        .collect();
    for b in blocks {
        let ok = b.rect < nr
            && (1..=MAX_BLOCK_LEVEL).contains(&b.level)
            && b.i0 < b.i1
            && b.i1 <= rects[b.rect].m << (b.level - 1)
            && b.j0 < b.j1
            && b.j1 <= rects[b.rect].n << (b.level - 1);
        if !ok {
            return Err(format!(
                "block {b:?} is not a box of cells of a strip (at most {MAX_BLOCK_LEVEL} levels)"
            ));
        }
        let s = b.cell_fine();
        let mids = |range: std::ops::Range<usize>| range.map(move |k| k * s + s / 2);
        let (su, sv) = (b.split_u(rects[b.rect].m), b.split_v(rects[b.rect].n));
        let mut r = b.rect;
        for _ in 0..nr {
            at_u[r].extend(mids(su.clone()));
            r = top[r];
            if r == b.rect {
                break;
            }
        }
        let c = rects[b.rect].cylinder;
        for (r, rc) in rects.iter().enumerate() {
            if rc.cylinder == c {
                at_v[r].extend(mids(sv.clone()));
            }
        }
    }
    let mut cells = 0;
    for (r, rc) in rects.iter_mut().enumerate() {
        let (bu, bv) = rc.base_knots();
        rc.u_fine = at_u[r].iter().copied().collect();
        rc.v_fine = at_v[r].iter().copied().collect();
        rc.xs = knots_at(&bu, &rc.u_fine);
        rc.ys = knots_at(&bv, &rc.v_fine);
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
            rc.u_fine[i as usize] / FINE,
            rc.v_fine[j as usize] / FINE,
        )
    }

    /// `None` if column knot `i` of strip `r` is the graded mesh's; else whether the T-mesh has
    /// that block line at row knot `j` (from one row below its block to one row above).
    pub(super) fn block_line_v(&self, r: usize, i: usize, j: usize) -> Option<bool> {
        let rc = &self.rects[r];
        let a = rc.u_fine[i];
        let level = knot_level(a);
        if level == 0 {
            return None;
        }
        let y = rc.v_fine[j];
        Some(self.blocks.iter().any(|b| {
            let s = b.cell_fine();
            // one row of its level beyond the box; one graded row for a box that splits no
            // row (at a strip's side: its nested boxes take the parent's rows)
            let beyond = if !b.split[1] || b.split_v(rc.base_n).is_empty() {
                FINE
            } else {
                s
            };
            b.rect == r
                && b.level == level
                && b.split_u(rc.base_m).contains(&(a / s))
                && y + beyond >= s * b.j0
                && y <= s * b.j1 + beyond
        }))
    }

    /// `None` if row knot `j` of strip `r` is the graded mesh's; else whether the T-mesh has
    /// that block line at column knot `i` (across its block's columns).
    pub(super) fn block_line_u(&self, r: usize, i: usize, j: usize) -> Option<bool> {
        let rc = &self.rects[r];
        let a = rc.v_fine[j];
        let level = knot_level(a);
        if level == 0 {
            return None;
        }
        let x = rc.u_fine[i];
        Some(self.blocks.iter().any(|b| {
            let s = b.cell_fine();
            b.rect == r
                && b.level == level
                && b.split_v(rc.base_n).contains(&(a / s))
                && x >= s * b.i0
                && x <= s * b.i1
        }))
    }

    /// The deepest block that splits cell `c` — it lies in its box, in columns or rows it
    /// splits — its index in [`DomainMesh::blocks`], and whether it lies in split columns and in
    /// split rows; if any.
    pub fn block_of_cell(&self, c: u32) -> Option<(usize, (bool, bool))> {
        self.block_of_cell_below(c, usize::MAX)
    }

    /// [`Self::block_of_cell`] among the blocks of level below `below`.
    pub fn block_of_cell_below(&self, c: u32, below: usize) -> Option<(usize, (bool, bool))> {
        let (r, i, j) = self.cell_at[c as usize];
        let rc = &self.rects[r as usize];
        let (i, j) = (i as usize, j as usize);
        let cell = [
            rc.u_fine[i],
            rc.u_fine[i + 1],
            rc.v_fine[j],
            rc.v_fine[j + 1],
        ];
        self.blocks
            .iter()
            .enumerate()
            .filter(|(_, b)| b.rect == r as usize && b.level < below)
            .map(|(k, b)| (k, b.splits(cell, rc.base_m, rc.base_n)))
            .filter(|(_, (u, v))| *u || *v)
            .max_by_key(|(k, _)| self.blocks[*k].level)
    }
}

/// Whether two boxes `[i0, i1, j0, j1]` are closer than [`GAP`] cells along both directions.
fn close(a: [usize; 4], b: [usize; 4]) -> bool {
    let gap = |lo0: usize, hi0: usize, lo1: usize, hi1: usize| {
        (lo1 as isize - hi0 as isize).max(lo0 as isize - hi1 as isize)
    };
    gap(a[0], a[1], b[0], b[1]) < GAP && gap(a[2], a[3], b[2], b[3]) < GAP
}

/// Boxes of one strip, one level, one parent block (index in the mesh's blocks, or none) and
/// the directions they split.
type Group = (usize, usize, Option<usize>, [bool; 2]);

/// The box a marked cell asks for: the box of [`box_in`] in the deepest block that splits it, or
/// — when the cell is in the first or last row or column of that block's split part, where no
/// block can nest — a box of that block's level around it in the block's parent, which the
/// closure of [`place_blocks`] merges into the block: the block **grows** (and the cell, inside
/// it then, can nest at the next step); up the chain of parents while the cell is at an edge of
/// each. `None`: no box (the cell is at an edge of the strip's split part); or why the cell can
/// take no block.
fn box_around(mesh: &DomainMesh, c: u32) -> Result<Option<(Group, [usize; 4])>, String> {
    let mut below = usize::MAX;
    loop {
        let found = mesh.block_of_cell_below(c, below);
        if let Some(x) = box_in(mesh, c, found)? {
            return Ok(Some(x));
        }
        match found {
            Some((p, _)) => below = mesh.blocks[p].level,
            None => return Ok(None),
        }
    }
}

/// The box a marked cell asks for inside the block `found` (its index and whether the cell lies
/// in its split columns and rows; `None`: the strip): the cell of the level-`ℓ − 1` mesh that
/// contains it and its neighbours, inside the strip (level 1) or inside the split part of the
/// parent block, one cell in from its sides (module doc), and its group; `None` when the cell
/// is in the first or last row or column of its block (a nested box there would end its lines
/// where the T-mesh has none, or meet the extensions of the parent's T-junctions), or why no
/// box can be placed.
fn box_in(
    mesh: &DomainMesh,
    c: u32,
    found: Option<(usize, (bool, bool))>,
) -> Result<Option<(Group, [usize; 4])>, String> {
    let (r, bi, bj) = mesh.base_cell(c);
    let rc = &mesh.rects[r];
    let (m, n) = (rc.base_m, rc.base_n);
    let parent = found.map(|f| f.0);
    let level = parent.map_or(0, |p| mesh.blocks[p].level) + 1;
    let at = || {
        format!(
            "cell ({bi}, {bj}) of strip {} of cylinder {} ({m} × {n} graded cells)",
            rc.strip, rc.cylinder
        )
    };
    if level > MAX_BLOCK_LEVEL {
        return Err(format!("{} is split {MAX_BLOCK_LEVEL} times already", at()));
    }
    let (_, i, j) = mesh.cell_at[c as usize];
    let s = FINE >> (level - 1);
    let (ci, cj) = (rc.u_fine[i as usize] / s, rc.v_fine[j as usize] / s);
    // per direction: the range the box may take, and whether it takes all of it
    let mut split = [true, true];
    let (u, v) = match parent {
        None => {
            let clear = |k: usize, len: usize| k >= CLEAR && k + CLEAR < len;
            if !clear(bi, m) && !clear(bj, n) {
                return Err(format!("{} is within {CLEAR} cells of two sides", at()));
            }
            ((0, m, false), (0, n, false))
        }
        Some(p) => {
            let b = &mesh.blocks[p];
            let (in_u, in_v) = found.map_or((false, false), |f| f.1);
            // one cell of its level in from every side of the parent's split part: its
            // lines along `v` end on the parent's lines along `u`, and the extensions of the
            // parent's T-junctions, one crossing back into the parent, meet none of its lines.
            // In a part the parent splits along one direction only (columns within `CLEAR` of
            // the strip's ends, or a box at a strip's side) the nested box splits only that
            // direction too, across the parent's whole box: its lines end where the parent's do
            let within = |split: std::ops::Range<usize>, lo: usize, hi: usize, inside: bool| {
                if inside {
                    (2 * split.start + 1, 2 * split.end - 1, false)
                } else {
                    (2 * lo, 2 * hi, true)
                }
            };
            split = [in_u, in_v];
            (
                within(b.split_u(m), b.i0, b.i1, in_u),
                within(b.split_v(n), b.j0, b.j1, in_v),
            )
        }
    };
    let span = |c: usize, (lo, hi, whole): (usize, usize, bool)| {
        if whole {
            (lo, hi)
        } else {
            (c.saturating_sub(1).max(lo), (c + 2).min(hi))
        }
    };
    let ((lo_i, hi_i), (lo_j, hi_j)) = ((u.0, u.1), (v.0, v.1));
    let (bu, bv) = (span(ci, u), span(cj, v));
    let bx = [bu.0, bu.1, bv.0, bv.1];
    let outside = ci < lo_i || ci >= hi_i || cj < lo_j || cj >= hi_j;
    if bx[0] >= bx[1] || bx[2] >= bx[3] || outside {
        return Ok(None);
    }
    Ok(Some(((r, level, parent, split), bx)))
}

/// The parent of `b` among `blocks`: the block one level up whose box (halved) holds its box.
fn parent_of(blocks: &[Block], b: &Block) -> Option<usize> {
    (b.level > 1)
        .then(|| {
            blocks.iter().position(|p| {
                p.rect == b.rect
                    && p.level + 1 == b.level
                    && 2 * p.i0 <= b.i0
                    && b.i1 <= 2 * p.i1
                    && 2 * p.j0 <= b.j0
                    && b.j1 <= 2 * p.j1
            })
        })
        .flatten()
}

/// The boxes of `blocks` by group ([`parent_of`]).
fn groups_of(blocks: &[Block]) -> std::collections::BTreeMap<Group, Vec<[usize; 4]>> {
    let mut groups: std::collections::BTreeMap<Group, Vec<[usize; 4]>> = Default::default();
    for b in blocks {
        groups
            .entry((b.rect, b.level, parent_of(blocks, b), b.split))
            .or_default()
            .push([b.i0, b.i1, b.j0, b.j1]);
    }
    groups
}

/// The blocks of `groups`, the boxes of a group closer than [`GAP`] merged into their bounding
/// box, repeatedly (module doc).
fn closure(groups: std::collections::BTreeMap<Group, Vec<[usize; 4]>>) -> Vec<Block> {
    let mut out = Vec::new();
    for ((r, level, _, split), mut bs) in groups {
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
            level,
            split,
        }));
    }
    out
}

/// The blocks that split the cells `marked` of `mesh` (and their neighbours) with those it
/// has, closed (module doc), in the indices of `mesh`'s graded mesh: a marked cell split
/// already asks for a block nested in the deepest block that split it, or grows that block when
/// it is at its edge ([`box_around`]); or why a block cannot be placed: a marked cell is within
/// [`CLEAR`] cells of two sides of its strip or split [`MAX_BLOCK_LEVEL`] times, or no cell
/// would be split that is not already.
pub fn place_blocks(mesh: &DomainMesh, marked: &[u32]) -> Result<Vec<Block>, String> {
    let mut groups = groups_of(&mesh.blocks);
    let mut seen = std::collections::HashSet::new();
    for &c in marked {
        if !seen.insert(c) {
            continue;
        }
        if let Some((g, bx)) = box_around(mesh, c)? {
            groups.entry(g).or_default().push(bx);
        }
    }
    let out = closure(groups);
    let mut old = mesh.blocks.clone();
    let mut new = out.clone();
    old.sort();
    new.sort();
    if old == new {
        return Err(format!(
            "the {} cells beyond the tolerance are in their blocks already",
            seen.len()
        ));
    }
    Ok(out)
}

/// The range `[lo, hi]` (coordinates along a strip side) in the intervals of the mesh whose
/// knots are `knots` halved `level − 1` times: the least range of them that covers it.
fn covering(knots: &[f64], level: usize, (lo, hi): (f64, f64)) -> (usize, usize) {
    let s = FINE >> (level - 1);
    let count = (knots.len() - 1) << (level - 1);
    let at = knots_at(knots, &(0..=count).map(|a| a * s).collect::<Vec<_>>());
    let eps = 1e-9 * (knots[knots.len() - 1] - knots[0]).abs();
    // the last knot at or before `lo`, the first at or after `hi`
    let i0 = at.partition_point(|&x| x <= lo + eps).saturating_sub(1);
    let i1 = at.partition_point(|&x| x < hi - eps).min(count);
    (i0, i1.max(i0 + 1).min(count))
}

/// The blocks of `old` carried to `new`, the graded mesh (no blocks) of a finer spacing and as
/// many levels at the zeros or more, over the same strips: what the blocks had split stays split
/// **at least as finely**. Block by block, parents first, the box of the same level of `new`
/// that covers the region of its box, inside the split part of
/// its carried parent one cell in from its sides (as [`box_in`] places a nested box), closed
/// (module doc). A level-`ℓ` cell on the spacing `h` is `h / 2^ℓ` wide; carried on `h / √2` it
/// is `√2` finer (the spacing's step doubles the blocks' control points, as everywhere else).
pub fn carry_blocks(old: &DomainMesh, new: &DomainMesh) -> Vec<Block> {
    if old.rects.len() != new.rects.len() || old.blocks.is_empty() {
        return Vec::new();
    }
    let mut order: Vec<usize> = (0..old.blocks.len()).collect();
    order.sort_by_key(|&k| old.blocks[k].level);
    let mut carried: Vec<Option<Block>> = vec![None; old.blocks.len()];
    for k in order {
        let b = &old.blocks[k];
        let level = b.level;
        let (orc, nrc) = (&old.rects[b.rect], &new.rects[b.rect]);
        let s = b.cell_fine();
        let ((bu, bv), (nu, nv)) = (orc.base_knots(), nrc.base_knots());
        let u = knots_at(&bu, &[b.i0 * s, b.i1 * s]);
        let v = knots_at(&bv, &[b.j0 * s, b.j1 * s]);
        let (mut i0, mut i1) = covering(&nu, level, (u[0], u[1]));
        let (mut j0, mut j1) = covering(&nv, level, (v[0], v[1]));
        if level > 1 {
            // inside its carried parent's split part, one cell in, along a direction it splits;
            // the parent's whole box along one it does not (as `box_in` nests a box)
            let Some(p) = parent_of(&old.blocks, b).and_then(|p| carried[p]) else {
                continue;
            };
            let inner = |(a, z): (usize, usize), r: std::ops::Range<usize>, lo, hi, split| {
                if split {
                    (a.max(2 * r.start + 1), z.min((2 * r.end).saturating_sub(1)))
                } else {
                    (2 * lo, 2 * hi)
                }
            };
            (i0, i1) = inner((i0, i1), p.split_u(nrc.base_m), p.i0, p.i1, b.split[0]);
            (j0, j1) = inner((j0, j1), p.split_v(nrc.base_n), p.j0, p.j1, b.split[1]);
        }
        if i0 < i1 && j0 < j1 {
            carried[k] = Some(Block {
                i0,
                i1,
                j0,
                j1,
                level,
                ..*b
            });
        }
    }
    let mut out: Vec<Block> = carried.into_iter().flatten().collect();
    // merging parents can bring their children within the gap: close again until it holds
    for _ in 0..=MAX_BLOCK_LEVEL {
        let next = closure(groups_of(&out));
        if next.len() == out.len() {
            return next;
        }
        out = next;
    }
    out
}
