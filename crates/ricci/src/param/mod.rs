//! Conformal UV maps of triangle meshes with cones and seams (`ricci param`).
//!
//! For every connected component of the input (each becomes its own chart):
//!
//! 1. **Target curvature.** Surfaces with boundary: flat inside, and on the boundary
//!    * `free` — `u = 0` on the boundary (the boundary keeps its lengths): among all conformal
//!      flattenings the one of least area distortion in the Dirichlet sense, the "minimal area
//!      distortion" boundary condition of Boundary First Flattening (Sawhney–Crane 2017, §4.3;
//!      Springborn–Schröder–Pinkall 2008 §5);
//!    * `round` — the boundary on a circle ([`crate::flow::TargetSpec::RoundBoundary`]);
//!    * `fixed-angles` — the boundary keeps its geodesic curvature `κ_i = π − Σθ` (the corner
//!      angles of the flattened boundary equal the surface's), with the interior curvature
//!      `2πχ − Σκ` moved to the boundary in proportion to the dual boundary lengths (BFF §4.2
//!      "prescribed curvature").
//!
//!    With cones asked for (`--cones N|auto|V=K,…`, interior vertices), the chart is flat
//!    inside except at the cones, placed by the greedy with the boundary held and curved for
//!    the least linearised σ(2u) as on the disk of free seams (submodule `free`,
//!    [`cones::free_boundary_cones`]); the cut runs from each cone to the boundary (step 3).
//!    The boundary then follows its condition with what the cones leave (Gauss–Bonnet,
//!    `Σ κ̄ + Σ K̄ = 2πχ`; submodule `boundary`): `free` holds `u = 0`; `round` puts every
//!    loop on a circle ([`crate::flow::TargetSpec::RoundBoundaryCones`]; genus 0: the longest
//!    loop turns by `2π − Σ K̄`, the holes by `−2π`), laid out as arcs of one radius between
//!    the cuts; `fixed-angles` keeps the surface's corner angles, greedy cones moved by a
//!    common amount to carry the interior's curvature (given cones keep theirs and the
//!    rest goes to the boundary as without cones). `--seamless` on a chart with boundary is
//!    `fixed-angles` with the cones rounded to quarter turns and then the boundary's turning
//!    to quarter turns with the total the cones leave, loop by loop: each loop's total
//!    rounded, then its running sum, so the corners are spread along the loop
//!    (`boundary::quarter_turn_boundary`).
//!
//!    Closed surfaces of genus ≥ 1 with [`SeamMode::Free`] (`--seams free`): cut along the
//!    homology generators into a disk, which is flattened as above with `free` (`u = 0` on
//!    the cut) and cones inside placed by the greedy with the cut held (submodule `free`); the
//!    homology seams are then not rigid. Otherwise closed surfaces: cones `K̄_c` at given vertices, or placed by the greedy of
//!    [`cones`] (Ben-Chen–Gotsman–Bunin 2008), flat elsewhere; a torus may have none.
//!    Greedy cones can be corrected on the nonlinear flow
//!    ([`ParamOptions::cone_corrections`], [`cones::correct_cone_curvatures`]): the cone
//!    curvatures are re-solved for the least `L²` norm of the flow's log scale factor
//!    (Soliman–Slepčev–Crane 2018 §4 with the positions fixed) and the flow runs again.
//!    `--seamless` rounds cone curvatures to multiples of π/2 ([`cones::round_to_quarter_turns`];
//!    Campen–Shen–Zhou–Zorin 2019 §3): on genus 0 every transition across a seam is then a
//!    rotation by a multiple of 90° (the holonomy around a cone is its curvature). On closed
//!    genus ≥ 1 the flow's metric is then changed by the least change of log lengths that
//!    makes the holonomy of `2g` homology loops multiples of π/2 as well ([`seamless`]).
//! 2. **Conformal flow** with intrinsic Delaunay flips ([`crate::flow`], `Scheme::Conformal`:
//!    discrete conformal equivalence of Gu–Luo–Sun–Wu 2018 / Springborn 2020, solved by
//!    Newton's method on the convex energy). The result is a flat metric with cones on a
//!    triangulation `T` of the same surface (same vertices; some edges flipped).
//! 3. **Cut** ([`seams`]): a shortest-path cut graph through every cone and the homology
//!    generators, first on input edges that `T` kept, so that the input mesh and `T` are
//!    opened along the same curves ([`transfer`]).
//! 4. **Layout** of the opened `T` in the plane ([`crate::layout::place::layout`]), exact up to
//!    rounding because the metric is flat off the cones, which lie on the cut.
//! 5. **UVs on the input's own faces**: every input corner takes the layout position of its
//!    vertex in the same wedge between cut edges ([`seams::wedge_key`], [`input_face_map`]);
//!    seams are vertices with several `vt`. The map is exact at the vertices and linear on
//!    input faces. When an input face's UV triangle would fold (`T` flipped input edges
//!    there), or no cut on kept input edges reaches every cone, the cut runs on `T`'s own
//!    edges and the UVs are written on the **common subdivision** of the input and `T`
//!    (Gillespie–Springborn–Crane 2021 §5; [`crate::metric::common_subdivision`]): every
//!    piece lies in one input face and one face of `T` and none folds
//!    ([`Parametrization::subdivision`], [`Chart::uv_faces`]).
//!    Before that, the UVs on the input faces move to the least-squares conformal map with
//!    the same cones, seam rotations and boundary ([`lscm`]; [`Chart::lscm_refined`]), kept
//!    when no triangle folds: it lowers the distortion of the input's own triangles and can
//!    unfold what the exact map folds, and then the input faces carry the map.
//! 6. **Flip-free** ([`ladder`]): a chart whose written triangles fold, or lie within
//!    rounding of folding (scale factors beyond what double-precision UVs resolve), or whose
//!    flow does not converge, is recomputed with rigid seams, then with more greedy cones;
//!    the chart says so ([`Chart::fallback`]).
//! 7. **Packing**: each chart scaled to its surface area, rotated to its smallest bounding
//!    box (not with `--seamless`), shelf-packed and scaled into `[margin, 1 − margin]²`.

