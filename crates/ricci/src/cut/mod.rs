//! Cut graphs and canonical fundamental group generators (paper 001 App. A, 002 §6.2.2.1 and
//! §7.3, 000 Steps 2 and 4).
//!
//! [`canonical_cut`] computes, through a base vertex `x`, a canonical system of loops
//! `a₁, b₁, …, a_g, b_g` — simple edge loops meeting only at `x`, `a_i` crossing `b_i` once and
//! nothing else — plus, on surfaces with boundary, paths `c_k` from `x` to every boundary loop
//! `d_k`. Slicing the mesh along them gives a disk whose boundary reads
//!
//! ```text
//! a₁ b₁ a₁⁻¹ b₁⁻¹ … a_g b_g a_g⁻¹ b_g⁻¹ c₁ d₁ c₁⁻¹ … c_b d_b c_b⁻¹
//! ```
//!
//! The fundamental polygon (sides in boundary order, each with its half-edges, label and
//! partner side) is **read from the cut mesh** and checked, and the intersection matrix of the
//! loops is computed by the push-off formula ([`paths`]) and checked against the standard
//! symplectic matrix (`a_i·b_i = +1`).
//!
//! Steps: (1) raise the valence of `x` and grade its neighbourhood by intrinsic,
//! metric-preserving edge splits ([`crate::metric::refine`]); (2) a Z₂ cohomology basis by
//! tree–cotree ([`homology`]); (3) the loops; (4) slicing ([`mod@slice`]) and reading the
//! polygon.
//!
//! **Closed surfaces of genus `g ≥ 1`: cut-and-paste ([`schema`]).** `2g` shortest simple
//! loops through `x`, pairwise disjoint except at `x`, with linearly independent Z₂ classes
//! (their complement is then a disk), followed by the cut-and-paste moves of the
//! classification of surfaces on the polygon (a chord of the disk between two corners
//! replaces one loop; two moves per handle). Every chord exists topologically; in the mesh it
//! exists because every *chord edge* (an uncut edge joining two cut vertices, the discrete
//! pinch) is split in place right after each new loop, which keeps the free vertices of the
//! disk connected and gives every sector at `x` a free neighbour. This construction does not
//! fail from any base vertex; it makes one attempt ([`CutOptions::max_attempts`] is not used).
//!
//! **Surfaces with boundary: the greedy of [`system`].** Handle by handle, short
//! non-separating loops through the free edges of `x` whose four ends are placed in one gap
//! between earlier handles, then the paths `c_k` to the boundary loops; when a handle does not
//! fit, the loops found so far are kept, a free row of vertices is split in along them and the
//! search resumes; after [`CutOptions::max_attempts`] such attempts the construction restarts
//! from the input with 3.5×, then 5× the valence at `x` (and a graded neighbourhood to match).
//! Its attempts fail for discrete reasons (the strip where `b_i` would pass is pinched by
//! earlier loops running alongside) — the reason the closed case moved to cut-and-paste; the
//! bordered shared meshes cut at the first attempt.
//!
//! Genus 0: a closed surface is slit along a path of two edges (word `c₁ c₁⁻¹`); a disk is
//! already cut (word `d₁`); with `b ≥ 2` boundary loops, `b` paths join them to `x`.

mod assemble;
pub(crate) mod error;
pub(crate) mod homology;
pub(crate) mod paths;
pub(crate) mod schema;
pub(crate) mod slice;
pub(crate) mod system;

use crate::error::{Error, Result};
use crate::mesh::{topology, Mesh, NONE};
use crate::metric::refine::{Refined, Refiner};
use crate::metric::{Geometry, IntrinsicMetric};
use crate::progress::Progress;
use assemble::assemble;
use serde::Serialize;
use system::RawPath;

pub use error::CutError;
pub use homology::Cohomology;
pub use paths::{
    halfedge_path, intersection_matrix, intersection_number, right_pushoff_crossings,
    standard_symplectic,
};
pub use slice::slice;
pub use system::SearchStats;

