//! Genus ≥ 2: least squares on the spline of the domain manifold's quad mesh
//! ([`super::domain_mesh`]), the default of `ricci tspline` for genus ≥ 2 (the per-cylinder
//! fit of [`super::cylinder_fit`] is the `--per-cylinder` option). The data points are
//! located in the cells from their cylinder coordinates and the gluing's strips ([`super::glue::CylinderLayout::locate`]);
//! the fairness term is the squared second differences of the control net along the mesh
//! lines through every regular vertex (as the per-cylinder fit's), the umbrella operator at
//! the zeros, and optionally the exact thin-plate energy ([`DomainFitOptions::thin_plate`]).
//! Refinement is local where it can be: while a point of a cell next to a zero
//! ([`DomainMesh::near_zero`]) is beyond the tolerance, the mesh is refined once more at the
//! zeros ([`DomainMesh::graded`]: two columns and rows per strip; no more once a level left
//! the largest error there within [`STALL_NEAR`] × the tolerance and not [`LEVEL_STALL`] lower,
//! those points then go to the blocks); while a point elsewhere is,
//! the cells around it are split 2×2 in blocks whose lines end in T-junctions
//! ([`super::domain_mesh::blocks`], [`DomainFitOptions::blocks`]; a cell split already by
//! blocks nested in the deepest block that split it; a cell in the first or last row or column
//! of its block, where none can nest, grows that block instead) — or, when no block can be
//! placed (the point's cell is within [`super::domain_mesh::blocks::CLEAR`] cells of two sides
//! of its strip, is split [`super::domain_mesh::blocks::MAX_BLOCK_LEVEL`] times, or no cell
//! would be split that is not already), the blocks would cover more than [`BLOCK_SHARE`] of the
//! cells, or their T-mesh is not analysis-suitable, the spacing shrinks (by 1/√2, everywhere;
//! [`DomainFit::refinements`] says which and why); until the largest error is below the tolerance
//! or the budget of control points is spent (the last refinement is cut to the largest mesh
//! within the budget).
//!
//! **The refinement keeps what it has learnt.** When the spacing shrinks, the blocks are not
//! dropped: they are **carried over** to the new spacing
//! ([`super::domain_mesh::blocks::carry_blocks`]): every region a block split stays split at
//! least as finely (a level-`ℓ` block on the spacing `h` becomes a level-`ℓ` block on `h/√2`
//! covering its region, its cells `√2` finer). Only when the carried blocks' T-mesh is not
//! analysis-suitable are they dropped, strip by strip where the extensions meet (all of them
//! only when that does not help). Before (session 18), a spacing step dropped every block and
//! the error jumped back up by up to 10× (fertility at 1 %: 1.25 % → 3.71 %, 10 933 control
//! points against 6 892 at 0.5 %; botijo at 80 000 points: 0.55 % → 6.8 %, not converged);
//! `docs/notes/wave2-s19-kb21.md`. By default the unknowns
//! are the free values of the mesh's [`super::domain_mesh::Reduction`]: the fitted net is G¹ at
//! every zero ([`DomainFitOptions::g1_at_zeros`]), and the graded lines end in T-junctions
//! [`T_MARGIN`] cells beyond the corner blocks ([`DomainFitOptions::t_junctions`],
//! [`DomainMesh::with_t_junctions`]): the control points are the T-mesh's anchors. While a
//! point beside a graded line past its T-junction ([`DomainMesh::past_t_junction`]) is beyond
//! the tolerance, the lines are extended by two cells (instead of a finer spacing).
//!
//! **Where the control points go on genus ≥ 3** (measured with `examples/diag_domain_refinement`;
//! `docs/notes/wave2-s18-ec20.md`). A level at the zeros is global: it adds a graded column and
//! row at every zero copy, each kept over `L + 2 + margin` cells, about 900 control points per
//! level on genus3.off (32 corners), 3 500 of its 6 119 at 0.5 %, asked for by 1–9 points.
//! Those points lie along the strip sides next to a zero: within `0.06 E_u` of the side
//! (`E_u`, `E_v` the ungraded edge intervals) and up to `2 E_v` from the zero, where the thin
//! cylinder (height 0.0117) made `E_v` thirteen times smaller than `E_u` — the corner cells are
//! anisotropic, and a level refines `u` (needed) and `v` (not). Per-corner levels or levels per
//! direction would make this local; blocks cannot help (they stay [`super::domain_mesh::blocks::CLEAR`]
//! intervals from the zeros), and dropping the blocks that break analysis suitability instead of
//! refining the spacing everywhere leaves their points beyond the tolerance while the levels grow
//! (3holes 4 623 → 7 221, fertility 6 892 → 9 905).
//!
//! **The fairness and the spline between the vertices** (`docs/notes/wave2-s19-bv21.md`). The
//! second differences are in index space: a cell `b` high costs `b²` times its thin-plate energy
//! per unit area, so the graded rows along the critical trajectories (down to `E_v / 2⁷` high)
//! are nearly free across, and the twist `S_uv` is free everywhere. The spline's largest
//! distances to the input triangles sit there, in cells without data next to a zero (genus3.off:
//! 6.4 % of the bounding box in rows `10⁻⁵` high of the thin cylinder, 1.3 `E_u` from a zero), and
//! those ripples are what fits the vertices next to the trajectories within the tolerance: any
//! thin-plate weight (even `10⁻³`) on the final mesh lifts L∞ from 0.50 to 0.69 %.
//! [`DomainFitOptions::thin_plate`] adds the exact thin-plate energy of every cell
//! (`thin_plate.rs`; times `min(1, r²/E²)` near the zeros, where the surface goes as `√w`): at
//! 0.3, genus3 6.40 → 0.57 % between the vertices at 8 075 control points (6 119), eight 2.72 →
//! 1.01 %, fertility 2.45 → 1.03 % (14 407); 3holes does not converge within the budget (all
//! measured with the session-18 refinement). With the carried-over blocks of [`refine`] the same
//! weight 0.3 stops at the budget on genus3 (L∞ 0.94 %), and 0.1 meets 0.5 % with 16 084
//! control points, 0.70 % between the vertices (`tests/tspline_domain_thin_plate.rs`): the
//! weight and the refinement interact, which is why it is off by default.

