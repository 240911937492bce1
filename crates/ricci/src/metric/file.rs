//! The metric file (`METRIC.json`) that `ricci flow --out` writes and `ricci cut`, `layout`
//! and `spectrum --metric` read: one reader and one writer for every command (docs/DESIGN.md §4).
//!
//! Format (a JSON object):
//! * `geometry`: `euclidean` | `hyperbolic` | `spherical` (default `euclidean` when absent);
//! * `lengths`: per edge, either plain numbers (indexed by edge id, or matched through
//!   `edge_vertices` = `[[a, b], …]`, also accepted under the key `edges`), or `[a, b, l]`
//!   triples, or `{"u": a, "v": b, "length": l}` objects;
//! * what the flow reached, when known: `converged`, `max_curvature_error`,
//!   `degenerate_faces` — a metric written by a flow that did not converge says so, and
//!   [`MetricFile::check_usable`] refuses it with one sentence;
//! * `faces` (with `"triangulation": "intrinsic"`): the metric lives on its own triangulation
//!   of the surface — the intrinsic Delaunay triangulation of `--scheme conformal`, input
//!   vertices first with their ids, vertices of metric-preserving splits appended. The
//!   lengths are matched on that mesh, which must have the input's Euler characteristic and
//!   at least its vertices; it is returned in [`MetricFile::mesh`];
//! * everything else that `ricci flow` writes (`u`, `curvature`, `target_curvature`, …) is
//!   informative and not read back.
//!
//! Every length must be finite and positive, and every face must satisfy the triangle
//! inequality of its geometry (for the sphere also perimeter < 2π); the reader names the edge
//! or face that does not.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::Geometry;
use serde_json::Value;
use std::path::Path;

/// A metric read from a file, on the edges of a given mesh.
#[derive(Debug, Clone)]
pub struct MetricFile {
    pub geometry: Geometry,
    /// Lengths by edge id of the mesh the file was matched against.
    pub lengths: Vec<f64>,
    /// `converged` as written by the flow (`None` when the file does not say).
    pub converged: Option<bool>,
    /// `max_curvature_error` as written by the flow.
    pub max_curvature_error: Option<f64>,
    /// `degenerate_faces` as written by the flow.
    pub degenerate_faces: Option<usize>,
    /// The triangulation the lengths belong to when the file brings its own (`faces`);
    /// `None`: the mesh the file was read against.
    pub mesh: Option<Mesh>,
}

impl MetricFile {
    /// The mesh the lengths belong to: the file's own triangulation, else `input`.
    pub fn mesh_or<'a>(&'a self, input: &'a Mesh) -> &'a Mesh {
        self.mesh.as_ref().unwrap_or(input)
    }
}

impl MetricFile {
    /// Refuse a metric that its flow reported as not converged: a layout, cut or spectrum
    /// computed from it would not be what it claims (e.g. a layout with flipped faces and a
    /// deck group that does not close).
    pub fn check_usable(&self, name: &str) -> Result<()> {
        if self.converged == Some(false) {
            let mut why = String::new();
            if let Some(e) = self.max_curvature_error {
                why.push_str(&format!("max |K − K̄| = {e:.3e}"));
            }
            if let Some(d) = self.degenerate_faces.filter(|&d| d > 0) {
                if !why.is_empty() {
                    why.push_str(", ");
                }
                why.push_str(&format!("{d} face(s) violating the triangle inequality"));
            }
            return Err(Error::input(format!(
                "{name}: this metric did not converge ({}); results computed from it would be \
                 wrong, so none are computed — run `ricci flow` again until it reports \
                 \"converged\": true (try another --scheme, or --refine-degenerate N)",
                if why.is_empty() {
                    "as its file says"
                } else {
                    &why
                }
            )));
        }
        Ok(())
    }
}

/// Read `path` as a metric on `mesh` (see the module docs for the format).
pub fn read_metric_file(path: &Path, mesh: &Mesh) -> Result<MetricFile> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| Error::input(format!("{name}: {e}")))?;
    parse_metric(&text, mesh).map_err(|e| Error::input(format!("{name}: {e}")))
}

