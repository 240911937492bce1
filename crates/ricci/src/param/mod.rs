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
//!    Closed surfaces: cones `K̄_c` at given vertices, or placed by the greedy of
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
//!    generators, built from input edges that `T` kept, so that the input mesh and `T`
//!    are opened along the same curves.
//! 4. **Layout** of the opened `T` in the plane ([`crate::layout::place::layout`]), exact up to
//!    rounding because the metric is flat off the cones, which lie on the cut.
//! 5. **UVs on the input's own faces**: every input corner takes the layout position of its
//!    vertex in the same wedge between cut edges ([`seams::wedge_key`]); seams are vertices
//!    with several `vt`. The map is exact at the vertices and linear on input faces; the
//!    report counts the faces whose UV triangle is not positive (`flipped_faces`, the
//!    measure of [`crate::analysis::distortion`]). [`input_face_map`] is the one place this
//!    transfer happens (the common subdivision of the input and `T` is the exact map).
//! 6. **Packing**: each chart scaled to its surface area, rotated to its smallest bounding
//!    box (not with `--seamless`), shelf-packed and scaled into `[margin, 1 − margin]²`.

pub mod boundary;
pub mod cones;
pub mod seamless;
pub mod seams;
pub mod sphere;
pub mod svg;

use crate::analysis::distortion::{uv_stats, DistortionStats};
use crate::error::{Error, Result};
use crate::flow::{ricci_flow, FlowOptions, TargetSpec};
use crate::layout::place::layout;
use crate::mesh::{topology, Mesh, Surface, NONE};
use crate::metric::{Euclidean, Geometry, Scheme};
use crate::progress::Progress;
use cones::{correct_cone_curvatures, greedy_cones, round_to_quarter_turns, ConeBudget};
use serde::Serialize;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::time::Instant;

/// Which cones a closed chart gets.
#[derive(Debug, Clone, PartialEq)]
pub enum ConeSpec {
    /// Genus 1: none; otherwise automatic with the default bound (`Auto { 1.0 }`).
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
    pub target: String,
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
    /// Which faces carry the UVs: `"input"`.
    pub uv_faces: String,
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
    /// Cones moved to a neighbour because the flow flipped away all their input edges (the
    /// cut runs on kept input edges), and flows run.
    pub moved_cones: usize,
    pub flow_runs: usize,
    /// Rounds of the cone-curvature correction on the nonlinear flow that ran, and the
    /// area-weighted `σ(2u)` of the flow's conformal factor that was kept.
    pub cone_corrections: usize,
    pub log_scale_sigma: f64,
    pub seconds: f64,
}

