//! Target curvature designs (paper 001 §V Step 1, §VI-B; paper 000 §4 Step 1; docs/DESIGN.md §4)
//! and their admissibility: Gauss–Bonnet (paper 001 eq. 8) and the combinatorial condition of
//! Chow and Luo (paper 000 eq. 7, paper 001 Theorem 4).
//!
//! Designs:
//! * `uniform` — `K̄ = 0` at every vertex: the constant curvature lives in the background
//!   (E² needs χ = 0, H² χ < 0, S² χ > 0);
//! * `cone:V=K,…` — the listed vertices get `K` (radians; `2pi`, `-1.5pi`, `pi/2` accepted),
//!   all others 0;
//! * `single-cone:V` — all of `2πχ` at `V` (the automatic choice comes with the atlas);
//! * `free-boundary` — `K̄ = 0` inside, `u` fixed at its initial value on the boundary (the
//!   boundary keeps its lengths: least area distortion near the boundary);
//! * `round-boundary` — `K̄ = 0` inside; the vertices of each boundary loop lie on a circle
//!   (constant geodesic curvature `1/R`): with the loop's current edge lengths `l_k`, edge `k`
//!   subtends `α_k = 2 asin(l_k/2R)`, `R` chosen so that `Σ α_k = |T|`, and a boundary vertex
//!   between edges `a`, `b` gets the turning angle `K̄_i = sign(T)(α_a + α_b)/2` —
//!   re-evaluated as the metric changes ([`Target::update_round`]). (To first order
//!   `K̄_i ≈ T (l_a + l_b)/2L`, the dual-length share of `T`; the exact rule is what puts the
//!   laid-out vertices on one circle, to rounding.) Totals `T`: for genus 0 the longest loop
//!   (input lengths) gets `+2π` and every other loop `−2π` (a disk with round holes); for
//!   genus ≥ 1 every loop gets `2πχ/b` (vertices on arcs of constant geodesic curvature, all
//!   loops alike). Euclidean only;
//! * `geodesic-boundary` — `K̄ = 0` everywhere including the boundary (hyperbolic metrics with
//!   geodesic boundaries);
//! * `file:PATH` — one value per vertex: a JSON array, a JSON object `{"targets": [...]}` or
//!   `{"vertex id": value, ...}` (others 0), or plain text with one value per line.
//!
//! **Chow–Luo.** For a circle packing with intersection angles φ ∈ [0, π/2] the angle at `v` in
//! a face whose opposite edge `e` avoids the vertex set `I` is below `π − φ(e)`, faces with two
//! corners in `I` contribute less than π there and faces inside `I` exactly π (less in H²).
//! Hence every metric satisfies, for every vertex set `I`,
//! `Σ_{i∈I} K_i > Σ_{i∈I} b_i − π(|F_I| + |F_2|) − Σ_{(e,v)∈Lk(I)} (π − φ(e))`
//! (`b_i = 2π` inside, `π` on the boundary, `F_2` the faces with two corners in `I`), which for
//! closed surfaces is exactly paper 000 eq. 7: `Σ K_i > −Σ_{Lk(I)} (π − φ(e)) + 2πχ(F_I)`.
//! Targets are checked on every single vertex and every closed one-ring (a vertex and its
//! neighbours); vertex scaling and inversive distance use the φ = 0 bound (angles below π).

use super::FlowError;
use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::metric::{euler_characteristic, Geometry};
use std::collections::VecDeque;
use std::f64::consts::PI;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// A target curvature design as given by the user.
#[derive(Debug, Clone, PartialEq)]
pub enum TargetSpec {
    Uniform,
    Cones(Vec<(u32, f64)>),
    SingleCone(Option<u32>),
    FreeBoundary,
    /// `free-boundary` with cones `(vertex, K̄)` at interior vertices: `u` held on the
    /// boundary, `K̄` at the cones, flat elsewhere inside (library use: `ricci param --seams
    /// free`, the boundary being the cut through the homology generators).
    FreeBoundaryCones(Vec<(u32, f64)>),
    RoundBoundary,
    /// `round-boundary` with cones `(vertex, K̄)` at interior vertices: the boundary loops on
    /// circles whose total turning leaves `2πχ − Σ K̄` to them (library use: `ricci param
    /// --boundary round --cones …`; genus 0: the longest loop turns by `2π − Σ K̄`, the others
    /// by `−2π`).
    RoundBoundaryCones(Vec<(u32, f64)>),
    GeodesicBoundary,
    File(PathBuf),
    /// One value per vertex (library use).
    PerVertex(Vec<f64>),
}

