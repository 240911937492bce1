//! `ricci spectrum` on a surface with boundary: the length spectrum of its double (issue 17,
//! paper 003 §2). A connected surface of genus `g` with `b ≥ 1` boundary loops is glued to its
//! mirror copy along the boundary (`ricci::analysis::forms::double::folded_double`: interior
//! edges between two boundary vertices split first, mirror vertices at their originals'
//! positions); the double is closed, of genus `G = 2g + b − 1`, and its uniformization metric
//! (flat for `G = 1`, hyperbolic otherwise) is the double of the surface's metric with
//! geodesic boundary. Its closed geodesics are what the spectrum lists; the σ-invariant ones
//! are the boundary loops (geodesic boundary lengths) and the doubled orthogeodesics (twice
//! the length of a geodesic arc meeting the boundary at right angles at both ends).

use super::Args;
use ricci::analysis::forms::double::folded_double;
use ricci::mesh::{topology, Surface};
use serde_json::{json, Value};

/// The double of `surface` (module docs) and the JSON object describing it. Errors (one
/// sentence) for a disk, whose double is a sphere.
pub fn double_surface(
    surface: &Surface,
    genus: usize,
    boundary_loops: usize,
) -> anyhow::Result<(Surface, Value)> {
    if 2 * genus + boundary_loops < 2 {
        anyhow::bail!(
            "a disk's double is a sphere, which has no closed geodesics; the spectrum needs a \
             surface of genus ≥ 1 or with at least two boundary loops"
        );
    }
    let (double, _, chord_splits) = folded_double(surface)?;
    let info = json!({
        "surface_genus": genus,
        "boundary_loops": boundary_loops,
        "genus": 2 * genus + boundary_loops - 1,
        "chord_splits": chord_splits,
        "vertices": double.mesh.n_vertices(),
        "faces": double.mesh.n_faces(),
        "lengths_are": "closed geodesics of the double; the mirror-symmetric ones are the \
                        boundary loops (geodesic boundary) and doubled orthogeodesics",
    });
    Ok((double, info))
}

/// The closed surface whose spectrum is computed: `surface` itself (no boundary), or its double
/// with the JSON describing it; and that closed surface's genus. Refused (one sentence naming
/// the file): more than one component, a sphere, a disk, or a metric file (of the surface)
/// with a surface with boundary.
pub fn spectrum_surface(
    a: &Args,
    surface: Surface,
) -> anyhow::Result<(Surface, Option<Value>, usize)> {
    let t = topology(&surface.mesh);
    let comp = t
        .components
        .first()
        .ok_or_else(|| anyhow::anyhow!("the mesh has no faces"))?;
    let (genus, boundary_loops) = (comp.genus.max(0) as usize, comp.boundary_loops);
    let closed_genus = if boundary_loops > 0 {
        2 * genus + boundary_loops - 1
    } else {
        genus
    };
    if t.components.len() != 1 || closed_genus < 1 {
        anyhow::bail!(
            "{}: the length spectrum needs one closed surface of genus ≥ 1, or one surface with boundary that is not a disk (the spectrum of its double); this mesh has {} component(s), genus {} and {} boundary loop(s); try: ricci layout {} (its layout and, for a surface with boundary, its geometry)",
            a.mesh.display(),
            t.components.len(),
            comp.genus,
            comp.boundary_loops,
            a.mesh.display()
        );
    }
    if boundary_loops == 0 {
        return Ok((surface, None, genus));
    }
    if a.metric.is_some() {
        anyhow::bail!(
            "{}: --metric gives a metric of the surface, but the spectrum of a surface with \
             boundary is its double's, from the double's own uniformization; drop --metric",
            a.mesh.display()
        );
    }
    let (d, info) = double_surface(&surface, genus, boundary_loops)
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.mesh.display()))?;
    Ok((d, Some(info), closed_genus))
}
