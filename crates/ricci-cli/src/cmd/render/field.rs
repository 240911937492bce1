//! The scalar field of `ricci render --scalar`: a built-in field computed from the mesh
//! (ricci-render's [`fields`]), or values read from a text file or a METRIC.json
//! (`ricci::mesh::io::scalars`).

use super::{usage, FoundUvs, BUILTIN};
use anyhow::bail;
use ricci::mesh::io::scalars::{read_scalar_file, ScalarFile};
use ricci::mesh::Surface;
use ricci_render::{fields, ScalarLocation};
use serde_json::json;
use std::path::Path;

/// Values per vertex or per face, their name and whether they take both signs.
pub(super) struct Field {
    pub(super) values: Vec<f64>,
    pub(super) location: ScalarLocation,
    pub(super) name: String,
    pub(super) signed: bool,
}

impl Field {
    /// The field's keys in the JSON report.
    pub(super) fn report(&self) -> serde_json::Value {
        let finite: Vec<f64> = self
            .values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .collect();
        json!({
            "name": self.name,
            "location": if self.location == ScalarLocation::Vertex { "vertex" } else { "face" },
            "min": finite.iter().copied().fold(f64::INFINITY, f64::min),
            "max": finite.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            "missing": self.values.len() - finite.len(),
        })
    }
}

/// The field named by `--scalar SPEC` on the surface `s`.
pub(super) fn scalar_field(
    spec: &str,
    s: &Surface,
    uvs: Option<&FoundUvs>,
) -> anyhow::Result<Field> {
    let p = &s.positions;
    let t = s.mesh.faces();
    let need_uv = |name: &str| -> anyhow::Result<&[[f64; 2]]> {
        match uvs {
            Some(u) => u.per_vertex().ok_or_else(|| anyhow::anyhow!("{name} needs one UV per vertex, but the UVs have seams (per-corner); give the cut mesh itself with its layout")),
            None => Err(usage(format!("--scalar {name} needs texture coordinates: give --uv FILE or a mesh with vt"))),
        }
    };
    let vertex = |values: Vec<f64>, name: &str, signed: bool| Field {
        values,
        location: ScalarLocation::Vertex,
        name: name.to_string(),
        signed,
    };
    if BUILTIN.contains(&spec) {
        return Ok(match spec {
            "angle-defect" => vertex(fields::angle_defect(p, t)?, spec, true),
            "gaussian-curvature" => vertex(fields::gaussian_curvature(p, t)?, spec, true),
            "mean-curvature" => vertex(fields::mean_curvature(p, t)?, spec, true),
            "x" | "y" | "z" => {
                let k = (spec.as_bytes()[0] - b'x') as usize;
                vertex(p.iter().map(|q| q[k]).collect(), spec, false)
            }
            "area-distortion" => Field {
                values: fields::area_distortion(p, need_uv(spec)?, t)?,
                location: ScalarLocation::Face,
                name: "log area ratio".into(),
                signed: true,
            },
            _ => {
                // angle-distortion: per face, the largest |log| of its corner angle ratios.
                let r = fields::angle_ratios(p, need_uv(spec)?, t)?;
                Field {
                    values: r
                        .chunks_exact(3)
                        .map(|c| c.iter().map(|x| x.ln().abs()).fold(0.0, f64::max))
                        .collect(),
                    location: ScalarLocation::Face,
                    name: "max |log angle ratio|".into(),
                    signed: false,
                }
            }
        });
    }
    // A file: PATH or PATH.json:KEY.
    let (path, key) = match spec.rsplit_once(':') {
        Some((f, k)) if f.to_ascii_lowercase().ends_with(".json") && !k.is_empty() => (f, Some(k)),
        _ => (spec, None),
    };
    let path = Path::new(path);
    if !path.exists() {
        return Err(usage(format!(
            "--scalar '{spec}' is neither a file nor a built-in field ({})",
            BUILTIN.join(", ")
        )));
    }
    let ScalarFile { values, name } = read_scalar_file(path, key)?;
    let (nv, nf) = (p.len(), t.len());
    let location = if values.len() == nv {
        ScalarLocation::Vertex
    } else if values.len() == nf {
        ScalarLocation::Face
    } else {
        bail!(
            "{}: {} values, but the mesh has {nv} vertices and {nf} faces",
            path.display(),
            values.len()
        );
    };
    let signed = values.iter().any(|v| *v < 0.0) && values.iter().any(|v| *v > 0.0);
    Ok(Field {
        values,
        location,
        name,
        signed,
    })
}