impl fmt::Display for TargetSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TargetSpec::Uniform => write!(f, "uniform"),
            TargetSpec::Cones(c) => {
                let s: Vec<String> = c.iter().map(|(v, k)| format!("{v}={k}")).collect();
                write!(f, "cone:{}", s.join(","))
            }
            TargetSpec::SingleCone(Some(v)) => write!(f, "single-cone:{v}"),
            TargetSpec::SingleCone(None) => write!(f, "single-cone"),
            TargetSpec::FreeBoundary => write!(f, "free-boundary"),
            TargetSpec::FreeBoundaryCones(c) => {
                let s: Vec<String> = c.iter().map(|(v, k)| format!("{v}={k}")).collect();
                write!(f, "free-boundary+cone:{}", s.join(","))
            }
            TargetSpec::RoundBoundary => write!(f, "round-boundary"),
            TargetSpec::RoundBoundaryCones(c) => {
                let s: Vec<String> = c.iter().map(|(v, k)| format!("{v}={k}")).collect();
                write!(f, "round-boundary+cone:{}", s.join(","))
            }
            TargetSpec::GeodesicBoundary => write!(f, "geodesic-boundary"),
            TargetSpec::File(p) => write!(f, "file:{}", p.display()),
            TargetSpec::PerVertex(_) => write!(f, "per-vertex"),
        }
    }
}

/// Parse a curvature value: a number, optionally times `pi` (`-2pi`, `1.5pi`, `pi/2`, `-pi/3`).
pub fn parse_angle(s: &str) -> Option<f64> {
    let t = s.trim().to_ascii_lowercase().replace('π', "pi");
    if let Ok(x) = t.parse::<f64>() {
        return x.is_finite().then_some(x);
    }
    let (num, den) = match t.split_once('/') {
        Some((a, b)) => (a.trim().to_string(), b.trim().parse::<f64>().ok()?),
        None => (t.clone(), 1.0),
    };
    let coef = num.strip_suffix("pi")?.trim().trim_end_matches('*').trim();
    let c = match coef {
        "" | "+" => 1.0,
        "-" => -1.0,
        c => c.parse::<f64>().ok()?,
    };
    let v = c * PI / den;
    v.is_finite().then_some(v)
}

impl FromStr for TargetSpec {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let (head, rest) = match s.split_once(':') {
            Some((h, r)) => (h, Some(r)),
            None => (s, None),
        };
        match (head.to_ascii_lowercase().as_str(), rest) {
            ("uniform", None) => Ok(TargetSpec::Uniform),
            ("free-boundary", None) => Ok(TargetSpec::FreeBoundary),
            ("round-boundary", None) => Ok(TargetSpec::RoundBoundary),
            ("geodesic-boundary", None) => Ok(TargetSpec::GeodesicBoundary),
            ("single-cone", None) => Ok(TargetSpec::SingleCone(None)),
            ("single-cone", Some(v)) => v
                .trim()
                .parse::<u32>()
                .map(|v| TargetSpec::SingleCone(Some(v)))
                .map_err(|_| format!("single-cone:V needs a vertex id, got '{v}'")),
            ("cone" | "cones", Some(list)) => {
                let mut out = Vec::new();
                for item in list.split(',').filter(|x| !x.trim().is_empty()) {
                    let (v, k) = item
                        .split_once('=')
                        .ok_or_else(|| format!("cone entry '{item}' is not of the form V=K"))?;
                    let v = v
                        .trim()
                        .parse::<u32>()
                        .map_err(|_| format!("cone entry '{item}': '{v}' is not a vertex id"))?;
                    let k = parse_angle(k).ok_or_else(|| {
                        format!("cone entry '{item}': '{k}' is not a curvature (e.g. -6.2832, -2pi, pi/2)")
                    })?;
                    out.push((v, k));
                }
                if out.is_empty() {
                    return Err("cone: needs at least one V=K entry".into());
                }
                Ok(TargetSpec::Cones(out))
            }
            ("file", Some(p)) if !p.is_empty() => Ok(TargetSpec::File(PathBuf::from(p))),
            _ => Err(format!(
                "unknown target '{s}' (expected uniform, cone:V=K,..., single-cone:V, \
                 free-boundary, round-boundary, geodesic-boundary or file:PATH)"
            )),
        }
    }
}