/// Parse the text of a metric file on `mesh`.
pub fn parse_metric(text: &str, input: &Mesh) -> Result<MetricFile> {
    let v: Value =
        serde_json::from_str(text).map_err(|e| Error::input(format!("not valid JSON ({e})")))?;
    let own = own_triangulation(&v, input)?;
    let mesh = own.as_ref().unwrap_or(input);
    let geometry: Geometry = match v.get("geometry") {
        None => Geometry::Euclidean,
        Some(g) => g
            .as_str()
            .ok_or_else(|| Error::input("\"geometry\" is not a string"))?
            .parse()
            .map_err(Error::input)?,
    };
    let lens = v
        .get("lengths")
        .and_then(|l| l.as_array())
        .ok_or_else(|| Error::input("no \"lengths\" array"))?;
    let pairs = v
        .get("edge_vertices")
        .or_else(|| v.get("edges"))
        .and_then(|e| e.as_array());
    let ne = mesh.n_edges();
    let nv = mesh.n_vertices() as u64;
    let mut out = vec![f64::NAN; ne];
    let edge_of = |i: usize, a: u64, b: u64| -> Result<usize> {
        (a < nv && b < nv)
            .then(|| mesh.halfedge_between(a as u32, b as u32))
            .flatten()
            .map(|h| mesh.he_edge(h) as usize)
            .ok_or_else(|| {
                Error::input(format!(
                    "lengths[{i}]: ({a}, {b}) is not an edge of the mesh"
                ))
            })
    };
    let all_numbers = lens.iter().all(|x| x.is_number());
    if all_numbers && pairs.is_none() {
        if lens.len() != ne {
            return Err(Error::input(format!(
                "{} lengths for a mesh with {ne} edges (give \"edge_vertices\" to match them by \
                 vertex pair)",
                lens.len()
            )));
        }
        for (i, x) in lens.iter().enumerate() {
            out[i] = x.as_f64().unwrap_or(f64::NAN);
        }
    } else {
        for (i, item) in lens.iter().enumerate() {
            let (a, b, l) = if let Some(l) = item.as_f64() {
                let e = pairs
                    .and_then(|p| p.get(i))
                    .and_then(|e| e.as_array())
                    .ok_or_else(|| {
                        Error::input(format!(
                            "lengths[{i}] has no vertex pair in \"edge_vertices\""
                        ))
                    })?;
                let f = |k: usize| e.get(k).and_then(|x| x.as_u64());
                match (f(0), f(1)) {
                    (Some(a), Some(b)) => (a, b, l),
                    _ => {
                        return Err(Error::input(format!(
                            "edge_vertices[{i}] is not a pair of vertex ids"
                        )))
                    }
                }
            } else if let Some(arr) = item.as_array() {
                let id = |k: usize| arr.get(k).and_then(|x| x.as_u64());
                match (id(0), id(1), arr.get(2).and_then(|x| x.as_f64())) {
                    (Some(a), Some(b), Some(l)) => (a, b, l),
                    _ => return Err(Error::input(format!("lengths[{i}] is not [a, b, length]"))),
                }
            } else {
                let id = |k: &str| item.get(k).and_then(|x| x.as_u64());
                let l = item
                    .get("length")
                    .or_else(|| item.get("l"))
                    .and_then(|x| x.as_f64());
                match (id("u").or(id("a")), id("v").or(id("b")), l) {
                    (Some(a), Some(b), Some(l)) => (a, b, l),
                    _ => {
                        return Err(Error::input(format!(
                            "lengths[{i}] is not {{u, v, length}}"
                        )))
                    }
                }
            };
            out[edge_of(i, a, b)?] = l;
        }
    }
    for (e, &l) in out.iter().enumerate() {
        if l.is_nan() {
            let [a, b] = mesh.edge_vertices(e as u32);
            return Err(Error::input(format!("no length for edge ({a}, {b})")));
        }
        if !(l.is_finite() && l > 0.0) {
            let [a, b] = mesh.edge_vertices(e as u32);
            return Err(Error::input(format!(
                "the length {l} of edge ({a}, {b}) is not a positive number"
            )));
        }
    }
    check_triangle_inequalities(mesh, geometry, &out)?;
    Ok(MetricFile {
        geometry,
        lengths: out,
        converged: v.get("converged").and_then(|c| c.as_bool()),
        max_curvature_error: v.get("max_curvature_error").and_then(|c| c.as_f64()),
        degenerate_faces: v
            .get("degenerate_faces")
            .and_then(|c| c.as_u64())
            .map(|d| d as usize),
        mesh: own,
    })
}