/// Options of [`canonical_cut`].
#[derive(Debug, Clone, Default)]
pub struct CutOptions {
    /// Base vertex (an interior vertex of the input mesh); `None` chooses a central one.
    pub base: Option<u32>,
    /// Minimum valence of the base vertex after refinement; `None` uses
    /// `max(4g + 4, 8g − 4) + b` (paper 000, Step 2: `8g − 4` lets the single-cone flat metric
    /// exist; `4g + b` edges are needed by the cut itself).
    pub min_valence: Option<usize>,
    /// Surfaces with boundary (the greedy construction of [`system`]): attempts per round (each
    /// refining along the loops found so far) when the loops do not fit (default 4). After a
    /// round fails, the construction restarts from the input with the valence at the base
    /// vertex scaled by 3.5, then by 5 (three rounds in all). Closed surfaces are cut by
    /// cut-and-paste ([`schema`]) in one attempt and ignore it.
    pub max_attempts: Option<usize>,
    /// How closed surfaces of genus ≥ 1 are cut (surfaces with boundary always use the greedy).
    pub construction: Construction,
}

/// The construction of the canonical system on a closed surface of genus `g ≥ 1`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Construction {
    /// Disjoint loops with independent classes, then cut-and-paste moves ([`schema`]): one
    /// attempt that does not fail, the fastest, but the moves' chords go around the disk, so
    /// the loops are longer (botijo: total length 115 against 43 for the greedy).
    #[default]
    CutAndPaste,
    /// The greedy construction of [`system`] with its attempts and restart rounds (shortest
    /// loops handle by handle; can fail from some base vertices).
    Greedy,
    /// The greedy (all its attempts and rounds), then cut-and-paste if it failed: short loops
    /// where the greedy finds them, a cut always. For the hyperbolic layout, whose
    /// fundamental polygon must stay within reach of double-double: from botijo's
    /// cut-and-paste loops the polygon spans 1 524 faces of depth and the relation product
    /// is lost (error 5e9), from the greedy's it is 1e-21.
    GreedyThenCutAndPaste,
}

/// The generator a polygon side or a loop stands for (indices are 1-based, as in the labels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Generator {
    /// `a_i`
    A { handle: usize },
    /// `b_i`
    B { handle: usize },
    /// `c_k`: the path from the base vertex to boundary loop `d_k`.
    C { boundary: usize },
    /// `d_k`: an original boundary loop (unpaired side).
    D { boundary: usize },
    /// The slit `c₁` of a closed genus-0 surface.
    Slit,
}

impl Generator {
    /// `"a1"`, `"b2"`, `"c1"`, `"d3"`.
    pub fn name(self) -> String {
        match self {
            Generator::A { handle } => format!("a{handle}"),
            Generator::B { handle } => format!("b{handle}"),
            Generator::C { boundary } => format!("c{boundary}"),
            Generator::D { boundary } => format!("d{boundary}"),
            Generator::Slit => "c1".to_string(),
        }
    }
}

/// A cut path: a loop `a_i`/`b_i` through the base vertex or a path `c_k` to a boundary loop.
#[derive(Debug, Clone, Serialize)]
pub struct Loop {
    /// `"a1"`, `"b1"`, …, `"c1"`, …
    pub label: String,
    pub generator: Generator,
    /// Vertices of the (refined) mesh; loops start and end at the base vertex, `c_k` runs from
    /// the base vertex to a vertex of boundary loop `d_k`.
    pub vertices: Vec<u32>,
    /// Half-edges of the (refined) mesh along the path.
    pub halfedges: Vec<u32>,
    /// Length in the given metric.
    pub length: f64,
}

/// A side of the fundamental polygon (the boundary of the cut mesh between two corners).
#[derive(Debug, Clone, Serialize)]
pub struct Side {
    /// `"a1"`, `"a1^-1"`, `"c2"`, `"d2"`, …
    pub label: String,
    pub generator: Generator,
    /// Whether the side runs against the orientation of its loop.
    pub inverse: bool,
    /// Interior half-edges of the cut mesh along the side, in boundary order (disk on the
    /// left); the same ids are half-edges of the refined mesh on the same faces.
    pub halfedges: Vec<u32>,
    /// Edges of the refined mesh along the side.
    pub edges: Vec<u32>,
    /// Cut-mesh vertices from the side's first corner to its last.
    pub vertices: Vec<u32>,
    /// Index of the partner side (same loop, opposite direction); `None` for original
    /// boundary loops.
    pub partner: Option<usize>,
    /// Index into [`CanonicalCut::loops`] (`None` for original boundary loops).
    pub loop_index: Option<usize>,
}

