//! Measurements of a partition-of-unity surface and the end-to-end construction:
//!
//! * [`chart_independence`]: `F` and its first and second partials at random points
//!   `(face, λ)`, evaluated in the charts of the face's three vertices and carried into one
//!   chart through the transition's jet (`F_u = F_v ∘ T_{u→v}`, [`super::jet::compose`]).
//! * [`continuity`]: the same across chart boundaries, orders 0–3: points on every edge
//!   `(a, b)`, evaluated in the charts of `a`, `b` and of the two opposite vertices (whose
//!   stars end at the edge) and compared in the chart of `a`.
//! * [`tessellate`]: a welded triangulation of `F` over the first sheet of the domain.
//! * [`run`]: atlas → radii → charts → fit → measurements.
//!
//! Relative jumps of order `k` are divided by the largest order-`k` partial met over all
//! samples (in the comparison chart), the values by the bounding-box diagonal.

use std::collections::HashMap;
use std::time::Instant;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::layout::isometry::{Complex, Mobius};
use crate::mesh::Surface;
use crate::numeric::vec3::{dot, sub};
use crate::progress::Progress;
use crate::spline::surface::point_triangle_distance;

use super::atlas::{double_cover, AtlasReport, HyperbolicAtlas};
use super::fit::{fit, PouFitOptions, PouFitReport};
use super::jet::{compose, exponents, mobius_jet, n_coeffs, Jet};
use super::local::{local_fits, LocalPolynomial};
use super::surface::{two_ring_radii, PouBasis, PouSurface};

/// Largest relative differences per order between evaluations in different charts.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ChartComparison {
    pub samples: usize,
    /// Comparisons (pairs of charts) made.
    pub comparisons: usize,
    /// `relative[k]`: order `k` (0: value, relative to the diagonal).
    pub relative: Vec<f64>,
    /// Largest partial of each order met (the denominators).
    pub scale: Vec<f64>,
}

/// Jets of `F` at `(f, λ)` in chart `v`, carried into chart `u` (`T` = transition `u → v`).
fn jets_in(
    s: &PouSurface,
    v: u32,
    f: u32,
    lambda: [f64; 3],
    order: usize,
    to: Option<(u32, Complex)>,
) -> Result<[Jet; 3]> {
    let atlas = s.basis.atlas;
    let zv = atlas
        .chart_point(v, f, lambda)
        .ok_or_else(|| Error::input(format!("face {f} is not in the star of vertex {v}")))?;
    let jv = s.jets(v, zv, order)?;
    let Some((u, zu)) = to else {
        return Ok(jv);
    };
    if u == v {
        return Ok(jv);
    }
    let t: Mobius = atlas
        .transition(u, v)
        .ok_or_else(|| Error::input(format!("charts {u} and {v} do not overlap")))?;
    let w = mobius_jet(t.a, t.b, zu, order);
    Ok(jv.map(|g| compose(&g, &w)))
}

/// A sample: reference chart, face and `λ` in it, and the other `(chart, face, λ)` that name
/// the same point.
type Sample = (u32, u32, [f64; 3], Vec<(u32, u32, [f64; 3])>);

/// Compare evaluations at points: for each `(reference chart u, reference face, λ, others)`,
/// the jets in every other chart `v` (with the face of `v`'s star that holds the point)
/// carried to `u`. `diag` scales the values.
fn compare(s: &PouSurface, points: &[Sample], order: usize, diag: f64) -> Result<ChartComparison> {
    let atlas = s.basis.atlas;
    type Diffs = (Vec<f64>, Vec<f64>, usize);
    let res: Vec<Diffs> = points
        .par_iter()
        .map(|(u, fu, lu, others)| -> Result<Diffs> {
            let zu = atlas
                .chart_point(*u, *fu, *lu)
                .ok_or_else(|| Error::input(format!("face {fu} is not in chart {u}")))?;
            let ju = s.jets(*u, zu, order)?;
            let mut diff = vec![0.0; order + 1];
            let mut scale = vec![0.0; order + 1];
            for i in 0..n_coeffs(order) {
                let (a, b) = exponents(i);
                for j in &ju {
                    scale[a + b] = f64::max(scale[a + b], j.partial(a, b).abs());
                }
            }
            let mut n = 0;
            for &(v, fv, lv) in others {
                let jv = jets_in(s, v, fv, lv, order, Some((*u, zu)))?;
                n += 1;
                for i in 0..n_coeffs(order) {
                    let (a, b) = exponents(i);
                    for d in 0..3 {
                        let e = (ju[d].partial(a, b) - jv[d].partial(a, b)).abs();
                        diff[a + b] = f64::max(diff[a + b], e);
                    }
                }
            }
            Ok((diff, scale, n))
        })
        .collect::<Result<_>>()?;
    let mut diff = vec![0.0f64; order + 1];
    let mut scale = vec![0.0f64; order + 1];
    let mut comparisons = 0;
    for (d, sc, n) in &res {
        comparisons += n;
        for k in 0..=order {
            diff[k] = diff[k].max(d[k]);
            scale[k] = scale[k].max(sc[k]);
        }
    }
    scale[0] = diag;
    let relative = (0..=order)
        .map(|k| diff[k] / scale[k].max(1e-300))
        .collect();
    Ok(ChartComparison {
        samples: points.len(),
        comparisons,
        relative,
        scale,
    })
}

