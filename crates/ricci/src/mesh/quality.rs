//! Triangle quality statistics of an embedded mesh (angles in degrees).

use super::Surface;
use serde::Serialize;

/// Minimum and maximum corner angle over all faces, in degrees.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct AngleStats {
    pub min_angle_deg: f64,
    pub max_angle_deg: f64,
}

/// Corner angles of face `f` at its three vertices, in radians (Euclidean, from positions).
pub fn face_angles(s: &Surface, f: u32) -> [f64; 3] {
    let t = s.mesh.face(f);
    let p = t.map(|v| s.positions[v as usize]);
    let mut out = [0.0; 3];
    for i in 0..3 {
        let (a, b, c) = (p[i], p[(i + 1) % 3], p[(i + 2) % 3]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let dot = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
        let cr = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        let crn = (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt();
        out[i] = crn.atan2(dot);
    }
    out
}

/// Minimum and maximum corner angle in degrees.
pub fn angle_stats(s: &Surface) -> AngleStats {
    let mut lo = f64::INFINITY;
    let mut hi = 0.0f64;
    for f in 0..s.mesh.n_faces() as u32 {
        for a in face_angles(s, f) {
            lo = lo.min(a);
            hi = hi.max(a);
        }
    }
    AngleStats {
        min_angle_deg: lo.to_degrees(),
        max_angle_deg: hi.to_degrees(),
    }
}
