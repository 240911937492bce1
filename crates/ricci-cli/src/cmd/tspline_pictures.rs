//! Pictures of a fitted T-spline (paper 003 Fig. 1(d), 5 and 7: "the red curves on the manifold
//! T-spline surface are the images of the edges on the domain manifold"): the mesh of the
//! domain drawn on the surface, and zebra stripes (reflection lines, whose kinks show C¹
//! defects). [`render_net_and_zebra`] is shared by the genus-1 T-mesh
//! (`crate::cmd::tspline::pictures`) and the genus ≥ 2 domain mesh ([`domain_pictures`]):
//! the cells' sides mapped through the spline, the strips' sides (critical horizontal
//! trajectories and the sides across the cylinders from the zeros and the gluing's added
//! points) drawn darker, and a ring around every zero (the extraordinary points). T-junctions
//! (graded lines, blocks) are ringed in red.

use ricci::spline::tspline::domain_fit::DomainFit;
use ricci_render::{render, Camera, Image, Paint, Polyline, RenderOptions, Style};
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
    let mut sides = Vec::with_capacity(mesh.n_cells());
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
        sides.push([
            (0..=k).map(|j| ids[j * (k + 1)]).collect(),
            ids[..=k].to_vec(),
        ]);
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
    Tessellation {
        positions,
        triangles,
        zeros: z.into_iter().map(|(_, i)| i).collect(),
        t_junctions: t.into_iter().map(|(_, i)| i).collect(),
        sides,
    }
}

/// The welded tessellation of [`tessellate`]: per domain-mesh zero and T-junction its point, per cell the
/// points of its left and bottom sides (`k + 1` each, bottom to top and left to right).
struct Tessellation {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    zeros: Vec<u32>,
    t_junctions: Vec<u32>,
    sides: Vec<[Vec<u32>; 2]>,
}

/// The pieces of the polyline through `points` (with unit `normals`, pointing out of the
/// closed surface) on the side facing the viewer: a segment is kept when the normal at both of
/// its ends has a positive component towards the viewer (`to_viewer`). Back-face culling: the
/// renderer's depth test alone lets lines of the far side show beside the silhouette, where
/// the tessellation's chords lie inside the curve the lines follow and the lines are moved
/// towards the viewer.
pub fn facing_pieces(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    to_viewer: impl Fn([f64; 3]) -> [f64; 3],
) -> Vec<Vec<[f64; 3]>> {
    let facing: Vec<bool> = points
        .iter()
        .zip(normals)
        .map(|(&p, n)| {
            let v = to_viewer(p);
            n[0] * v[0] + n[1] * v[1] + n[2] * v[2] > 0.0
        })
        .collect();
    let mut out: Vec<Vec<[f64; 3]>> = Vec::new();
    let mut run: Vec<[f64; 3]> = Vec::new();
    for i in 0..points.len() {
        if facing[i] {
            run.push(points[i]);
        } else if !run.is_empty() {
            out.push(std::mem::take(&mut run));
        }
    }
    out.push(run);
    out.retain(|r| r.len() >= 2);
    out
}

/// Outward unit normals of the closed tessellation: its angle-weighted vertex normals, flipped
/// when the enclosed signed volume is negative (the cells' orientation points inwards).
fn outward_normals(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let volume: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0])
        })
        .sum();
    let sign = if volume < 0.0 { -1.0 } else { 1.0 };
    ricci_render::render::vertex_normals(positions, triangles)
        .into_iter()
        .map(|n| n.map(|x| sign * x))
        .collect()
}

