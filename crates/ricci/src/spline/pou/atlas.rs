//! The hyperbolic atlas of a closed surface with χ < 0 (paper 004 §4.1): the uniformization
//! metric (hyperbolic Ricci flow, polished to double-double), the canonical cut, the layout of
//! the fundamental domain in the Poincaré disk in double-double, the Fuchsian side pairings —
//! and from them one chart per vertex.
//!
//! **Charts.** The chart of vertex `v` is the Poincaré-disk coordinate in which one lift of `v`
//! sits at the origin: `M = τ ∘ γ` maps the fundamental domain's coordinate to it, `τ` the
//! Möbius map taking the lift of `v` to 0 and `γ` a deck transformation. The chart is
//! *developed* from the fundamental domain: starting from a face at `v`, faces are reached
//! breadth first across edges; crossing an edge of the cut composes the map with the side
//! pairing of that edge (`σ`, computed in double-double from the edge's two end points, and
//! compared with the deck group's least-squares side map: `max_deck_mismatch`). Faces are
//! developed as *lifts* to the universal cover: a face met again at another position is a
//! different lift and is kept (a disk that wraps around a handle meets two lifts of the same
//! control point). The chart's domain is the open star of `v` (the faces at the origin); its
//! development reaches as far as the bases that can be non-zero on the star need (see
//! [`HyperbolicAtlas::develop_charts`]).
//!
//! **Points** of the surface are named `(face, λ)` with *hyperboloid barycentric coordinates*
//! `λ`: the point is `Σ λ_i X_i` normalized onto the hyperboloid, `X_i` the hyperboloid
//! points of the face's vertices. Isometries act linearly on the hyperboloid, so `(face, λ)`
//! is the same point in every chart (in the Klein model these are the affine barycentric
//! coordinates up to the weights `X_i⁰`). [`HyperbolicAtlas::locate`] inverts it in a chart.
//!
//! **Transitions** between overlapping charts (adjacent vertices; their stars share two faces)
//! are `M_v(f) ∘ M_u(f)⁻¹` for a face `f` of both stars, an SU(1,1) matrix.

use std::collections::HashMap;
use std::time::Instant;

use crate::error::{Error, Result};
use crate::flow::{flow_with_fallback, TargetSpec, UniformizationOptions};
use crate::layout::dd::MobiusDd;
use crate::layout::isometry::{Complex, Isometry, Mobius};
use crate::layout::pipeline::{cut_disk_polished, polish_uniformization};
use crate::layout::{deck_group, layout_dd, DeckGroup};
use crate::mesh::{topology, Mesh, Surface};
use crate::metric::{Geometry, Hyperbolic, IntrinsicMetric, Scheme};
use crate::numeric::dd::Cdd;
use crate::progress::Progress;

/// A face of a chart's star: its lift's map from the fundamental domain's coordinate to the
/// chart, and the chart positions of its vertices (in the order of the mesh's face).
#[derive(Debug, Clone)]
pub struct StarFace {
    pub face: u32,
    pub map: MobiusDd,
    /// Index of `map` among the distinct maps of the star (faces with the same index have
    /// the same map).
    pub map_id: u32,
    pub z: [Complex; 3],
}

/// A lift of a control point (vertex) in a chart.
#[derive(Debug, Clone, Copy)]
pub struct ControlLift {
    pub vertex: u32,
    /// Its position in the chart.
    pub z: Complex,
    /// The map from this chart to the chart of `vertex` that takes this lift to the origin
    /// (SU(1,1)): `|map(z)|² = tanh²(d/2)` and `map(z)` is the local coordinate of the basis.
    pub map: Mobius,
}

/// Face lifts developed from a chart ([`HyperbolicAtlas::develop_indexed`]).
pub struct Developed {
    /// The distinct maps from the fundamental domain's coordinate to the chart.
    pub maps: Vec<MobiusDd>,
    /// `(face, index of its map, chart positions of its vertices)`, the star first.
    pub lifts: Vec<(u32, u32, [Complex; 3])>,
}

/// A fast hasher for small integer keys (FNV-1a over the key's bytes is enough here and
/// much cheaper than SipHash).
#[derive(Default, Clone, Copy)]
pub struct FastHasher(u64);
impl std::hash::Hasher for FastHasher {
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x100000001b3);
        }
    }
    #[inline]
    fn write_u32(&mut self, x: u32) {
        self.0 = (self.0.rotate_left(29) ^ x as u64).wrapping_mul(0x9e3779b97f4a7c15);
    }
}
/// [`FastHasher`] as a `BuildHasher`.
pub type FastHash = std::hash::BuildHasherDefault<FastHasher>;