use super::cylinder_fit::GenusStep;
use super::domain_mesh::{bernstein, Block, Combination, DomainMesh};
use super::fit::bbox_scale;
use super::genus_domain::GenusDomain;
use super::glue::Gluing;
use crate::error::{Error, Result};
use crate::numeric::sparse::{BlockAssembly, Cholesky};
use faer::Mat;

mod between;
mod thin_plate;
use between::data;
pub use between::{deviation_between_vertices, deviation_per_cell, triangle_points};
mod refine;
use refine::{carry_over, next_blocks, step_mesh, within_budget};

/// The fitted spline on the domain mesh.
#[derive(Debug, Clone)]
pub struct DomainFit {
    pub mesh: DomainMesh,
    pub control: Vec<[f64; 3]>,
    /// Per data point (`GenusDomain::points` order): cell, local `(s, t) ∈ [0, 1]²`, error.
    pub located: Vec<(u32, f64, f64)>,
    pub errors: Vec<f64>,
    pub steps: Vec<GenusStep>,
    pub converged: bool,
    /// Longest bounding-box side (errors in percent are relative to it).
    pub scale: f64,
    /// Levels of refinement at the zeros of the last mesh.
    pub levels: usize,
    /// Per refinement (between two steps): what was refined, and why the spacing shrank
    /// everywhere when it did.
    pub refinements: Vec<String>,
}