/// What the refinement and the search did.
#[derive(Debug, Clone, Serialize)]
pub struct CutReport {
    pub base_vertex: u32,
    /// Whether the base vertex was chosen automatically.
    pub base_automatic: bool,
    pub valence_before: usize,
    pub valence_after: usize,
    /// Minimum valence requested at the base vertex (last attempt).
    pub min_valence: usize,
    /// Edge splits (new vertices) in the refinement.
    pub refinement_splits: usize,
    /// Construction attempts (each with more refinement than the previous one).
    pub attempts: usize,
    /// Why earlier attempts failed.
    pub failed_attempts: Vec<String>,
    pub search: SearchStats,
    /// Wall-clock seconds of the whole computation.
    pub seconds: f64,
}

/// The result of [`canonical_cut`].
#[derive(Debug, Clone)]
pub struct CanonicalCut {
    pub geometry: Geometry,
    pub genus: usize,
    /// Number of boundary loops of the input.
    pub boundary_loops: usize,
    /// The base vertex (same id in the input and the refined mesh).
    pub base: u32,
    /// The refined mesh, its metric and positions, and the provenance of new vertices (the
    /// identity refinement when nothing was split).
    pub refined: Refined,
    /// `a₁, b₁, …, a_g, b_g`, then `c₁ … c_b` (or the slit `c₁` of a closed genus-0 surface).
    pub loops: Vec<Loop>,
    /// The cut mesh: a disk. Faces and interior half-edges keep the refined mesh's ids.
    pub cut_mesh: Mesh,
    /// For every cut-mesh vertex, the refined-mesh vertex it is a copy of.
    pub cut_vertex_origin: Vec<u32>,
    /// Sides of the fundamental polygon in boundary order (disk on the left), starting at `a₁`.
    pub polygon: Vec<Side>,
    /// The labels of `polygon`, separated by spaces, e.g. `"a1 b1 a1^-1 b1^-1"`.
    pub boundary_word: String,
    /// `loops[i]·loops[j]` for the `2g` loops `a₁, b₁, …` (push-off formula).
    pub intersection_matrix: Vec<Vec<i64>>,
    pub report: CutReport,
    /// Polygon side of every cut-mesh interior half-edge on the boundary (`NONE` elsewhere).
    side_of_halfedge: Vec<u32>,
}

/// Compute a canonical system of loops through a base vertex and slice the mesh along it into
/// a disk (see the module docs). `metric` gives the edge lengths by edge id and their
/// geometry; `positions` are optional and only interpolated for new vertices.
pub fn canonical_cut(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    positions: Option<&[[f64; 3]]>,
    options: &CutOptions,
    progress: &mut dyn Progress,
) -> Result<CanonicalCut> {
    let (lengths, geometry) = (metric.lengths(), metric.geometry());
    let t0 = std::time::Instant::now();
    // Low parts (a double-double metric) are carried through the splits in E² and H².
    let lengths_lo = metric
        .lengths_lo()
        .filter(|_| geometry != Geometry::Spherical);
    let surface = Surface {
        mesh,
        lengths,
        lengths_lo,
        geometry,
        positions,
    };
    let setup = Setup::new(mesh, lengths, options)?;
    if setup.closed() && options.construction == Construction::CutAndPaste {
        return cut_and_paste(surface, &setup, setup.min_valence, progress, t0);
    }
    greedy(surface, &setup, options, progress, t0)
}

/// The surface being cut: connectivity, metric and (optional) positions.
#[derive(Clone, Copy)]
struct Surface<'a> {
    mesh: &'a Mesh,
    lengths: &'a [f64],
    /// Low parts of the lengths (double-double), kept through the refinement.
    lengths_lo: Option<&'a [f64]>,
    geometry: Geometry,
    positions: Option<&'a [[f64; 3]]>,
}