/// One boundary loop whose curvature follows its current dual lengths (round boundaries).
#[derive(Debug, Clone)]
pub struct RoundLoop {
    /// Vertices of the loop in order.
    pub vertices: Vec<u32>,
    /// Boundary edges of the loop: edge `k` joins `vertices[k]` and `vertices[k+1]`.
    pub edges: Vec<u32>,
    /// Total curvature of the loop.
    pub total: f64,
}

/// A resolved target: per-vertex K̄, vertices whose `u` is held fixed, round loops.
#[derive(Debug, Clone)]
pub struct Target {
    pub curvature: Vec<f64>,
    /// Vertices whose `u` stays at its initial value (their curvature is not prescribed).
    pub fixed: Vec<bool>,
    pub round_loops: Vec<RoundLoop>,
    /// The design as text.
    pub description: String,
}

impl Target {
    /// Recompute the round loops' boundary targets from the current lengths: the boundary
    /// vertices of a loop with total curvature `T` lie on a circle of radius `R` (a curve of
    /// constant geodesic curvature `1/R`) when each boundary edge `k` subtends the central
    /// angle `α_k = 2 asin(l_k / 2R)` with `Σ_k α_k = |T|`, and the turning angle at a vertex
    /// between edges `a` and `b` is `K̄_i = sign(T) (α_a + α_b)/2` (the base angles of the
    /// isosceles triangles over the edges). `R` is solved for per loop ([`circle_radius`]).
    /// `dlengths` and `edge_vertices` are not needed by this rule (kept for the callers'
    /// convenience: the Jacobian in [`super::newton`] uses them).
    pub fn update_round(
        &mut self,
        lengths: &[f64],
        _dlengths: &[[f64; 2]],
        _edge_vertices: &[[u32; 2]],
    ) {
        for lp in &self.round_loops {
            let n = lp.vertices.len();
            let l: Vec<f64> = lp.edges.iter().map(|&e| lengths[e as usize]).collect();
            let c = CircleLoop::new(&l, lp.total);
            for k in 0..n {
                let v = lp.vertices[k];
                self.curvature[v as usize] = c.sign * 0.5 * (c.alpha[(k + n - 1) % n] + c.alpha[k]);
            }
        }
    }
    /// Whether some target depends on the metric.
    pub fn is_dynamic(&self) -> bool {
        !self.round_loops.is_empty()
    }
}

/// The circle through the vertices of one boundary loop with edge lengths `l_k` and total
/// turning `T` (see [`Target::update_round`]): radius `R`, central angles `α_k`, and the
/// derivative data of Newton's method, `c_k = ∂α_k/∂l_k = 1/(R cos(α_k/2))` and
/// `S = Σ l_k c_k` (then `∂R/∂l_k = R c_k / S` along `Σ α_k = |T|`).
#[derive(Debug, Clone)]
pub struct CircleLoop {
    pub radius: f64,
    pub alpha: Vec<f64>,
    pub dalpha: Vec<f64>,
    pub s: f64,
    /// `sign(T)`: +1 for a loop bounding a disk on its left, −1 for a hole; 0 when `T = 0`.
    pub sign: f64,
}

impl CircleLoop {
    pub fn new(l: &[f64], total: f64) -> CircleLoop {
        let n = l.len();
        let t = total.abs();
        let sign = if total > 0.0 {
            1.0
        } else if total < 0.0 {
            -1.0
        } else {
            0.0
        };
        if t == 0.0 || n == 0 {
            return CircleLoop {
                radius: f64::INFINITY,
                alpha: vec![0.0; n],
                dalpha: vec![0.0; n],
                s: 1.0,
                sign,
            };
        }
        let radius = circle_radius(l, t);
        let mut alpha = Vec::with_capacity(n);
        let mut dalpha = Vec::with_capacity(n);
        let mut s = 0.0;
        for &x in l {
            let q = (x / (2.0 * radius)).min(1.0);
            alpha.push(2.0 * q.asin());
            let c = 1.0 / (radius * (1.0 - q * q).sqrt().max(1e-12));
            dalpha.push(c);
            s += x * c;
        }
        CircleLoop {
            radius,
            alpha,
            dalpha,
            s,
            sign,
        }
    }
}

