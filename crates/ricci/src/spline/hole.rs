//! The hole at an extraordinary point and its G¹ fill patch (paper 000 §5, last paragraph).
//!
//! The manifold spline of [`crate::spline::manifold`] is defined on the faces not incident to
//! the cone vertex `s`. Around `s` the flat cone metric has *cone polar coordinates*
//! `(ρ, φ)`, `0 ≤ φ < Θ` (`Θ` the cone angle at `s`): the star of `s` developed by angles
//! ([`crate::spline::manifold::star_frame`]) is the unrolled cone, and the stars of the link
//! vertices are attached to it through their faces at `s`, so every point of the two-ring of
//! `s` has unrolled coordinates `ρ e^{iφ}`.
//!
//! **Seam.** A smooth closed curve `ρ = R(ψ)`, `φ = Θψ/2π`, `ψ ∈ [0, 2π)`, just outside the
//! link of `s` (so inside the spline's domain): `ln R` is a truncated Fourier series of the
//! logarithm of the link's radial function `r_link(φ)` (the flat metric of a strong cone
//! varies over orders of magnitude around it), raised until `R` exceeds `r_link` everywhere by
//! a relative margin. The
//! seam is checked to lie in active faces near the link (the stars of the link vertices and two
//! more rings of stars, developed into the unrolled cone); otherwise construction fails naming
//! `s` (a very irregular neighbourhood).
//!
//! **Fill.** Over the unit disk `(t, ψ)`, `(x, y) = t (cos ψ, sin ψ)`, the patch matches the
//! seam data `C(ψ) = S(R, φ)` and `D(ψ) = R ∂S/∂ρ` of the spline `S` itself: at `t = 1` it has
//! the spline's value and `∂F/∂t = D`, `∂F/∂ψ = dC/dψ`, both in the spline's tangent plane, so
//! the join is G¹ (measured by [`Hole::seam_normal_jump`]). It is built from the Fourier modes
//! `C_k, D_k`, `k ≤ K` (`K` ≤ 32) of the seam data: mode `k` gets the radial profile
//! `α_k t^k + β_k t^{k+2}` with `α_k + β_k = C_k`, `k α_k + (k + 2) β_k = D_k` — `t^k e^{ikψ}`
//! and `t^{k+2} e^{ikψ}` are the polynomials `z^k` and `|z|² z^k`, so this part is a polynomial
//! in `(x, y)`, and it reproduces a plane — plus the rest, `C − C_K` and `D − D_K`, with the
//! cubic Hermite profiles of order `t³` at the centre (`4t³ − 3t⁴`, `t⁴ − t³`). The patch is
//! therefore C² at its centre (test `fill_patch_is_c2_at_its_centre`: the quadratic Taylor fit's
//! residual falls like `ε³`). The earlier radial cubic Hermite patch, `h₀₀ P₀ + h₁₀ T + h₀₁ C +
//! h₁₁ D` for every mode at once, gave every Fourier mode of `C` and `D` a `t²` term at the
//! centre: only C¹ there, and a starburst in the zebra stripes. This is not the paper's planar
//! triangular B-spline fill; it is a single smooth patch.

use std::collections::HashMap;
use std::f64::consts::PI;

/// Fourier modes of the seam data carried by the fill's polynomial part (at most `ns / 8` of
/// the seam samples).
const FILL_MODES: usize = 32;
/// Order at the centre of the profiles that carry the rest of the seam data.
const REST_ORDER: usize = 3;

use num_complex::Complex64 as C;

use crate::atlas::{fit_rigid, FlatCharts};
use crate::error::{Error, Result};
use crate::layout::RigidMotion;

use super::dms::Workspace;
use super::manifold::{apply, cz, rotate_partials, star_frame, ManifoldSpace};
use super::simplex::{det3, Point};
use super::space::evaluate;