/// The file's own triangulation (`faces`), checked against the input mesh: at least its
/// vertices, the same Euler characteristic.
fn own_triangulation(v: &Value, input: &Mesh) -> Result<Option<Mesh>> {
    let Some(faces) = v.get("faces") else {
        return Ok(None);
    };
    let faces = faces
        .as_array()
        .ok_or_else(|| Error::input("\"faces\" is not an array"))?;
    let mut tris = Vec::with_capacity(faces.len());
    let mut nv = 0u64;
    for (f, t) in faces.iter().enumerate() {
        let ids: Vec<u64> = t
            .as_array()
            .map(|a| a.iter().filter_map(|x| x.as_u64()).collect())
            .unwrap_or_default();
        let [a, b, c] = <[u64; 3]>::try_from(ids)
            .map_err(|_| Error::input(format!("faces[{f}] is not three vertex ids")))?;
        if a.max(b).max(c) >= u32::MAX as u64 / 2 {
            return Err(Error::input(format!(
                "faces[{f}] has a vertex id out of range"
            )));
        }
        nv = nv.max(a + 1).max(b + 1).max(c + 1);
        tris.push([a as u32, b as u32, c as u32]);
    }
    let nv = (nv as usize).max(input.n_vertices());
    let mesh = Mesh::from_triangles(nv, tris)
        .map_err(|e| Error::input(format!("its \"faces\" are not a valid mesh ({e})")))?;
    let chi = |m: &Mesh| m.n_vertices() as i64 - m.n_edges() as i64 + m.n_faces() as i64;
    if chi(&mesh) != chi(input) {
        return Err(Error::input(format!(
            "its triangulation has Euler characteristic {}, the mesh {}: it is a metric of \
             another surface",
            chi(&mesh),
            chi(input)
        )));
    }
    Ok(Some(mesh))
}