/// The radius `R` with `Σ_k 2 asin(l_k / 2R) = t` (`t > 0`): the circle on which a polygon
/// with sides `l_k` has its vertices while its sides turn by `t` in total (`t = 2π`: an
/// inscribed polygon around the centre). The left side decreases in `R`; the root lies in
/// `[max(L/t, l_max/2), πL/(2t)]` (from `x ≤ asin x ≤ πx/2`) and is found by Newton's method
/// safeguarded by bisection, to relative accuracy 1e-15. If even `R = l_max/2` turns by less
/// than `t` (one side longer than the rest can close), `R = l_max/2` is returned.
pub fn circle_radius(l: &[f64], t: f64) -> f64 {
    let total: f64 = l.iter().sum();
    let lmax = l.iter().cloned().fold(0.0, f64::max);
    let f = |r: f64| -> (f64, f64) {
        let mut v = -t;
        let mut d = 0.0;
        for &x in l {
            let q = (x / (2.0 * r)).min(1.0);
            v += 2.0 * q.asin();
            d -= x / (r * r * (1.0 - q * q).sqrt().max(1e-300));
        }
        (v, d)
    };
    let mut lo = (total / t).max(0.5 * lmax);
    let mut hi = (0.5 * PI * total / t).max(lo);
    if f(lo).0 <= 0.0 {
        return lo;
    }
    let mut r = lo.max(total / t);
    for _ in 0..200 {
        let (v, d) = f(r);
        if v > 0.0 {
            lo = r;
        } else {
            hi = r;
        }
        let mut next = r - v / d;
        if !(next > lo && next < hi && next.is_finite()) {
            next = 0.5 * (lo + hi);
        }
        if (next - r).abs() <= 1e-15 * r || hi - lo <= 1e-15 * hi {
            return next;
        }
        r = next;
    }
    r
}

fn read_target_file(path: &Path, n: usize) -> Result<Vec<f64>> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(&name, e))?;
    let trimmed = text.trim_start();
    let loc = |line: usize| crate::error::Location::file(&name).with_line(line);
    if trimmed.starts_with('[') || trimmed.starts_with('{') {
        let v: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| Error::parse(loc(e.line()), format!("invalid JSON: {e}")))?;
        let arr = match &v {
            serde_json::Value::Array(a) => Some(a.clone()),
            serde_json::Value::Object(o) => match o.get("targets").or_else(|| o.get("target")) {
                Some(serde_json::Value::Array(a)) => Some(a.clone()),
                _ => None,
            },
            _ => None,
        };
        if let Some(a) = arr {
            let mut out = Vec::with_capacity(a.len());
            for (i, x) in a.iter().enumerate() {
                out.push(x.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                    Error::parse(
                        crate::error::Location::file(&name),
                        format!("entry {i} ({x}) is not a finite number"),
                    )
                })?);
            }
            if out.len() != n {
                return Err(Error::input(format!(
                    "{name}: {} target values for a mesh with {n} vertices",
                    out.len()
                )));
            }
            return Ok(out);
        }
        if let serde_json::Value::Object(o) = &v {
            let mut out = vec![0.0; n];
            for (k, x) in o {
                let vid = k
                    .trim()
                    .parse::<usize>()
                    .ok()
                    .filter(|&v| v < n)
                    .ok_or_else(|| {
                        Error::input(format!("{name}: key '{k}' is not a vertex id below {n}"))
                    })?;
                out[vid] = x
                    .as_f64()
                    .or_else(|| x.as_str().and_then(parse_angle))
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        Error::input(format!("{name}: value of vertex {k} ({x}) is not a number"))
                    })?;
            }
            return Ok(out);
        }
        return Err(Error::parse(
            crate::error::Location::file(&name),
            "expected a JSON array of numbers or an object",
        ));
    }
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.split('#').next().unwrap_or("").trim();
        if t.is_empty() {
            continue;
        }
        out.push(
            parse_angle(t).ok_or_else(|| {
                Error::parse(loc(i + 1), format!("'{t}' is not a curvature value"))
            })?,
        );
    }
    if out.len() != n {
        return Err(Error::input(format!(
            "{name}: {} target values for a mesh with {n} vertices",
            out.len()
        )));
    }
    Ok(out)
}

