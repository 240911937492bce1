//! Affine atlas with a single extraordinary point (paper 000 §4 Steps 1–5, paper 002
//! §5.2–5.3.1).
//!
//! [`AffineAtlas::build`] turns a surface into a flat cone surface with charts:
//!
//! 1. **Singularity** ([`placement`]): closed surfaces of genus ≥ 2 get one cone carrying all
//!    of `2πχ`, at a vertex given by the user or chosen automatically by least area
//!    distortion `Σ_f (log S_f − log s_f)² / n` (linearized flow ranking, confirmed by full
//!    flows on a budget, on a mesh graded around the candidate when needed). Genus 1 gets
//!    none (uniform flat metric); open surfaces none (free boundary: the curvature is pushed
//!    to the boundary, `u` keeps its initial value there);
//!    `k` user cones (`cones`) on closed surfaces.
//! 2. **Connectivity modification** (Step 2): intrinsic, metric-preserving edge splits
//!    ([`crate::metric::refine`]) raise the valence of every cone `v` to at least
//!    `⌈4 − 2K̄(v)/π⌉`; the canonical cut then grades the neighbourhood of its base vertex
//!    (the cone) so its `4g` loops fit; finally the cone's one-ring neighbours get valence
//!    ≥ 6 by splitting their outer link edges off the cut ([`raise_ring_valence`]) — the
//!    cut's grading leaves valence-4 neighbours, and without this the Chow–Luo condition on
//!    the cone's closed one-ring refuses the target for genus ≥ 3. Then Step 2 (ii) proper:
//!    every vertex within `rings` (3) edge-rings of a cone gets valence ≥ 6 by intrinsic,
//!    metric-preserving **edge flips** ([`crate::metric::refine::Refiner::flip`]) that move
//!    spare valence inwards, and splits that make room where no flip can
//!    ([`flip_ring_valence`]); neither touches an edge of the cut loops or at a cone, so the
//!    loops stay edge paths. All of this happens before the flow, which therefore runs on the
//!    final connectivity. The count of vertices within `rings` rings still below 6 is
//!    reported (`low_valence_after`, 0 on every mesh tested).
//! 3. **Flat metric** (Step 3): Euclidean Ricci flow ([`crate::flow`]) on the refined mesh
//!    with the cone target, from the input metric.
//! 4. **Segmentation** (Step 4): the canonical cut through the cone ([`crate::cut`]), plus a
//!    shortest slit from the cut graph to every further cone, slices the surface into a disk.
//! 5. **Charts** (Step 5): the *central chart* is the layout of that disk
//!    ([`crate::layout::place::layout`]): every face exactly once. Faces near the cut are not
//!    covered with their neighbourhood there; for them, *cut charts* are developed
//!    ([`develop`]) from the union of the vertex stars of those faces (the paper's union of
//!    one-rings of the cut curves' interior vertices, widened so that every face's spline
//!    support fits), never across a cone. Every chart is validated (lengths reproduced, no
//!    flipped face, consistent closure) and the home chart of every face not incident to a
//!    cone is checked to contain that face's whole neighbourhood with one coordinate per
//!    vertex. The cone grades the faces around it down by orders of magnitude (1e-7 of the
//!    central chart on 3holes.off), where the central chart stores them only to ~1e-9 of
//!    their size; every face whose home chart is more than [`LOCAL_CHART_CONDITIONING`]
//!    of the face across ([`AffineAtlas::conditioning`]) is rehomed in a *local chart*, the
//!    development of the neighbourhoods of such faces within [`LOCAL_CHART_RINGS`] rings of
//!    a seed (validated the same way; 51 on 3holes.off, 17 on eight.off) — paper 000's
//!    atlas needs only charts that cover; in floating point they must also be of the size
//!    of the faces they carry.
//!
//! Transition maps are rigid motions, fitted per face ([`FlatCharts::transition`]); the
//! atlas reports the largest residual over all faces in two charts.
//!
//! * [`charts`] — the chart interface ([`charts::FlatCharts`]) shared with the manifold splines.

