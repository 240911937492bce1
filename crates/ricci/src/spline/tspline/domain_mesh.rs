//! Genus ≥ 2, the spline space of the domain manifold itself (issue 18, paper 003 §2–3): one
//! mesh of knot intervals over all the cylinders' strips, glued by the translations of
//! [`super::glue`], instead of one spline per cylinder.
//!
//! The strips of [`super::glue::Gluing`] are rectangles `[0, length] × [0, H]` in knot space
//! whose sides are glued **whole**: the right side of strip `s` to the left side of strip
//! `s + 1` of the same cylinder, the top to the bottom of one strip of the next band (equal
//! knot lengths along every chain of strips glued top to bottom). Every rectangle corner is a
//! zero of the form or a point the gluing added on a critical trajectory (genus ≥ 3, where a
//! cylinder's circles carry different zero copies; a regular vertex: four cells meet there).
//! Cutting every strip into `m × n`
//! cells, with `m` the same along every chain of strips glued top to bottom and `n` the same
//! in every cylinder (at least 5 each), gives a conforming quad mesh of the closed surface (no T-junctions) whose
//! only vertices of valence ≠ 4 are the zeros (valence `4 (k + 1)` at a zero of order `k`).
//! A ray from a vertex continues across a gluing by the translation: walking from cell to
//! cell over a side is always defined; only walking *through* a zero is not. The two first and
//! two last columns of every strip have one width `edge_u` and the two first and two last rows
//! one height `edge_v` (the smallest uniform cell size of any strip; the middle cells share
//! the rest): every cell within two knot intervals of a zero has the same size.
//!
//! **Local refinement at the zeros** ([`DomainMesh::graded`]): with `levels = L` the first
//! edge interval `E` at each end of every strip side is cut into `e, e, 2e, …, 2^{L−1} e`
//! (`e = E / 2^L`): the cells at a zero shrink by `2^L` in both directions while the rest of
//! the mesh keeps its size; each level adds two columns per strip and two rows per cylinder
//! (mesh lines through the whole strip; [`TJunctions`] then ends each of them in a T-junction
//! just past the zero's corner block, the T-mesh the fit uses by default). The two
//! intervals next to every zero stay equal (`e, e`), so everything said below holds as for
//! `L = 0`.
//!
//! **The spline.** One control point per vertex. Every cell is a bicubic Bézier patch whose 16
//! points are affine combinations of control points, each computed **once** per mesh entity
//! from the knot intervals (cell widths and heights) by blossoming the cubic B-spline:
//! * the 4 inner points of a cell: from its 4 corners, with the intervals of the cell and of
//!   its 4 side neighbours;
//! * the 2 points on a side: from the 6 corners of the two cells sharing it; an interval
//!   needed beyond an end of the side that is a zero is replaced by the side's own;
//! * the point at a vertex of valence 4: the B-spline's value there (3 × 3 neighbours, the
//!   same replacement for an interval beyond a neighbouring zero); at a zero of valence `n`:
//!   the mean of the `n` side points next to it (the first inner Bézier point of every side
//!   at the zero).
//!
//! Hence: partition of unity (every combination is affine), chart independence (every point
//! shared by two patches is one value), C⁰ everywhere; on every cell side **not incident to a
//! zero** the two patches are pieces of one tensor-product B-spline row by row: the replaced
//! intervals equal the true ones (all cells near a zero have the edge size), so the only
//! point no B-spline rule gives is the zero's own corner point, which the C² conditions across
//! such a side do not involve — the surface is **C²** there (measured: relative jumps of
//! orders 1 and 2 ≤ 1e-14, test `tspline_domain_mesh.rs`). (With uniform cells per strip the
//! sides one interval from a zero jumped in the first derivative by ~0.1 of its size:
//! session 12.)
//!
//! **G¹ at the zeros** (paper 003 §3: the extraordinary points). Across a side at a zero the
//! cross-boundary derivative of the two patches differs only in the Bézier column at the zero
//! (the other three columns are B-spline rows over cells of one size), so the surface is C¹ in
//! the translation chart across every side at a zero — and hence **G¹** there (one tangent plane
//! on both sides wherever the normal is defined) — iff the side's two neighbour points across
//! it and the zero's point are collinear in the ratio of the cell sizes. These are linear
//! conditions on the control points of the zero's 1-ring (the first Bézier points `dₖ` along the
//! rays from the zero satisfy `dₖ₊₁ − p = −(dₖ₋₁ − p)`: the first derivatives at the zero span
//! one plane, the tangent plane of every patch there). [`Reduction`] solves them once per mesh:
//! some ring vertices become fixed combinations of the others ([`DomainMesh::reduction`]); a net
//! expanded from free values ([`DomainMesh::expand`]) is G¹ at every zero, measured as the
//! angle between the two patches' normals along every side at a zero
//! ([`super::domain_continuity`]). A net that is not is only C⁰ there.

