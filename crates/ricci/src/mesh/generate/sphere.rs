//! Icosphere: the icosahedron, subdivided 1→4 `subdivisions` times, every new vertex pushed
//! radially onto the unit sphere.
//!
//! `F = 20·4^s`, `V = 10·4^s + 2`. All vertices lie on the unit sphere (up to rounding), faces
//! are oriented with outward normals. Minimum corner angle ≈ 49° at every level (the
//! distortion is worst next to the twelve valence-5 vertices).

use super::{too_many_faces, MAX_FACES};
use crate::error::{Error, Result};
use crate::mesh::Surface;
use std::collections::HashMap;

/// Largest accepted subdivision level (`20·4^10 ≈ 21M` faces).
pub const MAX_SUBDIVISIONS: u32 = 10;

/// Icosphere with `subdivisions` levels of 1→4 subdivision (0 = the icosahedron).
pub fn icosphere(subdivisions: u32) -> Result<Surface> {
    if subdivisions > MAX_SUBDIVISIONS {
        return Err(Error::input(format!(
            "icosphere: subdivisions = {subdivisions} is too many (at most {MAX_SUBDIVISIONS}, \
             which already gives {} faces)",
            20u64 << (2 * MAX_SUBDIVISIONS)
        )));
    }
    let faces_wanted = 20u64 << (2 * subdivisions);
    if faces_wanted > MAX_FACES {
        return Err(too_many_faces("icosphere", faces_wanted));
    }
    let (mut positions, mut faces) = icosahedron();
    for _ in 0..subdivisions {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.len() * 2);
        let mut next = Vec::with_capacity(faces.len() * 4);
        for t in &faces {
            let mut m = [0u32; 3];
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[i] = *midpoint.entry(key).or_insert_with(|| {
                    let (p, q) = (positions[a as usize], positions[b as usize]);
                    positions.push(normalize([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                    (positions.len() - 1) as u32
                });
            }
            // m[i] is the midpoint of edge (t[i], t[i+1]).
            next.push([t[0], m[0], m[2]]);
            next.push([m[0], t[1], m[1]]);
            next.push([m[2], m[1], t[2]]);
            next.push([m[0], m[1], m[2]]);
        }
        faces = next;
    }
    Surface::new(positions, faces)
}

fn normalize(p: [f64; 3]) -> [f64; 3] {
    let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    [p[0] / n, p[1] / n, p[2] / n]
}

/// The regular icosahedron inscribed in the unit sphere, faces oriented outward. The faces are
/// found as the triples of mutually adjacent vertices (edge length 2 before normalisation), so
/// there is no hand-typed face table to get wrong.
fn icosahedron() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut raw = Vec::with_capacity(12);
    for s1 in [-1.0, 1.0] {
        for s2 in [-1.0, 1.0] {
            raw.push([0.0, s1, s2 * phi]);
            raw.push([s1, s2 * phi, 0.0]);
            raw.push([s2 * phi, 0.0, s1]);
        }
    }
    let d2 = |a: [f64; 3], b: [f64; 3]| {
        (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
    };
    let adjacent = |i: usize, j: usize| (d2(raw[i], raw[j]) - 4.0).abs() < 1e-9;
    let mut faces = Vec::with_capacity(20);
    for i in 0..12 {
        for j in i + 1..12 {
            for k in j + 1..12 {
                if adjacent(i, j) && adjacent(j, k) && adjacent(i, k) {
                    let (a, b, c) = (raw[i], raw[j], raw[k]);
                    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                    let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                    let n = [
                        u[1] * w[2] - u[2] * w[1],
                        u[2] * w[0] - u[0] * w[2],
                        u[0] * w[1] - u[1] * w[0],
                    ];
                    let out = n[0] * a[0] + n[1] * a[1] + n[2] * a[2] > 0.0;
                    let (i, j, k) = (i as u32, j as u32, k as u32);
                    faces.push(if out { [i, j, k] } else { [i, k, j] });
                }
            }
        }
    }
    debug_assert_eq!(faces.len(), 20);
    (raw.into_iter().map(normalize).collect(), faces)
}