impl DomainFit {
    /// `(rms, L∞)` of this spline's distances to the data vertices, in percent of
    /// [`Self::scale`]: the last step's, or the best step's when the loop ended above the
    /// tolerance with an earlier fit nearer (the one returned then).
    pub fn errors_percent(&self) -> (f64, f64) {
        let n = self.errors.len().max(1) as f64;
        let rms = (self.errors.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
        let s = 100.0 / self.scale.max(1e-300);
        (rms * s, max_error(self) * s)
    }
}

/// Options of [`fit_domain_mesh`].
#[derive(Debug, Clone, Copy)]
pub struct DomainFitOptions {
    /// L∞ tolerance as a fraction of the longest bounding-box side.
    pub tolerance: f64,
    /// Weight of the fairness term (relative to the data term per control point).
    pub smoothing: f64,
    /// Initial spacing as a fraction of the longest circumference.
    pub initial: f64,
    /// Factor of the spacing per refinement (the control points grow by about its inverse
    /// square).
    pub refine: f64,
    pub max_iterations: usize,
    pub max_control_points: usize,
    /// Fit only nets that are G¹ at the zeros (the mesh's linear conditions there); `false`:
    /// every control point free, C⁰ at the zeros.
    pub g1_at_zeros: bool,
    /// Refine at the zeros only where the error there exceeds the tolerance (`false`: every
    /// refinement uniform).
    pub local_refinement: bool,
    /// Weight (relative to an input vertex's, times the triangle's area over the mean area) of
    /// the points on the input triangles — centroid and edge midpoints — that
    /// [`fit_domain_mesh_on_triangles`] adds to the least squares: they keep the surface near
    /// the mesh between the vertices, in cells without a vertex too. `0`: vertices only.
    pub between_vertices: f64,
    /// End the graded lines at the zeros in T-junctions ([`DomainMesh::with_t_junctions`]);
    /// only with [`Self::g1_at_zeros`] (the T-spline is a reduction of the full mesh's nets).
    pub t_junctions: bool,
    /// Refine the cells with errors away from the zeros in blocks split 2×2
    /// ([`super::domain_mesh::blocks`]; only with [`Self::t_junctions`]) rather than by a finer
    /// spacing everywhere (which stays the fallback when a block cannot be placed).
    pub blocks: bool,
    /// Weight of the thin-plate energy `∫∫ S_uu² + 2 S_uv² + S_vv²` over the domain
    /// (module `domain_fit::thin_plate`: exact per cell, in the strips' parameters, times
    /// `min(1, r²/E²)` near the zeros), added to the second differences in units of them on the
    /// ungraded cells. `0` (the default): the second differences only, which weigh the thin
    /// graded rows along the critical trajectories next to nothing and leave the twist free —
    /// the spline ripples there, between the vertices (genus3.off: 6.4 % of the bounding box);
    /// `0.3` brings that to 0.6 % at about 30 % more control points (BENCHMARKS "Session 19 (bv21)").
    pub thin_plate: f64,
}

/// Blocks splitting more than this share of the graded mesh's cells: a finer spacing
/// everywhere instead (blocks split cells 2×2 — four times the control points there — where the
/// spacing's step doubles them).
pub const BLOCK_SHARE: f64 = 0.5;

/// Cells beyond a corner block through which a graded line continues before its T-junction.
/// (Measured: 0, 1, 2, 4 on eight and the generated genus-2 surface at 0.5 % and 1 %; 2 is the
/// only one with fewer control points than the conforming grading in all four and the
/// between-vertex distance not above it: BENCHMARKS "Session 15 (tj18)".)
pub const T_MARGIN: usize = 2;

/// The most levels of refinement at the zeros; beyond, errors there refine uniformly.
pub const MAX_LEVELS: usize = 8;

/// A level at the zeros that leaves the largest error next to them above this fraction of what
/// it was, when that error is within [`STALL_NEAR`] times the tolerance, stops the levels: the
/// points there go to the blocks (or the spacing) instead. (3holes.off at 1 %: three levels,
/// ≈ 750 control points each, moved one point from 1.009 to 1.008 % of the box.) Farther from
/// the tolerance a level that does not help yet is kept: the spacing may be what is missing.
pub const LEVEL_STALL: f64 = 0.98;

/// See [`LEVEL_STALL`].
pub const STALL_NEAR: f64 = 1.5;

impl Default for DomainFitOptions {
    fn default() -> Self {
        DomainFitOptions {
            tolerance: 0.005,
            smoothing: 1e-4,
            initial: 0.125,
            refine: std::f64::consts::FRAC_1_SQRT_2,
            max_iterations: 16,
            max_control_points: 20_000,
            g1_at_zeros: true,
            local_refinement: true,
            between_vertices: 0.1,
            t_junctions: true,
            blocks: true,
            thin_plate: 0.0,
        }
    }
}

/// Cell and local coordinates of the cylinder point `(u, v)` of cylinder `c`.
pub fn locate(
    mesh: &DomainMesh,
    gluing: &Gluing,
    domain: &GenusDomain,
    c: usize,
    u: f64,
    v: f64,
) -> Option<(u32, f64, f64)> {
    let lay = gluing.layouts.get(c)?;
    let ch = &domain.cylinders[c];
    let (s, x) = lay.locate(u, v, ch.height, ch.circumference);
    let r = mesh
        .rects
        .iter()
        .position(|r| r.cylinder == c && r.strip == s)?;
    let rc = &mesh.rects[r];
    let (i, x) = rc.column(x);
    let (j, y) = rc.row(v);
    let cell = (rc.first_cell + j * rc.m + i) as u32;
    Some((cell, x, y))
}

/// Data points of a least-squares solve: cell and local `(s, t)`, target, weight.
type DataPoints<'a> = (&'a [(u32, f64, f64)], &'a [[f64; 3]], &'a [f64]);

/// The data points by cell (a counting sort, their order kept within a cell): the points of
/// cell `c` are `order[start[c]..start[c + 1]]`.
fn by_cell(located: &[(u32, f64, f64)], cells: usize) -> (Vec<usize>, Vec<usize>) {
    let mut start = vec![0usize; cells + 1];
    for &(c, _, _) in located {
        start[c as usize + 1] += 1;
    }
    for c in 0..cells {
        start[c + 1] += start[c];
    }
    let mut order = vec![0usize; located.len()];
    let mut next = start.clone();
    for (k, &(c, _, _)) in located.iter().enumerate() {
        order[next[c as usize]] = k;
        next[c as usize] += 1;
    }
    (start, order)
}

