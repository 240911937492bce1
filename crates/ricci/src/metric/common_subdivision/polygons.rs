//! The overlay inside one face of `T`: its boundary points (corners and crossings), the
//! convex polygons cut out by the chords of the input edges, their input faces, and their fan
//! triangulation (see the parent module).

use super::input::InputComplex;
use super::normal::{arc_end, face_counts, ArcEnd, TriangleArcs};
use super::CommonSubdivision;
use crate::error::{Error, Result};
use crate::mesh::NONE;

/// A point on the boundary of a face of `T`: its subdivision vertex and its weights on the
/// face's corners (input decoration).
#[derive(Clone, Copy)]
struct BoundaryPoint {
    vertex: u32,
    weights: [f64; 3],
    /// Crossing id, or `NONE` for a corner.
    crossing: u32,
}

/// Cut face `f` of `T` along its arcs into convex polygons, fan-triangulate them.
pub(super) fn face_polygons<M: InputComplex>(
    mesh: &M,
    sub: &mut CommonSubdivision,
    arcs: &TriangleArcs,
    f: u32,
) -> Result<()> {
    let tri = &sub.triangulation;
    let normal = &sub.normal;
    let nv = sub.n_input_vertices as u32;
    let counts = face_counts(tri, normal, f);
    let x = counts.map(|v| v.max(0) as u32);
    let base = [0, 1 + x[0], 2 + x[0] + x[1]];
    let np = (3 + x[0] + x[1] + x[2]) as usize;
    let mut pts = Vec::with_capacity(np);
    for j in 0..3usize {
        let mut w = [0.0; 3];
        w[j] = 1.0;
        pts.push(BoundaryPoint {
            vertex: tri.origin[3 * f as usize + j],
            weights: w,
            crossing: NONE,
        });
        let h = 3 * f + j as u32;
        let e = tri.edge[h as usize];
        let canonical = tri.edge_he[e as usize] == h;
        for p in 0..x[j] {
            let pc = if canonical { p } else { x[j] - 1 - p };
            let id = sub.crossing_offset[e as usize] + pc;
            let c = &sub.crossings[id as usize];
            // ρ = log(β_origin(h) / β_tip(h)).
            let rho = if canonical {
                c.t_log_ratio
            } else {
                -c.t_log_ratio
            };
            let mut w = [0.0; 3];
            w[j] = 1.0 / (1.0 + (-rho).exp());
            w[(j + 1) % 3] = 1.0 / (1.0 + rho.exp());
            pts.push(BoundaryPoint {
                vertex: nv + id,
                weights: w,
                crossing: id,
            });
        }
    }
    // Neighbours of every boundary point: its two boundary neighbours and its chords.
    let mut nbr: Vec<Vec<usize>> = (0..np)
        .map(|i| vec![(i + 1) % np, (i + np - 1) % np])
        .collect();
    for j in 0..3usize {
        for p in 0..x[j] {
            let me = (base[j] + 1 + p) as usize;
            let other = match arc_end(arcs, x, j, p) {
                ArcEnd::Corner(m) => base[m] as usize,
                ArcEnd::Side(k, q) => (base[k] + 1 + q) as usize,
            };
            if !nbr[me].contains(&other) {
                nbr[me].push(other);
                nbr[other].push(me);
            }
        }
    }
    for (i, list) in nbr.iter_mut().enumerate() {
        list.sort_by_key(|&n| (n + np - i) % np);
        list.dedup();
    }
    let mut seen = vec![false; np]; // boundary segment i → i+1 used
    for s in 0..np {
        if seen[s] {
            continue;
        }
        let mut poly = vec![s];
        let (mut prev, mut cur) = (s, (s + 1) % np);
        seen[s] = true;
        let mut closed = false;
        for _ in 0..=np {
            if cur == s {
                closed = true;
                break;
            }
            poly.push(cur);
            let back = (prev + np - cur) % np;
            let next = *nbr[cur]
                .iter()
                .rev()
                .find(|&&n| (n + np - cur) % np < back)
                .ok_or_else(|| {
                    Error::numerical(format!(
                        "face {f} of T: a polygon of the overlay does not close"
                    ))
                })?;
            if next == (cur + 1) % np {
                seen[cur] = true;
            }
            prev = cur;
            cur = next;
        }
        if !closed || poly.len() < 3 {
            return Err(Error::numerical(format!(
                "face {f} of T: a polygon of the overlay does not close"
            )));
        }
        // The input face: left of every side that lies on an input edge.
        let mut f0 = NONE;
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            let face = side_input_face(mesh, sub, &pts, f, base, np, a, b)?;
            if let Some(face) = face {
                if f0 == NONE {
                    f0 = face;
                } else if f0 != face {
                    return Err(Error::numerical(format!(
                        "face {f} of T: a polygon of the overlay lies in input faces {f0} and {face}"
                    )));
                }
            }
        }
        if f0 == NONE {
            return Err(Error::numerical(format!(
                "face {f} of T: a polygon of the overlay has no side on an input edge"
            )));
        }
        let fv = mesh.face(f0);
        let mut bary = Vec::with_capacity(poly.len());
        for &i in &poly {
            bary.push(input_barycentric(mesh, sub, &fv, &pts[i]).ok_or_else(|| {
                Error::numerical(format!(
                    "face {f} of T: a vertex of the overlay is not on input face {f0}"
                ))
            })?);
        }
        sub.report.polygons += 1;
        for k in 1..poly.len() - 1 {
            let corners = [0, k, k + 1];
            sub.triangles.push(corners.map(|c| pts[poly[c]].vertex));
            sub.input_face.push(f0);
            sub.t_face.push(f);
            for c in corners {
                sub.input_barycentric.push(bary[c]);
                sub.t_weights.push(pts[poly[c]].weights);
            }
        }
    }
    Ok(())
}