pub(crate) mod boundary;
mod chart;
pub mod cones;
mod develop;
mod free;
mod ladder;
mod lscm;
pub mod seamless;
pub(crate) mod seams;
pub mod sphere;
pub mod svg;
mod transfer;
mod unfold;

pub use transfer::input_face_map;

use crate::analysis::distortion::{uv_stats, DistortionStats};
use crate::error::{Error, Result};
use crate::mesh::{topology, Mesh, Surface, NONE};
use crate::progress::Progress;
use serde::Serialize;
use std::time::Instant;

/// Which cones a closed chart gets.
#[derive(Debug, Clone, PartialEq)]
pub enum ConeSpec {
    /// Genus 1 and surfaces with boundary: none; otherwise automatic with the default bound
    /// (`Auto { 1.0 }`). `Count`, `Auto` and `Given` place cones inside a surface with
    /// boundary too (under every boundary condition).
    Default,
    /// No cones (only a torus, or a surface with boundary, can be flat without).
    None,
    /// `(vertex, K̄)` by input vertex id, K̄ in radians (cone angle `2π − K̄`).
    Given(Vec<(u32, f64)>),
    /// This many cones by the greedy of [`cones`].
    Count(usize),
    /// As few greedy cones as give a linearised `max |log area ratio| ≤ max_area_distortion`.
    Auto { max_area_distortion: f64 },
}

/// Boundary condition of charts with boundary (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoundaryMode {
    Free,
    Round,
    FixedAngles,
}

impl std::str::FromStr for BoundaryMode {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "free" => Ok(BoundaryMode::Free),
            "round" => Ok(BoundaryMode::Round),
            "fixed-angles" | "fixed" => Ok(BoundaryMode::FixedAngles),
            _ => Err(format!(
                "unknown boundary '{s}' (expected free, round or fixed-angles)"
            )),
        }
    }
}