/// The unknowns a row of cell `c` can involve, appended to `out`: the vertices of its Bézier
/// points, with `g1` the free values they expand to (`mark`, per unknown, is left all false).
fn cell_set(mesh: &DomainMesh, c: usize, g1: bool, mark: &mut [bool], out: &mut Vec<u32>) {
    let from = out.len();
    for comb in mesh.bezier[c].iter().flatten() {
        for &(v, _) in comb {
            let itself = [(v, 1.0)];
            let free: &[(u32, f64)] = if g1 {
                &mesh.reduction.expand[v as usize]
            } else {
                &itself
            };
            for &(f, _) in free {
                if !mark[f as usize] {
                    mark[f as usize] = true;
                    out.push(f);
                }
            }
        }
    }
    out[from..].iter().for_each(|&f| mark[f as usize] = false);
}

/// The unknowns of cell `c` (`ids`, with `slot` their index there: reset it from `ids` after
/// use) and its 16 Bézier points (`local[4 i + j]`) as combinations of them; with `g1` the
/// unknowns are the free values of the mesh's reduction.
fn cell_local(
    mesh: &DomainMesh,
    c: usize,
    g1: bool,
    slot: &mut [u32],
    ids: &mut Vec<u32>,
    local: &mut [Vec<(usize, f64)>],
) {
    ids.clear();
    for (ij, l) in local.iter_mut().enumerate() {
        l.clear();
        let comb = &mesh.bezier[c][ij / 4][ij % 4];
        let reduced;
        let comb = if g1 {
            reduced = mesh.reduce(comb);
            &reduced
        } else {
            comb
        };
        for &(r, w) in comb {
            if slot[r as usize] == u32::MAX {
                slot[r as usize] = ids.len() as u32;
                ids.push(r);
            }
            l.push((slot[r as usize] as usize, w));
        }
    }
}

/// The data term of [`solve`]'s normal equations: `Σ w rowᵀ row` over the data points (grouped
/// by cell: [`by_cell`]) added to `asm`, and `Σ w row p` to `b`; with `g1` the rows are in the
/// free values of the mesh's reduction. The points are summed cell by cell in a dense block
/// over the cell's unknowns, added once per cell — not a triplet per pair and point, which held
/// genus3's fit at 0.9 GB — and a point's row is the Bernstein sum of the cell's 16 Bézier
/// points, each reduced once per cell.
fn data_term(
    mesh: &DomainMesh,
    (start, order): (&[usize], &[usize]),
    (located, targets, weights): DataPoints<'_>,
    g1: bool,
    asm: &mut BlockAssembly,
    b: &mut Mat<f64>,
) {
    // per unknown its index in the current cell's block (u32::MAX: not in it)
    let mut slot = vec![u32::MAX; b.nrows()];
    let mut ids = Vec::<u32>::new();
    // per Bézier point of the cell (`4 i + j`): its combination of the block's unknowns
    let mut local: Vec<Vec<(usize, f64)>> = vec![Vec::new(); 16];
    let (mut row, mut block) = (Vec::<f64>::new(), Vec::<f64>::new());
    for c in 0..mesh.n_cells() {
        let points = &order[start[c]..start[c + 1]];
        if points.is_empty() {
            continue;
        }
        cell_local(mesh, c, g1, &mut slot, &mut ids, &mut local);
        let m = ids.len();
        block.clear();
        block.resize(m * m, 0.0);
        for &k in points {
            let (_, s, t) = located[k];
            let (bu, bv) = (bernstein(s), bernstein(t));
            row.clear();
            row.resize(m, 0.0);
            for (ij, l) in local.iter().enumerate() {
                let f = bu[ij / 4] * bv[ij % 4];
                for &(a, w) in l {
                    row[a] += f * w;
                }
            }
            let (wk, p) = (weights.get(k).copied().unwrap_or(1.0), targets[k]);
            for (a, &x) in row.iter().enumerate() {
                let wx = wk * x;
                for (e, &y) in row.iter().enumerate() {
                    block[a * m + e] += wx * y;
                }
                for d in 0..3 {
                    b[(ids[a] as usize, d)] += wx * p[d];
                }
            }
        }
        for (a, &r) in ids.iter().enumerate() {
            for (e, &q) in ids.iter().enumerate() {
                if r >= q {
                    asm.add(r, q, block[a * m + e]);
                }
            }
        }
        ids.iter().for_each(|&r| slot[r as usize] = u32::MAX);
    }
}

