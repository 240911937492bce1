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

use super::cylinders::{cylinders, integral_form, CylinderDecomposition};
use crate::analysis::forms::cochain::on_halfedge;
use crate::analysis::forms::{HolomorphicForm, HolomorphicForms};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use serde::Serialize;

/// One cylinder of the domain with data.
#[derive(Debug, Clone, Serialize)]
pub struct CylinderChart {
    /// Band index and the `v` of its bottom (mod 1), its height and circumference.
    pub band: usize,
    pub bottom: f64,
    pub height: f64,
    pub circumference: f64,
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

/// The candidate combinations `n`: the unit vectors `e_k` and `e_i ± e_j`.
fn candidates(m: usize) -> Vec<Vec<i32>> {
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

/// Over the candidate combinations ([`genus_domain`]), the domain whose cylinders all hold data
/// (`Σ L·H` over the developed cylinders = the net's area) and whose poorest cylinder holds
/// the most data points (ties: the earlier candidate).
pub fn best_genus_domain(h: &HolomorphicForms, data: usize) -> Result<GenusDomain> {
    let mut best: Option<(usize, GenusDomain)> = None;
    let mut last_err = None;
    for n in candidates(2 * h.genus) {
        match genus_domain(h, &n, data) {
            Ok(d) => {
                let area: f64 = d.cylinders.iter().map(|c| c.circumference * c.height).sum();
                let net = d.decomposition.area;
                let covered = (area - net).abs() <= 1e-6 * net.abs();
                let poorest = d.cylinders.iter().map(|c| c.data_points).min().unwrap_or(0);
                let score = if covered { poorest } else { 0 };
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
            vertices: 0,
            data_points: 0,
        });
    }
    let mut points = Vec::new();
    let mut unassigned = Vec::new();
    let mut ucyl = vec![f64::NAN; nv];
    for x in 0..nv {
        let c = if comp[x] == usize::MAX {
            usize::MAX
        } else {
            chart_of[comp[x]]
        };
        if c == usize::MAX {
            if x < data {
                unassigned.push(x as u32);
            }
            continue;
        }
        let l = charts[c].circumference;
        ucyl[x] = uv[x][0].rem_euclid(l);
        charts[c].vertices += 1;
        if x < data {
            charts[c].data_points += 1;
            points.push(CylinderPoint {
                vertex: x as u32,
                cylinder: c,
                u: ucyl[x],
                v: uv[x][1],
            });
        }
    }
    let cyl: Vec<Option<usize>> = comp
        .iter()
        .map(|&k| match chart_of.get(k) {
            Some(&c) if c != usize::MAX => Some(c),
            _ => None,
        })
        .collect();
    let crossings = crossings(mesh, form, &cyl, &uv, &ucyl, &charts, bands.len());
    let zero_copies = zero_copies(mesh, form, &saddles, &cyl, &uv, &ucyl, &charts);
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
            let same = |z: &ZeroCopy| {
                let d = (z.u - u).abs();
                z.saddle == x && z.cylinder == c && z.top == top && d.min(l - d) < 1e-6 * l
            };
            if !out.iter().any(same) {
                out.push(ZeroCopy {
                    saddle: x,
                    cylinder: c,
                    top,
                    u,
                });
            }
        }
    }
    out
}
