//! Genus ≥ 2, step 2 of the domain manifold (paper 003 §2): every data point gets coordinates
//! `(cylinder, u mod L, v)` in one of the flat cylinders of [`super::cylinders`], and every
//! mesh edge that crosses a critical horizontal trajectory gives a pair of points, one on the
//! top of the cylinder below and one on the bottom of the cylinder above, that are the same
//! point of the surface (the gluing of the cylinders, used to measure the jumps there).
//!
//! The coordinates are developed from the holomorphic form itself, not from the cut mesh's
//! chart: inside a band (between two consecutive critical values of `v = Im ∫ω mod 1`), two
//! vertices joined by an edge that stays inside the band are in the same cylinder and differ
//! by `(Re ω, Im ω)` on the edge. The connected components of this graph with a non-zero
//! holonomy `(L, 0)` are the cylinders (their circumference `L` must equal the decomposition's
//! `∮ du`); `u mod L` does not depend on the path because `L` generates the holonomy (checked:
//! every other holonomy is an integer multiple of `L`, `holonomy_defect`). Vertices on a
//! critical level (the zeros) and components without holonomy (a few vertices cut off near a
//! zero) are not assigned and are counted.
//!
//! **Thin cylinders.** A band narrower than the mesh's edges in `v` (two critical values
//! closer than an edge's rise, e.g. botijo's `[1, 0, …]`: heights 0.0011 … 0.0076) can hold
//! no vertex, so the graph above has no component there; such a cylinder is found from the
//! level set at the band's middle ([`super::cylinders::level_curves`], on faces): every curve
//! that meets no edge ending inside the band in a developed cylinder is a thin cylinder, of
//! circumference `|∮ du|`, with `u` developed along the curve (the sum of the face segments'
//! `Δu`; the form is affine on a face, so this is the flat coordinate); the few vertices of
//! the band cut off near a zero that the curve meets (components without holonomy) join it,
//! their `u` shifted to the curve's where they meet. An edge through it
//! gives `u` at any height of the band: `u` at the middle level plus `(t − s)·Re ω` (`s`, `t`:
//! parameters along the edge of the middle level and of the height). So an edge from a
//! cylinder below to one above that spans the band crosses both its critical levels and gives
//! two crossings (lower → thin, thin → upper), and an edge from a saddle on the band's bottom
//! (or to one on its top) gives that saddle's copy on the thin cylinder's circle. Thin
//! cylinders carry few data points or none (the fit fairs them); with them the cylinders cover the
//! surface (`Σ L·H` = the net's area, [`GenusDomain::covers`]).

use super::cylinders::{cylinders, integral_form, level_curves, CylinderDecomposition};
use crate::analysis::forms::cochain::on_halfedge;
use crate::analysis::forms::{HolomorphicForm, HolomorphicForms};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use serde::Serialize;
use std::collections::BTreeMap;

/// One cylinder of the domain (a thin one has no vertices: the module doc).
#[derive(Debug, Clone, Serialize)]
pub struct CylinderChart {
    /// Band index and the `v` of its bottom (mod 1), its height and circumference.
    pub band: usize,
    pub bottom: f64,
    pub height: f64,
    pub circumference: f64,
    /// Found from its band's middle level curve, not from a component of vertices (a thin
    /// cylinder: the module doc).
    pub thin: bool,
    /// Refined-mesh vertices in it (all, and the data points among them).
    pub vertices: usize,
    pub data_points: usize,
}

/// A data point in cylinder coordinates.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct CylinderPoint {
    /// Index into the input positions.
    pub vertex: u32,
    pub cylinder: usize,
    /// `u ∈ [0, L)`, `v ∈ (0, H)`.
    pub u: f64,
    pub v: f64,
}

/// A point of a critical trajectory seen from both sides: `(u_lower, H_lower)` in the cylinder
/// below and `(u_upper, 0)` in the cylinder above are the same point of the surface.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Crossing {
    pub lower: usize,
    pub u_lower: f64,
    pub upper: usize,
    pub u_upper: f64,
}