use super::bezier::BezierPatch;
use super::genus_domain::GenusDomain;
use super::glue::Gluing;

/// A sparse affine combination of control points: `(vertex, weight)`.
pub type Combination = Vec<(u32, f64)>;

/// The quad mesh of knot intervals over the domain manifold and its Bézier extraction.
pub mod blocks;
mod g1;
mod suitability;
mod tjunctions;
pub use blocks::Block;
pub use g1::Reduction;
pub use tjunctions::{knot_insertion, TJunctions};

#[derive(Debug, Clone)]
pub struct DomainMesh {
    /// Per strip (rectangle): cylinder, strip index, length, height, cells `m × n`, and the
    /// index of its first cell.
    pub rects: Vec<Rect>,
    /// Per cell: `[right, top, left, bottom]` neighbour cells.
    pub neighbours: Vec<[u32; 4]>,
    /// Per cell: corners `[lower left, lower right, upper right, upper left]` (vertex ids).
    pub corners: Vec<[u32; 4]>,
    /// Per cell: its rectangle and `(i, j)` in it.
    pub cell_at: Vec<(u32, u32, u32)>,
    /// Per vertex: the number of cell corners there (4 = regular; a zero otherwise).
    pub valence: Vec<u32>,
    /// Per cell: its 16 Bézier points as combinations, `bezier[cell][i][j]`, `i` along `u`.
    pub bezier: Vec<[[Combination; 4]; 4]>,
    /// The control nets that are G¹ at the zeros: every vertex as a combination of free values
    /// (with T-junctions: of the T-spline's, [`Self::with_t_junctions`]).
    pub reduction: Reduction,
    /// The T-mesh when the graded lines end in T-junctions ([`Self::with_t_junctions`]).
    pub tjunctions: Option<TJunctions>,
    /// The boxes of cells split 2×2 by lines ending in T-junctions ([`blocks`]).
    pub blocks: Vec<Block>,
}

/// One strip of one cylinder, cut into `m × n` cells: the two first and the two last columns
/// are `edge_u` wide, the two first and two last rows `edge_v` high (the same in every strip:
/// every cell within two knot intervals of a zero has the same size, so the blossoms there
/// need no replaced interval), the others share the rest equally.
#[derive(Debug, Clone)]
pub struct Rect {
    pub cylinder: usize,
    pub strip: usize,
    pub length: f64,
    pub height: f64,
    pub m: usize,
    pub n: usize,
    pub edge_u: f64,
    pub edge_v: f64,
    /// Levels of refinement at the zeros (the same in every strip; see the module doc).
    pub levels: usize,
    pub first_cell: usize,
    /// Columns and rows of the graded mesh before the blocks ([`Block`]) split some of them.
    pub base_m: usize,
    pub base_n: usize,
    /// The knots along `u` (`m + 1`) and along `v` (`n + 1`): the graded mesh's and the
    /// blocks' midpoints ([`blocks`]).
    pub xs: Vec<f64>,
    pub ys: Vec<f64>,
    /// Per knot of `xs` / `ys`: its position in units of `1 / FINE` of a graded interval
    /// (`FINE b` for knot `b` of the graded mesh; a block's line of level `ℓ` at an odd
    /// multiple of `FINE / 2^ℓ`: [`blocks::FINE`], [`blocks::knot_level`]).
    pub u_fine: Vec<usize>,
    pub v_fine: Vec<usize>,
}

/// The least number of cells along a strip side: two edge cells at each end and one between.
pub const MIN_CELLS: usize = 5;

/// The knots of one strip side: `k` intervals over `[0, len]`; at each end the intervals
/// `e, e, 2e, …, 2^{levels−1} e, E` with `E = 2^levels e` (for `levels = 0`: `e, e`), the
/// middle ones equal.
#[derive(Debug, Clone, Copy)]
struct Knots {
    len: f64,
    k: usize,
    e: f64,
    levels: usize,
}