/// The chart of one vertex.
#[derive(Debug, Clone)]
pub struct Chart {
    pub vertex: u32,
    /// The faces at the origin (the chart's domain is their union).
    pub star: Vec<StarFace>,
    /// Every lift of a control point whose disk can reach the star.
    pub controls: Vec<ControlLift>,
    /// Face lifts developed for the basis of this vertex (its support, conservatively).
    pub developed_faces: usize,
}

/// What building the atlas measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AtlasReport {
    pub flow_iterations: usize,
    pub flow_max_curvature_error: f64,
    pub polish_residual_dd: f64,
    pub refined_vertices: usize,
    pub cut_edges: usize,
    pub relation_error: Option<f64>,
    /// Largest distance between an edge's side pairing `σ` (double-double, from the edge's
    /// end points) and the deck group's side map of its side (Frobenius norm of SU(1,1)).
    pub max_deck_mismatch: f64,
    pub seconds: f64,
}

/// The hyperbolic structure and the charts (module docs).
pub struct HyperbolicAtlas {
    /// The closed domain surface (the input, refined where the cut needed it).
    pub mesh: Mesh,
    /// Hyperbolic edge lengths of `mesh`.
    pub lengths: Vec<f64>,
    /// Positions in R³ of `mesh`'s vertices (refined vertices interpolated on the input's edges).
    pub positions: Vec<[f64; 3]>,
    /// For every face of `mesh`, the input face it lies in.
    pub face_origin: Vec<u32>,
    /// The fundamental domain (cut mesh: same faces and half-edges as `mesh`).
    pub cut_mesh: Mesh,
    /// Double-double positions of the cut mesh's vertices in the Poincaré disk.
    pub global: Vec<Cdd>,
    /// Per interior half-edge of `mesh`: the side pairing to compose with when crossing it
    /// (`None`: the edge is not cut).
    pub crossing: Vec<Option<MobiusDd>>,
    /// The Fuchsian group of the fundamental domain.
    pub deck: DeckGroup<Mobius>,
    /// One chart per vertex of `mesh` (after [`HyperbolicAtlas::develop_charts`]).
    pub charts: Vec<Chart>,
    pub report: AtlasReport,
}

/// Hyperboloid point `(X₁, X₂, X₀)` of a disk point.
#[inline]
pub fn hyperboloid(z: Complex) -> [f64; 3] {
    let d = 1.0 - z.norm_sqr();
    [2.0 * z.re / d, 2.0 * z.im / d, (1.0 + z.norm_sqr()) / d]
}

/// The disk point of `(face, λ)` given the chart positions of the face's vertices.
#[inline]
pub fn point_in_face(z: &[Complex; 3], lambda: [f64; 3]) -> Complex {
    let mut x = [0.0; 3];
    for k in 0..3 {
        let h = hyperboloid(z[k]);
        for d in 0..3 {
            x[d] += lambda[k] * h[d];
        }
    }
    let q = (x[2] * x[2] - x[0] * x[0] - x[1] * x[1])
        .max(f64::MIN_POSITIVE)
        .sqrt();
    let (x1, x2, x0) = (x[0] / q, x[1] / q, x[2] / q);
    Complex::new(x1, x2) / (1.0 + x0)
}

/// Hyperboloid barycentric coordinates of `p` in the triangle `z` (any sign; `None` for a
/// degenerate triangle).
pub fn barycentric(z: &[Complex; 3], p: Complex) -> Option<[f64; 3]> {
    // Klein coordinates: geodesic triangles are straight there.
    let k = |w: Complex| 2.0 * w / (1.0 + w.norm_sqr());
    let (a, b, c, q) = (k(z[0]), k(z[1]), k(z[2]), k(p));
    let det = (b - a).re * (c - a).im - (b - a).im * (c - a).re;
    if det.abs() < 1e-300 {
        return None;
    }
    let m1 = ((q - a).re * (c - a).im - (q - a).im * (c - a).re) / det;
    let m2 = ((b - a).re * (q - a).im - (b - a).im * (q - a).re) / det;
    let mu = [1.0 - m1 - m2, m1, m2];
    // λ_i ∝ μ_i / X_i⁰.
    let mut l = [0.0; 3];
    for i in 0..3 {
        l[i] = mu[i] / hyperboloid(z[i])[2];
    }
    let s: f64 = l.iter().sum();
    Some(l.map(|x| x / s))
}