/// What is settled before the construction: topology, base vertex, the valence wanted there.
struct Setup {
    genus: usize,
    /// Boundary loops of the input.
    nb: usize,
    base: u32,
    /// Whether the base vertex was chosen automatically.
    automatic: bool,
    /// Paths through the base vertex: `4g` loop ends and the connectors.
    paths_needed: usize,
    /// The minimum valence requested at the base vertex (first round).
    min_valence: usize,
    valence_before: usize,
    /// Dimension of the first Z₂ homology.
    expected_dim: usize,
    /// Mean length of the edges at the base vertex.
    mean_spoke: f64,
}

impl Setup {
    /// Check the input (one component, no isolated vertex, an interior base vertex) and
    /// settle the base vertex and the valence wanted there.
    fn new(mesh: &Mesh, lengths: &[f64], options: &CutOptions) -> Result<Setup> {
        if lengths.len() != mesh.n_edges() {
            return Err(Error::input(format!(
                "the metric has {} edge lengths but the mesh has {} edges",
                lengths.len(),
                mesh.n_edges()
            )));
        }
        let topo = topology(mesh);
        if topo.components.len() != 1 {
            return Err(Error::topology(format!(
                "cutting needs a connected surface; this mesh has {} components",
                topo.components.len()
            )));
        }
        let comp = &topo.components[0];
        if comp.vertices != mesh.n_vertices() {
            return Err(Error::topology(format!(
                "the mesh has {} isolated vertices",
                mesh.n_vertices() - comp.vertices
            )));
        }
        let genus = comp.genus.max(0) as usize;
        let nb = comp.boundary_loops;
        let (base, automatic) = match options.base {
            Some(v) if v as usize >= mesh.n_vertices() => {
                return Err(CutError::BaseVertexMissing {
                    vertex: v,
                    n_vertices: mesh.n_vertices(),
                }
                .into());
            }
            Some(v) => (v, false),
            None => (central_vertex(mesh, lengths)?, true),
        };
        let needs_base = genus > 0 || nb != 1;
        if needs_base && mesh.is_boundary_vertex(base) {
            return Err(CutError::BaseVertexOnBoundary { vertex: base }.into());
        }
        let n_connectors = if genus > 0 || nb >= 2 { nb } else { 0 };
        let paths_needed = 4 * genus + n_connectors;
        let default_valence = if genus > 0 {
            (4 * genus + 4).max(8 * genus - 4) + nb
        } else {
            paths_needed + 4
        };
        let valence_before = mesh.valence(base);
        let spokes: f64 = mesh
            .outgoing(base)
            .map(|h| lengths[mesh.he_edge(h) as usize])
            .sum();
        Ok(Setup {
            genus,
            nb,
            base,
            automatic,
            paths_needed,
            min_valence: options
                .min_valence
                .unwrap_or(default_valence)
                .max(paths_needed),
            valence_before,
            expected_dim: if nb == 0 {
                2 * genus
            } else {
                2 * genus + nb - 1
            },
            mean_spoke: spokes / valence_before.max(1) as f64,
        })
    }

    fn closed(&self) -> bool {
        self.nb == 0 && self.genus >= 1
    }

    /// The report of a cut made in `attempts` attempts with `min_valence` requested last.
    #[allow(clippy::too_many_arguments)]
    fn report(
        &self,
        out: &CanonicalCut,
        min_valence: usize,
        attempts: usize,
        failed_attempts: Vec<String>,
        search: SearchStats,
        t0: std::time::Instant,
    ) -> CutReport {
        CutReport {
            base_vertex: self.base,
            base_automatic: self.automatic,
            valence_before: self.valence_before,
            valence_after: out.refined.mesh.valence(self.base),
            min_valence,
            refinement_splits: out.refined.splits(),
            attempts,
            failed_attempts,
            search,
            seconds: t0.elapsed().as_secs_f64(),
        }
    }
}