impl Knots {
    /// The distance of knot `i ≤ levels + 2` from its end.
    fn end_offset(&self, i: usize) -> f64 {
        match i {
            0 => 0.0,
            i if i <= self.levels + 1 => self.e * (1u64 << (i - 1)) as f64,
            _ => self.e * (1u64 << (self.levels + 1)) as f64,
        }
    }

    /// Knot `i` (0..=k).
    fn knot(&self, i: usize) -> f64 {
        let g = self.levels + 2;
        if i <= g {
            self.end_offset(i)
        } else if i + g >= self.k {
            self.len - self.end_offset(self.k - i)
        } else {
            let end = self.end_offset(g);
            end + (i - g) as f64 * (self.len - 2.0 * end) / (self.k - 2 * g) as f64
        }
    }
}

/// The interval of `x` among the increasing `knots` (clamped to their range) and the local
/// coordinate in it.
fn interval(knots: &[f64], x: f64) -> (usize, f64) {
    let k = knots.len() - 1;
    let x = x.clamp(knots[0], knots[k]);
    let (mut lo, mut hi) = (0, k);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if knots[mid] <= x {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (a, b) = (knots[lo], knots[lo + 1]);
    (lo, ((x - a) / (b - a)).clamp(0.0, 1.0))
}

impl Rect {
    /// The start of column `i` (`i = m`: the strip's length).
    pub fn x(&self, i: usize) -> f64 {
        self.xs[i]
    }

    fn knots_u(&self) -> Knots {
        Knots {
            len: self.length,
            k: self.base_m,
            e: self.edge_u,
            levels: self.levels,
        }
    }

    fn knots_v(&self) -> Knots {
        Knots {
            len: self.height,
            k: self.base_n,
            e: self.edge_v,
            levels: self.levels,
        }
    }

    /// Whether cell `(i, j)` of the graded mesh (before the blocks) is in a corner block (the
    /// refined cells around a zero: the first or last `levels + 2` columns and rows).
    pub fn near_corner(&self, i: usize, j: usize) -> bool {
        let g = self.levels + 2;
        (i < g || i + g >= self.base_m) && (j < g || j + g >= self.base_n)
    }

    /// The start of row `j` (`j = n`: the height).
    pub fn y(&self, j: usize) -> f64 {
        self.ys[j]
    }

    /// The column of `x` along the strip and the local coordinate in it.
    pub fn column(&self, x: f64) -> (usize, f64) {
        interval(&self.xs, x)
    }

    /// The row of `y` and the local coordinate in it.
    pub fn row(&self, y: f64) -> (usize, f64) {
        interval(&self.ys, y)
    }

    /// The knots of the graded mesh (before the blocks) along `u` and along `v`.
    fn base_knots(&self) -> (Vec<f64>, Vec<f64>) {
        let (ku, kv) = (self.knots_u(), self.knots_v());
        (
            (0..=self.base_m).map(|i| ku.knot(i)).collect(),
            (0..=self.base_n).map(|j| kv.knot(j)).collect(),
        )
    }
}

/// `(i, j)` of a Bézier point of a cell, `i` along `u`.
type BezierIndex = (usize, usize);

/// Per cell corner `[lower left, lower right, upper right, upper left]`: its Bézier index and
/// those of the points next to it along `u` and along `v`.
const CORNER_POINTS: [(BezierIndex, BezierIndex, BezierIndex); 4] = [
    ((0, 0), (1, 0), (0, 1)),
    ((3, 0), (2, 0), (3, 1)),
    ((3, 3), (2, 3), (3, 2)),
    ((0, 3), (1, 3), (0, 2)),
];

const RIGHT: usize = 0;
const TOP: usize = 1;
const LEFT: usize = 2;
const BOTTOM: usize = 3;

/// A direction of the mesh lines: `U` along the strips (cell widths), `V` across them (cell
/// heights).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Axis {
    U,
    V,
}

impl Axis {
    fn other(self) -> Axis {
        match self {
            Axis::U => Axis::V,
            Axis::V => Axis::U,
        }
    }

    /// The sides of a cell before and after it along this direction.
    fn sides(self) -> (usize, usize) {
        match self {
            Axis::U => (LEFT, RIGHT),
            Axis::V => (BOTTOM, TOP),
        }
    }
}