/// A saddle (zero) seen from one side of a cylinder: it lies on the cylinder's top (`v = H`)
/// or bottom (`v = 0`) circle at `u`. A saddle can appear several times on one circle (the
/// circle running through it twice); each appearance is one copy.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ZeroCopy {
    pub saddle: u32,
    pub cylinder: usize,
    pub top: bool,
    pub u: f64,
}

/// The domain of a genus ≥ 2 surface: cylinders, data points in them, gluing samples.
#[derive(Debug, Clone)]
pub struct GenusDomain {
    pub decomposition: CylinderDecomposition,
    /// `n` of the form `Im ω = Σ n_k ζ_k` (see [`genus_domain`]).
    pub combination: Vec<i32>,
    /// The critical levels used: `v mod 1` of the saddles of the piecewise-linear `v`.
    pub levels: Vec<f64>,
    /// Those saddle vertices (of the forms' refined mesh).
    pub saddles: Vec<u32>,
    pub cylinders: Vec<CylinderChart>,
    pub points: Vec<CylinderPoint>,
    /// Data points not assigned (on a critical level, or cut off near a zero).
    pub unassigned: Vec<u32>,
    pub crossings: Vec<Crossing>,
    /// The saddles' copies on the cylinders' circles (from the edges into each cylinder).
    pub zero_copies: Vec<ZeroCopy>,
    /// `max |holonomy − k L| / L` over the non-tree edges of every cylinder.
    pub holonomy_defect: f64,
}

impl GenusDomain {
    /// Whether the cylinders cover the surface: `|Σ L·H − A| ≤ tol · |A|` over all cylinders
    /// (thin ones included), `A` the net's signed area `∫ du∧dv` (the coarea formula).
    pub fn covers(&self, tol: f64) -> bool {
        let area: f64 = self
            .cylinders
            .iter()
            .map(|c| c.circumference * c.height)
            .sum();
        let net = self.decomposition.area;
        (area - net).abs() <= tol * net.abs()
    }
}

/// The domain of the form whose imaginary part is `Σ_k n_k ζ_k` (`ζ_k`: the harmonic form dual
/// to loop `k`, see [`integral_form`]; integer `n` keep the imaginary periods integer, so the
/// horizontal trajectories close). The data points are the first `data` vertices of the forms'
/// refined mesh (the input vertices keep their ids).
pub fn genus_domain(h: &HolomorphicForms, n: &[i32], data: usize) -> Result<GenusDomain> {
    let ne = h.mesh().n_edges();
    let mut form = HolomorphicForm {
        re: vec![0.0; ne],
        im: vec![0.0; ne],
    };
    let mut defect = 0.0;
    for (k, &nk) in n.iter().enumerate() {
        if nk == 0 {
            continue;
        }
        let (f, d) = integral_form(h, k)?;
        for e in 0..ne {
            form.re[e] += nk as f64 * f.re[e];
            form.im[e] += nk as f64 * f.im[e];
        }
        defect += nk.unsigned_abs() as f64 * d;
    }
    let class = n.iter().position(|&x| x != 0).unwrap_or(0);
    let dec = cylinders(h, &form, class, defect)?;
    let mut d = develop(h, &form, dec, data)?;
    d.combination = n.to_vec();
    Ok(d)
}

/// The candidate combinations `n` of [`best_genus_domain`] for `m = 2g` loops: the unit vectors
/// `e_k` and `e_i ± e_j`.
pub fn candidates(m: usize) -> Vec<Vec<i32>> {
    let mut out = Vec::new();
    for k in 0..m {
        let mut n = vec![0; m];
        n[k] = 1;
        out.push(n);
    }
    for i in 0..m {
        for j in i + 1..m {
            for sj in [1, -1] {
                let mut n = vec![0; m];
                n[i] = 1;
                n[j] = sj;
                out.push(n);
            }
        }
    }
    out
}

