//! Writing layouts: Wavefront OBJ with texture coordinates (`vt`) of the cut mesh.
//!
//! The surface keeps its own vertices (`v`, watertight in 3D); each face corner refers to the
//! texture coordinate of its cut-mesh vertex (`f v/vt`), so the seams of the cut appear only
//! in the texture coordinates. Coordinates are written as computed (plane coordinates, or
//! Poincaré-disk coordinates for H²), with 17 significant digits.

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
    for p in positions {
        s.push('v');
        for &x in p {
            s.push(' ');
            push_exp(&mut s, x);
        }
        s.push('\n');
    }
    for t in uv {
        s.push_str("vt");
        for &x in t {
            s.push(' ');
            push_exp(&mut s, x);
        }
        s.push('\n');
    }
    let mut int = itoa::Buffer::new();
    for (f, t) in faces.iter().zip(uv_faces) {
        s.push('f');
        for i in 0..3 {
            s.push(' ');
            s.push_str(int.format(f[i] as u64 + 1));
            s.push('/');
            s.push_str(int.format(t[i] as u64 + 1));
        }
        s.push('\n');
    }
    s
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
    let mut index: std::collections::HashMap<(u32, u64, u64), u32> =
        std::collections::HashMap::with_capacity(positions.len() + positions.len() / 8);
    let mut uv = Vec::with_capacity(positions.len());
    let mut uv_faces = Vec::with_capacity(faces.len());
    for (f, t) in faces.iter().enumerate() {
        let mut out = [0u32; 3];
        for i in 0..3 {
            let c = corner_uv[3 * f + i];
            let key = (t[i], c[0].to_bits(), c[1].to_bits());
            out[i] = *index.entry(key).or_insert_with(|| {
                uv.push(c);
                (uv.len() - 1) as u32
            });
        }
        uv_faces.push(out);
    }
    obj_with_uv(positions, faces, &uv, &uv_faces, comments)
}
