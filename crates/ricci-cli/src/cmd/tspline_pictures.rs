//! Pictures of a fitted T-spline (paper 003 Fig. 1(d), 5 and 7: "the red curves on the manifold
//! T-spline surface are the images of the edges on the domain manifold"): the mesh of the
//! domain drawn on the surface, and zebra stripes (reflection lines, whose kinks show C¹
//! defects). [`render_net_and_zebra`] is shared by the genus-1 T-mesh
//! (`crate::cmd::tspline::pictures`) and the genus ≥ 2 domain mesh ([`domain_pictures`]):
//! the cells' sides mapped through the spline, the strips' sides (critical horizontal
//! trajectories and the vertical sides through the zeros) drawn darker, and a ring around
//! every zero (the extraordinary points). The domain mesh is conforming: it has no
//! T-junctions.

use ricci::spline::tspline::domain_fit::DomainFit;
use ricci_render::{render, Image, Paint, Polyline, RenderOptions, Style};
use std::collections::HashMap;

/// Colour of the cell sides and of the T-mesh edges.
const EDGE: [f32; 3] = [0.12, 0.12, 0.16];
/// Colour of the strips' sides (domain mesh).
const STRIP: [f32; 3] = [0.05, 0.2, 0.75];
/// Colour of the rings around the zeros (domain mesh).
const ZERO: [f32; 3] = [1.0, 0.5, 0.0];
/// T-junctions of the domain mesh (issue 18: "the T-mesh on the surface with T-junctions in red").
const T_JUNCTION: [f32; 3] = [0.85, 0.05, 0.05];
/// At most about this many cell sides are drawn: on a finer mesh only every `stride`-th knot
/// line (the strips' sides always).
const DRAWN_CELLS: usize = 2000;
/// At most about this many triangles in the tessellation the pictures are rendered from.
const TRIANGLES: usize = 300_000;

/// The surface `(positions, triangles)` rendered twice with `opts`: with `polylines` drawn on
/// it, and with zebra stripes.
pub fn render_net_and_zebra(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    polylines: Vec<Polyline>,
    opts: &RenderOptions,
) -> anyhow::Result<(Image, Image)> {
    let net = Style {
        polylines,
        ..Style::default()
    };
    let net = render(positions, triangles, &net, opts)?.image;
    let zebra = Style {
        paint: Paint::Zebra(ricci_render::Zebra::default()),
        ..Style::default()
    };
    let zebra = render(positions, triangles, &zebra, opts)?.image;
    Ok((net, zebra))
}

/// A polyline of the net.
pub fn line(points: Vec<[f64; 3]>, color: [f32; 3], width: f32, closed: bool) -> Polyline {
    Polyline {
        points,
        color,
        width,
        closed,
    }
}

/// What [`domain_pictures`] drew: every `stride`-th knot line, the zeros ringed.
#[derive(Debug, Clone, Copy)]
pub struct DomainPictures {
    pub stride: usize,
    pub segments_per_cell_side: usize,
    pub triangles: usize,
    pub zeros: usize,
    pub t_junctions: usize,
}

/// The domain-mesh spline as one welded triangle mesh: every cell's Bézier patch on a
/// `k × k` grid, points shared by two patches merged (the spline is C⁰, so they agree up to
/// rounding: merged when equal to `1e-9` of `scale`); and, per domain-mesh vertex that is a
/// zero, its index in the tessellation, then the same per T-junction.
type Tessellation = (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<u32>, Vec<u32>);

fn tessellate(fit: &DomainFit, k: usize) -> Tessellation {
    let mesh = &fit.mesh;
    let eps = 1e-9 * fit.scale.max(f64::MIN_POSITIVE);
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::with_capacity(2 * k * k * mesh.n_cells());
    let mut zeros: HashMap<u32, u32> = HashMap::new();
    let mut tees: HashMap<u32, u32> = HashMap::new();
    let tee_cells: HashMap<u32, ()> = mesh
        .tjunctions
        .iter()
        .flat_map(|t| &t.junctions)
        .map(|&(r, i, j, _)| {
            let rc = &mesh.rects[r as usize];
            ((rc.first_cell + j as usize * rc.m + i as usize) as u32, ())
        })
        .collect();
    let mut ids = vec![0u32; (k + 1) * (k + 1)];
    for c in 0..mesh.n_cells() as u32 {
        let p = mesh.patch(c, &fit.control, 0.0, 0.0);
        for j in 0..=k {
            for i in 0..=k {
                let (s, t) = (i as f64 / k as f64, j as f64 / k as f64);
                let x = p.point(p.u0 + s * (p.u1 - p.u0), p.v0 + t * (p.v1 - p.v0));
                let key = x.map(|y| (y / eps).round() as i64);
                ids[j * (k + 1) + i] = *index.entry(key).or_insert_with(|| {
                    positions.push(x);
                    (positions.len() - 1) as u32
                });
            }
        }
        for j in 0..k {
            for i in 0..k {
                let a = ids[j * (k + 1) + i];
                let (b, cc, d) = (
                    ids[j * (k + 1) + i + 1],
                    ids[(j + 1) * (k + 1) + i + 1],
                    ids[(j + 1) * (k + 1) + i],
                );
                triangles.push([a, b, cc]);
                triangles.push([a, cc, d]);
            }
        }
        // corners [lower left, lower right, upper right, upper left]
        let at = [0, k, (k + 1) * (k + 1) - 1, k * (k + 1)];
        for (q, &v) in mesh.corners[c as usize].iter().enumerate() {
            if mesh.is_zero(v) {
                zeros.entry(v).or_insert(ids[at[q]]);
            }
        }
        if tee_cells.contains_key(&c) {
            tees.insert(c, ids[0]);
        }
    }
    let mut z: Vec<(u32, u32)> = zeros.into_iter().collect();
    z.sort_unstable();
    let mut t: Vec<(u32, u32)> = tees.into_iter().collect();
    t.sort_unstable();
    (
        positions,
        triangles,
        z.into_iter().map(|(_, i)| i).collect(),
        t.into_iter().map(|(_, i)| i).collect(),
    )
}