/// The greedy construction of [`system`] with its attempts and restart rounds; on a closed
/// surface with [`Construction::GreedyThenCutAndPaste`], cut-and-paste when they all fail.
fn greedy(
    surface: Surface,
    setup: &Setup,
    options: &CutOptions,
    progress: &mut dyn Progress,
    t0: std::time::Instant,
) -> Result<CanonicalCut> {
    let (base, genus) = (setup.base, setup.genus);
    let max_attempts = options.max_attempts.unwrap_or(4).max(1);
    let mut min_valence = setup.min_valence;
    let mut failed = Vec::new();
    let mut attempt = 0;
    progress.report(
        "cut",
        Some(0.0),
        &format!("refining around vertex {base} to valence {min_valence}"),
    );
    // Rounds: when every attempt of a round fails, start again from the input mesh with the
    // valence at the base vertex (and the graded neighbourhood) scaled up.
    let round_valence: Vec<usize> = RESTART_FACTORS
        .iter()
        .map(|f| ((min_valence as f64) * f).ceil() as usize)
        .collect();
    let total_attempts = max_attempts * round_valence.len();
    let mut round = 0usize;
    let mut refined = grade_base(surface, setup, min_valence)?;
    let mut prior: Vec<RawPath> = Vec::new();
    let mut total = SearchStats::default();
    let mut round_attempt = 0usize;
    let raw = loop {
        attempt += 1;
        round_attempt += 1;
        progress.report(
            "cut",
            Some(0.1 + 0.8 * (attempt - 1) as f64 / total_attempts as f64),
            &format!("attempt {attempt}: searching {genus} handle(s)"),
        );
        let fail = match greedy_attempt(&refined, setup, &prior)? {
            Ok((raw, st)) => {
                total.add(&st);
                break raw;
            }
            Err(fail) => fail,
        };
        let system::Failure {
            reason: system::NoRoom(msg),
            paths: partial,
            stats: st,
        } = *fail;
        total.add(&st);
        failed.push(format!(
            "attempt {attempt} (valence {}): {msg}",
            refined.mesh.valence(base)
        ));
        if round_attempt >= max_attempts
            && round + 1 >= round_valence.len()
            && setup.closed()
            && options.construction == Construction::GreedyThenCutAndPaste
        {
            drop(refined);
            let mut out = cut_and_paste(surface, setup, round_valence[0], progress, t0)?;
            out.report.attempts += attempt;
            out.report.search.attempts += attempt;
            failed.append(&mut out.report.failed_attempts);
            out.report.failed_attempts = failed;
            return Ok(out);
        }
        if round_attempt >= max_attempts {
            round += 1;
            if round >= round_valence.len() {
                return Err(CutError::NoCanonicalSystem {
                    vertex: base,
                    attempts: attempt,
                    reason: msg,
                }
                .into());
            }
            // Start again with a larger graded neighbourhood of the base vertex.
            min_valence = round_valence[round];
            progress.report(
                "cut",
                None,
                &format!("restarting with valence {min_valence} at vertex {base}"),
            );
            refined = grade_base(surface, setup, min_valence)?;
            prior = Vec::new();
            round_attempt = 0;
            continue;
        }
        // Keep what was found, add a free row of vertices along it (only near the base vertex
        // when a handle other than the last failed, see `NEAR_BASE_REACH`) and more edges at
        // the base vertex, and resume.
        let complete = partial
            .iter()
            .filter(|p| matches!(p.kind, system::RawKind::Handle { which: 1, .. }))
            .count();
        let reach = (complete + 1 < genus).then_some(NEAR_BASE_REACH);
        min_valence = refined.mesh.valence(base) + 4;
        refined = widen(
            refined,
            &partial,
            base,
            surface.geometry,
            min_valence,
            reach,
        )?;
        prior = partial;
    };
    progress.report("cut", Some(0.9), "slicing");
    let mut out = assemble(refined, raw, base, genus, surface.geometry)?;
    out.report = setup.report(&out, min_valence, attempt, failed, total, t0);
    progress.report("cut", Some(1.0), "done");
    Ok(out)
}