/// Over the candidate combinations ([`genus_domain`]), the domain whose cylinders cover the
/// surface (`Σ L·H` over the cylinders = the net's area, [`GenusDomain::covers`]) and whose
/// poorest cylinder holds the most data points (ties: the earlier candidate). When every
/// covering domain has thin cylinders (which may hold no data, so "poorest" says nothing),
/// the one whose strips glue with the least sheared layout (the smallest largest slope
/// `|u_top − u_bottom| / H` of [`super::glue::gluing`]'s lines; botijo: 8.97 against 112 for the
/// most data, L∞ 4.2 % against 22 % at the budget).
pub fn best_genus_domain(h: &HolomorphicForms, data: usize) -> Result<GenusDomain> {
    let mut best: Option<((usize, f64), GenusDomain)> = None;
    let mut last_err = None;
    for n in candidates(2 * h.genus) {
        match genus_domain(h, &n, data) {
            Ok(d) => {
                let covered = d.covers(1e-6);
                let thin = d.cylinders.iter().any(|c| c.thin);
                let poorest = d
                    .cylinders
                    .iter()
                    .filter(|c| !c.thin)
                    .map(|c| c.data_points)
                    .min()
                    .unwrap_or(0);
                let score = match (covered, thin) {
                    (true, false) => (poorest, 0.0),
                    (true, true) => match super::glue::gluing(&d) {
                        Ok(g) => (0, 1.0 / (1.0 + g.max_slope)),
                        Err(_) => (0, 0.0),
                    },
                    _ => (0, 0.0),
                };
                if best.as_ref().is_none_or(|(s, _)| score > *s) {
                    best = Some((score, d));
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    match (best, last_err) {
        (Some((_, d)), _) => Ok(d),
        (None, Some(e)) => Err(e),
        (None, None) => Err(Error::topology(
            "no loop class: the surface has genus 0 (no holomorphic 1-forms)",
        )),
    }
}

fn develop(
    h: &HolomorphicForms,
    form: &HolomorphicForm,
    dec: CylinderDecomposition,
    data: usize,
) -> Result<GenusDomain> {
    let mesh = h.mesh();
    let nv = mesh.n_vertices();
    if data > nv {
        return Err(Error::input(format!(
            "{data} data points but the forms' mesh has {nv} vertices"
        )));
    }
    // v mod 1 per vertex, from any cut copy
    let mut vmod = vec![f64::NAN; nv];
    let net = h.net(form)?;
    for (c, &o) in h.cut.cut_vertex_origin.iter().enumerate() {
        vmod[o as usize] = net.uv[c][1].rem_euclid(1.0);
    }
    if let Some(x) = vmod.iter().position(|t| !t.is_finite()) {
        return Err(Error::topology(format!(
            "vertex {x} has no copy in the cut mesh"
        )));
    }
    let (saddles, levels, bands) = critical_bands(mesh, form, &vmod);
    // band and height in the band (rel ∈ (0, H)) per vertex; None on a critical level
    let eps = 1e-9;
    let mut band: Vec<Option<(usize, f64)>> = vec![None; nv];
    for x in 0..nv {
        let t = vmod[x];
        for (b, &(bottom, height)) in bands.iter().enumerate() {
            let rel = (t - bottom).rem_euclid(1.0);
            if rel > eps && rel < height - eps {
                band[x] = Some((b, rel));
                break;
            }
        }
    }
    let (comp, uv, holonomy, comp_band) = components(mesh, form, &band);
    // circumference per component: the smallest non-zero holonomy
    let scale = dec
        .cylinders
        .iter()
        .map(|c| c.circumference.abs())
        .fold(0.0, f64::max)
        .max(1e-300);
    let mut chart_of = vec![usize::MAX; holonomy.len()];
    let mut charts: Vec<CylinderChart> = Vec::new();
    let mut defect = 0.0f64;
    for (id, hol) in holonomy.iter().enumerate() {
        let l = hol
            .iter()
            .map(|x| x.abs())
            .filter(|&x| x > 1e-6 * scale)
            .fold(f64::INFINITY, f64::min);
        if !l.is_finite() {
            continue;
        }
        for x in hol {
            let k = (x / l).round();
            defect = defect.max((x - k * l).abs() / l);
        }
        let b = comp_band[id];
        chart_of[id] = charts.len();
        charts.push(CylinderChart {
            band: b,
            bottom: bands[b].0,
            height: bands[b].1,
            circumference: l,
            thin: false,
            vertices: 0,
            data_points: 0,
        });
    }
    let mut adopt = Adoption {
        band: &band,
        comp: &comp,
        uv: &uv,
        chart_of,
        shift: vec![0.0; holonomy.len()],
    };
    let thin = thin_cylinders(h, form, &net.uv, &bands, &mut adopt, &mut charts)?;
    let (points, unassigned, ucyl) = assign(&adopt, &mut charts, data);
    let cyl: Vec<Option<usize>> = comp
        .iter()
        .map(|&k| match adopt.chart_of.get(k) {
            Some(&c) if c != usize::MAX => Some(c),
            _ => None,
        })
        .collect();
    let mut crossings = crossings(mesh, form, &cyl, &uv, &ucyl, &charts, bands.len());
    let mut zero_copies = zero_copies(mesh, form, &saddles, &cyl, &uv, &ucyl, &charts);
    let developed = Developed {
        band: &band,
        cyl: &cyl,
        ucyl: &ucyl,
    };
    crossings.extend(thin_crossings(
        mesh, form, &vmod, &levels, &developed, &charts, &thin,
    ));
    thin_zero_copies(
        mesh,
        form,
        &saddles,
        &vmod,
        &charts,
        &thin,
        &mut zero_copies,
    );
    Ok(GenusDomain {
        decomposition: dec,
        combination: Vec::new(),
        levels,
        saddles,
        cylinders: charts,
        points,
        unassigned,
        crossings,
        zero_copies,
        holonomy_defect: defect,
    })
}

/// The saddles of the piecewise-linear function `v` (sign changes of `dv` around the vertex
/// ≥ 4), where its level sets change topology, their levels `v mod 1`, and the bands between
/// consecutive levels `(bottom, height)`. The saddles can sit at other vertices than the zeros
/// of the decomposition (found from the index of `Re ω`'s face vectors); a level missed here
/// would merge two cylinders of a band.
fn critical_bands(
    mesh: &Mesh,
    form: &HolomorphicForm,
    vmod: &[f64],
) -> (Vec<u32>, Vec<f64>, Vec<(f64, f64)>) {
    let mut saddles = Vec::new();
    for x in 0..mesh.n_vertices() as u32 {
        let signs: Vec<bool> = mesh
            .outgoing(x)
            .map(|hh| on_halfedge(mesh, &form.im, hh) >= 0.0)
            .collect();
        let k = signs.len();
        let changes = (0..k).filter(|&i| signs[i] != signs[(i + 1) % k]).count();
        if changes >= 4 {
            saddles.push(x);
        }
    }
    let mut levels: Vec<f64> = saddles.iter().map(|&x| vmod[x as usize]).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    let bands: Vec<(f64, f64)> = if levels.is_empty() {
        vec![(0.0, 1.0)]
    } else {
        (0..levels.len())
            .map(|i| {
                let hi = levels.get(i + 1).copied().unwrap_or(levels[0] + 1.0);
                (levels[i], hi - levels[i])
            })
            .collect()
    };
    (saddles, levels, bands)
}

/// `(re, im)` of the form on a half-edge.
fn step(mesh: &Mesh, form: &HolomorphicForm, hh: u32) -> (f64, f64) {
    (
        on_halfedge(mesh, &form.re, hh),
        on_halfedge(mesh, &form.im, hh),
    )
}

type Components = (Vec<usize>, Vec<[f64; 2]>, Vec<Vec<f64>>, Vec<usize>);

/// The components of the graph of edges inside one band (`band[x] = (band, height in it)`),
/// developed by breadth-first search: per vertex its component (`usize::MAX`: none) and
/// developed `(u, v)`, per component the `u` holonomies of its non-tree edges and its band.
fn components(mesh: &Mesh, form: &HolomorphicForm, band: &[Option<(usize, f64)>]) -> Components {
    let nv = mesh.n_vertices();
    let mut comp = vec![usize::MAX; nv];
    let mut uv = vec![[0.0f64; 2]; nv];
    let mut holonomy: Vec<Vec<f64>> = Vec::new();
    let mut comp_band = Vec::new();
    let in_band = |x: usize, y: usize, dv: f64| -> bool {
        match (band[x], band[y]) {
            (Some((a, rx)), Some((b, ry))) => a == b && (rx + dv - ry).abs() < 1e-7,
            _ => false,
        }
    };
    let mut out_edges: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for hh in 0..mesh.n_halfedges() as u32 {
        if !mesh.is_boundary_halfedge(hh) {
            out_edges[mesh.he_origin(hh) as usize].push(hh);
        }
    }
    for root in 0..nv {
        let Some((b, rel)) = band[root] else { continue };
        if comp[root] != usize::MAX {
            continue;
        }
        let id = holonomy.len();
        holonomy.push(Vec::new());
        comp_band.push(b);
        comp[root] = id;
        uv[root] = [0.0, rel];
        let mut queue = std::collections::VecDeque::from([root]);
        while let Some(x) = queue.pop_front() {
            for &hh in &out_edges[x] {
                let y = mesh.he_tip(hh) as usize;
                let (du, dv) = step(mesh, form, hh);
                if !in_band(x, y, dv) {
                    continue;
                }
                let p = [uv[x][0] + du, uv[x][1] + dv];
                if comp[y] == usize::MAX {
                    comp[y] = id;
                    uv[y] = p;
                    queue.push_back(y);
                } else {
                    holonomy[id].push(p[0] - uv[y][0]);
                }
            }
        }
    }
    (comp, uv, holonomy, comp_band)
}

/// The crossings of the critical levels: edges from a cylinder (`cyl[x]`) into a cylinder of
/// the next band that cross exactly that level, with the crossing point's `u` on both sides.
fn crossings(
    mesh: &Mesh,
    form: &HolomorphicForm,
    cyl: &[Option<usize>],
    uv: &[[f64; 2]],
    ucyl: &[f64],
    charts: &[CylinderChart],
    bands: usize,
) -> Vec<Crossing> {
    let mut out = Vec::new();
    for hh in 0..mesh.n_halfedges() as u32 {
        if mesh.is_boundary_halfedge(hh) {
            continue;
        }
        let (x, y) = (mesh.he_origin(hh) as usize, mesh.he_tip(hh) as usize);
        let (du, dv) = step(mesh, form, hh);
        let (Some(a), Some(b)) = (cyl[x], cyl[y]) else {
            continue;
        };
        if dv <= 0.0 {
            continue;
        }
        let (ha, rx, ry) = (charts[a].height, uv[x][1], uv[y][1]);
        let top = (charts[a].band + 1) % bands;
        if charts[b].band != top || rx + dv <= ha || (rx + dv - ha - ry).abs() > 1e-7 {
            continue;
        }
        let t = (ha - rx) / dv;
        out.push(Crossing {
            lower: a,
            u_lower: (ucyl[x] + t * du).rem_euclid(charts[a].circumference),
            upper: b,
            u_upper: (ucyl[y] - (1.0 - t) * du).rem_euclid(charts[b].circumference),
        });
    }
    out
}

/// The copies of each saddle on the circles of the cylinders around it: every edge from the
/// saddle to a vertex `y` of a cylinder gives the saddle's `u` there (`u_y − Re ω`), on the top
/// or bottom circle (`v_y − Im ω` = `H` or 0); copies closer than `1e-6 L` are one.
fn zero_copies(
    mesh: &Mesh,
    form: &HolomorphicForm,
    saddles: &[u32],
    cyl: &[Option<usize>],
    uv: &[[f64; 2]],
    ucyl: &[f64],
    charts: &[CylinderChart],
) -> Vec<ZeroCopy> {
    let mut out: Vec<ZeroCopy> = Vec::new();
    for &x in saddles {
        for hh in mesh.outgoing(x) {
            let y = mesh.he_tip(hh) as usize;
            let Some(c) = cyl[y] else { continue };
            let (du, dv) = step(mesh, form, hh);
            let (l, h) = (charts[c].circumference, charts[c].height);
            let v = uv[y][1] - dv;
            let top = if v.abs() < 1e-7 {
                false
            } else if (v - h).abs() < 1e-7 {
                true
            } else {
                continue;
            };
            let u = (ucyl[y] - du).rem_euclid(l);
            add_copy(
                &mut out,
                ZeroCopy {
                    saddle: x,
                    cylinder: c,
                    top,
                    u,
                },
                l,
            );
        }
    }
    out
}

/// Adds `z` to `out` unless a copy of the same saddle on the same circle lies within
/// `1e-6 l` of it (`l`: the cylinder's circumference).
fn add_copy(out: &mut Vec<ZeroCopy>, z: ZeroCopy, l: f64) {
    let same = |y: &ZeroCopy| {
        let d = (y.u - z.u).abs();
        y.saddle == z.saddle
            && y.cylinder == z.cylinder
            && y.top == z.top
            && d.min(l - d) < 1e-6 * l
    };
    if !out.iter().any(same) {
        out.push(z);
    }
}

/// What the development of the vertices gave: per vertex its band and height in it (`None`
/// on a critical level), its cylinder (`None`: not developed) and `u` there.
struct Developed<'a> {
    band: &'a [Option<(usize, f64)>],
    cyl: &'a [Option<usize>],
    ucyl: &'a [f64],
}

impl Developed<'_> {
    /// The cylinder of vertex `x` if it lies strictly inside band `b` and was developed.
    fn cylinder_in(&self, x: u32, b: usize) -> Option<usize> {
        match (self.band[x as usize], self.cyl[x as usize]) {
            (Some((bx, _)), Some(c)) if bx == b => Some(c),
            _ => None,
        }
    }
}

/// A mesh edge passing through a thin cylinder: the cylinder, the parameter `s` (from the
/// origin of the half-edge along which `v` increases) where it crosses the band's middle level,
/// and `u` there on the cylinder.
#[derive(Debug, Clone, Copy)]
struct ThinPass {
    band: usize,
    cylinder: usize,
    s: f64,
    u: f64,
}

/// Per half-edge along which `v` increases, the thin cylinders it passes through.
type ThinPasses = BTreeMap<u32, Vec<ThinPass>>;

/// The vertex components of the development ([`components`]) and their cylinders: per
/// component its chart (`usize::MAX`: none) and the shift of its developed `u` into it.
struct Adoption<'a> {
    band: &'a [Option<(usize, f64)>],
    comp: &'a [usize],
    uv: &'a [[f64; 2]],
    chart_of: Vec<usize>,
    shift: Vec<f64>,
}

impl Adoption<'_> {
    /// The component of vertex `x` if `x` lies strictly inside band `b`.
    fn component_in(&self, x: u32, b: usize) -> Option<usize> {
        match self.band[x as usize] {
            Some((bx, _)) if bx == b && self.comp[x as usize] != usize::MAX => {
                Some(self.comp[x as usize])
            }
            _ => None,
        }
    }
}