//!
//! The stages live in their own files: [`AffineAtlas::build`] and the segmentation in
//! `build.rs`, the flat metric with its scheme fallback in `flat.rs` ([`flat_flow`]), the
//! valence surgery in `valence.rs` ([`raise_ring_valence`], [`flip_ring_valence`]), the cover
//! by charts in `cover.rs`, the area distortion in `distortion.rs` ([`area_distortion`]); the
//! stage's errors that name a vertex or face in `error.rs` ([`AtlasError`]).

mod build;
pub(crate) mod charts;
mod cover;
pub(crate) mod develop;
mod distortion;
pub(crate) mod error;
mod flat;
mod overview;
pub mod placement;
mod valence;

pub use charts::{fit_rigid, ChartId, FlatCharts};
pub use distortion::area_distortion;
pub use error::AtlasError;
pub use flat::{flat_flow, flat_flow_limited, FlatFlow};
pub use placement::{Placement, PlacementOptions};
pub use valence::{flip_ring_valence, raise_ring_valence, RingValenceWork};

use crate::layout::RigidMotion;
use crate::mesh::{Mesh, NONE};
use crate::metric::Scheme;
use serde::Serialize;

/// Where the singular vertex of a closed surface of genus ≥ 2 goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Singularity {
    /// Least area distortion ([`placement`]).
    Auto,
    /// A vertex of the input mesh.
    Vertex(u32),
}

/// Options of [`AffineAtlas::build`].
#[derive(Debug, Clone)]
pub struct AtlasOptions {
    /// Closed genus ≥ 2 only (ignored when `cones` is given).
    pub singularity: Singularity,
    /// User cones `(vertex, K̄)` of a closed surface; `Σ K̄ = 2πχ`.
    pub cones: Option<Vec<(u32, f64)>>,
    /// Conformal scheme of the flow (the papers: Thurston circle packing).
    pub scheme: Scheme,
    /// Flow tolerance: max |K − K̄| (default 1e-10).
    pub tolerance: f64,
    /// Step 2 (ii): every vertex within this many edge-rings of a cone gets valence ≥ 6
    /// (flips and splits; 0 switches it off); the report counts the vertices within this
    /// many rings still below 6 (default 3, the paper's n).
    pub rings: usize,
    /// Options of the automatic placement.
    pub placement: PlacementOptions,
}

impl Default for AtlasOptions {
    fn default() -> Self {
        AtlasOptions {
            singularity: Singularity::Auto,
            cones: None,
            scheme: Scheme::Thurston,
            tolerance: 1e-10,
            rings: 3,
            placement: PlacementOptions::default(),
        }
    }
}

/// What Step 2 changed.
#[derive(Debug, Clone, Serialize, Default)]
pub struct RefinementReport {
    /// Per cone: (vertex, valence before, valence required by `4 − 2K̄/π`, valence after).
    pub cone_valence: Vec<(u32, usize, usize, usize)>,
    /// Edge splits of Step 2 (valences) and of the cut's grading.
    pub splits_step2: usize,
    pub splits_cut: usize,
    /// Splits that gave the cones' one-ring neighbours valence ≥ 6 after the cut.
    pub splits_ring: usize,
    /// Step 2 (ii) within `rings` rings ([`flip_ring_valence`]): intrinsic flips, and the
    /// splits that made room for them.
    pub flips_ring: usize,
    pub splits_ring_room: usize,
    /// Vertices within `rings` rings of a cone with valence < 6, before and after.
    pub low_valence_before: usize,
    pub low_valence_after: usize,
    /// One-ring neighbours of a cone with valence < 6 at the end (0 unless a neighbour's
    /// outer link lies on the cut).
    pub low_valence_ring1_after: usize,
    pub vertices_before: usize,
    pub vertices_after: usize,
}

/// One chart's validation.
#[derive(Debug, Clone, Serialize)]
pub struct ChartReport {
    pub id: ChartId,
    /// "central", "cut" or "local" (a development of one face's neighbourhood, see
    /// [`LOCAL_CHART_CONDITIONING`]).
    pub kind: &'static str,
    pub faces: usize,
    /// Faces whose home chart this is.
    pub home_faces: usize,
    pub flipped_faces: usize,
    /// Largest |chart distance − metric length| over the chart's face sides.
    pub max_length_error: f64,
    /// Region faces that did not close up consistently and were left out.
    pub rejected_faces: usize,
}

