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

pub mod charts;
pub mod develop;
pub mod placement;
pub mod svg;

pub use charts::{fit_rigid, ChartId, FlatCharts};
pub use placement::{Placement, PlacementOptions};

use crate::cut::{canonical_cut, CutOptions};
use crate::error::{Error, Result};
use crate::flow::{ricci_flow, FlowOptions, TargetSpec};
use crate::layout::place::layout;
use crate::layout::RigidMotion;
use crate::mesh::{topology, Mesh, Surface, NONE};
use crate::metric::refine::Refiner;
use crate::metric::{Euclidean, Geometry, Scheme};
use crate::progress::Progress;
use serde::Serialize;
use std::collections::VecDeque;
use std::f64::consts::PI;
use std::time::Instant;

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
    /// straddles two input faces and names one of them, see [`Refiner::flip`]).
    pub face_origin: Vec<u32>,
    pub report: AtlasReport,
}

impl AffineAtlas {
    /// Build the atlas of a connected surface (see the module docs).
    pub fn build(
        surface: &Surface,
        options: &AtlasOptions,
        progress: &mut dyn Progress,
    ) -> Result<AffineAtlas> {
        let t0 = Instant::now();
        let mesh = &surface.mesh;
        let topo = topology(mesh);
        if topo.components.len() != 1 {
            return Err(Error::topology(format!(
                "an atlas needs a connected surface; this one has {} components",
                topo.components.len()
            )));
        }
        let comp = &topo.components[0];
        if comp.vertices != mesh.n_vertices() {
            return Err(Error::topology(format!(
                "the mesh has {} vertices not used by any face; remove them first",
                mesh.n_vertices() - comp.vertices
            )));
        }
        let genus = comp.genus;
        let nb = comp.boundary_loops;
        let chi = 2 - 2 * genus - nb as i64;
        let lengths0 = surface.edge_lengths();
        let mut notes = Vec::new();
        let check_vertex = |v: u32, what: &str| -> Result<()> {
            if v as usize >= mesh.n_vertices() {
                return Err(Error::input(format!(
                    "{what} vertex {v} does not exist (the mesh has {} vertices)",
                    mesh.n_vertices()
                )));
            }
            if mesh.is_boundary_vertex(v) {
                return Err(Error::input(format!(
                    "{what} vertex {v} lies on the boundary; cones must be interior vertices"
                )));
            }
            Ok(())
        };
        // Step 1: the cones.
        let mut placement = None;
        let (cones, target_name): (Vec<(u32, f64)>, &str) = if let Some(list) = &options.cones {
            if nb > 0 {
                return Err(Error::input(
                    "cones are supported on closed surfaces only; an open surface gets the \
                     free-boundary flat metric with no singular point",
                ));
            }
            for &(v, k) in list {
                check_vertex(v, "cone")?;
                if !(k.is_finite() && k < 2.0 * PI) {
                    return Err(Error::input(format!(
                        "cone vertex {v} asks for curvature {k:.6}; a cone angle 2π − K̄ must be \
                         positive, so K̄ < 2π"
                    )));
                }
            }
            let sum: f64 = list.iter().map(|c| c.1).sum();
            if (sum - 2.0 * PI * chi as f64).abs() > 1e-9 {
                return Err(Error::input(format!(
                    "the cone curvatures sum to {sum:.6} but Gauss–Bonnet needs 2πχ = {:.6} \
                     (χ = {chi}); off by {:.3e}",
                    2.0 * PI * chi as f64,
                    sum - 2.0 * PI * chi as f64
                )));
            }
            let mut seen = std::collections::HashSet::new();
            for &(v, _) in list {
                if !seen.insert(v) {
                    return Err(Error::input(format!("cone vertex {v} is listed twice")));
                }
            }
            let l: Vec<(u32, f64)> = list.iter().copied().filter(|c| c.1 != 0.0).collect();
            (l, "cones")
        } else if nb > 0 {
            if let Singularity::Vertex(v) = options.singularity {
                return Err(Error::input(format!(
                    "an open surface needs no singular vertex (its curvature goes to the \
                     boundary), but vertex {v} was given"
                )));
            }
            (Vec::new(), "free-boundary")
        } else if genus == 1 {
            if let Singularity::Vertex(v) = options.singularity {
                return Err(Error::input(format!(
                    "a closed genus-1 surface has a flat metric without singular points, but \
                     vertex {v} was given"
                )));
            }
            (Vec::new(), "uniform")
        } else if genus == 0 {
            return Err(Error::topology(
                "a closed genus-0 surface has no flat metric with a single cone (it would need \
                 K̄ = 4π > 2π); give several cones with --cones (e.g. eight of π/2)",
            ));
        } else {
            let kappa = 2.0 * PI * chi as f64;
            let v = match options.singularity {
                Singularity::Vertex(v) => {
                    check_vertex(v, "singular")?;
                    v
                }
                Singularity::Auto => {
                    progress.report("placement", Some(0.0), "ranking candidate vertices");
                    let p = placement::place(surface, &lengths0, options, progress)?;
                    let v = p.chosen;
                    placement = Some(p);
                    v
                }
            };
            (vec![(v, kappa)], "single-cone")
        };

        // Step 2: valences around the cones.
        progress.report("refine", Some(0.0), "connectivity modification");
        let mut rep = RefinementReport {
            vertices_before: mesh.n_vertices(),
            ..RefinementReport::default()
        };
        let mut r = Refiner::new(
            mesh,
            &lengths0,
            Geometry::Euclidean,
            Some(&surface.positions),
        )?;
        rep.low_valence_before = rings_around(mesh, &cones, options.rings)
            .iter()
            .filter(|&&w| mesh.valence(w) < 6)
            .count();
        for &(v, k) in &cones {
            let need = (4.0 - 2.0 * k / PI - 1e-9).ceil().max(3.0) as usize;
            let before = mesh.valence(v);
            r.raise_valence(v, need)?;
            rep.cone_valence.push((v, before, need, 0));
        }
        rep.splits_step2 = r.splits();
        let step2 = r.finish()?;
        // Step 4 (cut) before Step 3 (flow): the cut only needs connectivity, and refines
        // around its base; the flow then runs once on the final mesh.
        progress.report("cut", Some(0.0), "canonical cut");
        let cut = canonical_cut(
            &step2.mesh,
            &step2.lengths,
            Geometry::Euclidean,
            step2.positions.as_deref(),
            &CutOptions {
                base: cones.first().map(|c| c.0),
                ..CutOptions::default()
            },
            progress,
        )?;
        rep.splits_cut = cut.refined.splits();
        // Step 2 (ii) after the cut's grading (which splits link edges of the cone, creating
        // valence-4 neighbours): the one-ring neighbours of every cone get valence ≥ 6 by
        // splitting their outer link edges off the cut, so the loops stay edge paths.
        let mut on_cut = std::collections::HashSet::new();
        for l in &cut.loops {
            for w in l.vertices.windows(2) {
                on_cut.insert((w[0].min(w[1]), w[0].max(w[1])));
            }
        }
        let (refined, ring_splits) = if options.rings > 0 && !cones.is_empty() {
            raise_ring_valence(cut.refined.clone(), &cones, 6, &on_cut)?
        } else {
            (cut.refined.clone(), 0)
        };
        rep.splits_ring = ring_splits;
        // Step 2 (ii) within `rings` rings: intrinsic flips, and splits to make room.
        let (refined, ring_work) = if options.rings > 0 && !cones.is_empty() {
            let around = rings_around(&refined.mesh, &cones, options.rings).len();
            flip_ring_valence(refined, &cones, options.rings, &on_cut, 40 * around + 1000)?
        } else {
            (refined, RingValenceWork::default())
        };
        rep.flips_ring = ring_work.flips;
        rep.splits_ring_room = ring_work.splits;
        let rmesh = refined.mesh.clone();
        rep.vertices_after = rmesh.n_vertices();
        for (k, c) in cones.iter().enumerate() {
            rep.cone_valence[k].3 = rmesh.valence(c.0);
        }
        rep.low_valence_after = rings_around(&rmesh, &cones, options.rings)
            .iter()
            .filter(|&&w| rmesh.valence(w) < 6)
            .count();
        rep.low_valence_ring1_after = rings_around(&rmesh, &cones, 1)
            .iter()
            .filter(|&&w| rmesh.valence(w) < 6)
            .count();
        let positions = refined
            .positions
            .clone()
            .ok_or_else(|| Error::numerical("internal error: the cut lost the positions"))?;
        // Face origin in the input mesh: compose the two refinements.
        let face_origin: Vec<u32> = refined
            .face_origin
            .iter()
            .map(|&f| step2.face_origin[f as usize])
            .collect();

        // Step 3: the flat metric.
        progress.report("flow", Some(0.0), "Euclidean Ricci flow");
        let target = match target_name {
            "free-boundary" => TargetSpec::FreeBoundary,
            "uniform" => TargetSpec::Uniform,
            _ => TargetSpec::Cones(cones.clone()),
        };
        let (flow, scheme_used, flow_notes) = match flat_flow(
            &rmesh,
            &refined.lengths,
            target.clone(),
            options.scheme,
            options.tolerance,
        ) {
            // Thurston's Chow–Luo bound uses its clamped intersection angles φ ≤ π/2, so it
            // can refuse at a valence-4 vertex made by the refinement (all four φ = π/2, by
            // exactly 0) what the φ = 0 bound of inversive distance admits.
            Err(Error::InvalidInput { message })
                if message.contains("Chow–Luo") && options.scheme == Scheme::Thurston =>
            {
                let (f, s, mut n) = flat_flow(
                    &rmesh,
                    &refined.lengths,
                    target,
                    Scheme::Inversive,
                    options.tolerance,
                )?;
                n.insert(
                    0,
                    format!(
                        "the thurston scheme refused the target ({message}); the metric comes \
                         from the {} scheme",
                        s.name()
                    ),
                );
                (f, s, n)
            }
            other => other?,
        };
        notes.extend(flow_notes);
        if !flow.converged {
            notes.push(format!(
                "the Ricci flow did not converge: max |K − K̄| = {:.3e} > {:.1e} after {} \
                 iterations; the charts are built from the metric reached",
                flow.max_curvature_error, options.tolerance, flow.iterations
            ));
        }
        let lengths = flow.lengths.clone();
        let area_distortion = area_distortion(
            &rmesh,
            &refined.lengths,
            &lengths,
            &face_origin,
            mesh.n_faces(),
        );

        // Segmentation: the canonical cut plus slits to the other cones.
        let mut cut_edge = vec![false; rmesh.n_edges()];
        for l in &cut.loops {
            for w in l.vertices.windows(2) {
                let h = rmesh.halfedge_between(w[0], w[1]).ok_or_else(|| {
                    Error::numerical(format!(
                        "internal error: loop {} lost its edge {}–{}",
                        l.label, w[0], w[1]
                    ))
                })?;
                cut_edge[rmesh.he_edge(h) as usize] = true;
            }
        }
        if cones.len() > 1 {
            add_slits(&rmesh, &lengths, &mut cut_edge, &cones[1..])?;
        }
        let reconnected = ring_splits + ring_work.flips + ring_work.splits > 0;
        let (disk, origin) = if cones.len() > 1 || reconnected {
            crate::cut::slice(&rmesh, &cut_edge)?
        } else {
            (cut.cut_mesh.clone(), cut.cut_vertex_origin.clone())
        };
        let mut dl = vec![0.0; disk.n_edges()];
        for h in 0..disk.n_corners() as u32 {
            dl[disk.he_edge(h) as usize] = lengths[rmesh.he_edge(h) as usize];
        }
        for f in 0..rmesh.n_faces() as u32 {
            let a = rmesh.face(f);
            let b = disk.face(f);
            if (0..3).any(|i| origin[b[i] as usize] != a[i]) {
                return Err(Error::numerical(format!(
                    "internal error: face {f} of the cut mesh does not match the surface"
                )));
            }
        }
        progress.report("layout", Some(0.0), "central chart");
        let central = layout::<Euclidean>(&disk, &dl, None)?;
        let singular: Vec<u32> = cones.iter().map(|c| c.0).collect();
        let mut atlas = AffineAtlas {
            mesh: rmesh,
            lengths,
            positions,
            singular,
            charts: Vec::new(),
            face_charts: Vec::new(),
            home: Vec::new(),
            input_lengths: refined.lengths.clone(),
            original_vertices: mesh.n_vertices(),
            face_origin,
            report: AtlasReport {
                genus,
                boundary_loops: nb,
                target: target_name.to_string(),
                singular_vertices: cones.iter().map(|c| c.0).collect(),
                placement,
                refinement: rep,
                scheme: scheme_used.name().to_string(),
                flow_converged: flow.converged,
                flow_iterations: flow.iterations,
                max_curvature_error: flow.max_curvature_error,
                gauss_bonnet_error: flow.gauss_bonnet_error,
                area_distortion,
                charts: Vec::new(),
                flipped_faces: 0,
                max_length_error: 0.0,
                max_transition_error: 0.0,
                max_relative_transition_error: 0.0,
                local_charts: 0,
                max_home_conditioning: 0.0,
                seconds_local_charts: 0.0,
                faces_without_home: 0,
                boundary_word: cut.boundary_word.clone(),
                seconds: 0.0,
                notes,
            },
        };
        let nf = atlas.mesh.n_faces();
        atlas.face_charts = vec![Vec::new(); nf];
        atlas.home = vec![NONE; nf];
        let coords: Vec<[[f64; 2]; 3]> = (0..nf as u32)
            .map(|f| {
                let v = disk.face(f);
                let mut c = [[0.0; 2]; 3];
                for i in 0..3 {
                    let p = central.positions[v[i] as usize];
                    c[i] = [p.re, p.im];
                }
                c
            })
            .collect();
        atlas.push_chart(
            Chart {
                faces: (0..nf as u32).collect(),
                coords,
            },
            "central",
            0,
        );
        atlas.cover(progress)?;
        atlas.finish_report();
        atlas.report.seconds = t0.elapsed().as_secs_f64();
        progress.report("atlas", Some(1.0), "done");
        Ok(atlas)
    }