/// The **thin cylinders**: the cylinders of a band that no developed vertex component lies in
/// (a band narrower than the mesh's edges in `v` holds few vertices or none). Per band, the
/// components of the level set at its middle ([`level_curves`], on faces, so thin bands have
/// them): a curve crossing an edge with an end strictly inside the band in a developed
/// cylinder is that cylinder; every other curve is a thin cylinder, with circumference
/// `|∮ du|` and `u` developed along the curve (the sum of its face segments). They are appended
/// to `charts`; the vertex components without holonomy that such a curve meets (a few vertices
/// next to a zero) are adopted by it (`u` shifted to agree with the curve's at the edge where
/// they meet). Returns the edges through the thin cylinders.
fn thin_cylinders(
    h: &HolomorphicForms,
    form: &HolomorphicForm,
    net_uv: &[[f64; 2]],
    bands: &[(f64, f64)],
    adopt: &mut Adoption,
    charts: &mut Vec<CylinderChart>,
) -> Result<ThinPasses> {
    let mesh = h.mesh();
    let mut out = ThinPasses::new();
    for (b, &(bottom, height)) in bands.iter().enumerate() {
        // a level through a vertex has no curve there: try another one inside the band
        let mut curves = Err(Error::numerical("no level tried"));
        for f in [0.5, 0.4, 0.6] {
            curves = level_curves(h, net_uv, (bottom + f * height).rem_euclid(1.0));
            if curves.is_ok() {
                break;
            }
        }
        for curve in curves? {
            let present = curve.crossings.iter().any(|&(hh, _, _)| {
                [mesh.he_origin(hh), mesh.he_tip(hh)].iter().any(|&x| {
                    adopt
                        .component_in(x, b)
                        .is_some_and(|k| adopt.chart_of[k] != usize::MAX)
                })
            });
            let l = curve.circumference.abs();
            if present || !(l > 0.0) {
                continue;
            }
            let c = charts.len();
            charts.push(CylinderChart {
                band: b,
                bottom,
                height,
                circumference: l,
                thin: true,
                vertices: 0,
                data_points: 0,
            });
            for &(hh, s, u) in &curve.crossings {
                out.entry(hh).or_default().push(ThinPass {
                    band: b,
                    cylinder: c,
                    s,
                    u: u.rem_euclid(l),
                });
                let (du, _) = step(mesh, form, hh);
                for (x, t) in [(mesh.he_origin(hh), 0.0), (mesh.he_tip(hh), 1.0)] {
                    if let Some(k) = adopt.component_in(x, b) {
                        if adopt.chart_of[k] == usize::MAX {
                            adopt.chart_of[k] = c;
                            adopt.shift[k] = u + (t - s) * du - adopt.uv[x as usize][0];
                        }
                    }
                }
            }
        }
    }
    Ok(out)
}