/// Turn a design into per-vertex targets for `mesh` in `geometry`.
pub fn resolve(mesh: &Mesh, geometry: Geometry, spec: &TargetSpec) -> Result<Target> {
    let n = mesh.n_vertices();
    let chi = euler_characteristic(mesh);
    let mut t = Target {
        curvature: vec![0.0; n],
        fixed: (0..n as u32).map(|v| mesh.is_isolated(v)).collect(),
        round_loops: Vec::new(),
        description: spec.to_string(),
    };
    let check_vertex = |v: u32| -> Result<()> {
        if v as usize >= n {
            return Err(Error::input(format!(
                "target vertex {v} does not exist (the mesh has {n} vertices)"
            )));
        }
        if mesh.is_isolated(v) {
            return Err(Error::input(format!(
                "target vertex {v} is not used by any face"
            )));
        }
        Ok(())
    };
    match spec {
        TargetSpec::Uniform | TargetSpec::GeodesicBoundary => {}
        TargetSpec::Cones(list) => {
            for &(v, k) in list {
                check_vertex(v)?;
                t.curvature[v as usize] = k;
            }
        }
        TargetSpec::SingleCone(v) => {
            let v = v.ok_or_else(|| {
                Error::input(
                    "single-cone needs a vertex (single-cone:V); automatic placement comes with \
                     the atlas",
                )
            })?;
            check_vertex(v)?;
            t.curvature[v as usize] = 2.0 * PI * chi as f64;
        }
        TargetSpec::FreeBoundary | TargetSpec::FreeBoundaryCones(_) => {
            if !mesh.has_boundary() {
                return Err(Error::topology(
                    "free-boundary needs a mesh with boundary; this mesh is closed",
                ));
            }
            for v in 0..n as u32 {
                if mesh.is_boundary_vertex(v) {
                    t.fixed[v as usize] = true;
                }
            }
            if let TargetSpec::FreeBoundaryCones(list) = spec {
                for &(v, k) in list {
                    check_vertex(v)?;
                    if mesh.is_boundary_vertex(v) {
                        return Err(Error::input(format!(
                            "cone vertex {v} lies on the boundary, where u is held"
                        )));
                    }
                    t.curvature[v as usize] = k;
                }
            }
        }
        TargetSpec::RoundBoundary | TargetSpec::RoundBoundaryCones(_) => {
            if geometry != Geometry::Euclidean {
                return Err(Error::input(
                    "round-boundary is defined for the euclidean geometry only",
                ));
            }
            let loops = mesh.boundary_loop_halfedges();
            if loops.is_empty() {
                return Err(Error::topology(
                    "round-boundary needs a mesh with boundary; this mesh is closed",
                ));
            }
            let topo = crate::mesh::topology(mesh);
            if topo.components.len() != 1 {
                return Err(Error::topology(format!(
                    "Ricci flow needs a connected mesh; this one has {} components",
                    topo.components.len()
                )));
            }
            let genus = topo.components[0].genus;
            let b = loops.len();
            let mut cone_sum = 0.0;
            if let TargetSpec::RoundBoundaryCones(list) = spec {
                for &(v, k) in list {
                    check_vertex(v)?;
                    if mesh.is_boundary_vertex(v) {
                        return Err(Error::input(format!(
                            "cone vertex {v} lies on the boundary, which the round boundary \
                             puts on a circle"
                        )));
                    }
                    t.curvature[v as usize] = k;
                    cone_sum += k;
                }
            }
            // Genus 0: totals are set from the loop lengths in `set_round_totals`.
            for l in &loops {
                let vertices: Vec<u32> = l.iter().map(|&h| mesh.he_origin(h)).collect();
                let edges: Vec<u32> = l.iter().map(|&h| mesh.he_edge(h)).collect();
                t.round_loops.push(RoundLoop {
                    vertices,
                    edges,
                    total: if genus == 0 {
                        0.0
                    } else {
                        (2.0 * PI * chi as f64 - cone_sum) / b as f64
                    },
                });
            }
        }
        TargetSpec::File(p) => {
            t.curvature = read_target_file(p, n)?;
        }
        TargetSpec::PerVertex(k) => {
            if k.len() != n {
                return Err(Error::input(format!(
                    "{} target values for a mesh with {n} vertices",
                    k.len()
                )));
            }
            t.curvature = k.clone();
        }
    }
    Ok(t)
}