/// Lifts developed per chart at most (a budget against radii far too large for the mesh).
pub const MAX_DEVELOPED_FACES: usize = 200_000;

impl HyperbolicAtlas {
    /// Uniformization, cut, double-double layout and deck group of a closed connected surface
    /// with χ < 0 (module docs). The charts are developed later, when the radii of the bases
    /// are known ([`HyperbolicAtlas::develop_charts`]).
    pub fn build(surface: &Surface, progress: &mut dyn Progress) -> Result<HyperbolicAtlas> {
        let t0 = Instant::now();
        let mesh = &surface.mesh;
        let topo = topology(mesh);
        if topo.components.len() != 1 {
            return Err(Error::topology(format!(
                "a hyperbolic atlas needs one connected surface, this mesh has {} components",
                topo.components.len()
            )));
        }
        if mesh.has_boundary() {
            return Err(Error::topology(
                "the hyperbolic atlas is built on closed surfaces; pass the double cover of a \
                 surface with boundary (spline::pou::double_cover)",
            ));
        }
        let chi = topo.euler_characteristic();
        if chi >= 0 {
            return Err(Error::topology(format!(
                "the surface has Euler characteristic {chi} ≥ 0: it carries no hyperbolic \
                 structure (genus ≥ 2 is needed)"
            )));
        }
        progress.report("flow", None, "hyperbolic uniformization metric");
        // Thurston's packing (the flow's default scheme), the uniform target.
        let opts =
            UniformizationOptions::single(Some(Geometry::Hyperbolic), Scheme::Thurston, 1e-12)
                .with_target(TargetSpec::Uniform);
        let input = IntrinsicMetric::euclidean(surface.edge_lengths());
        let flow = flow_with_fallback(mesh, &input, &opts, None, progress)?.result;
        if !flow.converged {
            return Err(Error::numerical(format!(
                "the hyperbolic Ricci flow did not converge (max curvature error {:.3e})",
                flow.max_curvature_error
            )));
        }
        progress.report("polish", None, "metric to double-double");
        let pol = polish_uniformization(mesh, &input, &flow)?;
        progress.report("cut", None, "canonical cut and fundamental domain");
        let disk = cut_disk_polished(mesh, &pol.metric, Some(&surface.positions), None, progress)?;
        let layout = layout_dd::<Hyperbolic>(&disk.mesh, &disk.metric, None)?;
        if !layout.flipped_faces.is_empty() {
            return Err(Error::numerical(format!(
                "the layout of the fundamental domain flipped {} faces (first: face {})",
                layout.flipped_faces.len(),
                layout.flipped_faces[0]
            )));
        }
        let deck = deck_group::<Hyperbolic>(&layout, &disk.polygon)?;
        let refined = &disk.cut.refined;
        let rm = refined.mesh.clone();
        let cm = disk.mesh.clone();
        let mut lengths = vec![0.0; rm.n_edges()];
        for h in 0..rm.n_corners() as u32 {
            lengths[rm.he_edge(h) as usize] = disk.metric[cm.he_edge(h) as usize];
        }
        let positions = refined
            .positions
            .clone()
            .ok_or_else(|| Error::input("the cut lost the vertex positions"))?;
        let global: Vec<Cdd> = (0..layout.positions.len())
            .map(|v| {
                let lo = layout
                    .positions_lo
                    .get(v)
                    .copied()
                    .unwrap_or(Complex::new(0.0, 0.0));
                Cdd::from_parts(layout.positions[v], lo)
            })
            .collect();
        // Side pairings per cut half-edge.
        let side_maps: Vec<Mobius> = (0..disk.polygon.sides.len())
            .filter_map(|s| deck.side_map(s))
            .collect();
        let mut crossing = vec![None; rm.n_corners()];
        let mut cut_edges = 0;
        let mut mismatch = 0.0f64;
        for h in 0..rm.n_corners() as u32 {
            if !cm.is_boundary_halfedge(cm.he_twin(h)) {
                continue;
            }
            cut_edges += 1;
            let t = rm.he_twin(h);
            if rm.is_boundary_halfedge(t) {
                continue;
            }
            // h: a → b in face f (copies ca, cb); t: b → a in face g (copies cb', ca').
            let (ca, cb) = (cm.he_origin(h), cm.he_tip(h));
            let (cbp, cap) = (cm.he_origin(t), cm.he_tip(t));
            let s = MobiusDd::from_pairs(
                global[cap as usize],
                global[cbp as usize],
                global[ca as usize],
                global[cb as usize],
            );
            let r = s.round();
            let best = side_maps
                .iter()
                .map(|m| m.distance(&r))
                .fold(f64::INFINITY, f64::min);
            mismatch = mismatch.max(best);
            crossing[h as usize] = Some(s);
        }
        let report = AtlasReport {
            flow_iterations: flow.iterations,
            flow_max_curvature_error: flow.max_curvature_error,
            polish_residual_dd: pol.residual_dd,
            refined_vertices: rm.n_vertices() - mesh.n_vertices(),
            cut_edges: cut_edges / 2,
            relation_error: deck.relation_error,
            max_deck_mismatch: if side_maps.is_empty() { 0.0 } else { mismatch },
            seconds: t0.elapsed().as_secs_f64(),
        };
        Ok(HyperbolicAtlas {
            mesh: rm,
            lengths,
            positions,
            face_origin: refined.face_origin.clone(),
            cut_mesh: cm,
            global,
            crossing,
            deck,
            charts: Vec::new(),
            report,
        })
    }