/// One attempt of the greedy on the refined mesh, keeping the paths of `prior`: the raw
/// system, or why it failed with the paths found so far.
#[allow(clippy::type_complexity)]
fn greedy_attempt(
    refined: &Refined,
    setup: &Setup,
    prior: &[RawPath],
) -> Result<std::result::Result<(Vec<RawPath>, SearchStats), Box<system::Failure>>> {
    let coh = Cohomology::new(&refined.mesh)?;
    if coh.dim != setup.expected_dim {
        return Err(Error::topology(format!(
            "the first Z2 homology has dimension {} but genus {} with {} boundary loops needs {}",
            coh.dim, setup.genus, setup.nb, setup.expected_dim
        )));
    }
    let input = system::Input {
        mesh: &refined.mesh,
        lengths: &refined.lengths,
        coh: &coh,
        x: setup.base,
        genus: setup.genus,
        boundary_loops: refined.mesh.boundary_loops(),
    };
    Ok(system::build(&input, prior))
}

/// Closed surfaces of genus `g ≥ 1`: the construction of [`schema`] (disjoint loops with
/// independent classes, then cut-and-paste moves on the polygon), which does not fail.
fn cut_and_paste(
    surface: Surface,
    setup: &Setup,
    min_valence: usize,
    progress: &mut dyn Progress,
    t0: std::time::Instant,
) -> Result<CanonicalCut> {
    let (base, genus) = (setup.base, setup.genus);
    progress.report(
        "cut",
        Some(0.0),
        &format!("refining around vertex {base} to valence {min_valence}"),
    );
    let refined = grade_base(surface, setup, min_valence)?;
    let coh = Cohomology::new(&refined.mesh)?;
    if coh.dim != 2 * genus {
        return Err(Error::topology(format!(
            "the first Z2 homology has dimension {} but a closed surface of genus {genus} needs {}",
            coh.dim,
            2 * genus
        )));
    }
    let omega = schema::Schema::halfedge_cocycles(&refined.mesh, &coh);
    let words = coh.words;
    drop(coh);
    let r = Refiner::resume(refined, surface.geometry)?;
    progress.report(
        "cut",
        Some(0.2),
        &format!(
            "{} loops with independent classes, then cut-and-paste",
            2 * genus
        ),
    );
    let mut sch = schema::Schema::new(r, omega, words, base);
    let raw = sch.build(genus)?;
    let stats = SearchStats {
        moves: sch.moves,
        attempts: 1,
        ..sch.stats.clone()
    };
    let refined = sch.into_refiner().finish()?;
    progress.report("cut", Some(0.9), "slicing");
    let mut out = assemble(refined, raw, base, genus, surface.geometry)?;
    out.report = setup.report(&out, min_valence, 1, Vec::new(), stats, t0);
    progress.report("cut", Some(1.0), "done");
    Ok(out)
}

/// Valence factors of the restart rounds of [`canonical_cut`] (relative to the requested
/// minimum valence).
const RESTART_FACTORS: [f64; 3] = [1.0, 3.5, 5.0];

/// The input refined around the base vertex: valence raised to `min_valence`, neighbourhood
/// graded so that about `max(min_valence, 2·paths)` vertices lie on every circle around it.
fn grade_base(surface: Surface, setup: &Setup, min_valence: usize) -> Result<Refined> {
    let Surface {
        mesh,
        lengths,
        lengths_lo,
        geometry,
        positions,
    } = surface;
    if setup.paths_needed == 0 {
        return Ok(Refined {
            lengths_lo: lengths_lo.map(<[f64]>::to_vec),
            ..Refined::identity(mesh, lengths, positions)
        });
    }
    let mut r = Refiner::new_with_low_parts(mesh, lengths, lengths_lo, geometry, positions)?;
    r.raise_valence(setup.base, min_valence)?;
    let grade = min_valence.max(2 * setup.paths_needed);
    let theta = r.cone_angle(setup.base);
    let radius = 1.5 * grade as f64 * setup.mean_spoke / theta.max(1e-3);
    r.grade_around(setup.base, grade, radius, 40 * grade * grade + 1000)?;
    r.finish()
}

/// Widening near the base vertex after a handle other than the last failed: the part of the
/// loops within this fraction of the distance from the base vertex to their farthest vertex.
/// Where a handle does not fit, its candidate loops are lassos of a single branch: the gap at
/// the base vertex opens into a corridor between two earlier loops that left it side by side,
/// too narrow for the two strands of `a_i` and for `b_i`. On botijo that corridor is near the
/// base vertex (widening only there: the same four attempts succeed with 14 805 splits instead
/// of 27 137); on seahorse2_100K, whose last handle fails, it is not (widening only near the
/// base vertex there makes every attempt of the first round fail), so a failed last handle
/// widens along the whole loops (BENCHMARKS.md, session 14, bot15).
const NEAR_BASE_REACH: f64 = 0.25;

