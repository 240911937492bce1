//! The domain of a surface of genus 0, closed or with boundary loops (paper 003 §2, "genus
//! zero closed surfaces" and "surfaces with boundaries"), as a flat torus: the double of an
//! annulus.
//!
//! Paper 003 maps a genus-0 surface to the sphere and takes the preimages of the poles as the
//! zeros of the conformal net; for the Stanford bunny it cuts the surface open at the two ear
//! tips and at the bottom and fits over the double cover (genus 2). We do the same with two
//! cuts instead of three:
//!
//! 1. every boundary loop is **filled** by a fan around a new vertex at the loop's centroid
//!    (the filled vertices carry no data: they are not among the fitted points);
//! 2. the two **poles** are the two extremities farthest from everything else — of the
//!    farthest-point samples of the graph distance ([`SAMPLES`] of them, the first the farthest
//!    vertex from vertex 0), the two with the largest mean distance to all samples (on the
//!    bunny: the ear tips, as in paper 003 Fig. 6). Long protrusions are where a conformal map
//!    shrinks the surface most (exponentially in their length over their girth); at a pole the
//!    map `log z` of the sphere map expands it instead;
//! 3. one **face** at each pole (of the input mesh) is removed: the surface becomes an annulus
//!    (genus 0, two boundary loops of three edges; no vertex is lost), whose **double** is a
//!    closed surface of genus `2·0 + 2 − 1 = 1`;
//! 4. the double's flat metric and fundamental domain ([`super::fit::flat_torus_domain`]) give
//!    the lattice and one parameter per vertex. The annulus is conformally a flat cylinder
//!    (the sphere map with the two poles, through `log z`, up to the two small cut disks);
//!    the double is the cylinder and its mirror image, so the torus is rectangular and the
//!    two boundary loops are closed geodesics of it.
//!
//! The T-spline lives on the whole torus; the data (the input vertices) lie on the half that is
//! the surface, the other half (the mirror copy) holds no data and is shaped only by the
//! thin-plate fairness. The spline restricted to the surface's half is the fitted surface; its
//! control points are counted in full (those of the empty half included).

use super::fit::flat_torus_domain;
use super::half::Half;
use super::tmesh::Lattice;
use crate::error::{Error, Result};
use crate::mesh::{double::double_cover, Mesh, Surface};
use crate::progress::Progress;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Farthest-point samples of the graph distance used to choose the poles.
pub const SAMPLES: usize = 12;

/// The flat-torus domain of a genus-0 surface (module docs).
#[derive(Debug, Clone)]
pub struct Genus0Domain {
    /// One parameter per input vertex, in `[0, W) × [0, H)`.
    pub uv: Vec<[f64; 2]>,
    pub lattice: Lattice,
    /// The two input vertices chosen as poles.
    pub poles: [u32; 2],
    /// The input faces removed at the poles.
    pub cut_faces: [u32; 2],
    /// Boundary loops of the input that were filled.
    pub filled_loops: usize,
    /// Vertices of the double (the closed genus-1 surface the flat metric is computed on).
    pub double_vertices: usize,
    /// The surface's half of the torus (the strip between the seams holding the input
    /// vertices); `None` when the lattice is not rectangular across the seams (then the whole
    /// torus counts).
    pub half: Option<Half>,
}

/// `x − c` reduced to `[−P/2, P/2)`.
fn wrap(x: f64, c: f64, period: f64) -> f64 {
    let d = (x - c) / period;
    (d - d.round()) * period
}