    /// Largest hyperbolic length of an edge at `v` (the star of `v` lies in the disk of this
    /// radius around it: the distance from a point is convex on geodesic triangles).
    pub fn star_radius(&self, v: u32) -> f64 {
        self.mesh
            .outgoing(v)
            .map(|h| self.lengths[self.mesh.he_edge(h) as usize])
            .fold(0.0, f64::max)
    }

    /// Develop the chart of `v` breadth first over face lifts, keeping the lifts for which
    /// `keep(face, positions)` holds (the star is always kept) and expanding only those.
    /// Returns the kept lifts, the star first.
    pub fn develop(
        &self,
        v: u32,
        keep: impl FnMut(u32, &[Complex; 3]) -> bool,
    ) -> Result<Vec<(u32, MobiusDd, [Complex; 3])>> {
        let d = self.develop_indexed(v, keep)?;
        Ok(d.lifts
            .into_iter()
            .map(|(f, mi, z)| (f, d.maps[mi as usize], z))
            .collect())
    }

    /// [`HyperbolicAtlas::develop`] with the distinct maps met listed once and the lifts
    /// referring to them by index (the same deck element reached along different paths is one
    /// map).
    pub fn develop_indexed(
        &self,
        v: u32,
        mut keep: impl FnMut(u32, &[Complex; 3]) -> bool,
    ) -> Result<Developed> {
        let m = &self.mesh;
        let f0 = m
            .vertex_faces(v)
            .next()
            .ok_or_else(|| Error::input(format!("vertex {v} has no faces")))?;
        let k = m
            .face(f0)
            .iter()
            .position(|&x| x == v)
            .ok_or_else(|| Error::input(format!("vertex {v} is not on face {f0}")))?;
        let cv = self.cut_mesh.face(f0)[k];
        // The distinct maps met (a lift refers to one by index; the same deck element reached
        // along different paths is one map) and the chart positions of the cut-mesh vertices
        // under each, computed once.
        let mut maps: Vec<MobiusDd> = vec![MobiusDd::to_origin(self.global[cv as usize])];
        let mut cache: HashMap<(u32, u32), Complex, FastHash> = HashMap::default();
        let mut lift = |f: u32, mi: u32, maps: &[MobiusDd]| -> [Complex; 3] {
            self.cut_mesh.face(f).map(|c| {
                *cache.entry((mi, c)).or_insert_with(|| {
                    let w = maps[mi as usize].apply(self.global[c as usize]);
                    w.hi() + w.lo()
                })
            })
        };
        let mut seen: HashMap<u32, Vec<Complex>, FastHash> = HashMap::default();
        let mut queue = std::collections::VecDeque::new();
        let z0 = lift(f0, 0, &maps);
        seen.entry(f0).or_default().push(z0[0]);
        queue.push_back((f0, 0u32, z0));
        let mut kept = Vec::new();
        let mut star = Vec::new();
        let mut visited = 0usize;
        while let Some((f, mi, z)) = queue.pop_front() {
            visited += 1;
            if visited > MAX_DEVELOPED_FACES {
                return Err(Error::numerical(format!(
                    "chart of vertex {v}: developing more than {MAX_DEVELOPED_FACES} face lifts; \
                     the radii of the bases are too large for this mesh"
                )));
            }
            let at_origin = m
                .face(f)
                .iter()
                .zip(&z)
                .any(|(&x, w)| x == v && w.norm() < 1e-9);
            if at_origin {
                star.push((f, mi, z));
            } else if keep(f, &z) {
                kept.push((f, mi, z));
            } else {
                continue;
            }
            for h in m.face_halfedges(f) {
                let t = m.he_twin(h);
                if m.is_boundary_halfedge(t) {
                    continue;
                }
                let g = m.he_face(t);
                let gi = match &self.crossing[h as usize] {
                    Some(s) => {
                        let gm = maps[mi as usize].compose(s).normalized();
                        match maps.iter().position(|x| x.distance(&gm) < 1e-20) {
                            Some(i) => i as u32,
                            None => {
                                maps.push(gm);
                                (maps.len() - 1) as u32
                            }
                        }
                    }
                    None => mi,
                };
                let zg = lift(g, gi, &maps);
                let lifts = seen.entry(g).or_default();
                if lifts.iter().any(|w| (w - zg[0]).norm() < 1e-9) {
                    continue;
                }
                lifts.push(zg[0]);
                queue.push_back((g, gi, zg));
            }
        }
        star.extend(kept);
        Ok(Developed { maps, lifts: star })
    }

