//! Harmonic interior ([`super::Interior::Harmonic`]): the UVs of the seam and boundary
//! vertices are those of the flat layout (exact), every other vertex is moved to the
//! cotangent-harmonic extension of them — the map of least Dirichlet energy, hence of least
//! conformal energy `E_D − A` (the UV area is fixed by the boundary polygon), with that
//! boundary (Boundary First Flattening's last step, Sawhney–Crane 2017 §5: "the interior is
//! given by harmonic extension"). The cone angles, the seams' transitions and edge lengths
//! are kept exactly (they depend on the boundary only, as long as no face folds); the angle
//! distortion of the input's own faces drops where the flat metric's triangulation differs
//! from the input's (flipped edges bend the exact map inside an input face).

use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::numeric::sparse::{LowerCsc, SymmetricSolver};
use std::collections::BTreeMap;

/// Corner UVs with the vertices off `cut` and off the boundary of `mesh` moved to the
/// harmonic extension (cotangent weights of the Euclidean `lengths`) of the others' corner
/// UVs `uv` (`uv[3f + i]`; a vertex off the cut has one UV).
pub(super) fn harmonic_interior(
    mesh: &Mesh,
    lengths: &[f64],
    cut: &[bool],
    uv: &[[f64; 2]],
) -> Result<Vec<[f64; 2]>> {
    let n = mesh.n_vertices();
    let mut fixed: Vec<bool> = (0..n as u32)
        .map(|v| mesh.is_boundary_vertex(v) || mesh.is_isolated(v))
        .collect();
    for e in 0..mesh.n_edges() as u32 {
        if cut[e as usize] {
            for v in mesh.edge_vertices(e) {
                fixed[v as usize] = true;
            }
        }
    }
    let mut index = vec![NONE; n];
    let mut free = Vec::new();
    for v in 0..n {
        if !fixed[v] {
            index[v] = free.len() as u32;
            free.push(v as u32);
        }
    }
    let m = free.len();
    if m == 0 {
        return Ok(uv.to_vec());
    }
    // Lower triangle by column (column j holds rows i ≥ j), right-hand sides.
    let mut cols: Vec<BTreeMap<u32, f64>> = vec![BTreeMap::new(); m];
    let mut rhs = vec![[0.0f64; 2]; m];
    for f in 0..mesh.n_faces() as u32 {
        let t = mesh.face(f);
        let hs = mesh.face_halfedges(f);
        // Half-edge 3f + i joins t[i], t[i+1]; the opposite corner is t[i+2].
        let l: Vec<f64> = hs
            .iter()
            .map(|&h| lengths[mesh.he_edge(h) as usize])
            .collect();
        let area = crate::numeric::vec3::heron([l[0], l[1], l[2]]);
        if area.is_nan() || area <= 0.0 {
            return Err(Error::numerical(format!(
                "face {f} has zero area; no harmonic interior"
            )));
        }
        for i in 0..3 {
            let (x, y, z) = (l[i], l[(i + 1) % 3], l[(i + 2) % 3]);
            let w = (y * y + z * z - x * x) / (8.0 * area);
            let (a, b) = (t[i] as usize, t[(i + 1) % 3] as usize);
            let (ca, cb) = (3 * f as usize + i, 3 * f as usize + (i + 1) % 3);
            for (p, q, cq) in [(a, b, cb), (b, a, ca)] {
                if fixed[p] {
                    continue;
                }
                let ip = index[p];
                *cols[ip as usize].entry(ip).or_insert(0.0) += w;
                if fixed[q] {
                    rhs[ip as usize][0] += w * uv[cq][0];
                    rhs[ip as usize][1] += w * uv[cq][1];
                } else if index[q] > ip {
                    *cols[ip as usize].entry(index[q]).or_insert(0.0) -= w;
                }
            }
        }
    }
    let mut col_ptr = vec![0u32];
    let (mut row_idx, mut values) = (Vec::new(), Vec::new());
    for c in &cols {
        for (&r, &v) in c {
            row_idx.push(r);
            values.push(v);
        }
        col_ptr.push(row_idx.len() as u32);
    }
    let mut solver = SymmetricSolver::new(LowerCsc {
        n: m,
        col_ptr: &col_ptr,
        row_idx: &row_idx,
    })?;
    if !solver.factor_llt(&values) {
        return Err(Error::numerical(
            "the cotangent Laplacian of the interior could not be factorized",
        ));
    }
    let mut xs: Vec<f64> = rhs.iter().map(|r| r[0]).collect();
    let mut ys: Vec<f64> = rhs.iter().map(|r| r[1]).collect();
    solver.solve(&mut xs);
    solver.solve(&mut ys);
    if xs.iter().chain(&ys).any(|x| !x.is_finite()) {
        return Err(Error::numerical("the harmonic interior is not finite"));
    }
    let mut out = uv.to_vec();
    for f in 0..mesh.n_faces() as u32 {
        for (i, &v) in mesh.face(f).iter().enumerate() {
            let k = index[v as usize];
            if k != NONE {
                out[3 * f as usize + i] = [xs[k as usize], ys[k as usize]];
            }
        }
    }
    Ok(out)
}