/// The rows of the fairness term of [`solve`] (before its weight): the second differences
/// along the mesh lines through every regular vertex, the umbrella operator at the zeros.
fn fairness_rows(mesh: &DomainMesh) -> Vec<Combination> {
    let mut rows = Vec::with_capacity(2 * mesh.n_cells());
    for c in 0..mesh.n_cells() as u32 {
        let a = mesh.corners[c as usize][0];
        let (l, bt) = (mesh.across(c, 2), mesh.across(c, 3));
        if mesh.is_zero(a) {
            continue;
        }
        let q = mesh.corners[c as usize];
        // second divided differences, scaled to (1, −2, 1) on cells of equal size: zero on
        // linear functions across the graded cells at the zeros too
        let (hl, hb, (hu, hv)) = (mesh.size(l).0, mesh.size(bt).1, mesh.size(c));
        let (ul, ur) = (2.0 * hu / (hl + hu), 2.0 * hl / (hl + hu));
        let (vb, vt) = (2.0 * hv / (hb + hv), 2.0 * hb / (hb + hv));
        rows.push(vec![
            (mesh.corners[l as usize][0], ul),
            (a, -2.0),
            (q[1], ur),
        ]);
        rows.push(vec![
            (mesh.corners[bt as usize][0], vb),
            (a, -2.0),
            (q[3], vt),
        ]);
    }
    for z in (0..mesh.n_vertices() as u32).filter(|&z| mesh.is_zero(z)) {
        let mut nb: Vec<u32> = Vec::new();
        for q in &mesh.corners {
            for k in 0..4 {
                if q[k] == z {
                    for x in [q[(k + 1) % 4], q[(k + 3) % 4]] {
                        if !nb.contains(&x) {
                            nb.push(x);
                        }
                    }
                }
            }
        }
        let k = nb.len() as f64;
        let mut row: Vec<(u32, f64)> = nb.iter().map(|&x| (x, 1.0 / k)).collect();
        row.push((z, -1.0));
        rows.push(row);
    }
    rows
}

/// One least-squares solve on `mesh`; with `g1`, for the free values of the mesh's reduction
/// (the net is G¹ at the zeros).
/// `weights` per data point (empty: all 1); the fairness weight grows with `vertices`, the
/// number of input vertices among the data; `thin_plate` > 0 adds the thin-plate energy
/// ([`DomainFitOptions::thin_plate`]) on every cell. The normal equations are assembled as their lower
/// triangle (all the Cholesky factorization reads) on the pattern of the cells' and the
/// fairness rows' unknowns ([`BlockAssembly`]).
fn solve(
    mesh: &DomainMesh,
    located: &[(u32, f64, f64)],
    targets: &[[f64; 3]],
    weights: &[f64],
    vertices: usize,
    (smoothing, thin_plate): (f64, f64),
    g1: bool,
) -> Result<Vec<[f64; 3]>> {
    let n = if g1 {
        mesh.reduction.free
    } else {
        mesh.n_vertices()
    };
    let fair: Vec<Combination> = fairness_rows(mesh)
        .into_iter()
        .map(|row| if g1 { mesh.reduce(&row) } else { row })
        .collect();
    let (start, order) = by_cell(located, mesh.n_cells());
    // the pattern: the unknowns of every cell with data, of every fairness row
    let (mut flat, mut at) = (Vec::<u32>::new(), vec![0usize]);
    let mut mark = vec![false; n];
    for c in (0..mesh.n_cells()).filter(|&c| thin_plate > 0.0 || start[c + 1] > start[c]) {
        cell_set(mesh, c, g1, &mut mark, &mut flat);
        at.push(flat.len());
    }
    for row in &fair {
        flat.extend(row.iter().map(|x| x.0));
        at.push(flat.len());
    }
    let mut asm = BlockAssembly::new(n, at.windows(2).map(|w| &flat[w[0]..w[1]]));
    drop(flat);
    let mut b = Mat::<f64>::zeros(n, 3);
    let points = (located, targets, weights);
    data_term(mesh, (&start, &order), points, g1, &mut asm, &mut b);
    let w = smoothing * (vertices as f64 / mesh.n_vertices() as f64).max(1.0);
    for row in &fair {
        for &(r, x) in row {
            for &(q, y) in row.iter().filter(|&&(q, _)| r >= q) {
                asm.add(r, q, w * x * y);
            }
        }
    }
    if thin_plate > 0.0 {
        // in the units of the second differences on the ungraded cells: `h²` times the
        // thin-plate energy, `h²` the domain's area over its ungraded cells
        let area: f64 = mesh.rects.iter().map(|r| r.length * r.height).sum();
        let uniform: usize = mesh
            .rects
            .iter()
            .map(|r| r.base_m.saturating_sub(2 * r.levels) * r.base_n.saturating_sub(2 * r.levels))
            .sum();
        let h2 = area / uniform.max(1) as f64;
        thin_plate::thin_plate_term(mesh, g1, thin_plate * w * h2, &mut asm, n);
    }
    // a tiny ridge keeps vertices without data determined by the fairness alone
    for i in 0..n as u32 {
        asm.add(i, i, 1e-12);
    }
    let a = asm.matrix().map_err(|k| {
        Error::numerical(format!(
            "domain mesh fit: {k} values of the normal equations ({n} unknowns) fall outside their pattern"
        ))
    })?;
    let chol = Cholesky::factor(a).map_err(|e| {
        Error::numerical(format!(
            "domain mesh fit: the normal equations ({n} unknowns, {} points) are not positive definite: {e:?}",
            located.len()
        ))
    })?;
    chol.solve_in_place(b.as_mut());
    let mut out: Vec<[f64; 3]> = (0..n).map(|i| [b[(i, 0)], b[(i, 1)], b[(i, 2)]]).collect();
    if g1 {
        out = mesh.expand(&out);
    }
    if out.iter().flatten().any(|x| !x.is_finite()) {
        return Err(Error::numerical(
            "domain mesh fit: the solve gave non-finite control points",
        ));
    }
    Ok(out)
}