/// Every face's lengths form a triangle of `geometry` (strict triangle inequalities; on the
/// sphere also perimeter < 2π); the error names the first face that does not.
pub fn check_triangle_inequalities(mesh: &Mesh, geometry: Geometry, lengths: &[f64]) -> Result<()> {
    for f in 0..mesh.n_faces() as u32 {
        let [a, b, c] = mesh.face_edges_opposite(f).map(|e| lengths[e as usize]);
        let ok = a < b + c
            && b < c + a
            && c < a + b
            && (geometry != Geometry::Spherical || a + b + c < 2.0 * std::f64::consts::PI);
        if !ok {
            let [i, j, k] = mesh.face(f);
            return Err(Error::input(format!(
                "face {f} ({i}, {j}, {k}) has lengths {a:.6e}, {b:.6e}, {c:.6e}, which violate \
                 the triangle inequality{}: this is not a metric on the mesh",
                if geometry == Geometry::Spherical {
                    " of the sphere"
                } else {
                    ""
                }
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Mesh {
        // Two triangles: (0,1,2), (0,2,3).
        Mesh::from_triangles(4, vec![[0, 1, 2], [0, 2, 3]]).unwrap()
    }

    #[test]
    fn reads_every_length_format_and_matches_edges_by_vertices() {
        let m = square();
        let by_pair = |a: u32, b: u32| m.he_edge(m.halfedge_between(a, b).unwrap()) as usize;
        let want = [
            (0, 1, 1.0),
            (1, 2, 1.1),
            (2, 0, 1.4),
            (2, 3, 1.2),
            (3, 0, 0.9),
        ];
        let triples: Vec<Value> = want
            .iter()
            .map(|&(a, b, l)| serde_json::json!([a, b, l]))
            .collect();
        let objects: Vec<Value> = want
            .iter()
            .map(|&(a, b, l)| serde_json::json!({"u": b, "v": a, "length": l}))
            .collect();
        let plain = serde_json::json!({
            "geometry": "euclidean",
            "lengths": want.iter().map(|w| w.2).collect::<Vec<_>>(),
            "edge_vertices": want.iter().map(|w| [w.0, w.1]).collect::<Vec<_>>(),
        });
        for text in [
            serde_json::json!({"lengths": triples}).to_string(),
            serde_json::json!({"lengths": objects}).to_string(),
            plain.to_string(),
        ] {
            let r = parse_metric(&text, &m).unwrap();
            for &(a, b, l) in &want {
                assert_eq!(r.lengths[by_pair(a, b)], l);
            }
            assert_eq!(r.converged, None);
        }
    }

    #[test]
    fn refuses_bad_metrics_naming_the_edge_or_face() {
        let m = square();
        let e = parse_metric(
            r#"{"lengths": [[0, 1, 1], [1, 2, 1], [2, 0, 1], [2, 3, 1]]}"#,
            &m,
        )
        .unwrap_err();
        assert!(e.to_string().contains("no length for edge"), "{e}");
        let e = parse_metric(
            r#"{"lengths": [[0,1,1],[1,2,1],[2,0,5],[2,3,3],[3,0,3]]}"#,
            &m,
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("face 0") && e.to_string().contains("triangle inequality"),
            "{e}"
        );
        let e = parse_metric(
            r#"{"lengths": [[0,1,1],[1,2,1],[2,0,1],[2,3,-1],[3,0,1]]}"#,
            &m,
        )
        .unwrap_err();
        assert!(e.to_string().contains("(2, 3)"), "{e}");
        let e = parse_metric(r#"{"lengths": [[0,7,1]]}"#, &m).unwrap_err();
        assert!(e.to_string().contains("not an edge"), "{e}");
    }

    #[test]
    fn a_metric_on_its_own_triangulation_is_matched_on_it() {
        // The square with the other diagonal (1, 3): edges (1, 3) is not an input edge.
        let m = square();
        let text = r#"{"triangulation": "intrinsic", "faces": [[0, 1, 3], [1, 2, 3]],
            "lengths": [[0,1,1],[1,3,1.3],[3,0,1],[1,2,1],[2,3,1]]}"#;
        let r = parse_metric(text, &m).unwrap();
        let own = r.mesh.as_ref().expect("own mesh");
        let h = own.halfedge_between(1, 3).unwrap();
        assert_eq!(r.lengths[own.he_edge(h) as usize], 1.3);
        assert!(m.halfedge_between(1, 3).is_none());
        // Another surface (two triangles apart, χ = 2) is refused.
        let e = parse_metric(
            r#"{"faces": [[0, 1, 2], [3, 4, 5]], "lengths": [[0,1,1],[1,2,1],[2,0,1],
                [3,4,1],[4,5,1],[5,3,1]]}"#,
            &m,
        )
        .unwrap_err();
        assert!(e.to_string().contains("Euler characteristic"), "{e}");
    }

    #[test]
    fn a_metric_that_did_not_converge_is_refused_with_the_reason() {
        let m = square();
        let text = r#"{"geometry": "hyperbolic", "converged": false, "max_curvature_error": 0.5,
            "degenerate_faces": 3, "lengths": [[0,1,1],[1,2,1],[2,0,1],[2,3,1],[3,0,1]]}"#;
        let r = parse_metric(text, &m).unwrap();
        assert_eq!(r.geometry, Geometry::Hyperbolic);
        let e = r.check_usable("m.json").unwrap_err().to_string();
        assert!(
            e.contains("m.json") && e.contains("5.000e-1") && e.contains("3 face(s)"),
            "{e}"
        );
        let ok = text.replace("\"converged\": false", "\"converged\": true");
        assert!(parse_metric(&ok, &m)
            .unwrap()
            .check_usable("m.json")
            .is_ok());
    }
}