/// Weights on `(P₋₁, P₀, P₁)` of the point at vertex 0 of a cubic B-spline whose anchors sit
/// at the vertices, with intervals `d` = `(d₋₂, d₋₁, d₀, d₁)` around it (blossom `f(0,0,0)`).
pub fn corner_weights(d: [f64; 4]) -> [f64; 3] {
    let [dm2, dm1, d0, d1] = d;
    // vertex positions x₋₂ … x₂ with x₀ = 0; P_j = f(x_{j−1}, x_j, x_{j+1})
    let (xm2, xm1, x1, x2) = (-dm1 - dm2, -dm1, d0, d0 + d1);
    // f(x₋₁, 0, 0) on P₋₁ … P₀: parameter 0 between x₋₂ and x₁
    let a = (0.0 - xm2) / (x1 - xm2);
    // f(0, 0, x₁) on P₀ … P₁: parameter 0 between x₋₁ and x₂
    let b = (0.0 - xm1) / (x2 - xm1);
    // f(0, 0, 0) on f(x₋₁, 0, 0) … f(0, 0, x₁): parameter 0 between x₋₁ and x₁
    let c = (0.0 - xm1) / (x1 - xm1);
    [(1.0 - c) * (1.0 - a), (1.0 - c) * a + c * (1.0 - b), c * b]
}

/// Weights on `(P₀, P₁)` of the two inner Bézier points of span `[x₀, x₁]` (intervals
/// `(d₋₁, d₀, d₁)`): `f(0, 0, x₁)` and `f(0, x₁, x₁)`.
pub fn inner_weights(d: [f64; 3]) -> [[f64; 2]; 2] {
    let [dm1, d0, d1] = d;
    let s = dm1 + d0 + d1;
    let (t1, t2) = (dm1 / s, (dm1 + d0) / s);
    [[1.0 - t1, t1], [1.0 - t2, t2]]
}

/// The four cubic Bernstein polynomials at `x ∈ [0, 1]`.
pub fn bernstein(x: f64) -> [f64; 4] {
    let y = 1.0 - x;
    [y * y * y, 3.0 * x * y * y, 3.0 * x * x * y, x * x * x]
}

fn add(out: &mut Combination, v: u32, w: f64) {
    if w == 0.0 {
        return;
    }
    match out.iter_mut().find(|x| x.0 == v) {
        Some(x) => x.1 += w,
        None => out.push((v, w)),
    }
}

fn find(p: &mut [u32], mut x: u32) -> u32 {
    while p[x as usize] != x {
        p[x as usize] = p[p[x as usize] as usize];
        x = p[x as usize];
    }
    x
}

/// Give every strip the same edge cells — the two first and two last columns of width `edge_u`,
/// the two first and two last rows of height `edge_v`, the smallest uniform cell size of any
/// strip (so the middle cells of every strip are at least as large), each end's first one
/// refined `levels` times (`m`, `n` count the refined cells: `2 levels` more).
fn size_edge_cells(rects: &mut [Rect], levels: usize) -> Result<(), String> {
    let fine = (1u64 << levels) as f64;
    let edge_u = rects
        .iter()
        .map(|r| r.length / (r.m - 2 * levels) as f64 / fine)
        .fold(f64::INFINITY, f64::min);
    let edge_v = rects
        .iter()
        .map(|r| r.height / (r.n - 2 * levels) as f64 / fine)
        .fold(f64::INFINITY, f64::min);
    if !(edge_u > 0.0 && edge_v > 0.0) {
        return Err(format!(
            "a strip has no positive length or height (edge cells {edge_u} × {edge_v})"
        ));
    }
    for r in rects.iter_mut() {
        r.edge_u = edge_u;
        r.edge_v = edge_v;
        r.levels = levels;
    }
    Ok(())
}

/// The number of columns `m` of every strip: the same along every chain of strips glued top to
/// bottom (a cycle of the permutation `top`), from the chain's longest strip.
fn columns_per_chain(
    rects: &mut [Rect],
    top: &[usize],
    spacing: f64,
    levels: usize,
) -> Result<(), String> {
    let nr = rects.len();
    let mut done = vec![false; nr];
    for r0 in 0..nr {
        if done[r0] {
            continue;
        }
        let mut chain = vec![r0];
        let mut r = top[r0];
        while r != r0 {
            if chain.len() > nr {
                return Err("the glues of the strips' tops are not a permutation".into());
            }
            chain.push(r);
            r = top[r];
        }
        let len = chain.iter().map(|&r| rects[r].length).fold(0.0, f64::max);
        let m = ((len / spacing).ceil() as usize).max(MIN_CELLS) + 2 * levels;
        for &r in &chain {
            rects[r].m = m;
            done[r] = true;
        }
    }
    Ok(())
}