    /// Develop every chart (in parallel) for bases of radii `radii` (per vertex).
    ///
    /// The control lifts are found from the bases' side, not the charts': the basis of `u`
    /// is developed in its own chart over the face lifts that can meet its disk
    /// `D(0, r_u)` — a face lift with vertices `z_k` and longest edge `h` is expanded while
    /// `min_k d(0, z_k) < r_u + h` (every point of the face is within `h` of each vertex;
    /// the faces meeting a geodesic disk are connected across edges because the disk is
    /// convex). Every face lift `f` found names, for each vertex `v` of `f`, one lift of `u`
    /// in the chart of `v`: `T⁻¹(0)` with `T = M ∘ M_v(f)⁻¹` the map from chart `v` to this
    /// lift's chart of `u` (`M` the lift's map, `M_v(f)` the star map of `f` in chart `v`),
    /// composed in double-double. A lift of `u` whose disk meets the star of `v` meets one of
    /// its faces, so it is found; it is kept when within `ρ₁(v) + r_u` of the origin (`ρ₁(v)`
    /// the star radius), the bases that can be non-zero on the star. The work is the sum of
    /// the bases' supports (what evaluation touches anyway), however fast the radii vary.
    /// The chart-independence and continuity checks ([`super::measure`]) would see a lift
    /// that was missed.
    pub fn develop_charts(&mut self, radii: &[f64], progress: &mut dyn Progress) -> Result<()> {
        use rayon::prelude::*;
        let nv = self.mesh.n_vertices();
        if radii.len() != nv {
            return Err(Error::input(format!(
                "{} radii for {nv} vertices",
                radii.len()
            )));
        }
        if let Some(v) = (0..nv).find(|&v| !(radii[v] > 0.0 && radii[v].is_finite())) {
            return Err(Error::input(format!(
                "the radius {} of vertex {v} is not a positive number",
                radii[v]
            )));
        }
        let face_diameter: Vec<f64> = (0..self.mesh.n_faces() as u32)
            .map(|f| {
                self.mesh
                    .face_halfedges(f)
                    .iter()
                    .map(|&h| self.lengths[self.mesh.he_edge(h) as usize])
                    .fold(0.0, f64::max)
            })
            .collect();
        progress.report("charts", None, &format!("developing {nv} stars"));
        let stars: Vec<Vec<StarFace>> = (0..nv as u32)
            .into_par_iter()
            .map(|v| -> Result<Vec<StarFace>> {
                let d = self.develop_indexed(v, |_, _| false)?;
                Ok(d.lifts
                    .into_iter()
                    .map(|(face, mi, z)| StarFace {
                        face,
                        map: d.maps[mi as usize],
                        map_id: mi,
                        z,
                    })
                    .collect())
            })
            .collect::<Result<_>>()?;
        let rho: Vec<f64> = (0..nv as u32).map(|v| self.star_radius(v)).collect();
        progress.report("charts", None, &format!("developing {nv} basis supports"));
        // Per basis u: (chart v, lift) pairs, deduplicated per chart.
        let per_basis: Vec<(Vec<(u32, ControlLift)>, usize)> = (0..nv as u32)
            .into_par_iter()
            .map(|u| -> Result<(Vec<(u32, ControlLift)>, usize)> {
                let ru = radii[u as usize];
                let d = self.develop_indexed(u, |f, z| {
                    let t = (0.5 * (ru + face_diameter[f as usize])).tanh();
                    z.iter().any(|w| w.norm_sqr() < t * t)
                })?;
                let mut out: Vec<(u32, ControlLift)> = Vec::new();
                let mut known: HashMap<u32, Vec<Complex>, FastHash> = HashMap::default();
                // (chart, map of the lift, map of the star face) already handled: the lift
                // of u in the chart is a function of the two maps.
                let mut done: std::collections::HashSet<(u32, u32, u32), FastHash> =
                    Default::default();
                for &(f, mi, _) in &d.lifts {
                    let map = &d.maps[mi as usize];
                    for &v in self.mesh.face(f).iter() {
                        let Some(sv) = stars[v as usize].iter().find(|s| s.face == f) else {
                            continue;
                        };
                        if !done.insert((v, mi, sv.map_id)) {
                            continue;
                        }
                        // T = M ∘ M_v(f)⁻¹ (chart v → this lift's chart of u); the lift sits
                        // at T⁻¹(0) = −b/a.
                        let tm = map.compose(&sv.map.inverse()).normalized().round();
                        let c = -tm.b / tm.a;
                        let t = (0.5 * (rho[v as usize] + ru)).tanh();
                        if c.norm_sqr() >= t * t {
                            continue;
                        }
                        let seen = known.entry(v).or_default();
                        if seen.iter().any(|x| (x - c).norm() < 1e-9) {
                            continue;
                        }
                        seen.push(c);
                        out.push((
                            v,
                            ControlLift {
                                vertex: u,
                                z: c,
                                map: tm,
                            },
                        ));
                    }
                }
                Ok((out, d.lifts.len()))
            })
            .collect::<Result<_>>()?;
        let mut controls: Vec<Vec<ControlLift>> = vec![Vec::new(); nv];
        let mut support = vec![0usize; nv];
        for (u, (list, n)) in per_basis.into_iter().enumerate() {
            support[u] = n;
            for (v, c) in list {
                controls[v as usize].push(c);
            }
        }
        self.charts = stars
            .into_iter()
            .zip(controls)
            .zip(support)
            .enumerate()
            .map(|(v, ((star, controls), developed_faces))| Chart {
                vertex: v as u32,
                star,
                controls,
                developed_faces,
            })
            .collect();
        Ok(())
    }