/// How closed components of genus ≥ 1 are opened (`ricci param --seams`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SeamMode {
    /// A flat metric with cones on the closed surface: every transition across a seam is a
    /// rigid motion (a rotation by the holonomy), what seamless maps and quad meshing need.
    #[default]
    Rigid,
    /// The homology seams are free (submodule `free`): the surface cut along its homology
    /// generators is flattened as a disk with `u = 0` on the cut and cones inside (Boundary
    /// First Flattening's kind of map on genus ≥ 1). Cone seams stay rigid.
    Free,
}

impl std::str::FromStr for SeamMode {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "rigid" => Ok(SeamMode::Rigid),
            "free" => Ok(SeamMode::Free),
            _ => Err(format!("unknown seams '{s}' (expected rigid or free)")),
        }
    }
}

impl SeamMode {
    pub fn name(self) -> &'static str {
        match self {
            SeamMode::Rigid => "rigid",
            SeamMode::Free => "free",
        }
    }
}

/// Options of [`parametrize`].
#[derive(Debug, Clone)]
pub struct ParamOptions {
    pub cones: ConeSpec,
    pub boundary: BoundaryMode,
    /// Cone curvatures rounded to multiples of π/2 (module docs).
    pub seamless: bool,
    /// Max |K − K̄| of the flow (default 1e-9: seams then match to ~1e-9 relative).
    pub tolerance: f64,
    /// Margin of the packing in `[0, 1]²` (default 0.01).
    pub margin: f64,
    /// Most cones the automatic placement may use (default 64).
    pub max_cones: usize,
    /// Rounds of [`cones::correct_cone_curvatures`] on the nonlinear flow for greedy cones
    /// (not with `--seamless`): each re-solves the cone curvatures for the least-squares log
    /// scale factor and runs the flow again, kept only when `σ(2u)` drops (default 0: each
    /// round costs one more flow).
    pub cone_corrections: usize,
    /// Write every chart on the common subdivision of the input and the flat triangulation,
    /// also where the input's own faces would not fold (default false: only where needed).
    pub on_subdivision: bool,
    /// Search of the automatic cone placement on closed surfaces (default
    /// [`cones::ConeSearch::Greedy`]; `Energy` is the wider, opt-in search).
    pub cone_search: cones::ConeSearch,
    /// Rigid (default) or free homology seams on closed components of genus ≥ 1.
    pub seams: SeamMode,
    /// Curvatures of the greedy cones with free seams (default least squares: the least
    /// linearised σ(2u) at the greedy's positions; `Dirichlet`: `u = 0` at the cones, BFF's).
    pub free_cone_rule: cones::CurvatureRule,
    /// Move the UVs on the input faces to the least-squares conformal map with the same
    /// cones, seam rotations and boundary, kept when nothing folds (submodule `lscm`;
    /// default true).
    pub lscm_refinement: bool,
}

impl Default for ParamOptions {
    fn default() -> Self {
        ParamOptions {
            cones: ConeSpec::Default,
            boundary: BoundaryMode::Free,
            seamless: false,
            tolerance: 1e-9,
            margin: 0.01,
            max_cones: 64,
            cone_corrections: 0,
            on_subdivision: false,
            cone_search: cones::ConeSearch::Greedy,
            seams: SeamMode::Rigid,
            free_cone_rule: cones::CurvatureRule::LeastSquares,
            lscm_refinement: true,
        }
    }
}

/// A cone of the flat metric.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Cone {
    /// Input vertex id.
    pub vertex: u32,
    /// Target curvature `K̄` (radians).
    pub curvature: f64,
    /// Cone angle `2π − K̄`.
    pub angle: f64,
}