/// The data points in their cylinders, the unassigned ones, and `u mod L` per vertex (NaN
/// outside the cylinders); counts every cylinder's vertices and data points.
fn assign(
    adopt: &Adoption,
    charts: &mut [CylinderChart],
    data: usize,
) -> (Vec<CylinderPoint>, Vec<u32>, Vec<f64>) {
    let nv = adopt.comp.len();
    let mut points = Vec::new();
    let mut unassigned = Vec::new();
    let mut ucyl = vec![f64::NAN; nv];
    for x in 0..nv {
        let k = adopt.comp[x];
        let c = if k == usize::MAX {
            usize::MAX
        } else {
            adopt.chart_of[k]
        };
        if c == usize::MAX {
            if x < data {
                unassigned.push(x as u32);
            }
            continue;
        }
        let l = charts[c].circumference;
        ucyl[x] = (adopt.uv[x][0] + adopt.shift[k]).rem_euclid(l);
        charts[c].vertices += 1;
        if x < data {
            charts[c].data_points += 1;
            points.push(CylinderPoint {
                vertex: x as u32,
                cylinder: c,
                u: ucyl[x],
                v: adopt.uv[x][1],
            });
        }
    }
    (points, unassigned, ucyl)
}

/// The crossings of the critical levels by the edges through thin cylinders: walking up an
/// edge, at every critical level it crosses, the cylinder below and the one above (the
/// developed cylinder of an end inside that band, else the thin cylinder the edge passes
/// through there) and the crossing point's `u` on both (on a thin cylinder: `u` at the middle
/// level moved along the edge). Crossings between two developed cylinders are
/// [`crossings`]'s.
fn thin_crossings(
    mesh: &Mesh,
    form: &HolomorphicForm,
    vmod: &[f64],
    levels: &[f64],
    developed: &Developed,
    charts: &[CylinderChart],
    thin: &ThinPasses,
) -> Vec<Crossing> {
    let n = levels.len();
    let eps = 1e-9;
    let mut out = Vec::new();
    for (&hh, passes) in thin {
        let (x, y) = (mesh.he_origin(hh), mesh.he_tip(hh));
        let (du, dv) = step(mesh, form, hh);
        let vx = vmod[x as usize];
        // the critical levels strictly inside (vx, vx + dv), upward
        let mut crossed: Vec<(f64, usize)> = Vec::new();
        for (i, &l) in levels.iter().enumerate() {
            let mut lam = l + (vx + eps - l).ceil();
            while lam < vx + dv - eps {
                crossed.push((lam, i));
                lam += 1.0;
            }
        }
        crossed.sort_by(|a, b| a.0.total_cmp(&b.0));
        // the cylinder of band `b` on this edge at parameter t below (`up` false) or above a
        // level, its `u` there, and whether it is thin
        let side = |b: usize, t: f64, up: bool| -> Option<(usize, f64, bool)> {
            let (end, dt) = if up { (y, t - 1.0) } else { (x, t) };
            if let Some(c) = developed.cylinder_in(end, b) {
                return Some((c, developed.ucyl[end as usize] + dt * du, false));
            }
            let p = passes.iter().find(|p| p.band == b)?;
            Some((p.cylinder, p.u + (t - p.s) * du, true))
        };
        for &(lam, i) in &crossed {
            let t = (lam - vx) / dv;
            let (Some(lo), Some(up)) = (side((i + n - 1) % n, t, false), side(i, t, true)) else {
                continue;
            };
            if lo.2 || up.2 {
                out.push(Crossing {
                    lower: lo.0,
                    u_lower: lo.1.rem_euclid(charts[lo.0].circumference),
                    upper: up.0,
                    u_upper: up.1.rem_euclid(charts[up.0].circumference),
                });
            }
        }
    }
    out
}