    /// Whether face `f` touches a singular vertex.
    fn at_cone(&self, f: u32) -> bool {
        self.mesh.face(f).iter().any(|v| self.singular.contains(v))
    }

    /// The faces sharing a vertex with `f`, except faces at a cone (sorted).
    fn neighbourhood(&self, f: u32) -> Vec<u32> {
        let mut out = Vec::with_capacity(24);
        for v in self.mesh.face(f) {
            for g in self.mesh.vertex_faces(v) {
                if !self.at_cone(g) {
                    out.push(g);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Whether chart `c` contains the neighbourhood of `f` with one coordinate per vertex
    /// (within `tol`).
    fn homes(&self, c: ChartId, f: u32, tol: f64) -> bool {
        let mut seen: Vec<(u32, [f64; 2])> = Vec::with_capacity(16);
        for g in self.neighbourhood(f) {
            let Some(co) = self.face_coords(c, g) else {
                return false;
            };
            let v = self.mesh.face(g);
            for i in 0..3 {
                match seen.iter().find(|s| s.0 == v[i]) {
                    Some(s) => {
                        if (s.1[0] - co[i][0]).hypot(s.1[1] - co[i][1]) > tol {
                            return false;
                        }
                    }
                    None => seen.push((v[i], co[i])),
                }
            }
        }
        true
    }

    fn push_chart(&mut self, chart: Chart, kind: &'static str, rejected: usize) -> ChartId {
        let id = self.charts.len() as ChartId;
        for (k, &f) in chart.faces.iter().enumerate() {
            self.face_charts[f as usize].push((id, k as u32));
        }
        let mut flipped = 0;
        let mut lerr: f64 = 0.0;
        for (k, &f) in chart.faces.iter().enumerate() {
            if develop::signed_area2(&chart.coords[k]) <= 0.0 {
                flipped += 1;
            }
            lerr = lerr.max(develop::face_length_error(
                &self.mesh,
                &self.lengths,
                f,
                &chart.coords[k],
            ));
        }
        self.report.charts.push(ChartReport {
            id,
            kind,
            faces: chart.faces.len(),
            home_faces: 0,
            flipped_faces: flipped,
            max_length_error: lerr,
            rejected_faces: rejected,
        });
        self.charts.push(chart);
        id
    }

    /// Closure tolerance: 1e-7 of the mean edge length.
    fn tolerance(&self) -> f64 {
        let n = self.lengths.len().max(1) as f64;
        1e-7 * self.lengths.iter().sum::<f64>() / n
    }

    /// Give every non-singular face a home chart: the central chart where it suffices, cut
    /// charts developed around the rest.
    fn cover(&mut self, progress: &mut dyn Progress) -> Result<()> {
        let nf = self.mesh.n_faces();
        let tol = self.tolerance();
        let mut remaining: Vec<bool> = vec![false; nf];
        for f in 0..nf as u32 {
            if self.at_cone(f) {
                continue;
            }
            if self.homes(0, f, tol) {
                self.home[f as usize] = 0;
            } else {
                remaining[f as usize] = true;
            }
        }
        let total = remaining.iter().filter(|&&b| b).count().max(1);
        let mut guard = 0;
        while let Some(seed) = (0..nf as u32).find(|&f| remaining[f as usize]) {
            guard += 1;
            if guard > nf {
                break;
            }
            let left = remaining.iter().filter(|&&b| b).count();
            progress.report(
                "charts",
                Some(1.0 - left as f64 / total as f64),
                &format!(
                    "{} charts, {left} faces near the cut left",
                    self.charts.len()
                ),
            );
            // The connected cluster of remaining faces around the seed (across shared vertices).
            let mut in_cluster = vec![false; nf];
            let mut cluster = vec![seed];
            in_cluster[seed as usize] = true;
            let mut q = VecDeque::from([seed]);
            while let Some(f) = q.pop_front() {
                for v in self.mesh.face(f) {
                    for g in self.mesh.vertex_faces(v) {
                        if remaining[g as usize] && !in_cluster[g as usize] {
                            in_cluster[g as usize] = true;
                            cluster.push(g);
                            q.push_back(g);
                        }
                    }
                }
            }
            let mut homed = self.try_chart(&cluster, seed, &remaining, tol);
            if !homed.contains(&seed) {
                homed = self.try_chart(&[seed], seed, &remaining, tol);
            }
            if homed.is_empty() {
                return Err(Error::numerical(format!(
                    "face {seed}: its neighbourhood does not develop consistently into the \
                     plane (is the metric flat there?)"
                )));
            }
            for f in homed {
                remaining[f as usize] = false;
            }
        }
        self.add_local_charts(progress);
        Ok(())
    }

    /// Conditioning of face `f`'s neighbourhood in chart `c`: the largest
    /// `max(|x|, |y|) / (shortest metric side)` over the faces of [`Self::neighbourhood`]`(f)`
    /// there (`∞` when one is missing). Coordinates round to `ε |x|`, so `ε ×` this bounds
    /// the rounding of every face the spline basis of `f` is evaluated on, relative to that
    /// face.
    pub fn conditioning(&self, c: ChartId, f: u32) -> f64 {
        let mut worst: f64 = 0.0;
        for g in self.neighbourhood(f) {
            let Some(co) = self.face_coords(c, g) else {
                return f64::INFINITY;
            };
            let hs = self.mesh.face_halfedges(g);
            let short = hs
                .iter()
                .map(|&h| self.lengths[self.mesh.he_edge(h) as usize])
                .fold(f64::INFINITY, f64::min);
            let big = co
                .iter()
                .map(|p| p[0].abs().max(p[1].abs()))
                .fold(0.0, f64::max);
            worst = worst.max(big / short);
        }
        worst
    }

    /// Step 5, conditioning: a single cone of angle `2π(2g − 1)` grades the faces around it
    /// down by orders of magnitude (1e-7 of the central chart on 3holes.off), and a face whose
    /// corners are stored in a chart `10⁷` of its size across has them to only `1e-9` of
    /// itself — the spline bases built there then jump by up to `1e-3` (relative) across
    /// edges. Every face whose home chart has [`Self::conditioning`] above
    /// [`LOCAL_CHART_CONDITIONING`] is rehomed in a *local chart*: the development
    /// ([`develop`]) of the neighbourhoods of the faces still to rehome within
    /// [`LOCAL_CHART_RINGS`] vertex-rings of a seed face, seeded there (so the coordinates are
    /// of the size of the cluster), with the closure tolerance 1e-7 of the seed's
    /// neighbourhood's mean edge, validated like every chart. A face of the cluster takes it as
    /// its home chart when the chart contains its neighbourhood with one coordinate per vertex
    /// and conditions it within the bound; a seed left over gets a chart of its own
    /// neighbourhood alone (kept when it is better conditioned than the old home).
    fn add_local_charts(&mut self, progress: &mut dyn Progress) {
        let t0 = Instant::now();
        let nf = self.mesh.n_faces();
        let mut todo: Vec<bool> = (0..nf as u32)
            .map(|f| {
                let h = self.home[f as usize];
                h != NONE && self.conditioning(h, f) > LOCAL_CHART_CONDITIONING
            })
            .collect();
        let list: Vec<u32> = (0..nf as u32).filter(|&f| todo[f as usize]).collect();
        let mut region = vec![false; nf];
        let mut stamp = vec![u32::MAX; nf];
        for (k, &f) in list.iter().enumerate() {
            if !todo[f as usize] {
                continue;
            }
            if k % 64 == 0 {
                progress.report(
                    "charts",
                    Some(k as f64 / list.len().max(1) as f64),
                    &format!("local charts near the cone: {k} of {} faces", list.len()),
                );
            }
            // Faces to rehome within LOCAL_CHART_RINGS vertex-rings of f.
            let mut cluster = vec![f];
            stamp[f as usize] = f;
            let mut front = vec![f];
            for _ in 0..LOCAL_CHART_RINGS {
                let mut next = Vec::new();
                for &g in &front {
                    for v in self.mesh.face(g) {
                        for e in self.mesh.vertex_faces(v) {
                            if todo[e as usize] && stamp[e as usize] != f {
                                stamp[e as usize] = f;
                                cluster.push(e);
                                next.push(e);
                            }
                        }
                    }
                }
                front = next;
            }
            self.try_local_chart(&cluster, f, &mut todo, &mut region, true);
            if todo[f as usize] {
                self.try_local_chart(&[f], f, &mut todo, &mut region, false);
                todo[f as usize] = false;
            }
        }
        self.report.local_charts = self
            .report
            .charts
            .iter()
            .filter(|c| c.kind == "local")
            .count();
        let (mut left, mut worst) = (0usize, 0.0f64);
        for &f in &list {
            let c = self.conditioning(self.home[f as usize], f);
            if c > LOCAL_CHART_CONDITIONING {
                left += 1;
                worst = worst.max(c);
            }
        }
        if left > 0 {
            self.report.notes.push(format!(
                "{left} faces keep a home chart more than {LOCAL_CHART_CONDITIONING:.0e} of \
                 their size across (worst {worst:.2e}): no local chart conditioned them \
                 better; their coordinates there are accurate to ~{:.0e} of the face",
                worst * f64::EPSILON
            ));
        }
        self.report.seconds_local_charts = t0.elapsed().as_secs_f64();
    }

    /// One local chart for `cluster` seeded at `seed` ([`Self::add_local_charts`]); `strict`:
    /// a face is rehomed only within [`LOCAL_CHART_CONDITIONING`], else whenever the chart
    /// conditions it better than its old home. The chart is dropped when it rehomes nothing.
    fn try_local_chart(
        &mut self,
        cluster: &[u32],
        seed: u32,
        todo: &mut [bool],
        region: &mut [bool],
        strict: bool,
    ) {
        let mut sum = 0.0;
        let mut count = 0usize;
        for g in self.neighbourhood(seed) {
            for h in self.mesh.face_halfedges(g) {
                sum += self.lengths[self.mesh.he_edge(h) as usize];
                count += 1;
            }
        }
        let tol = 1e-7 * sum / count.max(1) as f64;
        let mut marked = Vec::new();
        for &f in cluster {
            for g in self.neighbourhood(f) {
                if !region[g as usize] {
                    region[g as usize] = true;
                    marked.push(g);
                }
            }
        }
        let dev = develop::develop(&self.mesh, &self.lengths, region, seed, tol);
        for g in marked {
            region[g as usize] = false;
        }
        if dev.faces.is_empty() {
            return;
        }
        let id = self.push_chart(
            Chart {
                faces: dev.faces,
                coords: dev.coords,
            },
            "local",
            dev.rejected,
        );
        let mut any = false;
        for &f in cluster {
            if !todo[f as usize] || !self.homes(id, f, tol) {
                continue;
            }
            let c = self.conditioning(id, f);
            let better = if strict {
                c <= LOCAL_CHART_CONDITIONING
            } else {
                c < self.conditioning(self.home[f as usize], f)
            };
            if better {
                self.home[f as usize] = id;
                todo[f as usize] = false;
                any = true;
            }
        }
        if !any {
            self.pop_chart(id);
        }
    }

    /// Remove the last chart (`id`) again.
    fn pop_chart(&mut self, id: ChartId) {
        if let Some(chart) = self.charts.pop() {
            for &f in &chart.faces {
                self.face_charts[f as usize].retain(|x| x.0 != id);
            }
            self.report.charts.pop();
        }
    }

    /// Develop the union of the neighbourhoods of `cluster` from `seed`; keep the chart if it
    /// homes some remaining face; returns the faces it homes.
    fn try_chart(&mut self, cluster: &[u32], seed: u32, remaining: &[bool], tol: f64) -> Vec<u32> {
        let nf = self.mesh.n_faces();
        let mut region = vec![false; nf];
        for &f in cluster {
            for g in self.neighbourhood(f) {
                region[g as usize] = true;
            }
        }
        let dev = develop::develop(&self.mesh, &self.lengths, &region, seed, tol);
        if dev.faces.is_empty() {
            return Vec::new();
        }
        let id = self.push_chart(
            Chart {
                faces: dev.faces.clone(),
                coords: dev.coords,
            },
            "cut",
            dev.rejected,
        );
        let homed: Vec<u32> = cluster
            .iter()
            .copied()
            .filter(|&f| remaining[f as usize] && self.homes(id, f, tol))
            .collect();
        if homed.is_empty() {
            self.pop_chart(id);
            return Vec::new();
        }
        for &f in &homed {
            self.home[f as usize] = id;
        }
        homed
    }

    fn finish_report(&mut self) {
        let mut worst: f64 = 0.0;
        let mut worst_rel: f64 = 0.0;
        let mut worst_cond: f64 = 0.0;
        for f in 0..self.mesh.n_faces() as u32 {
            let short = self
                .mesh
                .face_halfedges(f)
                .iter()
                .map(|&h| self.lengths[self.mesh.he_edge(h) as usize])
                .fold(f64::INFINITY, f64::min);
            let cs = &self.face_charts[f as usize];
            for k in 1..cs.len() {
                if let Some((_, r)) = self.transition(cs[0].0, cs[k].0, f) {
                    worst = worst.max(r);
                    worst_rel = worst_rel.max(r / short);
                }
            }
            let h = self.home[f as usize];
            if h != NONE {
                worst_cond = worst_cond.max(self.conditioning(h, f));
            }
        }
        self.report.max_transition_error = worst;
        self.report.max_relative_transition_error = worst_rel;
        self.report.max_home_conditioning = worst_cond;
        for c in &mut self.report.charts {
            c.home_faces = 0;
        }
        let mut without = 0;
        for f in 0..self.mesh.n_faces() {
            let h = self.home[f];
            if h != NONE {
                self.report.charts[h as usize].home_faces += 1;
            } else if !self.at_cone(f as u32) {
                without += 1;
            }
        }
        self.report.faces_without_home = without;
        self.report.flipped_faces = self.report.charts.iter().map(|c| c.flipped_faces).sum();
        self.report.max_length_error = self
            .report
            .charts
            .iter()
            .map(|c| c.max_length_error)
            .fold(0.0, f64::max);
    }

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

/// The flat metric of `target` by Newton's method (tolerance `tolerance`, at most 400
/// iterations) with `scheme`; when that does not converge, again with inversive distance
/// and then tangential circle packing (strong cones can break Thurston's clamped packing).
/// Returns the result, the scheme used and notes.
pub fn flat_flow(
    mesh: &Mesh,
    lengths: &[f64],
    target: TargetSpec,
    scheme: Scheme,
    tolerance: f64,
) -> Result<(crate::flow::FlowResult, Scheme, Vec<String>)> {
    let mut unlimited = usize::MAX;
    let f = flat_flow_limited(
        mesh,
        lengths,
        target,
        scheme,
        tolerance,
        400,
        &mut unlimited,
    )?;
    Ok((f.result, f.scheme, f.notes))
}

/// What [`flat_flow_limited`] produced.
#[derive(Debug, Clone)]
pub struct FlatFlow {
    /// The converged flow, or the last one that ran when none converged.
    pub result: crate::flow::FlowResult,
    /// The scheme of `result`.
    pub scheme: Scheme,
    pub notes: Vec<String>,
    /// Newton iterations of all the schemes tried together.
    pub iterations: usize,
    /// The smallest max |K − K̄| any scheme reached.
    pub best_error: f64,
}

/// [`flat_flow`] with at most `max_iterations` Newton iterations per scheme and `budget`
/// iterations in all (the spent ones are subtracted; no further scheme is tried once it is
/// 0). The candidate flows of the automatic placement run with such a budget
/// ([`placement::PlacementOptions`]).
pub fn flat_flow_limited(
    mesh: &Mesh,
    lengths: &[f64],
    target: TargetSpec,
    scheme: Scheme,
    tolerance: f64,
    max_iterations: usize,
    budget: &mut usize,
) -> Result<FlatFlow> {
    let mut notes = Vec::new();
    let mut schemes = vec![scheme];
    for s in [Scheme::Inversive, Scheme::Tangential] {
        if !schemes.contains(&s) {
            schemes.push(s);
        }
    }
    let mut last = None;
    let mut iterations = 0;
    let mut best_error = f64::INFINITY;
    for (k, &s) in schemes.iter().enumerate() {
        if *budget == 0 {
            notes.push(format!(
                "the iteration budget was spent before the {} scheme could run",
                s.name()
            ));
            break;
        }
        let run = ricci_flow(
            mesh,
            lengths,
            &FlowOptions {
                geometry: Geometry::Euclidean,
                scheme: s,
                target: target.clone(),
                tolerance,
                max_iterations: Some(max_iterations.min(*budget).max(1)),
                ..FlowOptions::default()
            },
            &mut crate::progress::NoProgress,
        );
        if let Ok(f) = &run {
            *budget = budget.saturating_sub(f.iterations.max(1));
        }
        match run {
            Ok(f) if f.converged => {
                if k > 0 {
                    notes.push(format!(
                        "the {} flow did not converge; the metric comes from the {} scheme",
                        scheme.name(),
                        s.name()
                    ));
                }
                notes.extend(f.notes.iter().cloned());
                iterations += f.iterations;
                best_error = best_error.min(f.max_curvature_error);
                return Ok(FlatFlow {
                    result: f,
                    scheme: s,
                    notes,
                    iterations,
                    best_error,
                });
            }
            Ok(f) => {
                notes.push(format!(
                    "{} flow: max |K − K̄| = {:.3e} after {} iterations (not converged)",
                    s.name(),
                    f.max_curvature_error,
                    f.iterations
                ));
                iterations += f.iterations;
                if f.max_curvature_error.is_finite() {
                    best_error = best_error.min(f.max_curvature_error);
                }
                last = Some(Ok((f, s)));
            }
            Err(e) => {
                if k == 0 {
                    // A refused target (Gauss–Bonnet, Chow–Luo) is refused by every scheme.
                    if matches!(e, Error::InvalidInput { .. }) {
                        return Err(e);
                    }
                }
                notes.push(format!("{} flow failed: {e}", s.name()));
                if last.is_none() {
                    last = Some(Err(e));
                }
            }
        }
    }
    match last {
        Some(Ok((f, s))) => {
            notes.extend(f.notes.iter().cloned());
            Ok(FlatFlow {
                result: f,
                scheme: s,
                notes,
                iterations,
                best_error,
            })
        }
        Some(Err(e)) => Err(e),
        None => Err(Error::numerical("no flow was run")),
    }
}

/// Give the one-ring neighbours of every cone valence ≥ `min`: in rounds, split the longest
/// link edge of each such neighbour that avoids the cones and the `protected` edges (vertex
/// pairs, smaller first). Returns the refinement and the number of splits.
pub fn raise_ring_valence(
    refined: crate::metric::refine::Refined,
    cones: &[(u32, f64)],
    min: usize,
    protected: &std::collections::HashSet<(u32, u32)>,
) -> Result<(crate::metric::refine::Refined, usize)> {
    let mut refined = refined;
    let mut total = 0;
    for _round in 0..16 {
        let m = &refined.mesh;
        let is_cone = |x: u32| cones.iter().any(|c| c.0 == x);
        let mut todo: Vec<(u32, u32)> = Vec::new();
        for &(v, _) in cones {
            for w in m.vertex_neighbors(v) {
                if m.is_boundary_vertex(w) || is_cone(w) || m.valence(w) >= min {
                    continue;
                }
                let mut best: Option<(f64, (u32, u32))> = None;
                for f in m.vertex_faces(w) {
                    let t = m.face(f);
                    if t.iter().any(|&x| is_cone(x)) {
                        continue;
                    }
                    let i = t.iter().position(|&x| x == w).unwrap_or(0);
                    let (a, b) = (t[(i + 1) % 3], t[(i + 2) % 3]);
                    let key = (a.min(b), a.max(b));
                    if protected.contains(&key) || todo.contains(&key) {
                        continue;
                    }
                    let e = m.face_edges_opposite(f)[i];
                    let l = refined.lengths[e as usize];
                    if best.is_none_or(|b| l > b.0) {
                        best = Some((l, key));
                    }
                }
                if let Some((_, key)) = best {
                    todo.push(key);
                }
            }
        }
        if todo.is_empty() {
            break;
        }
        let mut r = Refiner::resume(refined, Geometry::Euclidean)?;
        for (a, b) in todo {
            if r.split_between(a, b).is_some() {
                total += 1;
            }
        }
        refined = r.finish()?;
    }
    Ok((refined, total))
}

/// What [`flip_ring_valence`] did.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct RingValenceWork {
    pub flips: usize,
    pub splits: usize,
    pub rounds: usize,
    /// Whether every vertex within the rings reached valence ≥ 6 (false: the work bound was
    /// reached, or no flip or split applied; the count left is in
    /// [`RefinementReport::low_valence_after`]).
    pub complete: bool,
}

/// Paper 000 §4 Step 2 (ii): every vertex within `rings` edge-rings of a cone gets valence
/// ≥ 6, by **intrinsic edge flips** ([`Refiner::flip`]) combined with intrinsic splits, both
/// metric-preserving. Greedy, in rounds (ring distances recomputed each round, kept up to
/// date within it; nearest vertices first): for a vertex `w` below 6, flip an edge `(a, b)`
/// opposite `w` (face `(w, a, b)`, replaced by `(w, x)`) when that keeps `a` and `b` at
/// valence ≥ 6 if they lie within the rings (≥ 5 otherwise), the edge is neither a
/// `protected` edge (the cut loops) nor at a cone, `x` is not a cone, and the flip is
/// intrinsically legal (strictly convex quad); among such flips the one leaving the most
/// spare valence, then the shortest new edge. Otherwise split (midpoint) an edge opposite
/// `w` to make room: the one whose endpoints and far vertex `x` lie farthest from the cones,
/// then the longest, so that the new valence-4 vertex lies outside the rings when `w` is on
/// the last ring and the deficit moves outwards otherwise. The new vertices just outside the
/// rings are then raised to valence 5 by flips where one is allowed (no splits there).
///
/// Why 5 and not 4 outside the rings: a valence-4 vertex whose four Thurston intersection
/// angles are clamped to π/2 fails the Chow–Luo condition (paper 000 eq. 7) of a flat target
/// by exactly 0, and the flat flow then refuses the target; the split vertices just outside
/// the rings are such vertices. Splits stop at edges shorter than 1e-6 of the longest.
///
/// At most `max_ops` flips and splits; a round that changes nothing ends the search.
/// Vertex ids are kept (new vertices appended), so the cut loops stay edge paths: a flip
/// never crosses an edge other than the one it removes, and protected edges are never split.
pub fn flip_ring_valence(
    refined: crate::metric::refine::Refined,
    cones: &[(u32, f64)],
    rings: usize,
    protected: &std::collections::HashSet<(u32, u32)>,
    max_ops: usize,
) -> Result<(crate::metric::refine::Refined, RingValenceWork)> {
    let mut work = RingValenceWork::default();
    if rings == 0 || cones.is_empty() {
        work.complete = true;
        return Ok((refined, work));
    }
    let n0 = refined.mesh.n_vertices() as u32;
    let mut r = Refiner::resume(refined, Geometry::Euclidean)?;
    let is_cone = |x: u32| cones.iter().any(|c| c.0 == x);
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    // Splits stop at edges shorter than 1e-6 of the longest (the metric stays well resolved).
    let min_len = 1e-6
        * (0..r.n_faces() as u32 * 3)
            .map(|h| r.length(h))
            .fold(0.0, f64::max);
    for _round in 0..4 * max_ops.max(1) {
        let mut dist = refiner_ring_distances(&r, cones, rings + 1);
        let mut low: Vec<u32> = (0..r.n_vertices() as u32)
            .filter(|&w| {
                let d = dist[w as usize];
                let target = if d <= rings { 6 } else { 5 };
                d >= 1
                    && (d <= rings || (d == rings + 1 && w >= n0))
                    && !r.is_boundary_vertex(w)
                    && r.valence(w) < target
            })
            .collect();
        if low.is_empty() {
            break;
        }
        if work.flips + work.splits >= max_ops {
            break;
        }
        work.rounds += 1;
        let ops_before = work.flips + work.splits;
        low.sort_by_key(|&w| (dist[w as usize], w));
        for w in low {
            if work.flips + work.splits >= max_ops {
                break;
            }
            let inside = dist[w as usize] <= rings;
            let target = if inside { 6 } else { 5 };
            while r.valence(w) < target && work.flips + work.splits < max_ops {
                let depth = |v: u32| dist.get(v as usize).copied().unwrap_or(usize::MAX);
                let need = |v: u32| if depth(v) <= rings { 6 } else { 5 };
                let mut best_flip: Option<((i64, f64), u32)> = None;
                let mut best_split: Option<((usize, f64), u32)> = None;
                for h in r.link(w) {
                    let (a, b) = r.endpoints(h);
                    if is_cone(a) || is_cone(b) || protected.contains(&key(a, b)) {
                        continue;
                    }
                    let x = r.opposite_across(h);
                    let l = r.length(h);
                    // The new vertex of a split lies next to a, b, w and x; prefer a, b, x
                    // far out, where its valence 4 can later be raised by a flip.
                    let far = depth(a).min(depth(b)).min(x.map_or(usize::MAX, depth));
                    if l > min_len && best_split.is_none_or(|s| (far, l) > s.0) {
                        best_split = Some(((far, l), h));
                    }
                    let Some(x) = x else {
                        continue;
                    };
                    if x == w || is_cone(x) || r.halfedge(w, x).is_some() {
                        continue;
                    }
                    let sa = r.valence(a) as i64 - 1 - need(a);
                    let sb = r.valence(b) as i64 - 1 - need(b);
                    if sa < 0 || sb < 0 {
                        continue;
                    }
                    let Ok(new_len) = r.flip_length(h) else {
                        continue;
                    };
                    let score = (sa.min(sb), -new_len / l);
                    if best_flip.is_none_or(|f| score > f.0) {
                        best_flip = Some((score, h));
                    }
                }
                if let Some((_, h)) = best_flip {
                    let x = r.opposite_across(h).unwrap_or(NONE);
                    r.flip(h)?;
                    work.flips += 1;
                    // The new edge (w, x) can only bring x closer.
                    let dw = depth(w);
                    if let Some(dx) = dist.get_mut(x as usize) {
                        *dx = (*dx).min(dw + 1);
                    }
                } else if let Some(((far, _), h)) = best_split.filter(|_| inside) {
                    r.split(h, 0.5);
                    work.splits += 1;
                    dist.push(far.min(depth(w)).saturating_add(1));
                } else {
                    break;
                }
            }
        }
        if work.flips + work.splits == ops_before {
            // Nothing more can be done (every remaining vertex is stuck).
            break;
        }
    }
    let dist = refiner_ring_distances(&r, cones, rings);
    work.complete = (0..r.n_vertices() as u32).all(|w| {
        let d = dist[w as usize];
        d == 0 || d > rings || r.is_boundary_vertex(w) || r.valence(w) >= 6
    });
    Ok((r.finish()?, work))
}

/// Edge-ring distance from the cones over a [`Refiner`]'s current connectivity, up to
/// `limit` (farther vertices get `usize::MAX`).
fn refiner_ring_distances(r: &Refiner, cones: &[(u32, f64)], limit: usize) -> Vec<usize> {
    let mut d = vec![usize::MAX; r.n_vertices()];
    let mut q = VecDeque::new();
    for &(v, _) in cones {
        if (v as usize) < d.len() {
            d[v as usize] = 0;
            q.push_back(v);
        }
    }
    while let Some(v) = q.pop_front() {
        if d[v as usize] >= limit {
            continue;
        }
        for w in r.neighbors(v) {
            if d[w as usize] == usize::MAX {
                d[w as usize] = d[v as usize] + 1;
                q.push_back(w);
            }
        }
    }
    d
}

/// Vertices within `rings` edge-rings of the cones (the cones excluded).
fn rings_around(mesh: &Mesh, cones: &[(u32, f64)], rings: usize) -> Vec<u32> {
    let mut d = vec![usize::MAX; mesh.n_vertices()];
    let mut q = VecDeque::new();
    for &(v, _) in cones {
        if (v as usize) < d.len() {
            d[v as usize] = 0;
            q.push_back(v);
        }
    }
    let mut out = Vec::new();
    while let Some(v) = q.pop_front() {
        if d[v as usize] >= rings {
            continue;
        }
        for w in mesh.vertex_neighbors(v) {
            if d[w as usize] == usize::MAX {
                d[w as usize] = d[v as usize] + 1;
                out.push(w);
                q.push_back(w);
            }
        }
    }
    out
}

/// Paper 000 §4 Step 1: `Σ_f (log S_f − log s_f)² / n` with `S_f` the area in the metric
/// `reference` and `s_f` the area in `flat`, over the faces of the *input* mesh: refined
/// faces are summed into the input face they lie in (`face_origin`, `n_input` input faces),
/// so the measure does not depend on how finely the cone's neighbourhood was refined.
pub fn area_distortion(
    mesh: &Mesh,
    reference: &[f64],
    flat: &[f64],
    face_origin: &[u32],
    n_input: usize,
) -> f64 {
    let mut a = vec![0.0; n_input];
    let mut b = vec![0.0; n_input];
    for f in 0..mesh.n_faces() as u32 {
        let e = mesh.face_edges_opposite(f);
        let o = face_origin.get(f as usize).copied().unwrap_or(f) as usize;
        if o >= n_input {
            continue;
        }
        a[o] += heron(e.map(|e| reference[e as usize]));
        b[o] += heron(e.map(|e| flat[e as usize]));
    }
    let mut sum = 0.0;
    let mut n = 0usize;
    for (x, y) in a.iter().zip(&b) {
        if *x > 0.0 && *y > 0.0 {
            sum += (x.ln() - y.ln()).powi(2);
            n += 1;
        }
    }
    sum / n.max(1) as f64
}

/// Compatibility re-export: Heron's formula (Kahan's stable form) moved to
/// [`crate::numeric::heron`]; the path `ricci::atlas::heron` keeps working.
pub use crate::numeric::heron;

/// Add to `cut_edge` a shortest path (in `lengths`) from the current cut graph to every cone
/// in `others`, through vertices off the cut graph and off the boundary.
fn add_slits(
    mesh: &Mesh,
    lengths: &[f64],
    cut_edge: &mut [bool],
    others: &[(u32, f64)],
) -> Result<()> {
    use crate::numeric::dijkstra::{Dijkstra, NO_PRED};
    for &(target, _) in others {
        let nv = mesh.n_vertices();
        let mut on_cut = vec![false; nv];
        for (e, _) in cut_edge.iter().enumerate().filter(|x| *x.1) {
            {
                let [a, b] = mesh.edge_vertices(e as u32);
                on_cut[a as usize] = true;
                on_cut[b as usize] = true;
            }
        }
        if on_cut[target as usize] {
            continue;
        }
        let on_cut = &on_cut;
        let mut search = Dijkstra::new(nv);
        search.offer(target, 0.0, NO_PRED);
        let hit = search.run(
            |v| {
                mesh.outgoing(v).filter_map(move |h| {
                    let w = mesh.he_tip(h);
                    (!mesh.is_boundary_vertex(w) || on_cut[w as usize])
                        .then(|| (w, lengths[mesh.he_edge(h) as usize]))
                })
            },
            |_, v| on_cut[v as usize],
        );
        let Some(hit) = hit else {
            return Err(Error::topology(format!(
                "cone vertex {target} cannot be joined to the cut graph"
            )));
        };
        let mut v = hit;
        while v != target {
            let p = search.pred(v);
            let h = mesh
                .halfedge_between(p, v)
                .ok_or_else(|| Error::numerical("internal error: slit path without an edge"))?;
            cut_edge[mesh.he_edge(h) as usize] = true;
            v = p;
        }
    }
    Ok(())
}