/// A small deterministic generator (xorshift) for sample points.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Chart independence of `F` and its partials up to order 2 at `samples` random points
/// (module docs).
pub fn chart_independence(s: &PouSurface, samples: usize, seed: u64) -> Result<ChartComparison> {
    let atlas = s.basis.atlas;
    let nf = atlas.mesh.n_faces();
    let mut rng = Rng(seed.max(1));
    let mut pts = Vec::with_capacity(samples);
    for _ in 0..samples {
        let f = ((rng.next() * nf as f64) as usize).min(nf - 1) as u32;
        let (a, b) = (rng.next(), rng.next());
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let l = [1.0 - a - b, a, b];
        let vs = atlas.mesh.face(f);
        pts.push((vs[0], f, l, vec![(vs[1], f, l), (vs[2], f, l)]));
    }
    compare(s, &pts, 2, diag_of(&atlas.positions))
}

fn diag_of(p: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in p {
        for d in 0..3 {
            lo[d] = lo[d].min(x[d]);
            hi[d] = hi[d].max(x[d]);
        }
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}

/// Jumps of orders 0..=3 across chart boundaries on every `stride`-th edge (module docs).
pub fn continuity(s: &PouSurface, stride: usize) -> Result<ChartComparison> {
    let edges: Vec<u32> = (0..s.basis.atlas.mesh.n_edges() as u32)
        .step_by(stride.max(1))
        .collect();
    continuity_on_edges(s, &edges)
}

/// The edges of the faces that touch the one-ring of vertex `v` (where a manifold spline
/// with its extraordinary point at `v` has its fill patch and seam).
pub fn edges_near_vertex(s: &PouSurface, v: u32) -> Vec<u32> {
    let m = &s.basis.atlas.mesh;
    let mut ring: Vec<u32> = m.vertex_neighbors(v).collect();
    ring.push(v);
    let mut edges: Vec<u32> = ring
        .iter()
        .flat_map(|&u| m.vertex_faces(u).collect::<Vec<_>>())
        .flat_map(|f| m.face_halfedges(f).map(|h| m.he_edge(h)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// Jumps of orders 0..=3 across chart boundaries at three points of each of `edges`.
pub fn continuity_on_edges(s: &PouSurface, edges: &[u32]) -> Result<ChartComparison> {
    let atlas = s.basis.atlas;
    let m = &atlas.mesh;
    let mut pts = Vec::new();
    for &e in edges {
        if e as usize >= m.n_edges() {
            return Err(Error::input(format!(
                "edge {e} is not an edge of the domain"
            )));
        }
        let h = m.edge_halfedge(e);
        let t = m.he_twin(h);
        if m.is_boundary_halfedge(h) || m.is_boundary_halfedge(t) {
            continue;
        }
        let (f, g) = (m.he_face(h), m.he_face(t));
        let (a, b) = (m.he_origin(h), m.he_tip(h));
        let c = m.face(f).into_iter().find(|&x| x != a && x != b);
        let d = m.face(g).into_iter().find(|&x| x != a && x != b);
        let (Some(c), Some(d)) = (c, d) else { continue };
        for tt in [0.25, 0.5, 0.75] {
            let lam_f = lambda_on_edge(m.face(f), a, b, tt);
            let lam_g = lambda_on_edge(m.face(g), a, b, tt);
            pts.push((
                a,
                f,
                lam_f,
                vec![(b, f, lam_f), (c, f, lam_f), (d, g, lam_g)],
            ));
        }
    }
    compare(s, &pts, 3, diag_of(&atlas.positions))
}

/// Barycentric coordinates of the point `(1 − t) a + t b` (hyperboloid combination) in a
/// face with vertices `vs`.
fn lambda_on_edge(vs: [u32; 3], a: u32, b: u32, t: f64) -> [f64; 3] {
    let mut l = [0.0; 3];
    for k in 0..3 {
        if vs[k] == a {
            l[k] = 1.0 - t;
        } else if vs[k] == b {
            l[k] = t;
        }
    }
    l
}

/// A welded triangulation of the surface.
#[derive(Debug, Clone)]
pub struct PouTessellation {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Per vertex: a domain face and barycentric coordinates.
    pub vertex_face: Vec<u32>,
    pub vertex_bary: Vec<[f64; 3]>,
}

/// Tessellate the faces `faces` of the domain with `k` segments per edge, welded at shared
/// vertices and edges.
pub fn tessellate(s: &PouSurface, faces: &[u32], k: usize) -> Result<PouTessellation> {
    let atlas = s.basis.atlas;
    let m = &atlas.mesh;
    let k = k.max(1);
    #[derive(Hash, PartialEq, Eq, Clone, Copy)]
    enum Key {
        Vertex(u32),
        Edge(u32, u32, usize),
        Inner(u32, usize, usize),
    }
    let mut index: HashMap<Key, u32> = HashMap::new();
    let mut samples: Vec<(u32, [f64; 3])> = Vec::new();
    let mut triangles = Vec::new();
    for &f in faces {
        let vs = m.face(f);
        let mut grid = vec![0u32; (k + 1) * (k + 2) / 2];
        let id = |i: usize, j: usize| i * (2 * k + 3 - i) / 2 + j;
        for i in 0..=k {
            for j in 0..=k - i {
                // Barycentric (k − i − j, i, j) / k over (v0, v1, v2).
                let c = [k - i - j, i, j];
                let nz: Vec<usize> = (0..3).filter(|&q| c[q] > 0).collect();
                let key = match nz.len() {
                    1 => Key::Vertex(vs[nz[0]]),
                    2 => {
                        let (p, q) = (nz[0], nz[1]);
                        let (a, b, t) = if vs[p] < vs[q] {
                            (vs[p], vs[q], c[q])
                        } else {
                            (vs[q], vs[p], c[p])
                        };
                        Key::Edge(a, b, t)
                    }
                    _ => Key::Inner(f, i, j),
                };
                let next = samples.len() as u32;
                let vid = *index.entry(key).or_insert_with(|| {
                    samples.push((f, c.map(|x| x as f64 / k as f64)));
                    next
                });
                grid[id(i, j)] = vid;
            }
        }
        for i in 0..k {
            for j in 0..k - i {
                triangles.push([grid[id(i, j)], grid[id(i + 1, j)], grid[id(i, j + 1)]]);
                if j + 1 < k - i {
                    triangles.push([
                        grid[id(i + 1, j)],
                        grid[id(i + 1, j + 1)],
                        grid[id(i, j + 1)],
                    ]);
                }
            }
        }
    }
    let positions: Vec<[f64; 3]> = samples
        .par_iter()
        .map_init(Vec::new, |scratch, &(f, l)| s.at(f, l, scratch))
        .collect::<Result<_>>()?;
    Ok(PouTessellation {
        positions,
        triangles,
        vertex_face: samples.iter().map(|s| s.0).collect(),
        vertex_bary: samples.iter().map(|s| s.1).collect(),
    })
}

/// Options of [`run`].
#[derive(Debug, Clone, Copy)]
pub struct PouOptions {
    /// Disk radius as a multiple of the two-ring radius (≥ 1).
    pub radius: f64,
    /// Degree of the local polynomials (0: constant control points, 1: affine, 2: quadratic;
    /// [`super::local`]).
    pub local_degree: usize,
    pub fit: PouFitOptions,
    /// Segments per domain edge in the tessellation.
    pub tessellation: usize,
    /// Random points of the chart-independence check.
    pub independence_samples: usize,
    /// The continuity check samples about this many edges, evenly spaced (0: all).
    pub continuity_edges: usize,
}

impl Default for PouOptions {
    fn default() -> Self {
        PouOptions {
            radius: 1.0,
            local_degree: 2,
            fit: PouFitOptions::default(),
            tessellation: 6,
            independence_samples: 2000,
            continuity_edges: 3000,
        }
    }
}

/// The continuity class reached.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PouContinuity {
    /// Jumps of orders 0..=3 across chart boundaries, relative (module docs).
    pub relative_jumps: Vec<f64>,
    pub samples: usize,
    pub comparisons: usize,
    /// Every `edge_stride`-th edge was sampled.
    pub edge_stride: usize,
    pub tolerance: f64,
    /// Orders ≤ 3 whose jumps are below the tolerance, all of them: "C∞ (orders 0–3 measured)".
    pub class: String,
}

/// What [`run`] measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PouReport {
    pub control_points: usize,
    pub domain_faces: usize,
    pub double_cover: bool,
    pub radius_factor: f64,
    pub local_degree: usize,
    pub radius_min: f64,
    pub radius_max: f64,
    pub mean_controls_per_chart: f64,
    pub rms_error_percent: f64,
    pub max_error_percent: f64,
    pub continuity: PouContinuity,
    pub chart_independence: ChartComparison,
    pub atlas: AtlasReport,
    pub fit: PouFitReport,
    pub seconds_atlas: f64,
    pub seconds_charts: f64,
    /// Local polynomial fits and the global least squares.
    pub seconds_fit: f64,
    /// Distances of the tessellation to the input mesh (the errors).
    pub seconds_error: f64,
    pub seconds_tessellation: f64,
    pub seconds_checks: f64,
    pub seconds: f64,
}

/// Atlas, charts and fitted partition-of-unity surface of a surface (built once, then
/// measured and tessellated).
pub struct PouConstruction {
    pub atlas: HyperbolicAtlas,
    pub radii: Vec<f64>,
    pub control: Vec<[f64; 3]>,
    /// Local polynomials (empty for degree 0).
    pub local: Vec<LocalPolynomial>,
    pub local_degree: usize,
    pub fit: PouFitReport,
    /// Faces of the domain on the input's sheet (all faces for a closed input).
    pub sheet_faces: Vec<u32>,
    pub double_cover: bool,
    pub seconds_atlas: f64,
    pub seconds_charts: f64,
    pub seconds_fit: f64,
}

impl PouConstruction {
    /// The surface (borrowing the atlas).
    pub fn surface(&self) -> PouSurface<'_> {
        PouSurface {
            basis: PouBasis::new(&self.atlas, self.radii.clone()),
            control: self.control.clone(),
            local: self.local.clone(),
        }
    }
}

/// Build the atlas, the bases and fit the control points (surfaces with boundary through
/// their double cover).
pub fn construct(
    input: &Surface,
    opts: &PouOptions,
    progress: &mut dyn Progress,
) -> Result<PouConstruction> {
    let t0 = Instant::now();
    let bordered = input.mesh.has_boundary();
    let (domain, sheet) = if bordered {
        double_cover(input)?
    } else {
        (input.clone(), input.mesh.n_faces())
    };
    let mut atlas = HyperbolicAtlas::build(&domain, progress)?;
    let seconds_atlas = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let radii = two_ring_radii(&atlas, opts.radius)?;
    atlas.develop_charts(&radii, progress)?;
    let seconds_charts = t1.elapsed().as_secs_f64();
    progress.report("fit", None, "least squares with thin-plate fairness");
    let t2 = Instant::now();
    let basis = PouBasis::new(&atlas, radii.clone());
    let local = local_fits(&basis, opts.local_degree)?;
    let (control, fit_report) = fit(&basis, &local, &opts.fit)?;
    let seconds_fit = t2.elapsed().as_secs_f64();
    let sheet_faces: Vec<u32> = (0..atlas.mesh.n_faces() as u32)
        .filter(|&f| (atlas.face_origin[f as usize] as usize) < sheet)
        .collect();
    Ok(PouConstruction {
        atlas,
        radii,
        control,
        local,
        local_degree: opts.local_degree,
        fit: fit_report,
        sheet_faces,
        double_cover: bordered,
        seconds_atlas,
        seconds_charts,
        seconds_fit,
    })
}

/// The whole construction with its measurements: report, tessellation, control points.
pub fn run(
    input: &Surface,
    opts: &PouOptions,
    progress: &mut dyn Progress,
) -> Result<(PouReport, PouTessellation, PouConstruction)> {
    let t0 = Instant::now();
    let c = construct(input, opts, progress)?;
    let s = c.surface();
    progress.report("tessellate", None, "sampling the surface");
    let t1 = Instant::now();
    let tess = tessellate(&s, &c.sheet_faces, opts.tessellation)?;
    let seconds_tessellation = t1.elapsed().as_secs_f64();
    let t3 = Instant::now();
    let dist = NearestTriangle::new(&input.positions, input.mesh.faces());
    let (rms, max) = dist.error_percent(&tess.positions);
    let seconds_error = t3.elapsed().as_secs_f64();
    progress.report("checks", None, "chart independence and continuity");
    let t2 = Instant::now();
    let ci = chart_independence(&s, opts.independence_samples, 0x9e3779b97f4a7c15)?;
    let ne = c.atlas.mesh.n_edges();
    let stride = match opts.continuity_edges {
        0 => 1,
        n => ne.div_ceil(n).max(1),
    };
    let cont = continuity(&s, stride)?;
    let seconds_checks = t2.elapsed().as_secs_f64();
    let tol = 1e-10;
    let reached = cont.relative.iter().take_while(|&&j| j <= tol).count();
    let class = if reached == cont.relative.len() {
        "C∞ (jumps of orders 0–3 at rounding level)".to_string()
    } else if reached == 0 {
        "C⁻¹ (values differ between charts)".to_string()
    } else {
        format!("C{} (order {} jumps)", reached - 1, reached)
    };
    let nch = c.atlas.charts.len().max(1) as f64;
    let report = PouReport {
        control_points: c.control.len(),
        domain_faces: c.atlas.mesh.n_faces(),
        double_cover: c.double_cover,
        radius_factor: opts.radius,
        local_degree: c.local_degree,
        radius_min: c.radii.iter().copied().fold(f64::INFINITY, f64::min),
        radius_max: c.radii.iter().copied().fold(0.0, f64::max),
        mean_controls_per_chart: c
            .atlas
            .charts
            .iter()
            .map(|x| x.controls.len())
            .sum::<usize>() as f64
            / nch,
        rms_error_percent: rms,
        max_error_percent: max,
        continuity: PouContinuity {
            relative_jumps: cont.relative.clone(),
            samples: cont.samples,
            comparisons: cont.comparisons,
            edge_stride: stride,
            tolerance: tol,
            class,
        },
        chart_independence: ci,
        atlas: c.atlas.report.clone(),
        fit: c.fit.clone(),
        seconds_atlas: c.seconds_atlas,
        seconds_charts: c.seconds_charts,
        seconds_fit: c.seconds_fit,
        seconds_error,
        seconds_tessellation,
        seconds_checks,
        seconds: 0.0,
    };
    let mut report = report;
    report.seconds = t0.elapsed().as_secs_f64();
    drop(s);
    Ok((report, tess, c))
}

/// Partials of the jets as rows (for tests and reports): `out[d][i]` for coefficient `i`.
pub fn partials(j: &[Jet; 3]) -> [Vec<f64>; 3] {
    [j[0].partials(), j[1].partials(), j[2].partials()]
}

/// Exact distances from points to a triangle mesh: a uniform grid of cell `≈` the mean edge
/// length; a query scans its own cell for a first bound `δ`, then every cell meeting the box
/// `p ± δ` (a triangle closer than `δ` is registered in one of them). Points near the surface
/// (a fitted surface's samples) touch a few cells.
pub struct NearestTriangle {
    tris: Vec<[[f64; 3]; 3]>,
    lo: [f64; 3],
    cell: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
    /// Bounding-box diagonal of the mesh.
    pub diagonal: f64,
}

impl NearestTriangle {
    pub fn new(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> NearestTriangle {
        let tris: Vec<[[f64; 3]; 3]> = triangles
            .iter()
            .map(|t| t.map(|v| positions[v as usize]))
            .collect();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut mean = 0.0;
        for t in &tris {
            for p in t {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            mean += dot(sub(t[1], t[0]), sub(t[1], t[0])).sqrt();
        }
        if tris.is_empty() {
            lo = [0.0; 3];
            hi = [0.0; 3];
        }
        mean /= tris.len().max(1) as f64;
        let diagonal = dot(sub(hi, lo), sub(hi, lo)).sqrt();
        // About the mean edge, but never more than ~4 cells per triangle.
        let volume: f64 = (0..3)
            .map(|k| (hi[k] - lo[k]).max(diagonal / 256.0))
            .product();
        let cell = mean
            .max(diagonal / 256.0)
            .max((volume / (4.0 * tris.len().max(1) as f64)).cbrt())
            .max(1e-300);
        let dims: [usize; 3] =
            std::array::from_fn(|k| (((hi[k] - lo[k]) / cell).floor() as usize + 1).min(512));
        let ncell = dims[0] * dims[1] * dims[2];
        let mut grid = NearestTriangle {
            tris,
            lo,
            cell,
            dims,
            start: vec![0; ncell + 1],
            items: Vec::new(),
            diagonal,
        };
        let ranges: Vec<[usize; 6]> = grid
            .tris
            .iter()
            .map(|t| {
                let mut r = [0usize; 6];
                for k in 0..3 {
                    let a = t.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
                    let b = t.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
                    r[2 * k] = grid.index(a, k);
                    r[2 * k + 1] = grid.index(b, k);
                }
                r
            })
            .collect();
        let mut count = vec![0u32; ncell + 1];
        for r in &ranges {
            grid.for_cells(r, |c| count[c + 1] += 1);
        }
        for k in 1..count.len() {
            count[k] += count[k - 1];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; count[ncell] as usize];
        for (ti, r) in ranges.iter().enumerate() {
            grid.for_cells(r, |c| {
                items[fill[c] as usize] = ti as u32;
                fill[c] += 1;
            });
        }
        grid.start = count;
        grid.items = items;
        grid
    }

    #[inline]
    fn index(&self, x: f64, k: usize) -> usize {
        (((x - self.lo[k]) / self.cell).floor().max(0.0) as usize).min(self.dims[k] - 1)
    }

    #[inline]
    fn for_cells(&self, r: &[usize; 6], mut f: impl FnMut(usize)) {
        for z in r[4]..=r[5] {
            for y in r[2]..=r[3] {
                for x in r[0]..=r[1] {
                    f((z * self.dims[1] + y) * self.dims[0] + x);
                }
            }
        }
    }

    fn scan(&self, p: [f64; 3], r: &[usize; 6], best: &mut f64) {
        self.for_cells(r, |c| {
            for &t in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
                *best = best.min(point_triangle_distance(p, &self.tris[t as usize]));
            }
        });
    }

    /// Distance from `p` to the mesh (`∞` for an empty mesh).
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        if self.tris.is_empty() {
            return f64::INFINITY;
        }
        let c: [usize; 3] = std::array::from_fn(|k| self.index(p[k], k));
        let mut best = f64::INFINITY;
        // A first bound: the own cell, then growing boxes of cells until a triangle is met.
        let mut grow = 0usize;
        while !best.is_finite() {
            let r: [usize; 6] = std::array::from_fn(|i| {
                let k = i / 2;
                if i % 2 == 0 {
                    c[k].saturating_sub(grow)
                } else {
                    (c[k] + grow).min(self.dims[k] - 1)
                }
            });
            self.scan(p, &r, &mut best);
            if r.chunks(2)
                .enumerate()
                .all(|(k, x)| x[0] == 0 && x[1] == self.dims[k] - 1)
            {
                break;
            }
            grow = 2 * grow + 1;
        }
        // Every triangle within `best` is registered in a cell meeting the box p ± best.
        let r: [usize; 6] = std::array::from_fn(|i| {
            let k = i / 2;
            let x = if i % 2 == 0 { p[k] - best } else { p[k] + best };
            self.index(x, k)
        });
        self.scan(p, &r, &mut best);
        best
    }

    /// RMS and maximum distance of `points` to the mesh, in percent of its bounding-box
    /// diagonal.
    pub fn error_percent(&self, points: &[[f64; 3]]) -> (f64, f64) {
        let d: Vec<f64> = points.par_iter().map(|&p| self.distance(p)).collect();
        let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt();
        let max = d.iter().fold(0.0f64, |a, &b| a.max(b));
        let s = 100.0 / self.diagonal.max(1e-300);
        (rms * s, max * s)
    }
}