/// The mesh of `spacing` graded `levels` times at the zeros with the cells of `blocks` split,
/// its graded lines ending in T-junctions if `opts` say so.
fn domain_mesh(
    domain: &GenusDomain,
    gluing: &Gluing,
    (spacing, levels, margin): (f64, usize, usize),
    blocks: &[Block],
    opts: &DomainFitOptions,
) -> Result<DomainMesh> {
    let mesh =
        DomainMesh::refined(domain, gluing, spacing, levels, blocks).map_err(Error::numerical)?;
    if opts.t_junctions && opts.g1_at_zeros && (levels > 0 || !blocks.is_empty()) {
        mesh.with_t_junctions(margin).map_err(Error::numerical)
    } else {
        Ok(mesh)
    }
}

/// A mesh with more than `count` and at most `budget` control points, finer than the one of
/// `spacing` (which has `count`): they grow about as `1 / spacing²`, so a few spacings
/// just above `spacing · √(count / budget)` are tried, coarsest last.
fn fill_budget(
    domain: &GenusDomain,
    gluing: &Gluing,
    (spacing, levels, margin): (f64, usize, usize),
    count: usize,
    opts: &DomainFitOptions,
) -> Result<Option<DomainMesh>> {
    let budget = opts.max_control_points;
    if count >= budget {
        return Ok(None);
    }
    let base = spacing * (count as f64 / budget as f64).sqrt();
    for k in 0..6 {
        let at = (base * (1.0 + 0.03 * k as f64), levels, margin);
        let mesh = domain_mesh(domain, gluing, at, &[], opts)?;
        let n = mesh.n_control_points();
        if n <= count {
            return Ok(None);
        }
        if n <= budget {
            return Ok(Some(mesh));
        }
    }
    Ok(None)
}

/// Fit the data points of `domain` (positions by vertex) on the domain mesh, refining (at the
/// zeros or uniformly, module doc) until `L∞ ≤ tolerance` or the budget is spent. Vertices
/// only: [`fit_domain_mesh_on_triangles`] with no triangles.
pub fn fit_domain_mesh(
    domain: &GenusDomain,
    gluing: &Gluing,
    positions: &[[f64; 3]],
    opts: &DomainFitOptions,
) -> Result<DomainFit> {
    fit_domain_mesh_on_triangles(domain, gluing, positions, &[], opts)
}