/// Everything [`AffineAtlas::build`] measured.
#[derive(Debug, Clone, Serialize)]
pub struct AtlasReport {
    pub genus: i64,
    pub boundary_loops: usize,
    /// "single-cone", "cones", "uniform" (genus 1) or "free-boundary" (open).
    pub target: String,
    pub singular_vertices: Vec<u32>,
    pub placement: Option<Placement>,
    pub refinement: RefinementReport,
    /// The conformal scheme of the flow that produced the metric (the requested one, or the
    /// fallback when it did not converge).
    pub scheme: String,
    pub flow_converged: bool,
    pub flow_iterations: usize,
    pub max_curvature_error: f64,
    pub gauss_bonnet_error: f64,
    /// Paper 000 §4 Step 1: `Σ_f (log S_f − log s_f)² / n` over the input faces (S: R³
    /// area, s: flat area of the face's refined pieces).
    pub area_distortion: f64,
    pub charts: Vec<ChartReport>,
    pub flipped_faces: usize,
    pub max_length_error: f64,
    /// Largest residual of the per-face rigid transitions over all faces in ≥ 2 charts.
    pub max_transition_error: f64,
    /// The same residual relative to the face's shortest side (the faces graded towards the
    /// cone are orders of magnitude smaller than the central chart).
    pub max_relative_transition_error: f64,
    /// Local charts added for faces whose home chart was too large for them (Step 5, see
    /// [`LOCAL_CHART_CONDITIONING`]).
    pub local_charts: usize,
    /// Largest conditioning ([`AffineAtlas::conditioning`]) of a face in its home chart:
    /// `ε ×` this is the relative rounding of the face's neighbourhood there.
    pub max_home_conditioning: f64,
    /// Time spent on the local charts (part of `seconds`).
    pub seconds_local_charts: f64,
    /// Non-singular faces without a home chart (0 when the atlas is complete).
    pub faces_without_home: usize,
    pub boundary_word: String,
    pub seconds: f64,
    pub notes: Vec<String>,
}

/// Corner coordinates of one face in one chart (corner order of [`Mesh::face`]).
pub type Corners = [[f64; 2]; 3];

/// Largest [`AffineAtlas::conditioning`] of a face in its home chart before the face gets a
/// local chart of its own (Step 5): the neighbourhood is then stored to `ε × 10³ ≈ 2·10⁻¹³`
/// of each face. On eight.off the central chart reaches `10⁵` (order-2 jumps still 1e-9),
/// on 3holes.off `10⁷` (jumps 1e-3); `LocalCharts` sits at `10`–`10²`.
pub const LOCAL_CHART_CONDITIONING: f64 = 1e3;

/// Vertex-rings of faces to rehome gathered into one local chart around a seed face (Step 5,
/// [`LOCAL_CHART_CONDITIONING`]): the chart then spans a few rings of the graded
/// neighbourhood of the cone, small against its faces, and one chart serves tens of faces.
pub const LOCAL_CHART_RINGS: usize = 3;

/// A chart: faces and corner coordinates.
#[derive(Debug, Clone)]
struct Chart {
    faces: Vec<u32>,
    coords: Vec<[[f64; 2]; 3]>,
}

/// An affine atlas of a surface with a flat cone metric (see the module docs).
#[derive(Debug, Clone)]
pub struct AffineAtlas {
    mesh: Mesh,
    lengths: Vec<f64>,
    positions: Vec<[f64; 3]>,
    singular: Vec<u32>,
    charts: Vec<Chart>,
    /// Per face: (chart, slot in the chart).
    face_charts: Vec<Vec<(ChartId, u32)>>,
    home: Vec<ChartId>,
    /// Input-metric lengths of the refined mesh (R³ metric).
    input_lengths: Vec<f64>,
    /// Number of vertices of the input mesh (refined vertices are appended).
    pub original_vertices: usize,
    /// For every refined face, the input face it lies in (a face made by an intrinsic flip
    /// straddles two input faces and names one of them, see [`crate::metric::refine::Refiner::flip`]).
    pub face_origin: Vec<u32>,
    pub report: AtlasReport,
}

impl AffineAtlas {
    /// The R³ (input) metric of the refined mesh, by edge id.
    pub fn input_lengths(&self) -> &[f64] {
        &self.input_lengths
    }