/// The saddles' copies on the circles of the thin cylinders: an edge through a thin cylinder
/// from a saddle on its bottom level (or to one on its top level) gives the saddle's `u` there,
/// `u` at the middle level moved along the edge.
fn thin_zero_copies(
    mesh: &Mesh,
    form: &HolomorphicForm,
    saddles: &[u32],
    vmod: &[f64],
    charts: &[CylinderChart],
    thin: &ThinPasses,
    out: &mut Vec<ZeroCopy>,
) {
    let mut is_saddle = vec![false; vmod.len()];
    for &x in saddles {
        is_saddle[x as usize] = true;
    }
    let on = |x: u32, level: f64| {
        let d = (vmod[x as usize] - level).rem_euclid(1.0);
        is_saddle[x as usize] && d.min(1.0 - d) < 1e-7
    };
    for (&hh, passes) in thin {
        let (x, y) = (mesh.he_origin(hh), mesh.he_tip(hh));
        let (du, _) = step(mesh, form, hh);
        for p in passes {
            let ch = &charts[p.cylinder];
            let l = ch.circumference;
            for (saddle, top, t) in [(x, false, 0.0), (y, true, 1.0)] {
                let level = ch.bottom + if top { ch.height } else { 0.0 };
                if on(saddle, level) {
                    let z = ZeroCopy {
                        saddle,
                        cylinder: p.cylinder,
                        top,
                        u: (p.u + (t - p.s) * du).rem_euclid(l),
                    };
                    add_copy(out, z, l);
                }
            }
        }
    }
}