/// Round boundaries of genus-0 surfaces: the longest loop (by `lengths`) gets +2π, the
/// others −2π. Then targets are set from the metric.
pub fn set_round_totals(
    target: &mut Target,
    lengths: &[f64],
    dlengths: &[[f64; 2]],
    edge_vertices: &[[u32; 2]],
) {
    if target.round_loops.is_empty() {
        return;
    }
    let genus0 = target.round_loops.iter().all(|l| l.total == 0.0);
    if genus0 {
        let len = |l: &RoundLoop| -> f64 { l.edges.iter().map(|&e| lengths[e as usize]).sum() };
        let longest = (0..target.round_loops.len())
            .max_by(|&a, &b| len(&target.round_loops[a]).total_cmp(&len(&target.round_loops[b])))
            .unwrap_or(0);
        // Cones inside (`RoundBoundaryCones`) take their curvature from the longest loop.
        let mut on_loop = vec![false; target.curvature.len()];
        for l in &target.round_loops {
            for &v in &l.vertices {
                on_loop[v as usize] = true;
            }
        }
        let inside: f64 = (0..on_loop.len())
            .filter(|&v| !on_loop[v])
            .map(|v| target.curvature[v])
            .sum();
        for (k, l) in target.round_loops.iter_mut().enumerate() {
            l.total = if k == longest {
                2.0 * PI - inside
            } else {
                -2.0 * PI
            };
        }
    }
    target.update_round(lengths, dlengths, edge_vertices);
}

/// Gauss–Bonnet check of a target (paper 001 eq. 8). E²: `Σ K̄ = 2πχ` within `tol`;
/// H²: the area `Σ K̄ − 2πχ` must be positive; S²: the area `2πχ − Σ K̄` must be positive.
/// Returns the area the target asks for (0 for E²). Targets with fixed vertices are not
/// constrained (the fixed vertices' curvature is free).
pub fn check_gauss_bonnet(mesh: &Mesh, geometry: Geometry, target: &Target) -> Result<f64> {
    let chi_int = euler_characteristic(mesh);
    let chi = chi_int as f64;
    let sum: f64 = target.curvature.iter().sum();
    let gauss_bonnet = |message: String| -> Error {
        FlowError::GaussBonnet {
            geometry,
            curvature_sum: sum,
            euler_characteristic: chi_int,
            message,
        }
        .into()
    };
    let free_boundary = target
        .fixed
        .iter()
        .enumerate()
        .any(|(v, &f)| f && !mesh.is_isolated(v as u32));
    let two_pi_chi = 2.0 * PI * chi;
    match geometry {
        Geometry::Euclidean => {
            if free_boundary {
                return Ok(0.0);
            }
            let tol = 1e-9 * (1.0 + target.curvature.len() as f64).sqrt();
            if (sum - two_pi_chi).abs() > tol {
                return Err(gauss_bonnet(format!(
                    "target curvature violates Gauss–Bonnet: Σ K̄ = {sum:.6} but a flat metric \
                     needs 2πχ = {two_pi_chi:.6} (χ = {chi}); off by {:.3e}",
                    sum - two_pi_chi
                )));
            }
            Ok(0.0)
        }
        Geometry::Hyperbolic => {
            let area = sum - two_pi_chi;
            if !free_boundary && area <= 0.0 {
                return Err(gauss_bonnet(format!(
                    "target curvature violates Gauss–Bonnet for a hyperbolic metric: the area \
                     would be Σ K̄ − 2πχ = {area:.6} (Σ K̄ = {sum:.6}, χ = {chi}), but it must be \
                     positive; off by {:.3e}",
                    -area
                )));
            }
            Ok(area)
        }
        Geometry::Spherical => {
            let area = two_pi_chi - sum;
            if !free_boundary && area <= 0.0 {
                return Err(gauss_bonnet(format!(
                    "target curvature violates Gauss–Bonnet for a spherical metric: the area \
                     would be 2πχ − Σ K̄ = {area:.6} (Σ K̄ = {sum:.6}, χ = {chi}), but it must be \
                     positive; off by {:.3e}",
                    -area
                )));
            }
            Ok(area)
        }
    }
}