    /// Index of face `f` in the star of chart `v`.
    pub fn star_index(&self, v: u32, f: u32) -> Option<usize> {
        self.charts
            .get(v as usize)?
            .star
            .iter()
            .position(|s| s.face == f)
    }

    /// The chart coordinate of the surface point `(f, λ)` in the chart of `v` (`f` must be in
    /// the star of `v`).
    pub fn chart_point(&self, v: u32, f: u32, lambda: [f64; 3]) -> Option<Complex> {
        let i = self.star_index(v, f)?;
        Some(point_in_face(&self.charts[v as usize].star[i].z, lambda))
    }

    /// Point location: the face of the star of `v` containing the chart point `z` and its
    /// hyperboloid barycentric coordinates (`None` outside the star).
    pub fn locate(&self, v: u32, z: Complex) -> Option<(u32, [f64; 3])> {
        let chart = self.charts.get(v as usize)?;
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for s in &chart.star {
            let Some(l) = barycentric(&s.z, z) else {
                continue;
            };
            let worst = l.iter().fold(f64::INFINITY, |a, &b| a.min(b));
            if best.as_ref().is_none_or(|b| worst > b.0) {
                best = Some((worst, s.face, l));
            }
        }
        best.filter(|b| b.0 > -1e-12).map(|b| (b.1, b.2))
    }