/// A point of the two-ring of a cone: face, barycentric coordinates, and the motion from the
/// unrolled frame to the face's canonical chart.
#[derive(Debug, Clone, Copy)]
pub struct Located {
    pub face: u32,
    pub bary: [f64; 3],
    pub motion: RigidMotion,
}

/// A candidate face of a sector: id, unrolled corners, motion to its canonical chart, unrolled
/// angle of its centroid.
type Candidate = (u32, [Point; 3], RigidMotion, f64);

/// Where each face of the sectors' candidate lists first occurs: (sector, position).
fn first_occurrences(sector_faces: &[Vec<Candidate>]) -> HashMap<u32, (usize, usize)> {
    let mut first = HashMap::new();
    for (k, list) in sector_faces.iter().enumerate() {
        for (i, x) in list.iter().enumerate() {
            first.entry(x.0).or_insert((k, i));
        }
    }
    first
}

/// Seam data at one `ψ`: `C(ψ)`, `D(ψ)` and the spline's partials `(S_X, S_Y)`.
pub type SeamData = ([f64; 3], [f64; 3], [[f64; 3]; 2]);

/// The hole around one cone vertex, its seam and the fill patch.
#[derive(Debug, Clone)]
pub struct Hole {
    pub vertex: u32,
    /// Cone angle `Θ` (angle sum at the vertex).
    pub cone_angle: f64,
    /// Start angle of each sector (face at the vertex), counter-clockwise; `sector_start[d] = Θ`.
    sector_start: Vec<f64>,
    /// Link vertices' unrolled positions, `link[k]` = first link vertex of sector `k`.
    link: Vec<Point>,
    /// Candidate active faces per sector: id, unrolled coordinates, motion to the canonical
    /// chart, and the unrolled angle `φ` of the centroid (tracked through the development, so
    /// it is not ambiguous by multiples of 2π where the cone angle exceeds 2π).
    sector_faces: Vec<Vec<Candidate>>,
    /// Per face of `sector_faces`, where it first occurs (sector, position): the lookup of
    /// [`Self::cone_polar`], once per tessellation vertex near the hole.
    first_occurrence: HashMap<u32, (usize, usize)>,
    /// Seam radius: `ln R(ψ) = a₀ + Σ a_k cos kψ + b_k sin kψ + shift`.
    fourier: Vec<(f64, f64)>,
    shift: f64,
    /// Centre of the fill, `F(0, ·) = α_0`.
    pub center: [f64; 3],
    /// Per Fourier mode `k = 0..=K` of the seam data, the coefficients `α_k`, `β_k` of its
    /// radial profile `α_k t^k + β_k t^{k+2}`, for the cos and the sin part (module docs).
    profile: Vec<[[[f64; 3]; 2]; 2]>,
    /// Smallest `R(ψ) / r_link(ψ) − 1` over the checked samples.
    pub min_clearance: f64,
}

/// What the fill measured along its seam.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct SeamReport {
    pub vertex: u32,
    pub cone_angle: f64,
    pub samples: usize,
    /// Largest angle between the spline's and the fill's normals along the seam (degrees).
    pub max_normal_jump_deg: f64,
    /// Largest distance between the spline and the fill on the seam, relative to the seam's
    /// diameter.
    pub max_position_gap: f64,
}