/// The input face left of the polygon side from boundary point `a` to `b` of face `f` of `T`,
/// when that side lies on an input edge.
#[allow(clippy::too_many_arguments)]
fn side_input_face<M: InputComplex>(
    mesh: &M,
    sub: &CommonSubdivision,
    pts: &[BoundaryPoint],
    f: u32,
    base: [u32; 3],
    np: usize,
    a: usize,
    b: usize,
) -> Result<Option<u32>> {
    let tri = &sub.triangulation;
    let (pa, pb) = (&pts[a], &pts[b]);
    let left_of = |h0: u32| -> Result<Option<u32>> {
        let face = mesh.he_face(h0);
        if face == NONE {
            return Err(Error::numerical(format!(
                "face {f} of T: an overlay polygon lies outside the input surface"
            )));
        }
        Ok(Some(face))
    };
    if b == (a + 1) % np {
        // A boundary segment: on an input edge only if it is a whole side of T that is one.
        if pa.crossing != NONE || pb.crossing != NONE {
            return Ok(None);
        }
        let j = match base.iter().position(|&x| x as usize == a) {
            Some(j) => j,
            None => return Ok(None),
        };
        let h = 3 * f + j as u32;
        if sub.normal[tri.edge[h as usize] as usize] != -1 {
            return Ok(None);
        }
        let e = tri.edge[h as usize];
        let h_in = sub.shared_input[e as usize];
        let h0 = if h_in == NONE {
            NONE
        } else if tri.edge_he[e as usize] == h {
            h_in
        } else {
            mesh.he_twin(h_in)
        };
        if h0 == NONE {
            return Err(Error::numerical(format!(
                "face {f} of T: side {j} is marked as an input edge, but no input half-edge \
                 runs along it"
            )));
        }
        return left_of(h0);
    }
    // A chord: a piece of one input edge.
    let c = if pa.crossing != NONE {
        pa.crossing
    } else {
        pb.crossing
    };
    if c == NONE {
        return Err(Error::numerical(format!(
            "face {f} of T: an overlay chord joins two corners"
        )));
    }
    let e0 = sub.crossings[c as usize].input_edge;
    let [v0, _] = mesh.edge_vertices(e0);
    let rank = |p: &BoundaryPoint| -> Result<u64> {
        if p.crossing != NONE {
            let cr = &sub.crossings[p.crossing as usize];
            if cr.input_edge != e0 {
                return Err(Error::numerical(format!(
                    "face {f} of T: an overlay chord joins two different input edges"
                )));
            }
            Ok(cr.input_rank as u64)
        } else if p.vertex == v0 {
            Ok(0)
        } else {
            Ok(u64::MAX)
        }
    };
    let (ra, rb) = (rank(pa)?, rank(pb)?);
    let h0 = mesh.edge_halfedge(e0);
    if ra < rb {
        left_of(h0)
    } else {
        left_of(mesh.he_twin(h0))
    }
}

/// Barycentric coordinates of a boundary point on input face `fv`.
fn input_barycentric<M: InputComplex>(
    mesh: &M,
    sub: &CommonSubdivision,
    fv: &[u32; 3],
    p: &BoundaryPoint,
) -> Option<[f64; 3]> {
    let mut b = [0.0; 3];
    if p.crossing == NONE {
        let i = fv.iter().position(|&v| v == p.vertex)?;
        b[i] = 1.0;
        return Some(b);
    }
    let c = &sub.crossings[p.crossing as usize];
    let [v0, v1] = mesh.edge_vertices(c.input_edge);
    let i0 = fv.iter().position(|&v| v == v0)?;
    let i1 = fv.iter().position(|&v| v == v1)?;
    b[i0] = 1.0 - c.input_t;
    b[i1] = c.input_t;
    Some(b)
}