    /// The transition from the chart of `from` to the chart of `to` (chart-`to` coordinate as
    /// a function of the chart-`from` coordinate) as an SU(1,1) matrix, through a face of both
    /// stars (`None` if the stars share no face, i.e. the charts do not overlap).
    pub fn transition(&self, from: u32, to: u32) -> Option<Mobius> {
        let a = self.charts.get(from as usize)?;
        let b = self.charts.get(to as usize)?;
        for s in &a.star {
            if let Some(t) = b.star.iter().find(|t| t.face == s.face) {
                return Some(t.map.compose(&s.map.inverse()).normalized().round());
            }
        }
        None
    }

    /// The transition through a given face of both stars.
    pub fn transition_via(&self, from: u32, to: u32, face: u32) -> Option<Mobius> {
        let s = &self.charts.get(from as usize)?.star[self.star_index(from, face)?];
        let t = &self.charts.get(to as usize)?.star[self.star_index(to, face)?];
        Some(t.map.compose(&s.map.inverse()).normalized().round())
    }
}

/// The double cover of a surface with boundary (paper 004 §1, Gu–Yau 2003): the surface and
/// its mirror image (faces reversed) glued along the boundary, with the same positions.
/// Interior edges whose two end points are on the boundary are split at their midpoint first
/// (otherwise the two sheets would share them and the cover would not be a manifold).
/// Returns the closed surface and the number of faces of the first sheet (faces `0..n` are
/// the input's, after those splits).
pub fn double_cover(surface: &Surface) -> Result<(Surface, usize)> {
    use std::collections::HashSet;
    let m = &surface.mesh;
    let mut positions = surface.positions.clone();
    let mut faces: Vec<[u32; 3]> = m.faces().to_vec();
    let on_boundary: Vec<bool> = (0..m.n_vertices() as u32)
        .map(|v| m.is_boundary_vertex(v))
        .collect();
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let boundary_edges: HashSet<(u32, u32)> = (0..m.n_edges() as u32)
        .filter(|&e| m.is_boundary_edge(e))
        .map(|e| {
            let [a, b] = m.edge_vertices(e);
            key(a, b)
        })
        .collect();
    let chords: Vec<(u32, u32)> = (0..m.n_edges() as u32)
        .map(|e| m.edge_vertices(e))
        .filter(|[a, b]| {
            on_boundary[*a as usize]
                && on_boundary[*b as usize]
                && !boundary_edges.contains(&key(*a, *b))
        })
        .map(|[a, b]| (a, b))
        .collect();
    for (a, b) in chords {
        let (pa, pb) = (positions[a as usize], positions[b as usize]);
        positions.push([0, 1, 2].map(|d| 0.5 * (pa[d] + pb[d])));
        let mid = (positions.len() - 1) as u32;
        let mut added = Vec::new();
        for f in faces.iter_mut() {
            for k in 0..3 {
                let (x, y) = (f[k], f[(k + 1) % 3]);
                if key(x, y) == key(a, b) {
                    let z = f[(k + 2) % 3];
                    *f = [x, mid, z];
                    added.push([mid, y, z]);
                    break;
                }
            }
        }
        faces.extend(added);
    }
    let nv = positions.len();
    let nb = on_boundary.len();
    let mut index = vec![u32::MAX; nv];
    for v in 0..nv {
        index[v] = if v < nb && on_boundary[v] {
            v as u32
        } else {
            positions.push(positions[v]);
            (positions.len() - 1) as u32
        };
    }
    let sheet = faces.len();
    for k in 0..sheet {
        let f = faces[k];
        faces.push([
            index[f[0] as usize],
            index[f[2] as usize],
            index[f[1] as usize],
        ]);
    }
    Ok((Surface::new(positions, faces)?, sheet))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_inverts_point_in_face() {
        let z = [
            Complex::new(0.1, 0.2),
            Complex::new(-0.5, 0.1),
            Complex::new(0.2, -0.6),
        ];
        let l = [0.2, 0.5, 0.3];
        let p = point_in_face(&z, l);
        let back = barycentric(&z, p).unwrap();
        for k in 0..3 {
            assert!((back[k] - l[k]).abs() < 1e-13);
        }
        // Möbius invariance of (face, λ).
        let m = Mobius::new(Complex::new(1.2, 0.3), Complex::new(0.4, -0.5)).unwrap();
        let zm = z.map(|w| m.apply(w));
        let pm = point_in_face(&zm, l);
        assert!((pm - m.apply(p)).norm() < 1e-13);
    }
}