/// Split every edge that touches a vertex of the given paths (except cut edges and edges at the
/// base vertex): a free row of vertices appears on both sides of every path, so later loops
/// can pass between earlier ones. With `reach`, only vertices within `reach` times the
/// largest distance from the base vertex to a path vertex count. The base vertex's valence is
/// raised to `min_valence`.
fn widen(
    refined: Refined,
    paths: &[RawPath],
    base: u32,
    geometry: Geometry,
    min_valence: usize,
    reach: Option<f64>,
) -> Result<Refined> {
    let mesh = &refined.mesh;
    let mut on_path = vec![false; mesh.n_vertices()];
    let mut cut = std::collections::HashSet::new();
    for p in paths {
        for w in p.vertices.windows(2) {
            cut.insert((w[0].min(w[1]), w[0].max(w[1])));
        }
        for &v in &p.vertices {
            on_path[v as usize] = true;
        }
    }
    on_path[base as usize] = false;
    if let Some(f) = reach {
        let d = distances(mesh, &refined.lengths, &[base]);
        let far = paths
            .iter()
            .flat_map(|p| p.vertices.iter())
            .map(|&v| d[v as usize])
            .fold(0.0, f64::max);
        for (v, on) in on_path.iter_mut().enumerate() {
            *on &= d[v] <= f * far;
        }
    }
    let mut todo = Vec::new();
    for e in 0..mesh.n_edges() as u32 {
        let [a, b] = mesh.edge_vertices(e);
        if a == base || b == base || cut.contains(&(a.min(b), a.max(b))) {
            continue;
        }
        if on_path[a as usize] || on_path[b as usize] {
            todo.push((a, b));
        }
    }
    let mut r = Refiner::resume(refined, geometry)?;
    for (a, b) in todo {
        r.split_between(a, b);
    }
    r.raise_valence(base, min_valence)?;
    r.finish()
}

impl CanonicalCut {
    /// Positions of the cut-mesh vertices (copies of the refined positions), if known.
    pub fn cut_positions(&self) -> Option<Vec<[f64; 3]>> {
        self.refined.positions.as_ref().map(|p| {
            self.cut_vertex_origin
                .iter()
                .map(|&v| p[v as usize])
                .collect()
        })
    }

    /// The `2g` generator loops `a₁, b₁, …` as half-edge sequences.
    pub fn generators(&self) -> Vec<Vec<u32>> {
        self.loops[..2 * self.genus]
            .iter()
            .map(|l| l.halfedges.clone())
            .collect()
    }

    /// The polygon sides crossed by the right push-off of the closed path (half-edges of the
    /// refined mesh), in order: each entry is the side through which the path leaves the disk
    /// (it re-enters through the partner side). Lifting the path to the universal cover, it
    /// ends in the copy `T_{s₁} ∘ … ∘ T_{s_k}(D)` of the disk, `T_s` being the side pairing that
    /// maps the partner of `s` onto `s`.
    pub fn crossings(&self, path: &[u32]) -> Result<Vec<usize>> {
        let mesh = &self.refined.mesh;
        let cr = right_pushoff_crossings(mesh, path)?;
        let mut out = Vec::new();
        for e in cr {
            let t = mesh.he_twin(e);
            let s = self.side_of_halfedge[t as usize];
            if s != NONE {
                out.push(s as usize);
            }
        }
        Ok(out)
    }