/// The strip between the two seams through the cut faces that holds most input vertices: the
/// seams are lines `u = const` or `v = const` (the axis along which a cut face's vertices
/// spread least), at the cut faces' mean coordinates.
fn surface_half(mesh: &Mesh, uv: &[[f64; 2]], lattice: &Lattice, cut: [u32; 2]) -> Option<Half> {
    let periods = [lattice.width, lattice.height];
    let spread = |axis: usize| {
        let vs = mesh.face(cut[0]);
        let c = uv[vs[0] as usize][axis];
        vs.iter()
            .map(|&v| wrap(uv[v as usize][axis], c, periods[axis]).abs() / periods[axis])
            .fold(0.0, f64::max)
    };
    let axis = if spread(0) <= spread(1) { 0 } else { 1 };
    if axis == 0 && lattice.shift != 0.0 {
        return None;
    }
    let p = periods[axis];
    let seam = |f: u32| {
        let vs = mesh.face(f);
        let c = uv[vs[0] as usize][axis];
        c + vs
            .iter()
            .map(|&v| wrap(uv[v as usize][axis], c, p))
            .sum::<f64>()
            / 3.0
    };
    let (c0, c1) = (seam(cut[0]), seam(cut[1]));
    let positive = uv.iter().filter(|q| wrap(q[axis], c0, p) > 0.0).count();
    let (from, to) = if 2 * positive >= uv.len() {
        (c0, c1)
    } else {
        (c1, c0)
    };
    Some(Half {
        axis,
        from: from.rem_euclid(p),
        width: (to - from).rem_euclid(p),
        period: p,
    })
}

/// Graph distances (Euclidean edge lengths) from `sources` on `surface` (Dijkstra).
pub fn graph_distances(surface: &Surface, sources: &[u32]) -> Vec<f64> {
    let mesh = &surface.mesh;
    let n = mesh.n_vertices();
    let mut d = vec![f64::INFINITY; n];
    let mut heap = BinaryHeap::new();
    for &s in sources {
        d[s as usize] = 0.0;
        heap.push(Reverse((0u64, s)));
    }
    while let Some(Reverse((key, v))) = heap.pop() {
        let dv = f64::from_bits(key);
        if dv > d[v as usize] {
            continue;
        }
        if mesh.is_isolated(v) {
            continue;
        }
        let pv = surface.positions[v as usize];
        for w in mesh.vertex_neighbors(v) {
            let pw = surface.positions[w as usize];
            let l = ((pv[0] - pw[0]).powi(2) + (pv[1] - pw[1]).powi(2) + (pv[2] - pw[2]).powi(2))
                .sqrt();
            let dw = dv + l;
            if dw < d[w as usize] {
                d[w as usize] = dw;
                // non-negative finite f64s order as their bit patterns
                heap.push(Reverse((dw.to_bits(), w)));
            }
        }
    }
    d
}

/// The two poles among the first `candidates` vertices (module docs, step 2).
pub fn choose_poles(surface: &Surface, candidates: usize) -> Result<[u32; 2]> {
    let n = surface.mesh.n_vertices();
    let start = (0..n as u32).find(|&v| !surface.mesh.is_isolated(v));
    let Some(start) = start else {
        return Err(Error::input("the mesh has no faces"));
    };
    let argmax = |d: &[f64]| -> u32 {
        let mut best = start;
        for v in 0..candidates.min(n) {
            if d[v].is_finite() && d[v] > d[best as usize] {
                best = v as u32;
            }
        }
        best
    };
    let first = argmax(&graph_distances(surface, &[start]));
    let mut samples = vec![first];
    let mut dists = vec![graph_distances(surface, &[first])];
    let mut nearest = dists[0].clone();
    while samples.len() < SAMPLES {
        let s = argmax(&nearest);
        if nearest[s as usize] <= 0.0 || samples.contains(&s) {
            break;
        }
        let ds = graph_distances(surface, &[s]);
        for (a, b) in nearest.iter_mut().zip(&ds) {
            *a = a.min(*b);
        }
        samples.push(s);
        dists.push(ds);
    }
    if samples.len() < 2 {
        return Err(Error::input(
            "the mesh has fewer than two distinct vertices to put the poles of its genus-0 domain at",
        ));
    }
    let mean = |v: u32| dists.iter().map(|d| d[v as usize]).sum::<f64>() / dists.len() as f64;
    let mut order: Vec<(u32, f64)> = samples.iter().map(|&s| (s, mean(s))).collect();
    order.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    Ok([order[0].0, order[1].0])
}