impl DomainMesh {
    /// The mesh with cells of size about `spacing` (at least [`MIN_CELLS`] along every strip
    /// side), or why not.
    pub fn new(domain: &GenusDomain, gluing: &Gluing, spacing: f64) -> Result<Self, String> {
        Self::graded(domain, gluing, spacing, 0)
    }

    /// The mesh of [`Self::new`] refined `levels` times at the zeros (module doc).
    pub fn graded(
        domain: &GenusDomain,
        gluing: &Gluing,
        spacing: f64,
        levels: usize,
    ) -> Result<Self, String> {
        Self::refined(domain, gluing, spacing, levels, &[])
    }

    /// The mesh of [`Self::graded`] whose full mesh also has the lines of `blocks` (through
    /// whole strips; [`Self::with_t_junctions`] keeps them only in their blocks).
    pub fn refined(
        domain: &GenusDomain,
        gluing: &Gluing,
        spacing: f64,
        levels: usize,
        blocks: &[Block],
    ) -> Result<Self, String> {
        if !(spacing > 0.0) {
            return Err(format!("spacing {spacing} must be positive"));
        }
        if levels > 20 {
            return Err(format!(
                "{levels} levels of refinement at the zeros (at most 20)"
            ));
        }
        // rectangles and their top neighbours
        let mut rects = Vec::new();
        let mut index = std::collections::HashMap::new();
        for (c, lay) in gluing.layouts.iter().enumerate() {
            let ch = &domain.cylinders[c];
            let n = ((ch.height / spacing).ceil() as usize).max(MIN_CELLS) + 2 * levels;
            for s in 0..lay.strips() {
                index.insert((c, s), rects.len());
                rects.push(Rect {
                    cylinder: c,
                    strip: s,
                    length: lay.strip_length(s),
                    height: ch.height,
                    m: 0,
                    n,
                    edge_u: 0.0,
                    edge_v: 0.0,
                    levels,
                    first_cell: 0,
                    base_m: 0,
                    base_n: 0,
                    xs: Vec::new(),
                    ys: Vec::new(),
                    u_fine: Vec::new(),
                    v_fine: Vec::new(),
                });
            }
        }
        let nr = rects.len();
        let mut top = vec![usize::MAX; nr];
        for g in &gluing.glues {
            let (Some(&a), Some(&b)) = (
                index.get(&(g.lower, g.lower_strip)),
                index.get(&(g.upper, g.upper_strip)),
            ) else {
                return Err(format!("glue {g:?} names a strip that does not exist"));
            };
            top[a] = b;
        }
        if let Some(r) = top.iter().position(|&t| t == usize::MAX) {
            return Err(format!(
                "the top of strip {} of cylinder {} is glued to nothing",
                rects[r].strip, rects[r].cylinder
            ));
        }
        columns_per_chain(&mut rects, &top, spacing, levels)?;
        size_edge_cells(&mut rects, levels)?;
        let cells = blocks::split_knots(&mut rects, &top, blocks)?;
        let right_rect = |r: usize| {
            let (c, s) = (rects[r].cylinder, rects[r].strip);
            let k = gluing.layouts[c].strips();
            index[&(c, (s + 1) % k)]
        };
        let cell = |r: usize, i: usize, j: usize| (rects[r].first_cell + j * rects[r].m + i) as u32;
        let mut neighbours = vec![[u32::MAX; 4]; cells];
        let mut cell_at = Vec::with_capacity(cells);
        for (r, rc) in rects.iter().enumerate() {
            for j in 0..rc.n {
                for i in 0..rc.m {
                    cell_at.push((r as u32, i as u32, j as u32));
                    let me = cell(r, i, j);
                    let right = if i + 1 < rc.m {
                        cell(r, i + 1, j)
                    } else {
                        cell(right_rect(r), 0, j)
                    };
                    let up = if j + 1 < rc.n {
                        cell(r, i, j + 1)
                    } else {
                        cell(top[r], i, 0)
                    };
                    neighbours[me as usize][RIGHT] = right;
                    neighbours[me as usize][TOP] = up;
                    neighbours[right as usize][LEFT] = me;
                    neighbours[up as usize][BOTTOM] = me;
                }
            }
        }
        if neighbours.iter().any(|n| n.contains(&u32::MAX)) {
            return Err("a cell has no neighbour across one of its sides".into());
        }
        // vertices: the lower-left corners of the cells, identified across the sides
        let mut parent: Vec<u32> = (0..cells as u32).collect();
        // c.lr = right(c).ll; c.ul = top(c).ll; c.ur = top(right(c)).ll = right(top(c)).ll
        let mut corners_key = vec![[0u32; 4]; cells];
        for c in 0..cells {
            let [r, t, _, _] = neighbours[c];
            let tr = neighbours[r as usize][TOP];
            let rt = neighbours[t as usize][RIGHT];
            let (a, b) = (find(&mut parent, tr), find(&mut parent, rt));
            parent[a as usize] = b;
            corners_key[c] = [c as u32, r, tr, t];
        }
        let mut id = vec![u32::MAX; cells];
        let mut nv = 0u32;
        for c in 0..cells as u32 {
            let root = find(&mut parent, c);
            if id[root as usize] == u32::MAX {
                id[root as usize] = nv;
                nv += 1;
            }
        }
        let mut corners = vec![[0u32; 4]; cells];
        let mut valence = vec![0u32; nv as usize];
        for c in 0..cells {
            for k in 0..4 {
                let v = id[find(&mut parent, corners_key[c][k]) as usize];
                corners[c][k] = v;
                valence[v as usize] += 1;
            }
        }
        let mut mesh = DomainMesh {
            rects,
            neighbours,
            corners,
            cell_at,
            valence,
            bezier: Vec::new(),
            reduction: Reduction::default(),
            tjunctions: None,
            blocks: blocks.to_vec(),
        };
        mesh.bezier = (0..cells).map(|c| mesh.extract(c)).collect();
        mesh.points_at_zeros();
        mesh.reduction = mesh.g1_reduction()?;
        Ok(mesh)
    }