    /// The charts containing the point of face `f` with barycentric coordinates `bary`
    /// (corner order of [`Mesh::face`]) and its coordinates in each.
    pub fn locate(&self, f: u32, bary: [f64; 3]) -> Vec<(ChartId, [f64; 2])> {
        let Some(cs) = self.face_charts.get(f as usize) else {
            return Vec::new();
        };
        cs.iter()
            .map(|&(c, k)| {
                let co = &self.charts[c as usize].coords[k as usize];
                let mut p = [0.0; 2];
                for i in 0..3 {
                    p[0] += bary[i] * co[i][0];
                    p[1] += bary[i] * co[i][1];
                }
                (c, p)
            })
            .collect()
    }

    /// The charts containing vertex `v` and its coordinates in each (a vertex on the cut has
    /// several copies in the central chart; each distinct copy is listed; a cone appears
    /// only in the central chart, once per corner of the fundamental polygon).
    pub fn vertex_coords(&self, v: u32) -> Vec<(ChartId, [f64; 2])> {
        let mut out: Vec<(ChartId, [f64; 2])> = Vec::new();
        if v as usize >= self.mesh.n_vertices() {
            return out;
        }
        let tol = self.tolerance();
        for c in self.mesh.vertex_corners(v) {
            let f = c / 3;
            let i = (c % 3) as usize;
            for &(ch, k) in &self.face_charts[f as usize] {
                let p = self.charts[ch as usize].coords[k as usize][i];
                if !out
                    .iter()
                    .any(|q| q.0 == ch && (q.1[0] - p[0]).hypot(q.1[1] - p[1]) <= tol)
                {
                    out.push((ch, p));
                }
            }
        }
        out.sort_by_key(|x| x.0);
        out
    }

    /// The transition maps from chart `a` to chart `b`: the distinct rigid motions over their
    /// common faces (a cut chart overlaps the central chart on both sides of the cut), each
    /// with the number of faces it holds on and its largest residual.
    pub fn transitions_between(&self, a: ChartId, b: ChartId) -> Vec<(RigidMotion, usize, f64)> {
        let mut out: Vec<(RigidMotion, usize, f64)> = Vec::new();
        if a as usize >= self.charts.len() || b as usize >= self.charts.len() {
            return out;
        }
        let scale = self.tolerance() * 1e3;
        for &f in &self.charts[a as usize].faces {
            let Some((m, r)) = self.transition(a, b, f) else {
                continue;
            };
            match out
                .iter_mut()
                .find(|x| (x.0.rot - m.rot).norm() < 1e-6 && (x.0.t - m.t).norm() < scale.max(1e-9))
            {
                Some(x) => {
                    x.1 += 1;
                    x.2 = x.2.max(r);
                }
                None => out.push((m, 1, r)),
            }
        }
        out
    }

    /// Faces and corner coordinates of chart `c` (for pictures and export).
    pub fn chart_faces(&self, c: ChartId) -> Option<(&[u32], &[Corners])> {
        self.charts
            .get(c as usize)
            .map(|ch| (ch.faces.as_slice(), ch.coords.as_slice()))
    }
}

impl FlatCharts for AffineAtlas {
    fn mesh(&self) -> &Mesh {
        &self.mesh
    }
    fn lengths(&self) -> &[f64] {
        &self.lengths
    }
    fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }
    fn singular_vertices(&self) -> &[u32] {
        &self.singular
    }
    fn n_charts(&self) -> usize {
        self.charts.len()
    }
    fn face_coords(&self, c: ChartId, f: u32) -> Option<[[f64; 2]; 3]> {
        let cs = self.face_charts.get(f as usize)?;
        let &(_, k) = cs.iter().find(|x| x.0 == c)?;
        Some(self.charts[c as usize].coords[k as usize])
    }
    fn charts_of_face(&self, f: u32) -> Vec<ChartId> {
        self.face_charts
            .get(f as usize)
            .map(|cs| cs.iter().map(|x| x.0).collect())
            .unwrap_or_default()
    }
    fn home_chart(&self, f: u32) -> Option<ChartId> {
        let h = *self.home.get(f as usize)?;
        (h != NONE).then_some(h)
    }
}