impl Hole {
    /// Build the seam and the fill around cone vertex `s` for the spline with `control`
    /// (3 numbers per control point).
    pub fn new<A: FlatCharts + Sync + ?Sized>(
        space: &ManifoldSpace<'_, A>,
        control: &[f64],
        s: u32,
    ) -> Result<Hole> {
        let charts = space.charts();
        let mesh = charts.mesh();
        let lengths = charts.lengths();
        if s as usize >= mesh.n_vertices() || mesh.is_boundary_vertex(s) || mesh.is_isolated(s) {
            return Err(Error::input(format!(
                "hole filling: vertex {s} is not an interior vertex"
            )));
        }
        let sf = star_frame(mesh, lengths, s);
        let d = sf.faces.len();
        let theta = sf.total_angle;
        let mut sector_start = sf.start_angles.clone();
        sector_start.push(theta);
        // Link vertices in sector order: v_k = corner after s in face k.
        let mut link_ids = Vec::with_capacity(d);
        let mut link = Vec::with_capacity(d);
        for (f, c) in &sf.faces {
            let t = mesh.face(*f);
            let i = t.iter().position(|&v| v == s).unwrap_or(0);
            link_ids.push(t[(i + 1) % 3]);
            link.push(c[(i + 1) % 3]);
        }
        // Unrolled coordinates of face j (any integer), continuous across the cut φ = 0.
        let unrolled = |j: isize| -> [Point; 3] {
            let k = j.rem_euclid(d as isize) as usize;
            let turns = j.div_euclid(d as isize) as f64;
            let r = C::from_polar(1.0, turns * theta);
            sf.faces[k].1.map(|p| super::manifold::pt(r * cz(p)))
        };
        let centroid = |c: &[Point; 3]| {
            cz([
                (c[0][0] + c[1][0] + c[2][0]) / 3.0,
                (c[0][1] + c[1][1] + c[2][1]) / 3.0,
            ])
        };
        // Angle of the centroid of `cg` from that of `cf` (angle `phi_f`) through their common
        // vertex at `zw`: straight segments inside the two faces, which miss the cone.
        let carry = |phi_f: f64, cf: &[Point; 3], zw: C, cg: &[Point; 3]| {
            phi_f + (zw / centroid(cf)).arg() + (centroid(cg) / zw).arg()
        };
        let mut sector_faces = Vec::with_capacity(d);
        for k in 0..d as isize {
            let mut list: Vec<Candidate> = Vec::new();
            for j in [k - 1, k, k + 1] {
                let jj = j.rem_euclid(d as isize) as usize;
                let fj = sf.faces[jj].0;
                let uj = unrolled(j);
                // Face j spans less than π from the cone: its centroid's angle from the middle
                // of its sector.
                let mid_j = sf.start_angles[jj]
                    + 0.5 * sf.corner_angles[jj]
                    + j.div_euclid(d as isize) as f64 * theta;
                let phi_j = mid_j + (centroid(&uj) * C::from_polar(1.0, -mid_j)).arg();
                for (wi, &w) in mesh.face(fj).iter().enumerate() {
                    if w == s {
                        continue;
                    }
                    let zw = cz(uj[wi]);
                    let Some(wf) = space.vertex_frame(w) else {
                        continue;
                    };
                    let Some(cw) = wf.faces.iter().find(|x| x.0 == fj).map(|x| x.1) else {
                        continue;
                    };
                    let (m, _) = fit_rigid(&cw, &uj);
                    for (g, c) in &wf.faces {
                        if !space.is_active(*g) || list.iter().any(|x| x.0 == *g) {
                            continue;
                        }
                        let cu = c.map(|p| apply(&m, p));
                        let (mc, _) = fit_rigid(&cu, &space.canonical_coords(*g));
                        let phi = carry(phi_j, &uj, zw, &cu);
                        list.push((*g, cu, mc, phi));
                    }
                }
            }
            // One more ring: the stars of the vertices reached so far, aligned through a face
            // already placed (the seam of an irregular, graded link can leave the two-ring).
            let mut expanded: Vec<u32> = Vec::new();
            let mut level = 0;
            while level < 2 {
                level += 1;
                let verts: Vec<u32> = list
                    .iter()
                    .flat_map(|x| mesh.face(x.0))
                    .filter(|&w| w != s)
                    .collect();
                for w in verts {
                    if expanded.contains(&w) {
                        continue;
                    }
                    expanded.push(w);
                    let Some(wf) = space.vertex_frame(w) else {
                        continue;
                    };
                    let Some((fw, cw, cu, phi_w)) = wf.faces.iter().find_map(|(g, c)| {
                        list.iter().find(|x| x.0 == *g).map(|x| (*g, *c, x.1, x.3))
                    }) else {
                        continue;
                    };
                    let Some(wi) = mesh.face(fw).iter().position(|&x| x == w) else {
                        continue;
                    };
                    let zw = cz(cu[wi]);
                    let (m, _) = fit_rigid(&cw, &cu);
                    let mut add = Vec::new();
                    for (g, c) in &wf.faces {
                        if !space.is_active(*g) || list.iter().any(|x| x.0 == *g) {
                            continue;
                        }
                        let cn = c.map(|p| apply(&m, p));
                        let (mc, _) = fit_rigid(&cn, &space.canonical_coords(*g));
                        let phi = carry(phi_w, &cu, zw, &cn);
                        add.push((*g, cn, mc, phi));
                    }
                    list.extend(add);
                }
            }
            sector_faces.push(list);
        }
        let first_occurrence = first_occurrences(&sector_faces);
        let mut hole = Hole {
            vertex: s,
            cone_angle: theta,
            sector_start,
            link,
            sector_faces,
            first_occurrence,
            fourier: Vec::new(),
            shift: 0.0,
            center: [0.0; 3],
            profile: Vec::new(),
            min_clearance: 0.0,
        };
        let _ = link_ids;
        let last_err = hole.fit_seam(d);
        if hole.min_clearance <= 0.0 {
            return Err(Error::numerical(format!(
                "hole filling at singular vertex {s}: no smooth seam fits between its link and the two-ring ({last_err})"
            )));
        }
        hole.fit_profile(space, control)?;
        hole.center = hole.profile[0][0][0];
        Ok(hole)
    }