    pub fn n_cells(&self) -> usize {
        self.corners.len()
    }

    pub fn n_vertices(&self) -> usize {
        self.valence.len()
    }

    /// Whether cell `c` is in the refined block around a zero ([`Rect::near_corner`]).
    pub fn near_zero(&self, c: u32) -> bool {
        let (r, i, j) = self.base_cell(c);
        self.rects[r].near_corner(i, j)
    }

    /// Whether vertex `v` is a zero (valence ≠ 4).
    pub fn is_zero(&self, v: u32) -> bool {
        self.valence[v as usize] != 4
    }

    fn nb(&self, c: u32, side: usize) -> u32 {
        self.neighbours[c as usize][side]
    }

    /// Width and height of a cell.
    pub fn size(&self, c: u32) -> (f64, f64) {
        let (r, i, j) = self.cell_at[c as usize];
        let r = &self.rects[r as usize];
        let (i, j) = (i as usize, j as usize);
        (r.x(i + 1) - r.x(i), r.y(j + 1) - r.y(j))
    }

    /// The size of cell `c` along `axis` (its knot interval in that direction).
    fn len(&self, c: u32, axis: Axis) -> f64 {
        match axis {
            Axis::U => self.size(c).0,
            Axis::V => self.size(c).1,
        }
    }

    fn w(&self, c: u32) -> f64 {
        self.len(c, Axis::U)
    }

    fn h(&self, c: u32) -> f64 {
        self.len(c, Axis::V)
    }

    /// The Bézier point at the lower-left corner of cell `c`.
    fn vertex_point(&self, c: u32) -> Combination {
        let a = self.corners[c as usize][0];
        let mut out = Combination::new();
        if self.is_zero(a) {
            // the mean of the side points next to the zero: [`Self::points_at_zeros`]
            return out;
        }
        let (l, b) = (self.nb(c, LEFT), self.nb(c, BOTTOM));
        let bl = self.nb(b, LEFT);
        let right = self.corners[c as usize][1];
        let left = self.corners[l as usize][0];
        let up = self.corners[c as usize][3];
        let down = self.corners[b as usize][0];
        let wl2 = self.beyond(l, left, LEFT, Axis::U);
        let wr2 = self.beyond(c, right, RIGHT, Axis::U);
        let hb2 = self.beyond(b, down, BOTTOM, Axis::V);
        let ht2 = self.beyond(c, up, TOP, Axis::V);
        let uw = corner_weights([wl2, self.w(l), self.w(c), wr2]);
        let vw = corner_weights([hb2, self.h(b), self.h(c), ht2]);
        let k = |x: u32| self.corners[x as usize];
        // 3 × 3 vertices, [column][row]
        let grid = [
            [k(bl)[0], k(l)[0], k(l)[3]],
            [k(b)[0], a, k(c)[3]],
            [k(b)[1], k(c)[1], k(c)[2]],
        ];
        for x in 0..3 {
            for y in 0..3 {
                add(&mut out, grid[x][y], uw[x] * vw[y]);
            }
        }
        out
    }