/// One least-squares solve of [`fit_domain_mesh_on_triangles`]'s loop on `mesh`: the input
/// vertices located in its cells, the fitted control net, and the spline's distance to every
/// input vertex.
#[allow(clippy::type_complexity)]
fn fit_on_mesh(
    mesh: &DomainMesh,
    gluing: &Gluing,
    domain: &GenusDomain,
    (targets, weights, n_vertices): (&[[f64; 3]], &[f64], usize),
    extra: &[(usize, f64, f64, [f64; 3], f64)],
    opts: &DomainFitOptions,
) -> Result<(Vec<(u32, f64, f64)>, Vec<[f64; 3]>, Vec<f64>)> {
    let mut located = Vec::with_capacity(targets.len());
    for p in &domain.points {
        let x = locate(mesh, gluing, domain, p.cylinder, p.u, p.v).ok_or_else(|| {
            Error::numerical(format!(
                "domain mesh fit: vertex {} (cylinder {}) is in no strip",
                p.vertex, p.cylinder
            ))
        })?;
        located.push(x);
    }
    let mut data = located.clone();
    let mut data_targets = targets[..n_vertices].to_vec();
    let mut data_weights = weights[..n_vertices].to_vec();
    for (e, (&t, &w)) in extra
        .iter()
        .zip(targets[n_vertices..].iter().zip(&weights[n_vertices..]))
    {
        if let Some(x) = locate(mesh, gluing, domain, e.0, e.1, e.2) {
            data.push(x);
            data_targets.push(t);
            data_weights.push(w);
        }
    }
    let control = solve(
        mesh,
        &data,
        &data_targets,
        &data_weights,
        n_vertices,
        (opts.smoothing, opts.thin_plate),
        opts.g1_at_zeros,
    )?;
    let errors: Vec<f64> = located
        .iter()
        .zip(&targets[..n_vertices])
        .map(|(&(c, s, t), q)| {
            let p = mesh.patch(c, &control, 0.0, 0.0);
            let [u0, u1, v0, v1] = [p.u0, p.u1, p.v0, p.v1];
            let x = p.point(u0 + s * (u1 - u0), v0 + t * (v1 - v0));
            ((x[0] - q[0]).powi(2) + (x[1] - q[1]).powi(2) + (x[2] - q[2]).powi(2)).sqrt()
        })
        .collect();
    Ok((located, control, errors))
}

/// The graded cells in the boxes of `blocks` (nested boxes lie inside their parents'; counted
/// once).
pub fn graded_cells(blocks: &[Block]) -> usize {
    blocks
        .iter()
        .filter(|b| b.level == 1)
        .map(Block::cells)
        .sum()
}

/// [`fit_domain_mesh`] with points on the input `triangles` as data too
/// ([`DomainFitOptions::between_vertices`]); the tolerance is still checked at the vertices.
pub fn fit_domain_mesh_on_triangles(
    domain: &GenusDomain,
    gluing: &Gluing,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    opts: &DomainFitOptions,
) -> Result<DomainFit> {
    let scale = bbox_scale(positions);
    let l = domain
        .cylinders
        .iter()
        .map(|c| c.circumference)
        .fold(0.0, f64::max);
    let (targets, weights, n_vertices, extra) = data(domain, positions, triangles, opts);
    let mut spacing = opts.initial * l;
    let (mut steps, mut refinements) = (Vec::new(), Vec::new());
    let (mut last, mut best): (Option<DomainFit>, Option<DomainFit>) = (None, None);
    let refine = opts.refine.clamp(0.1, 0.95);
    let (mut filled, mut carried_now) = (false, false);
    let (mut levels, mut previous_spacing, mut margin) = (0, spacing, T_MARGIN);
    let (mut max_levels, mut worst_before) = (MAX_LEVELS, None);
    let mut blocks: Vec<Block> = Vec::new();
    let use_blocks = opts.blocks && opts.t_junctions && opts.g1_at_zeros;
    for _ in 0..opts.max_iterations.max(1) {
        let at = (&mut spacing, levels, margin);
        let mut mesh = step_mesh(
            (domain, gluing, opts),
            at,
            (&mut blocks, carried_now),
            (last.as_ref(), refine),
            &mut refinements,
        )?;
        if carried_now {
            let (at, r) = ((spacing, levels, margin), &mut refinements);
            mesh = within_budget(mesh, (domain, gluing, opts), at, &mut blocks, r)?;
        }
        if let Some(prev) = last
            .as_ref()
            .filter(|_| mesh.n_control_points() > opts.max_control_points)
        {
            if !blocks.is_empty() {
                // blocks over the budget: the last fit stands
                refinements.push(format!(
                    "{} control points with {} blocks: over the budget of {}, stopped",
                    mesh.n_control_points(),
                    blocks.len(),
                    opts.max_control_points
                ));
                if let Some(l) = last.as_mut() {
                    l.refinements = refinements;
                }
                break;
            }
            // the next refinement is over the budget: one last fit on the largest mesh within it
            match fill_budget(
                domain,
                gluing,
                (previous_spacing, levels, margin),
                prev.mesh.n_control_points(),
                opts,
            )? {
                Some(m) => {
                    mesh = m;
                    filled = true;
                }
                None => break,
            }
        }
        let (located, control, errors) = fit_on_mesh(
            &mesh,
            gluing,
            domain,
            (&targets, &weights, n_vertices),
            &extra,
            opts,
        )?;
        let max = errors.iter().fold(0.0f64, |a, &b| a.max(b));
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len().max(1) as f64).sqrt();
        steps.push(GenusStep {
            control_points: mesh.n_control_points(),
            rms_error_percent: 100.0 * rms / scale,
            max_error_percent: 100.0 * max / scale,
        });
        let converged = max <= opts.tolerance * scale;
        // where the tolerance is exceeded: next to a zero, elsewhere; a level at the zeros that
        // did not lower the error next to them by LEVEL_STALL, when it is within STALL_NEAR of
        // the tolerance, stops the levels
        let worst = near_worst(&mesh, &located, &errors, opts.tolerance * scale);
        if let (Some(before), Some(now)) = (worst_before, worst) {
            if now > LEVEL_STALL * before && now <= STALL_NEAR * opts.tolerance * scale {
                max_levels = levels;
            }
        }
        let allow = opts.local_refinement && levels < max_levels;
        let (near, extend, far) = classify(&mesh, &located, &errors, opts.tolerance * scale, allow);
        worst_before = worst.filter(|_| near);
        let mesh_levels = mesh.rects.first().map_or(0, |r| r.levels);
        keep_best(&mut best, last.take());
        last = Some(DomainFit {
            mesh,
            control,
            located,
            errors,
            steps: steps.clone(),
            converged,
            scale,
            levels: mesh_levels,
            refinements: refinements.clone(),
        });
        if converged || filled {
            break;
        }
        previous_spacing = spacing;
        let mut what = Vec::new();
        if near {
            levels += 1;
            what.push(format!("{levels} levels at the zeros"));
        }
        if extend {
            margin += 2;
            what.push(format!(
                "graded lines {margin} cells past the corner blocks"
            ));
        }
        let finer = next_blocks(
            (use_blocks, &far, last.as_ref(), usize::from(near)),
            &mut blocks,
            (&mut spacing, refine),
            &mut what,
        );
        let from = last.as_ref().filter(|_| finer && use_blocks);
        let (dg, at) = ((domain, gluing), (spacing, levels));
        carried_now = carry_over(dg, at, from, &mut blocks, &mut what)?;
        refinements.push(format!(
            "step {}: {} control points, L∞ {:.3} %; next: {}",
            steps.len(),
            steps.last().map_or(0, |s| s.control_points),
            steps.last().map_or(f64::NAN, |s| s.max_error_percent),
            what.join(", ")
        ));
    }
    let last = last.ok_or_else(|| Error::numerical("domain mesh fit: no iteration ran"))?;
    Ok(best_of(last, best))
}