    /// The word of a closed path in the side pairings, written with the convention of paper
    /// 002 §6.2.2.3 (`β_k` maps `a_k` to `a_k⁻¹`, `α_k` maps `b_k⁻¹` to `b_k`): leaving through
    /// side `b_k` gives `a_k` (α_k), through `a_k⁻¹` gives `b_k` (β_k), inverses alike; through
    /// `c_k⁻¹` gives `d_k`. Freely and cyclically reduced. A generator loop `a_k` reads `a_k`
    /// (up to the relation), and the exponent sums give its homology class.
    pub fn word(&self, path: &[u32]) -> Result<Vec<(Generator, i32)>> {
        let mut w: Vec<(Generator, i32)> = Vec::new();
        for s in self.crossings(path)? {
            let side = &self.polygon[s];
            let (g, sign) = match side.generator {
                Generator::A { handle } => {
                    (Generator::B { handle }, if side.inverse { 1 } else { -1 })
                }
                Generator::B { handle } => {
                    (Generator::A { handle }, if side.inverse { -1 } else { 1 })
                }
                Generator::C { boundary } => {
                    (Generator::D { boundary }, if side.inverse { 1 } else { -1 })
                }
                _ => continue,
            };
            if let Some(&(lg, ls)) = w.last() {
                if lg == g && ls == -sign {
                    w.pop();
                    continue;
                }
            }
            w.push((g, sign));
        }
        // Cyclic reduction.
        while w.len() >= 2 {
            let (f, l) = (w[0], w[w.len() - 1]);
            if f.0 == l.0 && f.1 == -l.1 {
                w.pop();
                w.remove(0);
            } else {
                break;
            }
        }
        Ok(w)
    }

    /// The word as a string, e.g. `"a1 b2^-1"` (empty for the identity).
    pub fn word_string(&self, path: &[u32]) -> Result<String> {
        Ok(self
            .word(path)?
            .iter()
            .map(|&(g, s)| {
                if s > 0 {
                    g.name()
                } else {
                    format!("{}^-1", g.name())
                }
            })
            .collect::<Vec<_>>()
            .join(" "))
    }

    /// Homology class of a closed path in the basis `a₁, b₁, …, a_g, b_g`, by intersection
    /// numbers: the coefficient of `a_i` is `P·b_i`, that of `b_i` is `−P·a_i`.
    pub fn homology_class(&self, path: &[u32]) -> Result<Vec<i64>> {
        let mesh = &self.refined.mesh;
        let mut out = vec![0i64; 2 * self.genus];
        for i in 0..self.genus {
            out[2 * i] = intersection_number(mesh, path, &self.loops[2 * i + 1].halfedges)?;
            out[2 * i + 1] = -intersection_number(mesh, path, &self.loops[2 * i].halfedges)?;
        }
        Ok(out)
    }
}

/// Shortest-path distances from `sources` (Dijkstra over edges).
pub(crate) fn distances(mesh: &Mesh, lengths: &[f64], sources: &[u32]) -> Vec<f64> {
    crate::numeric::dijkstra::distances(mesh.n_vertices(), sources, |v| {
        mesh.outgoing(v)
            .map(move |h| (mesh.he_tip(h), lengths[mesh.he_edge(h) as usize]))
    })
}

/// A central interior vertex: with `v₁` farthest from an arbitrary vertex and `v₂` farthest
/// from `v₁` (double sweep), the interior vertex minimizing `max(d(v₁, ·), d(v₂, ·))`.
pub(crate) fn central_vertex(mesh: &Mesh, lengths: &[f64]) -> Result<u32> {
    let start = (0..mesh.n_vertices() as u32)
        .find(|&v| !mesh.is_isolated(v))
        .ok_or_else(|| Error::topology("the mesh has no faces"))?;
    let far = |d: &[f64]| -> u32 {
        (0..d.len())
            .filter(|&v| d[v].is_finite())
            .max_by(|&a, &b| d[a].total_cmp(&d[b]))
            .unwrap_or(0) as u32
    };
    let d0 = distances(mesh, lengths, &[start]);
    let v1 = far(&d0);
    let d1 = distances(mesh, lengths, &[v1]);
    let v2 = far(&d1);
    let d2 = distances(mesh, lengths, &[v2]);
    (0..mesh.n_vertices() as u32)
        .filter(|&v| !mesh.is_isolated(v) && !mesh.is_boundary_vertex(v))
        .min_by(|&a, &b| {
            d1[a as usize]
                .max(d2[a as usize])
                .total_cmp(&d1[b as usize].max(d2[b as usize]))
        })
        .or(Some(start))
        .ok_or_else(|| Error::topology("the mesh has no interior vertex"))
}