/// The result of [`parametrize`].
#[derive(Debug, Clone)]
pub struct Parametrization {
    /// `corner_uv[3f + i]`: UV of corner `i` of input face `f`, packed into `[0, 1]²`.
    pub corner_uv: Vec<[f64; 2]>,
    /// Input edges along which the surface was cut.
    pub seam: Vec<bool>,
    pub charts: Vec<Chart>,
    pub stats: DistortionStats,
    pub seconds: f64,
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

/// The map of the input's faces into the layout of the opened intrinsic triangulation: one
/// UV per input corner (see the module docs, step 5). `t_mesh` is the simplicial mesh of the
/// flow (input vertices first, same ids), `t_cut` its cut flags, `t_uv[3f + i]` the layout
/// position of corner `i` of its face `f`; `cut` are the cut flags of `input`.
///
/// The one place where input UVs are taken from the intrinsic triangulation, so that the
/// exact transfer (the common subdivision) can replace it.
pub fn input_face_map(
    input: &Mesh,
    cut: &[bool],
    t_mesh: &Mesh,
    t_cut: &[bool],
    t_uv: &[[f64; 2]],
) -> Result<Vec<[f64; 2]>> {
    let nv = input.n_vertices();
    let mut table: HashMap<(u32, u32), [f64; 2]> = HashMap::with_capacity(nv + nv / 4);
    for h in 0..t_mesh.n_corners() as u32 {
        let v = t_mesh.he_origin(h);
        if (v as usize) < nv {
            let key = seams::wedge_key(t_mesh, h, t_cut);
            table.entry((v, key)).or_insert(t_uv[h as usize]);
        }
    }
    let mut out = Vec::with_capacity(input.n_corners());
    for h in 0..input.n_corners() as u32 {
        let v = input.he_origin(h);
        let key = seams::wedge_key(input, h, cut);
        let uv = table.get(&(v, key)).ok_or_else(|| {
            Error::numerical(format!(
                "input vertex {v} (face {}) has no position in the layout of the intrinsic \
                 triangulation",
                h / 3
            ))
        })?;
        out.push(*uv);
    }
    Ok(out)
}

/// A flow result kept while the cone correction tries another: flow, cut, cones, `σ(2u)`.
type Candidate = (crate::flow::FlowResult, Vec<bool>, Vec<(u32, f64)>, f64);

struct ChartUv {
    corner_uv: Vec<[f64; 2]>,
    cut: Vec<bool>,
    chart: Chart,
}

fn chart_uv(
    piece: &Piece,
    component: usize,
    opts: &ParamOptions,
    progress: &mut dyn Progress,
) -> Result<ChartUv> {
    let t0 = Instant::now();
    let mesh = &piece.surface.mesh;
    let n = mesh.n_vertices();
    let topo = topology(mesh);
    let comp = &topo.components[0];
    let lengths = piece.surface.edge_lengths();
    let to_local: HashMap<u32, u32> = piece
        .vertices
        .iter()
        .enumerate()
        .map(|(i, &v)| (v, i as u32))
        .collect();
    let mut history = Vec::new();
    let mut cone_source = "none".to_string();
    let mut cone_list: Vec<(u32, f64)> = Vec::new();
    let target = if comp.boundary_loops > 0 {
        match &opts.cones {
            ConeSpec::Given(c) if c.iter().any(|x| to_local.contains_key(&x.0)) => {
                return Err(Error::input(format!(
                    "component {component} has a boundary; cones on surfaces with boundary \
                     are not supported yet (the boundary takes the curvature)"
                )));
            }
            ConeSpec::Count(k) if *k > 0 => {
                return Err(Error::input(format!(
                    "component {component} has a boundary; cones on surfaces with boundary \
                     are not supported yet (the boundary takes the curvature)"
                )));
            }
            _ => {}
        }
        match (opts.boundary, opts.seamless) {
            (BoundaryMode::Free, false) => TargetSpec::FreeBoundary,
            (BoundaryMode::Round, false) => TargetSpec::RoundBoundary,
            (BoundaryMode::FixedAngles, _) | (_, true) => {
                TargetSpec::PerVertex(boundary::fixed_angle_targets(mesh, &lengths, opts.seamless))
            }
        }
    } else {
        let chi = 2.0 - 2.0 * comp.genus as f64;
        let spec = match &opts.cones {
            ConeSpec::Default if comp.genus == 1 => ConeSpec::None,
            ConeSpec::Default => ConeSpec::Auto {
                max_area_distortion: 1.0,
            },
            c => c.clone(),
        };
        match spec {
            ConeSpec::None | ConeSpec::Default => {}
            ConeSpec::Given(c) => {
                for (v, k) in c {
                    if let Some(&l) = to_local.get(&v) {
                        cone_list.push((l, k));
                    }
                }
                cone_source = "given".into();
            }
            ConeSpec::Count(k) => {
                progress.report("cones", None, "greedy cone placement");
                let p = greedy_cones(mesh, &lengths, ConeBudget::Count(k))?;
                cone_list = p.cones;
                history = p.distortion_history;
                cone_source = "greedy".into();
            }
            ConeSpec::Auto {
                max_area_distortion,
            } => {
                progress.report("cones", None, "greedy cone placement");
                let p = greedy_cones(
                    mesh,
                    &lengths,
                    ConeBudget::AreaDistortion {
                        bound: max_area_distortion,
                        max_cones: opts.max_cones,
                    },
                )?;
                cone_list = p.cones;
                history = p.distortion_history;
                cone_source = "greedy".into();
            }
        }
        if opts.seamless {
            cone_list = round_to_quarter_turns(&cone_list, 2.0 * PI * chi, 3);
        }
        if cone_list.is_empty() {
            if comp.genus != 1 {
                return Err(Error::input(format!(
                    "component {component} (closed, genus {}) needs cones to be flattened \
                     (--cones N, auto or V=K,…; or --sphere for genus 0)",
                    comp.genus
                )));
            }
            TargetSpec::Uniform
        } else {
            TargetSpec::Cones(cone_list.clone())
        }
    };
    // The flow, and the cut on input edges the final triangulation kept. A cone whose input
    // edges were all flipped away cannot be reached by the cut: it moves to the neighbour
    // with the most kept edges and the flow runs again (at most `CONE_MOVES` rounds).
    const CONE_MOVES: usize = 3;
    let mut moved_cones = 0usize;
    let mut round = 0usize;
    let mut corrections_left = if cone_source == "greedy" && !opts.seamless {
        opts.cone_corrections
    } else {
        0
    };
    let mut best: Option<Candidate> = None;
    let mut corrections = 0usize;
    let (r, cut) = loop {
        round += 1;
        let target = if cone_list.is_empty() {
            target.clone()
        } else {
            TargetSpec::Cones(cone_list.clone())
        };
        progress.report("flow", None, "conformal flow with intrinsic Delaunay flips");
        let fo = FlowOptions {
            geometry: Geometry::Euclidean,
            scheme: Scheme::Conformal,
            target,
            tolerance: opts.tolerance,
            ..FlowOptions::default()
        };
        let r = match ricci_flow(mesh, &lengths, &fo, progress) {
            Ok(r) if !r.converged && best.is_some() => {
                let (r, cut, c, _) = best.take().expect("checked");
                cone_list = c;
                break (r, cut);
            }
            Err(_) if best.is_some() => {
                let (r, cut, c, _) = best.take().expect("checked");
                cone_list = c;
                break (r, cut);
            }
            x => x?,
        };
        if !r.converged {
            return Err(Error::numerical(format!(
                "component {component}: the conformal flow did not converge (max |K − K̄| = \
                 {:.3e} after {} iterations{})",
                r.max_curvature_error,
                r.iterations,
                if r.notes.is_empty() {
                    String::new()
                } else {
                    format!("; {}", r.notes.join("; "))
                }
            )));
        }
        let tr = r
            .triangulation
            .as_ref()
            .ok_or_else(|| Error::numerical("the conformal flow returned no triangulation"))?;
        let t_mesh = &tr.simplicial.mesh;
        // Edges the cut may use: input edges never flipped and not doubled in the Δ-complex.
        let mut flipped = vec![false; mesh.n_edges()];
        for &e in &tr.triangulation.flip_log {
            flipped[e as usize] = true;
        }
        let mut pairs: HashMap<(u32, u32), u32> = HashMap::new();
        for e in 0..tr.triangulation.n_edges() as u32 {
            let [a, b] = tr.triangulation.edge_vertices(e);
            *pairs.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
        let allowed: Vec<bool> = (0..mesh.n_edges() as u32)
            .map(|e| {
                let [a, b] = mesh.edge_vertices(e);
                !flipped[e as usize]
                    && pairs.get(&(a.min(b), a.max(b))) == Some(&1)
                    && t_mesh.halfedge_between(a, b).is_some()
            })
            .collect();
        if round <= CONE_MOVES && !cone_list.is_empty() {
            // Components of the graph of kept interior edges; every cone must lie in the
            // largest one (the cut reaches it without flipped edges). Cones outside move to
            // the nearest vertex inside (breadth first over the input mesh).
            let nv = mesh.n_vertices();
            let mut parent: Vec<u32> = (0..nv as u32).collect();
            fn find(p: &mut [u32], mut x: u32) -> u32 {
                while p[x as usize] != x {
                    p[x as usize] = p[p[x as usize] as usize];
                    x = p[x as usize];
                }
                x
            }
            for e in 0..mesh.n_edges() as u32 {
                if allowed[e as usize] && !mesh.is_boundary_edge(e) {
                    let [a, b] = mesh.edge_vertices(e);
                    let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                    if ra != rb {
                        parent[ra as usize] = rb;
                    }
                }
            }
            let mut size = vec![0usize; nv];
            for v in 0..nv as u32 {
                let r = find(&mut parent, v);
                size[r as usize] += 1;
            }
            let main = (0..nv).max_by_key(|&v| size[v]).unwrap_or(0) as u32;
            let mut in_main = vec![false; nv];
            for v in 0..nv as u32 {
                in_main[v as usize] = find(&mut parent, v) == main;
            }
            let mut is_cone = vec![false; nv];
            for c in &cone_list {
                is_cone[c.0 as usize] = true;
            }
            let mut moved = false;
            for cone in cone_list.iter_mut() {
                let c = cone.0;
                if in_main[c as usize] {
                    continue;
                }
                let mut seen = vec![false; nv];
                let mut queue = std::collections::VecDeque::from([c]);
                seen[c as usize] = true;
                let mut found = None;
                while let Some(v) = queue.pop_front() {
                    if in_main[v as usize] && !is_cone[v as usize] && !mesh.is_boundary_vertex(v) {
                        found = Some(v);
                        break;
                    }
                    for w in mesh.vertex_neighbors(v) {
                        if !seen[w as usize] {
                            seen[w as usize] = true;
                            queue.push_back(w);
                        }
                    }
                }
                if let Some(w) = found {
                    is_cone[c as usize] = false;
                    is_cone[w as usize] = true;
                    cone.0 = w;
                    moved = true;
                    moved_cones += 1;
                }
            }
            if moved {
                continue;
            }
        }
        let cone_vertices: Vec<u32> = cone_list.iter().map(|c| c.0).collect();
        let needs_cut = comp.boundary_loops != 1 || comp.genus > 0 || !cone_vertices.is_empty();
        let cut = if needs_cut {
            progress.report("cut", None, "cut graph through the cones and the handles");
            match seams::cut_graph(mesh, &lengths, &allowed, &cone_vertices) {
                Ok(c) => c,
                Err(_) if best.is_some() => {
                    let (r, cut, c, _) = best.take().expect("checked");
                    cone_list = c;
                    break (r, cut);
                }
                Err(e) => {
                    return Err(Error::numerical(format!("component {component}: {e}")));
                }
            }
        } else {
            vec![false; mesh.n_edges()]
        };
        let sigma = log_scale_sigma(&piece.surface, &r.u);
        let better = best.as_ref().is_none_or(|b| sigma < b.3);
        if corrections_left > 0 {
            // Re-solve the cone curvatures on the nonlinear result and flow again.
            corrections_left -= 1;
            progress.report("cones", None, "cone curvatures corrected on the flow");
            if let Ok(next) = correct_cone_curvatures(mesh, &lengths, &cone_list, &r.u, 1.0) {
                if better {
                    best = Some((r, cut, cone_list.clone(), sigma));
                }
                cone_list = next;
                corrections += 1;
                continue;
            }
        }
        if !better {
            let (r, cut, c, _) = best.take().expect("checked");
            cone_list = c;
            break (r, cut);
        }
        break (r, cut);
    };
    let flow_seconds = r.seconds;
    let tr = r
        .triangulation
        .as_ref()
        .ok_or_else(|| Error::numerical("the conformal flow returned no triangulation"))?;
    let t_mesh = &tr.simplicial.mesh;
    let mut t_cut = vec![false; t_mesh.n_edges()];
    for e in 0..mesh.n_edges() as u32 {
        if cut[e as usize] {
            let [a, b] = mesh.edge_vertices(e);
            let h = t_mesh.halfedge_between(a, b).ok_or_else(|| {
                Error::numerical(format!(
                    "cut edge {a}–{b} is missing in the flat triangulation"
                ))
            })?;
            t_cut[t_mesh.he_edge(h) as usize] = true;
        }
    }
    let t_lengths = if opts.seamless && comp.genus > 0 && comp.boundary_loops == 0 {
        seamless::chart_holonomy(t_mesh, &r.lengths, n, &cone_list, progress)?
    } else {
        r.lengths.clone()
    };
    progress.report("layout", None, "flat layout of the opened surface");
    let (disk, _origin) = crate::cut::slice(t_mesh, &t_cut)?;
    let mut dl = vec![0.0; disk.n_edges()];
    for h in 0..disk.n_corners() as u32 {
        dl[disk.he_edge(h) as usize] = t_lengths[t_mesh.he_edge(h) as usize];
    }
    let lay = layout::<Euclidean>(&disk, &dl, None)?;
    let t_uv: Vec<[f64; 2]> = (0..disk.n_corners() as u32)
        .map(|h| {
            let p = lay.positions[disk.he_origin(h) as usize];
            [p.re, p.im]
        })
        .collect();
    let mut corner_uv = input_face_map(mesh, &cut, t_mesh, &t_cut, &t_uv)?;
    // Scale to the surface's area.
    let (mut a3, mut a2) = (0.0, 0.0);
    for (f, t) in mesh.faces().iter().enumerate() {
        let p = |i: usize| piece.surface.positions[t[i] as usize];
        a3 += 0.5
            * crate::numeric::vec3::norm(crate::numeric::vec3::cross(
                crate::numeric::vec3::sub(p(1), p(0)),
                crate::numeric::vec3::sub(p(2), p(0)),
            ));
        let q = &corner_uv[3 * f..3 * f + 3];
        a2 += 0.5
            * ((q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]));
    }
    if a2 > 0.0 && a3 > 0.0 {
        let s = (a3 / a2).sqrt();
        for q in corner_uv.iter_mut() {
            q[0] *= s;
            q[1] *= s;
        }
    }
    // Seams: transitions between the two sides of every cut edge.
    let (mut seam_edges, mut seam_length, mut mismatch, mut qerr) = (0usize, 0.0, 0.0f64, 0.0f64);
    let mut angles: Vec<f64> = Vec::new();
    for e in 0..mesh.n_edges() as u32 {
        if !cut[e as usize] {
            continue;
        }
        seam_edges += 1;
        seam_length += lengths[e as usize];
        let h = mesh.edge_halfedge(e);
        let g = mesh.he_twin(h);
        // h: a→b in face h/3; g: b→a.
        let (pa, pb) = (corner_uv[h as usize], corner_uv[mesh.he_next(h) as usize]);
        let (qb, qa) = (corner_uv[g as usize], corner_uv[mesh.he_next(g) as usize]);
        let d1 = [pb[0] - pa[0], pb[1] - pa[1]];
        let d2 = [qb[0] - qa[0], qb[1] - qa[1]];
        let (l1, l2) = (d1[0].hypot(d1[1]), d2[0].hypot(d2[1]));
        mismatch = mismatch.max((l1 - l2).abs() / l1.max(l2).max(1e-300));
        let ang = (d1[0] * d2[1] - d1[1] * d2[0]).atan2(d1[0] * d2[0] + d1[1] * d2[1]);
        let q = (ang / (PI / 2.0)).round() * (PI / 2.0);
        qerr = qerr.max((ang - q).abs());
        if !angles.iter().any(|&a| {
            let d = (a - ang).abs();
            d < 1e-6 || (2.0 * PI - d).abs() < 1e-6
        }) && angles.len() < 64
        {
            angles.push(ang);
        }
    }
    angles.sort_by(f64::total_cmp);
    let cones_out: Vec<Cone> = cone_list
        .iter()
        .map(|&(v, k)| Cone {
            vertex: piece.vertices[v as usize],
            curvature: k,
            angle: 2.0 * PI - k,
        })
        .collect();
    let chart = Chart {
        component,
        faces: mesh.n_faces(),
        vertices: n,
        genus: comp.genus,
        boundary_loops: comp.boundary_loops,
        target: r.target_description.clone(),
        cones: cones_out,
        cone_source,
        cone_distortion_history: history,
        flow_iterations: r.iterations,
        flow_converged: r.converged,
        max_curvature_error: r.max_curvature_error,
        flips: tr.initial_flips + tr.flips,
        splits: tr.splits,
        uv_faces: "input".into(),
        seam_edges,
        seam_length,
        seam_length_mismatch: mismatch,
        transition_angles: angles,
        quarter_turn_error: qerr,
        flow_seconds,
        moved_cones,
        flow_runs: round,
        cone_corrections: corrections,
        log_scale_sigma: log_scale_sigma(&piece.surface, &r.u),
        seconds: t0.elapsed().as_secs_f64(),
    };
    Ok(ChartUv {
        corner_uv,
        cut,
        chart,
    })
}

/// Rotate corner UVs (in place) to the smallest-area axis-aligned bounding box among 90
/// rotations by 1°, and move it to the origin; returns (width, height).
fn orient(uv: &mut [[f64; 2]], rotate: bool) -> (f64, f64) {
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
    for p in uv.iter_mut() {
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
    for (c, p) in ps.iter().enumerate() {
        let mut cu = chart_uv(p, c, opts, progress)?;
        let wh = orient(&mut cu.corner_uv, !opts.seamless);
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
        chart_uvs.push(cu.corner_uv);
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
    for (c, p) in ps.iter().enumerate() {
        for (lf, &f) in p.faces.iter().enumerate() {
            for i in 0..3 {
                let q = chart_uvs[c][3 * lf + i];
                corner_uv[3 * f as usize + i] = [
                    opts.margin + s * (q[0] + offset[c][0]),
                    opts.margin + s * (q[1] + offset[c][1]),
                ];
            }
        }
    }
    let stats = uv_stats(&surface.positions, surface.mesh.faces(), &corner_uv);
    Ok(Parametrization {
        corner_uv,
        seam,
        charts,
        stats,
        seconds: t0.elapsed().as_secs_f64(),
    })
}