/// The images of the cells' left and bottom sides (each side once: every side is the left or
/// the bottom side of a cell) on every `stride`-th knot line of each strip and on the strips'
/// sides, along the tessellation's points (the lines lie on the rendered surface), only their
/// pieces facing the viewer ([`facing_pieces`]); the strips' sides in their own colour; sides
/// on no line of the T-mesh (a graded line past its T-junction) left out.
fn cell_sides(
    fit: &DomainFit,
    t: &Tessellation,
    stride: usize,
    to_viewer: impl Fn([f64; 3]) -> [f64; 3],
) -> Vec<Polyline> {
    let normals = outward_normals(&t.positions, &t.triangles);
    let mut out = Vec::new();
    for (c, sides) in t.sides.iter().enumerate() {
        let (r, i, j) = fit.mesh.cell_at[c];
        let (r, iu, ju) = (r as usize, i as usize, j as usize);
        let mesh = &fit.mesh;
        // a side on no line of the T-mesh (a graded line past its T-junction) is left out
        let on = [
            mesh.on_line_v(r, iu, ju) && mesh.on_line_v(r, iu, ju + 1),
            mesh.on_line_u(r, iu, ju) && mesh.on_line_u(r, iu + 1, ju),
        ];
        for (k, ids, on) in [(iu, &sides[0], on[0]), (ju, &sides[1], on[1])] {
            if !on {
                continue;
            }
            let (color, width) = match k {
                0 => (STRIP, 1.8),
                k if k % stride == 0 => (EDGE, 0.8),
                _ => continue,
            };
            let points: Vec<[f64; 3]> = ids.iter().map(|&v| t.positions[v as usize]).collect();
            let n: Vec<[f64; 3]> = ids.iter().map(|&v| normals[v as usize]).collect();
            for piece in facing_pieces(&points, &n, &to_viewer) {
                out.push(line(piece, color, width, false));
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
    let t = tessellate(fit, k);
    let camera = Camera::frame(
        &t.positions,
        &opts.view,
        [0.0, 0.0, opts.width as f64, opts.height as f64],
    )?;
    let mut polylines = cell_sides(fit, &t, stride, |p| camera.to_viewer(p));
    // the zeros' rings 3 wide, the T-junctions' 2.5 (normals computed once for all)
    let marks: Vec<_> = (t.zeros.iter().map(|&z| (z, 0.02, ZERO)))
        .chain(t.t_junctions.iter().map(|&v| (v, 0.012, T_JUNCTION)))
        .collect();
    let rings = crate::util::ring_markers(&t.positions, &t.triangles, &marks);
    for (k, mut ring) in rings.into_iter().enumerate() {
        ring.width = if k < t.zeros.len() { 3.0 } else { 2.5 };
        polylines.push(ring);
    }
    let (net, zebra) = render_net_and_zebra(&t.positions, &t.triangles, polylines, opts)?;
    let info = DomainPictures {
        stride,
        segments_per_cell_side: k,
        triangles: t.triangles.len(),
        zeros: t.zeros.len(),
        t_junctions: t.t_junctions.len(),
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
        "The domain mesh on the surface: {lines} mapped through the spline in dark grey, the strips' sides (critical horizontal trajectories of the 1-form and the sides across its cylinders from its zeros, and from the points the gluing added where a cylinder's two circles carry different zero copies) in blue, and the {} zeros of the form — the extraordinary points, where the spline is G¹ — ringed in orange; lines on the far side of the surface are not drawn. {}",
        info.zeros,
        if info.t_junctions > 0 {
            format!("The graded lines at the zeros and the lines of any blocks (cells split 2×2 where the error was beyond the tolerance, nested where it stayed) end in the {} T-junctions ringed in red (the T-mesh; its sides only are drawn).", info.t_junctions)
        } else {
            "The mesh is conforming: no T-junctions.".to_string()
        }
    )
}

/// The caption of the zebra picture of a domain-mesh spline.
pub const ZEBRA_CAPTION: &str = "Reflection lines (zebra) on the domain-mesh spline: C² on every cell side not at a zero, so the stripes run smoothly across the cells and the strips' sides; at the zeros (G¹: C¹ in the translation chart) they stay continuous but their width may jump.";

#[cfg(test)]
mod tests {
    use super::facing_pieces;

    /// A great circle of the unit sphere seen from +z (orthographic): the pieces drawn hold
    /// every point of the near half and none of the far half.
    #[test]
    fn facing_pieces_drop_the_far_side_of_a_sphere() {
        let n = 64;
        let points: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                let a = 2.0 * std::f64::consts::PI * (k as f64 + 0.25) / n as f64;
                [a.cos(), 0.0, a.sin()]
            })
            .collect();
        let pieces = facing_pieces(&points, &points, |_| [0.0, 0.0, 1.0]);
        let drawn: Vec<[f64; 3]> = pieces.concat();
        assert_eq!(drawn.iter().filter(|p| p[2] <= 0.0).count(), 0);
        let near = points.iter().filter(|p| p[2] > 0.0).count();
        assert_eq!(drawn.len(), near);
        assert_eq!(pieces.len(), 1, "one arc");
        // inward normals would draw the far half instead
        let inward: Vec<[f64; 3]> = points.iter().map(|p| p.map(|x| -x)).collect();
        let wrong = facing_pieces(&points, &inward, |_| [0.0, 0.0, 1.0]).concat();
        assert!(wrong.iter().all(|p| p[2] < 0.0));
    }

    /// The octahedron with its faces in either orientation: the normals point outwards.
    #[test]
    fn outward_normals_point_out_whatever_the_orientation() {
        let positions = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let out: Vec<[u32; 3]> = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        let flipped: Vec<[u32; 3]> = out.iter().map(|t| [t[0], t[2], t[1]]).collect();
        for tris in [out, flipped] {
            let n = super::outward_normals(&positions, &tris);
            for (p, n) in positions.iter().zip(&n) {
                let d = p[0] * n[0] + p[1] * n[1] + p[2] * n[2];
                assert!((d - 1.0).abs() < 1e-12, "{p:?} {n:?}");
            }
        }
    }
}
