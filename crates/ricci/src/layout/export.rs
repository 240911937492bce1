//! Writing layouts: Wavefront OBJ with texture coordinates (`vt`) of the cut mesh.
//!
//! The surface keeps its own vertices (`v`, watertight in 3D); each face corner refers to the
//! texture coordinate of its cut-mesh vertex (`f v/vt`), so the seams of the cut appear only
//! in the texture coordinates. Coordinates are written as computed (plane coordinates, or
//! Poincaré-disk coordinates for H²), with 17 significant digits.

use rayon::prelude::*;
use std::fmt::Write;

/// OBJ text: `positions`/`faces` of the surface, `uv`/`uv_faces` of the cut mesh (one face per
/// surface face, same order), preceded by `#` comment lines from `comments`.
pub fn obj_with_uv(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    uv: &[[f64; 2]],
    uv_faces: &[[u32; 3]],
    comments: &[String],
) -> String {
    let mut s = String::with_capacity(64 * (positions.len() + uv.len() + faces.len()));
    for c in comments {
        let _ = writeln!(s, "# {c}");
    }
    use crate::numeric::float_text::push_exp;
    lines(&mut s, positions, |s, p| {
        s.push('v');
        for &x in p {
            s.push(' ');
            push_exp(s, x);
        }
        s.push('\n');
    });
    lines(&mut s, uv, |s, t| {
        s.push_str("vt");
        for &x in t {
            s.push(' ');
            push_exp(s, x);
        }
        s.push('\n');
    });
    let corners: Vec<([u32; 3], [u32; 3])> = faces
        .iter()
        .copied()
        .zip(uv_faces.iter().copied())
        .collect();
    lines(&mut s, &corners, |s, (f, t)| {
        let mut int = itoa::Buffer::new();
        s.push('f');
        for i in 0..3 {
            s.push(' ');
            s.push_str(int.format(f[i] as u64 + 1));
            s.push('/');
            s.push_str(int.format(t[i] as u64 + 1));
        }
        s.push('\n');
    });
    s
}

/// Appends the lines `line` writes for each item to `s`, in item order; blocks of items are
/// formatted in parallel (rayon) — the same text as one sequential pass.
fn lines<T: Sync>(s: &mut String, items: &[T], line: impl Fn(&mut String, &T) + Sync) {
    const BLOCK: usize = 8192;
    let blocks: Vec<String> = items
        .par_chunks(BLOCK)
        .map(|block| {
            let mut b = String::with_capacity(48 * block.len());
            for x in block {
                line(&mut b, x);
            }
            b
        })
        .collect();
    for b in blocks {
        s.push_str(&b);
    }
}

/// OBJ text of a surface with one texture coordinate per face corner (`corner_uv[3f + i]`
/// for corner `i` of face `f`): corners of one vertex with the same coordinate share a `vt`
/// line, so the seams are where a vertex has several.
pub fn obj_with_corner_uv(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    corner_uv: &[[f64; 2]],
    comments: &[String],
) -> String {
    // Per vertex, the list of its distinct coordinates so far (`head[v]`, then `next[i]`
    // from entry i of `uv`; `u32::MAX` ends a list), compared bit for bit.
    let nv = faces
        .iter()
        .flatten()
        .map(|&v| v as usize + 1)
        .max()
        .unwrap_or(0);
    let mut head = vec![u32::MAX; nv.max(positions.len())];
    let mut next: Vec<u32> = Vec::with_capacity(positions.len());
    let mut uv: Vec<[f64; 2]> = Vec::with_capacity(positions.len());
    let mut uv_faces = Vec::with_capacity(faces.len());
    let same = |a: [f64; 2], b: [f64; 2]| a.map(f64::to_bits) == b.map(f64::to_bits);
    for (f, t) in faces.iter().enumerate() {
        let mut out = [0u32; 3];
        for i in 0..3 {
            let c = corner_uv[3 * f + i];
            let v = t[i] as usize;
            let mut at = head[v];
            while at != u32::MAX && !same(uv[at as usize], c) {
                at = next[at as usize];
            }
            if at == u32::MAX {
                at = uv.len() as u32;
                uv.push(c);
                next.push(head[v]);
                head[v] = at;
            }
            out[i] = at;
        }
        uv_faces.push(out);
    }
    obj_with_uv(positions, faces, &uv, &uv_faces, comments)
}