/// What happened in one chart.
#[derive(Debug, Clone, Serialize)]
pub struct Chart {
    pub component: usize,
    pub faces: usize,
    pub vertices: usize,
    pub genus: i64,
    pub boundary_loops: usize,
    /// The flow's target (`uniform`, `cone:v=K,…`, `free-boundary+cone:v=K,…`, …), its cones
    /// named by their input vertices as in [`Chart::cones`] and `--cones V=K,…`.
    pub target: String,
    /// `"free"` when this chart's homology seams are free (closed, genus ≥ 1, `--seams
    /// free`), else `"rigid"` (also charts with no homology seams).
    pub seams: String,
    pub cones: Vec<Cone>,
    /// How the cones were chosen (`given`, `greedy`, `none`).
    pub cone_source: String,
    /// Linearised log-area spread after each greedy cone.
    pub cone_distortion_history: Vec<f64>,
    pub flow_iterations: usize,
    pub flow_converged: bool,
    pub max_curvature_error: f64,
    /// Intrinsic flips of the flow (isometric + Ptolemy) and splits of its simplicial mesh.
    pub flips: usize,
    pub splits: usize,
    /// Which faces carry the UVs: `"input"` (the input's own faces) or
    /// `"common_subdivision"` (the input's faces would fold, or the cut needs edges the flow
    /// flipped; [`Parametrization::subdivision`]).
    pub uv_faces: String,
    /// Input faces whose own UV triangle is not positive (with the cut on input edges; all
    /// faces when no such cut exists) — the reason for `common_subdivision`.
    pub input_flipped_faces: usize,
    /// The UVs on the input faces are the least-squares conformal refinement of the exact
    /// map (same cones, seam rotations and boundary; submodule `lscm`).
    pub lscm_refined: bool,
    /// Cut edges (input edges) and their total 3D length.
    pub seam_edges: usize,
    pub seam_length: f64,
    /// Largest relative difference of the UV length of a seam edge on its two sides.
    pub seam_length_mismatch: f64,
    /// Rotation angles (radians, in (−π, π]) of the transitions across the seams, one per
    /// distinct value (1e-6).
    pub transition_angles: Vec<f64>,
    /// Largest distance of a transition's rotation from a multiple of π/2.
    pub quarter_turn_error: f64,
    pub flow_seconds: f64,
    /// Always 0: cones are no longer moved (a cut that needs edges the flow flipped runs on
    /// the flat triangulation, and the UVs go on the common subdivision). Flows run.
    pub moved_cones: usize,
    pub flow_runs: usize,
    /// Rounds of the cone-curvature correction on the nonlinear flow that ran, and the
    /// area-weighted `σ(2u)` of the flow's conformal factor that was kept.
    pub cone_corrections: usize,
    pub log_scale_sigma: f64,
    /// `None` when the chart is what was asked for; otherwise why and how it was recomputed
    /// to get a map without flipped triangles (rigid seams, more cones: [`ladder`]).
    pub fallback: Option<String>,
    pub seconds: f64,
}

/// The result of [`parametrize`].
#[derive(Debug, Clone)]
pub struct Parametrization {
    /// `corner_uv[3f + i]`: UV of corner `i` of input face `f`, packed into `[0, 1]²`. In a
    /// chart on the common subdivision these are the subdivision's UVs at the input vertices
    /// (exact there, but the input face's own UV triangle may fold).
    pub corner_uv: Vec<[f64; 2]>,
    /// Input edges along which the surface was cut.
    pub seam: Vec<bool>,
    pub charts: Vec<Chart>,
    /// Distortion of what carries the map: the common subdivision when there is one, else
    /// the input's faces.
    pub stats: DistortionStats,
    /// The map on the common subdivision of the input and the flat triangulations, when some
    /// chart needs it (charts on the input's faces are copied into it unchanged).
    pub subdivision: Option<SubdivisionMap>,
    pub seconds: f64,
}