    /// The interval two steps from the cell before a vertex: the size along `axis` of the
    /// neighbour of `c` across `side`, or `c`'s own when the vertex `v` between them is a zero
    /// (no mesh line runs through a zero).
    fn beyond(&self, c: u32, v: u32, side: usize, axis: Axis) -> f64 {
        if self.is_zero(v) {
            self.len(c, axis)
        } else {
            self.len(self.nb(c, side), axis)
        }
    }

    /// The two Bézier points inside the side of cell `c` that runs along `along` from its
    /// lower-left corner (the bottom side for `U`: `b₁₀`, `b₂₀`; the left side for `V`: `b₀₁`,
    /// `b₀₂`): the blossom along the side (its interval and its two neighbours) of the
    /// corner points of the mesh lines across it, each from the cell `c`, the cell before it
    /// across the side, and the intervals beyond them.
    fn side_points(&self, c: u32, along: Axis) -> [Combination; 2] {
        let across = along.other();
        let (prev, next) = along.sides();
        let (before, after) = across.sides();
        let b = self.nb(c, before);
        // corner indices: the side's far end, and the start of the opposite side
        let (end, far) = match along {
            Axis::U => (1, 3),
            Axis::V => (3, 1),
        };
        let q = self.corners[c as usize];
        let (a0, a1, f0, f1) = (q[0], q[end], q[far], q[2]);
        let (d0, d1) = (self.corners[b as usize][0], self.corners[b as usize][end]);
        let aw = inner_weights([
            self.beyond(c, a0, prev, along),
            self.len(c, along),
            self.beyond(c, a1, next, along),
        ]);
        let line = |lo: u32, hi: u32| {
            corner_weights([
                self.beyond(b, lo, before, across),
                self.len(b, across),
                self.len(c, across),
                self.beyond(c, hi, after, across),
            ])
        };
        let lines = [(d0, a0, f0), (d1, a1, f1)];
        let ws = [line(d0, f0), line(d1, f1)];
        std::array::from_fn(|p| {
            let mut out = Combination::new();
            for k in 0..2 {
                let (x, y, z) = lines[k];
                for (v, w) in [(x, ws[k][0]), (y, ws[k][1]), (z, ws[k][2])] {
                    add(&mut out, v, aw[p][k] * w);
                }
            }
            out
        })
    }

    /// The 16 Bézier points of cell `c`.
    fn extract(&self, c: usize) -> [[Combination; 4]; 4] {
        let cu = c as u32;
        let (r, t) = (self.nb(cu, RIGHT), self.nb(cu, TOP));
        let tr = self.nb(r, TOP);
        let mut out: [[Combination; 4]; 4] = Default::default();
        out[0][0] = self.vertex_point(cu);
        out[3][0] = self.vertex_point(r);
        out[0][3] = self.vertex_point(t);
        out[3][3] = self.vertex_point(tr);
        let [b1, b2] = self.side_points(cu, Axis::U);
        out[1][0] = b1;
        out[2][0] = b2;
        let [t1, t2] = self.side_points(t, Axis::U);
        out[1][3] = t1;
        out[2][3] = t2;
        let [l1, l2] = self.side_points(cu, Axis::V);
        out[0][1] = l1;
        out[0][2] = l2;
        let [r1, r2] = self.side_points(r, Axis::V);
        out[3][1] = r1;
        out[3][2] = r2;
        let uw = inner_weights([self.w(self.nb(cu, LEFT)), self.w(cu), self.w(r)]);
        let vw = inner_weights([self.h(self.nb(cu, BOTTOM)), self.h(cu), self.h(t)]);
        let q = self.corners[c];
        let grid = [[q[0], q[3]], [q[1], q[2]]];
        for p in 0..2 {
            for s in 0..2 {
                let mut comb = Combination::new();
                for x in 0..2 {
                    for y in 0..2 {
                        add(&mut comb, grid[x][y], uw[p][x] * vw[s][y]);
                    }
                }
                out[p + 1][s + 1] = comb;
            }
        }
        out
    }