/// `surface` with every boundary loop filled by a fan around its centroid (new vertices at
/// the end), and the number of loops filled.
pub fn fill_boundary_loops(surface: &Surface) -> Result<(Surface, usize)> {
    let loops = surface.mesh.boundary_loops();
    let mut positions = surface.positions.clone();
    let mut faces = surface.mesh.faces().to_vec();
    for lp in &loops {
        let c = positions.len() as u32;
        let mut centroid = [0.0; 3];
        for &v in lp {
            for k in 0..3 {
                centroid[k] += positions[v as usize][k] / lp.len() as f64;
            }
        }
        positions.push(centroid);
        // the loop runs with the surface on its left: the fill traverses its edges backwards
        for i in 0..lp.len() {
            let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
            faces.push([c, b, a]);
        }
    }
    Ok((Surface::new(positions, faces)?, loops.len()))
}

/// The flat-torus domain of a connected genus-0 surface (module docs).
pub fn genus0_domain(surface: &Surface, progress: &mut dyn Progress) -> Result<Genus0Domain> {
    let t = crate::mesh::topology(&surface.mesh);
    let c = t.components.first();
    if t.components.len() != 1 || c.map(|c| c.genus) != Some(0) {
        return Err(Error::topology(format!(
            "the genus-0 domain needs one connected surface of genus 0; this mesh has {} component(s) and genus {}",
            t.components.len(),
            c.map_or(0, |c| c.genus)
        )));
    }
    let n = surface.mesh.n_vertices();
    let (filled, filled_loops) = fill_boundary_loops(surface)?;
    let poles = choose_poles(&filled, n)?;
    let nf = surface.mesh.n_faces();
    let cut = |p: u32| -> Result<u32> {
        filled
            .mesh
            .vertex_faces(p)
            .filter(|&f| (f as usize) < nf)
            .min()
            .ok_or_else(|| Error::input(format!("pole vertex {p} has no face")))
    };
    let cut_faces = [cut(poles[0])?, cut(poles[1])?];
    let shared = surface.mesh.face(cut_faces[0]).iter().any(|v| {
        surface
            .mesh
            .face(cut_faces[1])
            .iter()
            .any(|w| w == v || surface.mesh.halfedge_between(*v, *w).is_some())
    });
    if cut_faces[0] == cut_faces[1] || shared {
        return Err(Error::input(format!(
            "the poles {} and {} of the genus-0 domain are too close (faces {} and {} touch)",
            poles[0], poles[1], cut_faces[0], cut_faces[1]
        )));
    }
    let faces: Vec<[u32; 3]> = filled
        .mesh
        .faces()
        .iter()
        .enumerate()
        .filter(|(f, _)| *f as u32 != cut_faces[0] && *f as u32 != cut_faces[1])
        .map(|(_, &f)| f)
        .collect();
    let annulus = Mesh::from_triangles(filled.positions.len(), faces)?;
    let (double, sigma) = double_cover(&annulus)?;
    let positions: Vec<[f64; 3]> = (0..double.n_vertices())
        .map(|v| {
            filled.positions[crate::mesh::double::double_vertex_origin(&sigma, v as u32) as usize]
        })
        .collect();
    let double_vertices = positions.len();
    let ds = Surface {
        mesh: double,
        positions,
        uvs: None,
    };
    let (uv_d, lattice) = flat_torus_domain(&ds, progress)?;
    let half = surface_half(&surface.mesh, &uv_d[..n], &lattice, cut_faces);
    Ok(Genus0Domain {
        half,
        uv: uv_d[..n].to_vec(),
        lattice,
        poles,
        cut_faces,
        filled_loops,
        double_vertices,
    })
}