    /// The seam: a Fourier smoothing of the link's radial function (at most 24 harmonics,
    /// fewer if the seam leaves the two-ring), shifted outwards by the smallest margin that
    /// keeps it outside the link and inside the active faces (`d` link vertices). Sets
    /// `fourier`, `shift` and `min_clearance` (≤ 0 when no seam fits); returns why the last
    /// attempt failed.
    fn fit_seam(&mut self, d: usize) -> String {
        let theta = self.cone_angle;
        const M: usize = 1024;
        let rl: Vec<f64> = (0..M)
            .map(|j| self.r_link(theta * j as f64 / M as f64))
            .collect();
        let mut last_err = String::new();
        'outer: for harmonics in [d.min(24), d.min(12), d.min(6), 3] {
            let mut fourier = Vec::with_capacity(harmonics + 1);
            for h in 0..=harmonics {
                let (mut a, mut b) = (0.0, 0.0);
                for (j, r) in rl.iter().enumerate() {
                    let psi = 2.0 * PI * j as f64 / M as f64;
                    a += r.ln() * (h as f64 * psi).cos();
                    b += r.ln() * (h as f64 * psi).sin();
                }
                let w = if h == 0 { 1.0 } else { 2.0 } / M as f64;
                fourier.push((a * w, b * w));
            }
            self.fourier = fourier;
            self.shift = 0.0;
            let mut over = f64::NEG_INFINITY;
            for (j, r) in rl.iter().enumerate() {
                over = over.max(r.ln() - self.radius(2.0 * PI * j as f64 / M as f64).ln());
            }
            'margin: for margin in [0.06, 0.03, 0.015] {
                self.shift = over + margin;
                // Check: seam outside the link and inside active faces.
                let mut clearance = f64::INFINITY;
                for (j, r) in rl.iter().enumerate() {
                    let psi = 2.0 * PI * j as f64 / M as f64;
                    let rr = self.radius(psi);
                    clearance = clearance.min(rr / r - 1.0);
                    if self.locate(rr, theta * psi / (2.0 * PI)).is_none() {
                        last_err = format!(
                        "the seam point at angle {:.3} rad (radius {rr:.3e}) leaves the two-ring",
                        theta * psi / (2.0 * PI)
                    );
                        continue 'margin;
                    }
                }
                self.min_clearance = clearance;
                break 'outer;
            }
        }
        last_err
    }

    /// The fill's profile from the Fourier modes of the seam data (module docs, *Fill*).
    fn fit_profile<A: FlatCharts + Sync + ?Sized>(
        &mut self,
        space: &ManifoldSpace<'_, A>,
        control: &[f64],
    ) -> Result<()> {
        let d = self.link.len();
        const M: usize = 1024;
        let ns = 4 * M.min(64 * d).max(256) / 4;
        let modes = (ns / 8).min(FILL_MODES);
        let mut cm = vec![[[0.0; 3]; 2]; modes + 1];
        let mut dm = vec![[[0.0; 3]; 2]; modes + 1];
        let mut ws = Workspace::default();
        for j in 0..ns {
            let psi = 2.0 * PI * j as f64 / ns as f64;
            let (c, dd, _) = self.seam_data(space, control, psi, &mut ws)?;
            for k in 0..=modes {
                let w = if k == 0 { 1.0 } else { 2.0 } / ns as f64;
                let (co, si) = ((k as f64 * psi).cos() * w, (k as f64 * psi).sin() * w);
                for x in 0..3 {
                    cm[k][0][x] += c[x] * co;
                    cm[k][1][x] += c[x] * si;
                    dm[k][0][x] += dd[x] * co;
                    dm[k][1][x] += dd[x] * si;
                }
            }
        }
        // α_k + β_k = C_k and k α_k + (k + 2) β_k = D_k.
        self.profile = cm
            .iter()
            .zip(&dm)
            .enumerate()
            .map(|(k, (ck, dk))| {
                let beta: [[f64; 3]; 2] = std::array::from_fn(|p| {
                    std::array::from_fn(|x| 0.5 * (dk[p][x] - k as f64 * ck[p][x]))
                });
                let alpha = std::array::from_fn(|p| std::array::from_fn(|x| ck[p][x] - beta[p][x]));
                [alpha, beta]
            })
            .collect();
        Ok(())
    }

    /// Radial distance from the cone to its link at unrolled angle `phi` (mod Θ).
    pub fn r_link(&self, phi: f64) -> f64 {
        let k = self.sector(phi);
        let d = self.link.len();
        let a = self.link[k];
        let mut b = self.link[(k + 1) % d];
        if k + 1 == d {
            let r = C::from_polar(1.0, self.cone_angle);
            b = super::manifold::pt(r * cz(b));
        }
        let e = [phi.cos(), phi.sin()];
        let ba = [b[0] - a[0], b[1] - a[1]];
        let cross = |p: Point, q: Point| p[0] * q[1] - p[1] * q[0];
        cross(a, ba) / cross(e, ba)
    }

    fn sector(&self, phi: f64) -> usize {
        let phi = phi.rem_euclid(self.cone_angle);
        let d = self.link.len();
        match self.sector_start[..d].binary_search_by(|x| x.total_cmp(&phi)) {
            Ok(k) => k,
            Err(k) => k.saturating_sub(1),
        }
    }

    /// Seam radius `R(ψ)`.
    pub fn radius(&self, psi: f64) -> f64 {
        let mut r = self.shift;
        for (h, &(a, b)) in self.fourier.iter().enumerate() {
            if h == 0 {
                r += a;
            } else {
                r += a * (h as f64 * psi).cos() + b * (h as f64 * psi).sin();
            }
        }
        r.exp()
    }

    /// Locate the point with cone polar coordinates `(rho, phi)` in an active face.
    pub fn locate(&self, rho: f64, phi: f64) -> Option<Located> {
        let k = self.sector(phi);
        // Unrolled angle continuous with sector k.
        let phi = phi.rem_euclid(self.cone_angle);
        let p = [rho * phi.cos(), rho * phi.sin()];
        let mut best: Option<(f64, Located)> = None;
        for (g, c, m, phi_c) in &self.sector_faces[k] {
            let area = det3(c[0], c[1], c[2]);
            let b = [
                det3(p, c[1], c[2]) / area,
                det3(c[0], p, c[2]) / area,
                det3(c[0], c[1], p) / area,
            ];
            let q = b[0].min(b[1]).min(b[2]);
            // The face must hold the point on the right sheet of the cone (a face of a
            // graded neighbourhood can overlap the plane point a full turn of 2π away).
            let cc = cz([
                (c[0][0] + c[1][0] + c[2][0]) / 3.0,
                (c[0][1] + c[1][1] + c[2][1]) / 3.0,
            ]);
            let sheet = (phi_c + (cz(p) / cc).arg() - phi).abs() < 1e-6;
            if q >= -1e-12 && sheet && best.as_ref().is_none_or(|(s, _)| q > *s) {
                best = Some((
                    q,
                    Located {
                        face: *g,
                        bary: b,
                        motion: *m,
                    },
                ));
            }
        }
        best.map(|x| x.1)
    }

    /// Developed corners of active face `g` in the unrolled frame (from the first sector whose
    /// candidate list holds it), or `None` when `g` is not in the two-ring.
    fn developed(&self, g: u32) -> Option<([Point; 3], f64)> {
        let &(k, i) = self.first_occurrence.get(&g)?;
        let x = &self.sector_faces[k][i];
        Some((x.1, x.3))
    }

    /// Cone polar coordinates `(ρ, φ)` of the point of face `g` with barycentric `bary`
    /// (`None` when `g` is not in the two-ring). `φ` is measured from the direction of the
    /// face's centroid, whose unrolled angle was tracked through the development.
    pub fn cone_polar(&self, g: u32, bary: [f64; 3]) -> Option<(f64, f64)> {
        let (c, phi_c) = self.developed(g)?;
        let at = |b: [f64; 3]| {
            cz([
                b[0] * c[0][0] + b[1] * c[1][0] + b[2] * c[2][0],
                b[0] * c[0][1] + b[1] * c[1][1] + b[2] * c[2][1],
            ])
        };
        let zc = at([1.0 / 3.0; 3]);
        let z = at(bary);
        Some((z.norm(), phi_c + (z / zc).arg()))
    }

    /// The seam parameter `ψ = 2πφ/Θ` of unrolled angle `φ`, in `[0, 2π)`.
    pub fn psi_of_phi(&self, phi: f64) -> f64 {
        (2.0 * PI * phi / self.cone_angle).rem_euclid(2.0 * PI)
    }

    /// Signed level of the seam at the point of face `g` with barycentric `bary`:
    /// `ln ρ − ln R(ψ)`, negative inside the seam, zero on it (`None` outside the two-ring).
    pub fn seam_level(&self, g: u32, bary: [f64; 3]) -> Option<f64> {
        let (rho, phi) = self.cone_polar(g, bary)?;
        Some(rho.ln() - self.radius(2.0 * PI * phi / self.cone_angle).ln())
    }

    /// Is the point of face `g` with barycentric `bary` inside the seam? (`None` when `g` is
    /// not in the two-ring.)
    pub fn inside_seam(&self, g: u32, bary: [f64; 3]) -> Option<bool> {
        self.seam_level(g, bary).map(|l| l < 0.0)
    }

    /// Where the straight segment from barycentric `a` to `b` of face `g` crosses the seam,
    /// for endpoints on opposite sides: `(s, bary, ψ)` with the point `(1 − s) a + s b`, found by
    /// bisection of [`Hole::seam_level`] to `|Δs| ≤ 2⁻⁶⁰` (the level is smooth along the
    /// segment, which is straight in the unrolled frame). When rounding puts both endpoints on
    /// one side, the endpoint nearer the seam is returned (`s = 0` or `1`). `None` when `g` is
    /// not in the two-ring.
    pub fn seam_crossing(&self, g: u32, a: [f64; 3], b: [f64; 3]) -> Option<(f64, [f64; 3], f64)> {
        let at = |s: f64| -> [f64; 3] { std::array::from_fn(|k| (1.0 - s) * a[k] + s * b[k]) };
        let la = self.seam_level(g, a)?;
        let lb = self.seam_level(g, b)?;
        let s = if la == 0.0 || (la < 0.0) == (lb < 0.0) && la.abs() <= lb.abs() {
            0.0
        } else if lb == 0.0 || (la < 0.0) == (lb < 0.0) {
            1.0
        } else {
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            let neg_at_lo = la < 0.0;
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                let l = self.seam_level(g, at(mid))?;
                if l == 0.0 {
                    lo = mid;
                    hi = mid;
                    break;
                }
                if (l < 0.0) == neg_at_lo {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            0.5 * (lo + hi)
        };
        let bary = at(s);
        let (_, phi) = self.cone_polar(g, bary)?;
        Some((s, bary, self.psi_of_phi(phi)))
    }

    /// The seam point at `ψ`: spline value `C(ψ)`, `D(ψ) = R ∂S/∂ρ`, and the spline's partials
    /// `(S_X, S_Y)` in the unrolled frame.
    pub fn seam_data<A: FlatCharts + Sync + ?Sized>(
        &self,
        space: &ManifoldSpace<'_, A>,
        control: &[f64],
        psi: f64,
        ws: &mut Workspace,
    ) -> Result<SeamData> {
        let phi = self.cone_angle * psi / (2.0 * PI);
        let r = self.radius(psi);
        let loc = self.locate(r, phi).ok_or_else(|| {
            Error::numerical(format!(
                "hole at vertex {}: seam point at angle {phi:.4} not found",
                self.vertex
            ))
        })?;
        let p = [r * phi.cos(), r * phi.sin()];
        let u = apply(&loc.motion, p);
        let mut out = [0.0; 9];
        evaluate(space, control, 3, loc.face, u, 1, ws, &mut out)?;
        // Partials in the canonical chart → unrolled frame (u = rot p + t).
        let mut sx = [0.0; 3];
        let mut sy = [0.0; 3];
        for k in 0..3 {
            let mut v = [out[k], out[3 + k], out[6 + k]];
            rotate_partials(1, loc.motion.rot, &mut v);
            sx[k] = v[1];
            sy[k] = v[2];
        }
        let c = [out[0], out[1], out[2]];
        let mut dd = [0.0; 3];
        for k in 0..3 {
            dd[k] = r * (phi.cos() * sx[k] + phi.sin() * sy[k]);
        }
        Ok((c, dd, [sx, sy]))
    }

    /// The fill patch at `(t, ψ)`, `t ∈ [0, 1]` (module docs).
    pub fn fill_point<A: FlatCharts + Sync + ?Sized>(
        &self,
        space: &ManifoldSpace<'_, A>,
        control: &[f64],
        t: f64,
        psi: f64,
        ws: &mut Workspace,
    ) -> Result<[f64; 3]> {
        let (c, dd, _) = self.seam_data(space, control, psi, ws)?;
        // Low modes: `α_k t^k + β_k t^{k+2}` per mode (a polynomial in the disk's x, y);
        // the rest of the seam data with profiles vanishing to order `REST_ORDER` at the centre.
        let low = self.low_mode_value(t, psi);
        let (lc, ld) = self.low_mode_seam(psi);
        let m = REST_ORDER as i32;
        let tm = t.powi(m);
        let p = (m as f64 + 1.0) * tm - m as f64 * tm * t;
        let q = tm * t - tm;
        let mut f = [0.0; 3];
        for k in 0..3 {
            f[k] = low[k] + p * (c[k] - lc[k]) + q * (dd[k] - ld[k]);
        }
        Ok(f)
    }

    /// `Σ_k (α_k t^k + β_k t^{k+2})(cos kψ, sin kψ)` over the stored modes (value and radial
    /// derivative of the truncated seam data at `t = 1`).
    fn low_mode_value(&self, t: f64, psi: f64) -> [f64; 3] {
        let mut f = [0.0; 3];
        for (k, [alpha, beta]) in self.profile.iter().enumerate() {
            let tk = t.powi(k as i32);
            let trig = [(k as f64 * psi).cos(), (k as f64 * psi).sin()];
            for p in 0..2 {
                for x in 0..3 {
                    f[x] += trig[p] * tk * (alpha[p][x] + beta[p][x] * t * t);
                }
            }
        }
        f
    }

    /// The truncated seam data `(C_K(ψ), D_K(ψ))`: `C_k = α_k + β_k`, `D_k = k α_k + (k + 2) β_k`.
    fn low_mode_seam(&self, psi: f64) -> ([f64; 3], [f64; 3]) {
        let (mut c, mut d) = ([0.0; 3], [0.0; 3]);
        for (k, [alpha, beta]) in self.profile.iter().enumerate() {
            let kf = k as f64;
            let trig = [(kf * psi).cos(), (kf * psi).sin()];
            for p in 0..2 {
                for x in 0..3 {
                    c[x] += trig[p] * (alpha[p][x] + beta[p][x]);
                    d[x] += trig[p] * (kf * alpha[p][x] + (kf + 2.0) * beta[p][x]);
                }
            }
        }
        (c, d)
    }

    /// Measure the join at `samples` seam points: the angle between the spline's normal
    /// (`S_X × S_Y`, analytic) and the fill's (`F_t × F_ψ` by finite differences of the fill
    /// itself, one-sided in `t` from inside the hole), and the position gap.
    pub fn seam_normal_jump<A: FlatCharts + Sync + ?Sized>(
        &self,
        space: &ManifoldSpace<'_, A>,
        control: &[f64],
        samples: usize,
    ) -> Result<SeamReport> {
        let mut ws = Workspace::default();
        let mut worst: f64 = 0.0;
        let mut gap: f64 = 0.0;
        let mut diam: f64 = 0.0;
        let h = 1e-6;
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        let mut pts = Vec::with_capacity(samples);
        for j in 0..samples {
            let psi = 2.0 * PI * (j as f64 + 0.5) / samples as f64;
            let (c, _, [sx, sy]) = self.seam_data(space, control, psi, &mut ws)?;
            pts.push(c);
            let f1 = self.fill_point(space, control, 1.0, psi, &mut ws)?;
            let fi = self.fill_point(space, control, 1.0 - h, psi, &mut ws)?;
            let fp = self.fill_point(space, control, 1.0, psi + h, &mut ws)?;
            let fm = self.fill_point(space, control, 1.0, psi - h, &mut ws)?;
            let ft: [f64; 3] = std::array::from_fn(|k| (f1[k] - fi[k]) / h);
            let fpsi: [f64; 3] = std::array::from_fn(|k| (fp[k] - fm[k]) / (2.0 * h));
            let ns = cross(sx, sy);
            let nf = cross(ft, fpsi);
            let cosang = (ns[0] * nf[0] + ns[1] * nf[1] + ns[2] * nf[2]) / (norm(ns) * norm(nf));
            let ang = cosang.clamp(-1.0, 1.0).acos().to_degrees();
            worst = worst.max(if ang.is_finite() { ang } else { 180.0 });
            gap = gap.max(norm(std::array::from_fn(|k| f1[k] - c[k])));
        }
        for a in &pts {
            for b in &pts {
                diam = diam.max(norm(std::array::from_fn(|k| a[k] - b[k])));
            }
        }
        Ok(SeamReport {
            vertex: self.vertex,
            cone_angle: self.cone_angle,
            samples,
            max_normal_jump_deg: worst,
            max_position_gap: gap / diam.max(1e-300),
        })
    }
}