    /// The cell's rectangle in its strip's coordinates `[u0, u1] × [v0, v1]`.
    pub fn cell_box(&self, c: u32) -> [f64; 4] {
        let (r, i, j) = self.cell_at[c as usize];
        let r = &self.rects[r as usize];
        let (i, j) = (i as usize, j as usize);
        [r.x(i), r.x(i + 1), r.y(j), r.y(j + 1)]
    }

    /// The Bézier patch of cell `c` for control points `control` (one per vertex), over its
    /// box translated by `(du, dv)`.
    pub fn patch(&self, c: u32, control: &[[f64; 3]], du: f64, dv: f64) -> BezierPatch {
        let [u0, u1, v0, v1] = self.cell_box(c);
        let mut p = [[[0.0; 3]; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                for &(v, w) in &self.bezier[c as usize][i][j] {
                    for d in 0..3 {
                        p[i][j][d] += w * control[v as usize][d];
                    }
                }
            }
        }
        BezierPatch {
            u0: u0 + du,
            u1: u1 + du,
            v0: v0 + dv,
            v1: v1 + dv,
            control: p,
        }
    }

    /// Per strip, the translation of its `u` coordinate in the exported parameter plane: the
    /// strips side by side along `u`, a quarter of the longest strip apart, so that every
    /// Bézier patch has a parameter rectangle of its own (as the per-cylinder fit's offsets).
    pub fn export_offsets(&self) -> Vec<f64> {
        let gap = 0.25 * self.rects.iter().map(|r| r.length).fold(0.0, f64::max);
        let mut at = 0.0;
        self.rects
            .iter()
            .map(|r| {
                let off = at;
                at += r.length + gap;
                off
            })
            .collect()
    }

    /// Every cell's Bézier patch (cell order) over its box in the exported parameters
    /// ([`Self::export_offsets`]): one bicubic patch per cell (merged into Bézier elements for
    /// export by [`super::bezier_elements::domain_elements`]).
    pub fn patches(&self, control: &[[f64; 3]]) -> Vec<BezierPatch> {
        let offsets = self.export_offsets();
        (0..self.n_cells() as u32)
            .map(|c| {
                let r = self.cell_at[c as usize].0 as usize;
                self.patch(c, control, offsets[r], 0.0)
            })
            .collect()
    }

    /// The spline's point at `(s, t) ∈ [0, 1]²` of cell `c` from the blending functions (not
    /// the patches).
    pub fn point(&self, c: u32, s: f64, t: f64, control: &[[f64; 3]]) -> [f64; 3] {
        let mut x = [0.0; 3];
        for (v, w) in self.blending(c, s, t) {
            for d in 0..3 {
                x[d] += w * control[v as usize][d];
            }
        }
        x
    }

    /// The blending functions non-zero at `(s, t) ∈ [0, 1]²` of cell `c`: vertex and value
    /// (summed over the Bézier points; a vertex may appear once).
    pub fn blending(&self, c: u32, s: f64, t: f64) -> Combination {
        let (bu, bv) = (bernstein(s), bernstein(t));
        let mut out = Combination::new();
        for i in 0..4 {
            for j in 0..4 {
                for &(v, w) in &self.bezier[c as usize][i][j] {
                    add(&mut out, v, bu[i] * bv[j] * w);
                }
            }
        }
        out
    }

    /// Sides: `(cell, side)` for `side ∈ {RIGHT = 0, TOP = 1}` of every cell, and whether
    /// the side has a zero at an end.
    pub fn sides(&self) -> Vec<(u32, usize, bool)> {
        let mut out = Vec::with_capacity(2 * self.n_cells());
        for c in 0..self.n_cells() as u32 {
            let q = self.corners[c as usize];
            out.push((c, RIGHT, self.is_zero(q[1]) || self.is_zero(q[2])));
            out.push((c, TOP, self.is_zero(q[2]) || self.is_zero(q[3])));
        }
        out
    }

    /// The neighbour across `side` of `c`.
    pub fn across(&self, c: u32, side: usize) -> u32 {
        self.nb(c, side)
    }
}