/// Local repair of folded input faces ([`super::Interior::Repair`]): the vertices off the
/// cut of the folded faces, grown by 2, 4, 8 or 16 rings (off the cut), are moved to the
/// mean-value average of their neighbours (Floater 2003: positive weights `(tan(α/2) +
/// tan(β/2)) / |p_i − p_j|` of the 3D triangles; with a convex enough surrounding polygon the
/// result folds nothing, Tutte's theorem), every other corner keeps the exact layout. Returns
/// the corner UVs and the number of vertices moved, or `None` when no ring count unfolds
/// every face (or a folded face has only cut vertices).
pub(super) fn repair_folds(
    mesh: &Mesh,
    lengths: &[f64],
    cut: &[bool],
    uv: &[[f64; 2]],
) -> Option<(Vec<[f64; 2]>, usize)> {
    let n = mesh.n_vertices();
    let nf = mesh.n_faces();
    let mut fixed: Vec<bool> = (0..n as u32)
        .map(|v| mesh.is_boundary_vertex(v) || mesh.is_isolated(v))
        .collect();
    for e in 0..mesh.n_edges() as u32 {
        if cut[e as usize] {
            for v in mesh.edge_vertices(e) {
                fixed[v as usize] = true;
            }
        }
    }
    let folded = |uv: &[[f64; 2]], f: usize| {
        let q = &uv[3 * f..3 * f + 3];
        let a =
            (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
        a.is_nan() || a <= 0.0
    };
    let mut seeds = Vec::new();
    for f in (0..nf).filter(|&f| folded(uv, f)) {
        let t = mesh.face(f as u32);
        if t.iter().all(|&v| fixed[v as usize]) {
            return None;
        }
        seeds.extend(t.iter().copied().filter(|&v| !fixed[v as usize]));
    }
    if seeds.is_empty() {
        return Some((uv.to_vec(), 0));
    }
    let mut faces_of: Vec<Vec<u32>> = vec![Vec::new(); n];
    for f in 0..nf as u32 {
        for v in mesh.face(f) {
            faces_of[v as usize].push(f);
        }
    }
    // Mean-value weight terms per corner: tan(θ/2) at corner i of face f.
    let corner = |f: u32, i: usize| -> (f64, f64, f64) {
        let hs = mesh.face_halfedges(f);
        // Half-edge 3f + i joins t[i], t[i+1]: lengths at t[i] are l[i] (to t[i+1]) and
        // l[i+2] (to t[i+2]); the opposite side is l[i+1].
        let l: Vec<f64> = hs
            .iter()
            .map(|&h| lengths[mesh.he_edge(h) as usize])
            .collect();
        let (a, b, c) = (l[i], l[(i + 2) % 3], l[(i + 1) % 3]);
        let cos = ((a * a + b * b - c * c) / (2.0 * a * b)).clamp(-1.0, 1.0);
        ((cos.acos() / 2.0).tan(), a, b)
    };
    let scale = uv
        .iter()
        .fold(0.0f64, |m, q| m.max(q[0].abs()).max(q[1].abs()))
        .max(1e-300);
    for rings in [2usize, 4, 8, 16] {
        let mut index = vec![NONE; n];
        let mut region: Vec<u32> = Vec::new();
        let mut frontier = seeds.clone();
        for &v in &seeds {
            if index[v as usize] == NONE {
                index[v as usize] = region.len() as u32;
                region.push(v);
            }
        }
        for _ in 0..rings {
            let mut next = Vec::new();
            for &v in &frontier {
                for &f in &faces_of[v as usize] {
                    for w in mesh.face(f) {
                        if !fixed[w as usize] && index[w as usize] == NONE {
                            index[w as usize] = region.len() as u32;
                            region.push(w);
                            next.push(w);
                        }
                    }
                }
            }
            frontier = next;
        }
        // Per region vertex: (neighbour region index or NONE, weight, fixed UV).
        let mut x: Vec<[f64; 2]> = vec![[0.0; 2]; region.len()];
        let mut terms: Vec<Vec<(u32, f64, [f64; 2])>> = vec![Vec::new(); region.len()];
        for (k, &v) in region.iter().enumerate() {
            for &f in &faces_of[v as usize] {
                let t = mesh.face(f);
                let i = t.iter().position(|&w| w == v).unwrap_or(0);
                x[k] = uv[3 * f as usize + i];
                let (tan, a, b) = corner(f, i);
                for (j, len) in [((i + 1) % 3, a), ((i + 2) % 3, b)] {
                    let w = t[j];
                    terms[k].push((index[w as usize], tan / len, uv[3 * f as usize + j]));
                }
            }
        }
        for _sweep in 0..20_000 {
            let mut change = 0.0f64;
            for (k, tk) in terms.iter().enumerate() {
                let (mut s, mut ws) = ([0.0; 2], 0.0);
                for &(j, w, q) in tk {
                    let p = if j == NONE { q } else { x[j as usize] };
                    s[0] += w * p[0];
                    s[1] += w * p[1];
                    ws += w;
                }
                let p = [s[0] / ws, s[1] / ws];
                change = change.max((p[0] - x[k][0]).abs().max((p[1] - x[k][1]).abs()));
                x[k] = p;
            }
            if change <= 1e-14 * scale {
                break;
            }
        }
        let mut out = uv.to_vec();
        for f in 0..nf as u32 {
            for (i, &v) in mesh.face(f).iter().enumerate() {
                let k = index[v as usize];
                if k != NONE {
                    out[3 * f as usize + i] = x[k as usize];
                }
            }
        }
        if x.iter().all(|p| p[0].is_finite() && p[1].is_finite())
            && !(0..nf).any(|f| folded(&out, f))
        {
            return Some((out, region.len()));
        }
    }
    None
}