/// Check the Chow–Luo condition (see the module docs) on all single vertices and all closed
/// one-rings. `phi` gives the intersection angle of every edge (use zeros for schemes other
/// than Thurston/tangential packings). Spherical metrics are not checked (angle sums exceed π).
pub fn check_chow_luo(mesh: &Mesh, geometry: Geometry, target: &Target, phi: &[f64]) -> Result<()> {
    if geometry == Geometry::Spherical {
        return Ok(());
    }
    let n = mesh.n_vertices();
    let mut in_set = vec![false; n];
    // `set` is a vertex alone or its closed one-ring (the vertex first).
    let chow_luo = |set: &[u32], message: String, shortfall: f64| -> Error {
        FlowError::ChowLuo {
            vertex: set[0],
            one_ring: set.len() > 1,
            shortfall,
            message,
        }
        .into()
    };
    let mut check = |set: &[u32], label: &str| -> Result<()> {
        if set.iter().any(|&v| target.fixed[v as usize]) {
            return Ok(());
        }
        for &v in set {
            in_set[v as usize] = true;
        }
        let mut bound = 0.0;
        let mut sum = 0.0;
        for &v in set {
            sum += target.curvature[v as usize];
            bound += if mesh.is_boundary_vertex(v) {
                PI
            } else {
                2.0 * PI
            };
        }
        // Faces touching the set, each once.
        let mut faces: Vec<u32> = set.iter().flat_map(|&v| mesh.vertex_faces(v)).collect();
        faces.sort_unstable();
        faces.dedup();
        let (mut f3, mut f2, mut link) = (0usize, 0usize, 0.0);
        for &f in &faces {
            let t = mesh.face(f);
            let k = t.iter().filter(|&&v| in_set[v as usize]).count();
            match k {
                3 => f3 += 1,
                2 => f2 += 1,
                _ => {
                    let e = mesh.face_edges_opposite(f);
                    let i = (0..3).find(|&i| in_set[t[i] as usize]).unwrap_or(0);
                    link += PI - phi[e[i] as usize];
                }
            }
        }
        bound -= PI * (f3 + f2) as f64 + link;
        for &v in set {
            in_set[v as usize] = false;
        }
        let margin = 1e-12 * (1.0 + bound.abs());
        if sum <= bound + margin {
            // An ear (a boundary vertex with one face) needs a split, not more neighbours.
            let ear = set.len() == 1
                && mesh.is_boundary_vertex(set[0])
                && mesh.vertex_faces(set[0]).count() == 1;
            let why = if ear {
                "split the edge opposite the ear to give it two faces: `--widen-boundary 2 \
                 --refined-out MESH`"
            } else {
                "too few neighbours for the curvature asked; `ricci atlas` raises the valence \
                 around a cone"
            };
            return Err(chow_luo(
                set,
                format!(
                    "target curvature is not admissible (Chow–Luo condition, paper 000 eq. 7) at \
                 {label}: Σ K̄ = {sum:.6} must exceed −Σ(π − φ) + 2πχ(F_I) = {bound:.6} (short by \
                 {:.3e}): circle packing cannot give these vertices their target on this \
                 triangulation ({why}); try: --scheme conformal (the default), which has no \
                 such condition",
                    bound - sum
                ),
                bound - sum,
            ));
        }
        Ok(())
    };
    for v in 0..n as u32 {
        if mesh.is_isolated(v) {
            continue;
        }
        let label = if mesh.is_boundary_vertex(v) && mesh.vertex_faces(v).count() == 1 {
            format!(
                "the single vertex {v}, a boundary vertex with one face (an ear: its one corner \
                 would have to open to π − K̄)"
            )
        } else {
            format!("the single vertex {v} (valence {})", mesh.valence(v))
        };
        check(&[v], &label)?;
    }
    let mut ring = Vec::new();
    for v in 0..n as u32 {
        if mesh.is_isolated(v) {
            continue;
        }
        ring.clear();
        ring.push(v);
        ring.extend(mesh.vertex_neighbors(v));
        check(
            &ring,
            &format!(
                "the closed one-ring of vertex {v} ({} vertices)",
                ring.len()
            ),
        )?;
    }
    Ok(())
}