/// The images of the cells' left and bottom sides (each side once: every side is the left or
/// the bottom side of a cell) on every `stride`-th knot line of each strip and on the strips'
/// sides, with `per_side` segments each; the strips' sides in their own colour; sides on no
/// line of the T-mesh (a graded line past its T-junction) left out.
fn cell_sides(fit: &DomainFit, stride: usize, per_side: usize) -> Vec<Polyline> {
    let mesh = &fit.mesh;
    let mut out = Vec::new();
    for c in 0..mesh.n_cells() as u32 {
        let (r, i, j) = mesh.cell_at[c as usize];
        let (r, iu, ju) = (r as usize, i as usize, j as usize);
        let on = [
            mesh.on_line_v(r, iu, ju) && mesh.on_line_v(r, iu, ju + 1),
            mesh.on_line_u(r, iu, ju) && mesh.on_line_u(r, iu + 1, ju),
        ];
        let p = mesh.patch(c, &fit.control, 0.0, 0.0);
        let along = |vertical: bool| -> Vec<[f64; 3]> {
            (0..=per_side)
                .map(|m| {
                    let t = m as f64 / per_side as f64;
                    if vertical {
                        p.point(p.u0, p.v0 + t * (p.v1 - p.v0))
                    } else {
                        p.point(p.u0 + t * (p.u1 - p.u0), p.v0)
                    }
                })
                .collect()
        };
        for (k, vertical) in [(iu, true), (ju, false)] {
            if !on[usize::from(!vertical)] {
                continue;
            }
            if k == 0 {
                out.push(line(along(vertical), STRIP, 1.8, false));
            } else if k % stride == 0 {
                out.push(line(along(vertical), EDGE, 0.8, false));
            }
        }
    }
    out
}

/// The pictures of the domain-mesh spline `fit` (module docs): the cell sides on the surface
/// (every `stride`-th knot line when the mesh has more than about [`DRAWN_CELLS`] cells) with
/// the zeros ringed, and zebra stripes; rendered from a welded tessellation of at most
/// `per_side` segments per cell side (fewer when the cells are many).
pub fn domain_pictures(
    fit: &DomainFit,
    per_side: usize,
    opts: &RenderOptions,
) -> anyhow::Result<(Image, Image, DomainPictures)> {
    let cells = fit.mesh.n_cells().max(1);
    let budget = ((TRIANGLES / (2 * cells)) as f64).sqrt().floor() as usize;
    let k = per_side.min(budget).max(1);
    let stride = ((cells as f64 / DRAWN_CELLS as f64).sqrt().ceil() as usize).max(1);
    let (positions, triangles, zeros, tees) = tessellate(fit, k);
    let mut polylines = cell_sides(fit, stride, 4);
    for &z in &zeros {
        let mut ring = crate::util::ring_marker(&positions, &triangles, z, 0.02, ZERO);
        ring.width = 3.0;
        polylines.push(ring);
    }
    for &t in &tees {
        let mut ring = crate::util::ring_marker(&positions, &triangles, t, 0.012, T_JUNCTION);
        ring.width = 2.5;
        polylines.push(ring);
    }
    let (net, zebra) = render_net_and_zebra(&positions, &triangles, polylines, opts)?;
    let info = DomainPictures {
        stride,
        segments_per_cell_side: k,
        triangles: triangles.len(),
        zeros: zeros.len(),
        t_junctions: tees.len(),
    };
    Ok((net, zebra, info))
}

/// The caption of the domain mesh's picture (for the CLI's JSON and the demo's page).
pub fn domain_caption(info: &DomainPictures, cells: usize) -> String {
    let lines = if info.stride > 1 {
        format!(
            "one knot line in {} of the {cells} cells' sides (all of them would blacken the picture)",
            info.stride
        )
    } else {
        format!("the sides of all {cells} cells")
    };
    format!(
        "The domain mesh on the surface: {lines} mapped through the spline in dark grey, the strips' sides (critical horizontal trajectories of the 1-form and the vertical sides through its zeros) in blue, and the {} zeros of the form — the extraordinary points, where the spline is C⁰ — ringed in orange. {}",
        info.zeros,
        if info.t_junctions > 0 {
            format!("The graded lines at the zeros end in the {} T-junctions ringed in red (the T-mesh; its sides only are drawn).", info.t_junctions)
        } else {
            "The mesh is conforming: no T-junctions.".to_string()
        }
    )
}

/// The caption of the zebra picture of a domain-mesh spline.
pub const ZEBRA_CAPTION: &str = "Reflection lines (zebra) on the domain-mesh spline: C² on every cell side not at a zero, so the stripes run smoothly across the cells and the strips' sides; at the zeros (C⁰, G¹ not guaranteed) they may kink.";