/// The largest error beyond `tolerance` of a point in a cell next to a zero, if any.
fn near_worst(
    mesh: &DomainMesh,
    located: &[(u32, f64, f64)],
    errors: &[f64],
    tolerance: f64,
) -> Option<f64> {
    located
        .iter()
        .zip(errors)
        .filter(|&(&(c, _, _), &e)| e > tolerance && mesh.near_zero(c))
        .map(|(_, &e)| e)
        .reduce(f64::max)
}

/// Where the points beyond `tolerance` lie: next to a zero (when `levels` may grow), beside a
/// graded line past its T-junction, or elsewhere (their cells).
fn classify(
    mesh: &DomainMesh,
    located: &[(u32, f64, f64)],
    errors: &[f64],
    tolerance: f64,
    levels: bool,
) -> (bool, bool, Vec<u32>) {
    let (mut near, mut extend) = (false, false);
    let mut far = Vec::new();
    for (&(c, _, _), &e) in located.iter().zip(errors) {
        if e > tolerance {
            if levels && mesh.near_zero(c) {
                near = true;
            } else if mesh.past_t_junction(c) {
                extend = true;
            } else {
                far.push(c);
            }
        }
    }
    (near, extend, far)
}

/// The largest distance of `f`'s spline to a data vertex.
fn max_error(f: &DomainFit) -> f64 {
    f.errors.iter().fold(0.0f64, |a, &b| a.max(b))
}

/// Keeps in `best` the one of `best` and `f` with the smaller L∞ (the earlier on a tie).
fn keep_best(best: &mut Option<DomainFit>, f: Option<DomainFit>) {
    if let Some(f) = f {
        if best.as_ref().is_none_or(|b| max_error(&f) < max_error(b)) {
            *best = Some(f);
        }
    }
}

/// `last`, or when it is above the tolerance and an earlier fit (`best`) had a smaller L∞, that
/// one, with every step and refinement of the run and a line saying which step it was (its
/// errors: [`DomainFit::errors_percent`], not the last step's).
fn best_of(last: DomainFit, best: Option<DomainFit>) -> DomainFit {
    match best {
        Some(mut b) if !last.converged && max_error(&b) < max_error(&last) => {
            let k = b.steps.len();
            b.steps = last.steps;
            b.refinements = last.refinements;
            b.refinements.push(format!(
                "not converged: the fit of step {k} (the smallest L∞, {:.3} %) is the result, not the last one",
                100.0 * max_error(&b) / b.scale
            ));
            b
        }
        _ => last,
    }
}