/// A UV map on the common subdivision (see [`transfer`]): vertices are points of the input
/// surface, every triangle lies in one input face and is mapped linearly.
#[derive(Debug, Clone)]
pub struct SubdivisionMap {
    /// Points on the input surface.
    pub positions: Vec<[f64; 3]>,
    /// The triangles (counter-clockwise on the input surface), as a mesh.
    pub mesh: Mesh,
    /// Input face of every triangle.
    pub input_face: Vec<u32>,
    /// `corner_uv[3t + i]`, packed into `[0, 1]²` with the other charts.
    pub corner_uv: Vec<[f64; 2]>,
    /// Seam edges of `mesh` (interior edges whose two sides' UVs differ).
    pub seam: Vec<bool>,
    /// Vertex of `mesh` at each input vertex.
    pub input_vertex: Vec<u32>,
    /// Distortion of the input's own faces (`corner_uv` of the parametrization).
    pub input_stats: DistortionStats,
}

impl Parametrization {
    /// `"common_subdivision"` when the map is carried by [`Parametrization::subdivision`],
    /// else `"input"`.
    pub fn uv_on(&self) -> &'static str {
        if self.subdivision.is_some() {
            "common_subdivision"
        } else {
            "input"
        }
    }
}

/// One connected component as a surface of its own, with the maps back to the input.
struct Piece {
    surface: Surface,
    /// Piece vertex → input vertex.
    vertices: Vec<u32>,
    /// Piece face → input face.
    faces: Vec<u32>,
}

fn pieces(s: &Surface) -> Result<Vec<Piece>> {
    let t = topology(&s.mesh);
    let mut out = Vec::new();
    for c in 0..t.components.len() as u32 {
        let faces: Vec<u32> = (0..s.mesh.n_faces() as u32)
            .filter(|&f| t.face_component[f as usize] == c)
            .collect();
        let mut map = vec![NONE; s.mesh.n_vertices()];
        let mut vertices = Vec::new();
        let mut tris = Vec::with_capacity(faces.len());
        for &f in &faces {
            let tri = s.mesh.face(f);
            let mut o = [0u32; 3];
            for i in 0..3 {
                let v = tri[i] as usize;
                if map[v] == NONE {
                    map[v] = vertices.len() as u32;
                    vertices.push(v as u32);
                }
                o[i] = map[v];
            }
            tris.push(o);
        }
        let positions = vertices.iter().map(|&v| s.positions[v as usize]).collect();
        out.push(Piece {
            surface: Surface::new(positions, tris)?,
            vertices,
            faces,
        });
    }
    Ok(out)
}

/// Area-weighted standard deviation of the log area ratio `2u` of a conformal factor `u` per
/// vertex (face value: the mean of its corners), the quantity the cone correction lowers.
fn log_scale_sigma(surface: &Surface, u: &[f64]) -> f64 {
    use crate::numeric::vec3::{cross, norm, sub};
    let (mut w, mut s1, mut s2) = (0.0, 0.0, 0.0);
    for t in surface.mesh.faces() {
        let p = |i: usize| surface.positions[t[i] as usize];
        let a = 0.5 * norm(cross(sub(p(1), p(0)), sub(p(2), p(0))));
        let x = 2.0 * (u[t[0] as usize] + u[t[1] as usize] + u[t[2] as usize]) / 3.0;
        w += a;
        s1 += a * x;
        s2 += a * x * x;
    }
    if w <= 0.0 {
        return 0.0;
    }
    let m = s1 / w;
    (s2 / w - m * m).max(0.0).sqrt()
}