/// `count` well-separated vertices of valence ≥ `min_valence`, by farthest-point sampling of
/// the graph distance (deterministic: start from the eligible vertex farthest from vertex 0,
/// ties to the smaller id). Useful to place `2g − 2` cones of −2π.
pub fn separated_vertices(mesh: &Mesh, count: usize, min_valence: usize) -> Vec<u32> {
    let n = mesh.n_vertices();
    let eligible: Vec<bool> = (0..n as u32)
        .map(|v| {
            !mesh.is_isolated(v) && !mesh.is_boundary_vertex(v) && mesh.valence(v) >= min_valence
        })
        .collect();
    let bfs = |src: &[u32], dist: &mut Vec<u32>| {
        let mut q: VecDeque<u32> = VecDeque::new();
        for &s in src {
            dist[s as usize] = 0;
            q.push_back(s);
        }
        while let Some(v) = q.pop_front() {
            for w in mesh.vertex_neighbors(v) {
                if dist[w as usize] == NONE {
                    dist[w as usize] = dist[v as usize] + 1;
                    q.push_back(w);
                }
            }
        }
    };
    let start = match (0..n as u32).find(|&v| !mesh.is_isolated(v)) {
        Some(s) => s,
        None => return Vec::new(),
    };
    let mut dist = vec![NONE; n];
    bfs(&[start], &mut dist);
    let pick = |dist: &[u32]| -> Option<u32> {
        (0..n as u32)
            .filter(|&v| eligible[v as usize] && dist[v as usize] != NONE)
            .max_by(|&a, &b| dist[a as usize].cmp(&dist[b as usize]).then(b.cmp(&a)))
    };
    let mut chosen = Vec::new();
    let mut dmin = vec![NONE; n];
    if let Some(first) = pick(&dist) {
        chosen.push(first);
    }
    while chosen.len() < count {
        dmin.iter_mut().for_each(|d| *d = NONE);
        bfs(&chosen, &mut dmin);
        match pick(&dmin) {
            Some(v) if dmin[v as usize] > 0 => chosen.push(v),
            _ => break,
        }
    }
    chosen
}

#[cfg(test)]
mod circle_tests {
    use super::*;

    /// Closed forms: a regular n-gon with side l has circumradius l / (2 sin(π/n)); a polygon
    /// built on a circle of radius R from unequal central angles gives back R; the central
    /// angles sum to the total turning.
    #[test]
    fn circle_radius_of_cyclic_polygons() {
        for n in [3usize, 4, 7, 100, 1000] {
            let l = vec![0.37; n];
            let want = 0.37 / (2.0 * (PI / n as f64).sin());
            let r = circle_radius(&l, 2.0 * PI);
            assert!((r / want - 1.0).abs() < 1e-13, "n = {n}: {r} vs {want}");
        }
        // Unequal central angles (summing to 2π), sides 2R sin(α/2).
        let weights: Vec<f64> = (0..57).map(|k| 1.0 + ((k * 7919) % 13) as f64).collect();
        let wsum: f64 = weights.iter().sum();
        let radius = 2.5;
        let alpha: Vec<f64> = weights.iter().map(|w| 2.0 * PI * w / wsum).collect();
        let l: Vec<f64> = alpha
            .iter()
            .map(|a| 2.0 * radius * (0.5 * a).sin())
            .collect();
        let c = CircleLoop::new(&l, -2.0 * PI);
        assert!((c.radius / radius - 1.0).abs() < 1e-13, "{}", c.radius);
        assert_eq!(c.sign, -1.0);
        for (a, b) in c.alpha.iter().zip(&alpha) {
            assert!((a - b).abs() < 1e-12);
        }
        assert!((c.alpha.iter().sum::<f64>() - 2.0 * PI).abs() < 1e-12);
        // An arc of total turning π on the same circle (half the angles doubled up).
        let half: Vec<f64> = l[..l.len() / 2].to_vec();
        let t: f64 = alpha[..alpha.len() / 2].iter().sum();
        assert!((circle_radius(&half, t) / radius - 1.0).abs() < 1e-13);
    }
}
