//! Paper 000 §4 Step 1: the area distortion of a flat metric against the input metric,
//! measured over the faces of the input mesh.

use crate::mesh::Mesh;
use crate::numeric::heron;

/// Paper 000 §4 Step 1: `Σ_f (log S_f − log s_f)² / n` with `S_f` the area in the metric
/// `reference` and `s_f` the area in `flat`, over the faces of the *input* mesh: refined
/// faces are summed into the input face they lie in (`face_origin`, `n_input` input faces),
/// so the measure does not depend on how finely the cone's neighbourhood was refined.
pub fn area_distortion(
    mesh: &Mesh,
    reference: &[f64],
    flat: &[f64],
    face_origin: &[u32],
    n_input: usize,
) -> f64 {
    let mut a = vec![0.0; n_input];
    let mut b = vec![0.0; n_input];
    for f in 0..mesh.n_faces() as u32 {
        let e = mesh.face_edges_opposite(f);
        let o = face_origin.get(f as usize).copied().unwrap_or(f) as usize;
        if o >= n_input {
            continue;
        }
        a[o] += heron(e.map(|e| reference[e as usize]));
        b[o] += heron(e.map(|e| flat[e as usize]));
    }
    let mut sum = 0.0;
    let mut n = 0usize;
    for (x, y) in a.iter().zip(&b) {
        if *x > 0.0 && *y > 0.0 {
            sum += (x.ln() - y.ln()).powi(2);
            n += 1;
        }
    }
    sum / n.max(1) as f64
}