/// Rotate corner UVs (in place) to the smallest-area axis-aligned bounding box among 90
/// rotations by 1°, and move it to the origin; `also` (points inside the same chart) gets the
/// same motion; returns (width, height).
fn orient(uv: &mut [[f64; 2]], also: &mut [[f64; 2]], rotate: bool) -> (f64, f64) {
    let bbox = |uv: &[[f64; 2]], c: f64, s: f64| -> [f64; 4] {
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in uv {
            let x = c * p[0] - s * p[1];
            let y = s * p[0] + c * p[1];
            b[0] = b[0].min(x);
            b[1] = b[1].min(y);
            b[2] = b[2].max(x);
            b[3] = b[3].max(y);
        }
        b
    };
    let mut best = (f64::INFINITY, 0.0);
    if rotate {
        let step = (uv.len() / 20_000).max(1);
        let sample: Vec<[f64; 2]> = uv.iter().step_by(step).copied().collect();
        for k in 0..90 {
            let t = (k as f64).to_radians();
            let b = bbox(&sample, t.cos(), t.sin());
            let a = (b[2] - b[0]) * (b[3] - b[1]);
            if a < best.0 {
                best = (a, t);
            }
        }
    }
    let (c, s) = (best.1.cos(), best.1.sin());
    let b = bbox(uv, c, s);
    for p in uv.iter_mut().chain(also.iter_mut()) {
        let x = c * p[0] - s * p[1];
        let y = s * p[0] + c * p[1];
        *p = [x - b[0], y - b[1]];
    }
    (b[2] - b[0], b[3] - b[1])
}

/// Conformal UV map of `surface` (module docs). Errors name the component and what failed.
pub fn parametrize(
    surface: &Surface,
    opts: &ParamOptions,
    progress: &mut dyn Progress,
) -> Result<Parametrization> {
    let t0 = Instant::now();
    if !(opts.margin >= 0.0 && opts.margin < 0.5) {
        return Err(Error::input(format!(
            "margin {} must lie in [0, 0.5)",
            opts.margin
        )));
    }
    if let ConeSpec::Given(c) = &opts.cones {
        for &(v, _) in c {
            if v as usize >= surface.mesh.n_vertices() || surface.mesh.is_isolated(v) {
                return Err(Error::input(format!(
                    "cone vertex {v} is not a vertex of the mesh"
                )));
            }
        }
    }
    let ps = pieces(surface)?;
    if ps.is_empty() {
        return Err(Error::input("the mesh has no faces"));
    }
    let nf = surface.mesh.n_faces();
    let mut corner_uv = vec![[0.0; 2]; 3 * nf];
    let mut seam = vec![false; surface.mesh.n_edges()];
    let mut charts = Vec::new();
    let mut boxes = Vec::new();
    let mut chart_uvs = Vec::new();
    let mut subdivision_meshes = Vec::new();
    for (c, p) in ps.iter().enumerate() {
        let mut cu = ladder::flip_free_chart(p, c, opts, progress)?;
        let wh = match cu.subdivision.as_mut() {
            Some(sub) => orient(&mut sub.corner_uv, &mut cu.corner_uv, !opts.seamless),
            None => orient(&mut cu.corner_uv, &mut [], !opts.seamless),
        };
        boxes.push(wh);
        for e in 0..p.surface.mesh.n_edges() as u32 {
            if cu.cut[e as usize] {
                let [a, b] = p.surface.mesh.edge_vertices(e);
                let (a, b) = (p.vertices[a as usize], p.vertices[b as usize]);
                if let Some(h) = surface.mesh.halfedge_between(a, b) {
                    seam[surface.mesh.he_edge(h) as usize] = true;
                }
            }
        }
        charts.push(cu.chart);
        chart_uvs.push((cu.corner_uv, cu.subdivision));
        subdivision_meshes.push(cu.subdivision_mesh);
    }
    // Shelf packing, tallest first.
    let gap = 0.02 * boxes.iter().map(|b| b.0 * b.1).sum::<f64>().sqrt();
    let row_width = boxes.iter().map(|b| b.0).fold(
        boxes.iter().map(|b| b.0 * b.1).sum::<f64>().sqrt() * 1.2,
        f64::max,
    );
    let mut order: Vec<usize> = (0..boxes.len()).collect();
    order.sort_by(|&a, &b| boxes[b].1.total_cmp(&boxes[a].1));
    let mut offset = vec![[0.0; 2]; boxes.len()];
    let (mut x, mut y, mut row_h, mut w_max) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for &i in &order {
        if x > 0.0 && x + boxes[i].0 > row_width {
            y += row_h + gap;
            x = 0.0;
            row_h = 0.0;
        }
        offset[i] = [x, y];
        x += boxes[i].0 + gap;
        row_h = row_h.max(boxes[i].1);
        w_max = w_max.max(x - gap);
    }
    let h_max = y + row_h;
    let side = w_max.max(h_max).max(1e-300);
    let s = (1.0 - 2.0 * opts.margin) / side;
    let place = |c: usize, q: [f64; 2]| {
        [
            opts.margin + s * (q[0] + offset[c][0]),
            opts.margin + s * (q[1] + offset[c][1]),
        ]
    };
    for (c, p) in ps.iter().enumerate() {
        for (lf, &f) in p.faces.iter().enumerate() {
            for i in 0..3 {
                corner_uv[3 * f as usize + i] = place(c, chart_uvs[c].0[3 * lf + i]);
            }
        }
    }
    let input_stats = uv_stats(&surface.positions, surface.mesh.faces(), &corner_uv);
    let subdivision = if chart_uvs.iter().any(|x| x.1.is_some()) {
        // One chart: the mesh of its subdivision is the whole map's (same points, same
        // triangles), already built by the chart.
        let single = match subdivision_meshes.as_mut_slice() {
            [m] => m.take(),
            _ => None,
        };
        Some(subdivision_map(
            &ps,
            &chart_uvs,
            &place,
            input_stats.clone(),
            single,
        )?)
    } else {
        None
    };
    Ok(Parametrization {
        corner_uv,
        seam,
        charts,
        stats: subdivision.as_ref().map_or(input_stats, |m| {
            uv_stats(&m.positions, m.mesh.faces(), &m.corner_uv)
        }),
        subdivision,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// A chart's points, triangles, input faces and corner UVs.
type ChartParts<'a> = (&'a [[f64; 3]], &'a [[u32; 3]], Vec<u32>, &'a [[f64; 2]]);

/// The whole map on the common subdivision: every chart's subdivision, or its input faces
/// when it has none, with the packed UVs (`place(chart, uv)`). `single`: the mesh of these
/// triangles when it is already built (one chart); it is used when its counts match.
fn subdivision_map(
    ps: &[Piece],
    charts: &[(Vec<[f64; 2]>, Option<transfer::SubdivisionChart>)],
    place: &dyn Fn(usize, [f64; 2]) -> [f64; 2],
    input_stats: DistortionStats,
    single: Option<Mesh>,
) -> Result<SubdivisionMap> {
    let (mut positions, mut triangles, mut input_face, mut corner_uv) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let n_input = ps
        .iter()
        .flat_map(|p| &p.vertices)
        .max()
        .map_or(0, |&v| v as usize + 1);
    let mut input_vertex = vec![NONE; n_input];
    for (c, (p, (uv, sub))) in ps.iter().zip(charts).enumerate() {
        let o = positions.len() as u32;
        // Input vertices come first, in the piece's order, in both meshes.
        for (l, &v) in p.vertices.iter().enumerate() {
            input_vertex[v as usize] = o + l as u32;
        }
        let (pos, tris, faces, uv): ChartParts = match sub {
            Some(x) => (
                &x.positions,
                &x.triangles,
                x.input_face.iter().map(|&f| p.faces[f as usize]).collect(),
                &x.corner_uv,
            ),
            None => (
                &p.surface.positions,
                p.surface.mesh.faces(),
                p.faces.clone(),
                uv,
            ),
        };
        positions.extend_from_slice(pos);
        triangles.extend(tris.iter().map(|t| t.map(|v| v + o)));
        input_face.extend(faces);
        corner_uv.extend(uv.iter().map(|&q| place(c, q)));
    }
    let mesh = match single {
        Some(m) if m.n_vertices() == positions.len() && m.faces() == triangles.as_slice() => m,
        _ => Mesh::from_triangles(positions.len(), triangles)?,
    };
    let seam = transfer::seam_edges(&mesh, &corner_uv);
    Ok(SubdivisionMap {
        positions,
        mesh,
        input_face,
        corner_uv,
        seam,
        input_vertex,
        input_stats,
    })
}
