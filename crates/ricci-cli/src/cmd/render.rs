//! `ricci render MESH [--uv FILE] [--scalar NAME|FILE] [--zebra] [--wireframe] [--view x,y,z]
//! [--size N] --out PIC.png|PIC.glb`: pictures of a surface (ricci-render's software
//! renderer) or a glTF binary with the checkerboard texture.
//!
//! What is painted: `--zebra` reflection lines; `--scalar` a field through a colormap with a
//! legend; otherwise a checkerboard (or `--circles`) when UVs are known (`--uv FILE`, or `vt`
//! in the mesh file itself); otherwise plain grey.

use crate::util::read_surface;
use crate::util::{print_json, write_atomic, UsageError};
use anyhow::{bail, Context};
use ricci::mesh::Surface;
use ricci_render::render::Uvs;
use ricci_render::{
    fields, gltf, render, Background, Checker, Circles, Colormap, Lighting, Paint, Polyline,
    Projection, RenderOptions, Scalar, ScalarLocation, ScalarRange, Style, View, Wireframe, Zebra,
};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Built-in scalar fields computed from the mesh.
const BUILTIN: &[&str] = &[
    "angle-defect",
    "gaussian-curvature",
    "mean-curvature",
    "area-distortion",
    "angle-distortion",
    "x",
    "y",
    "z",
];

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL).
    pub mesh: PathBuf,
    /// Texture coordinates: an OBJ with `vt` (or a planar mesh) whose faces match MESH face
    /// by face, e.g. the output of `ricci layout`.
    #[arg(long, value_name = "FILE")]
    pub uv: Option<PathBuf>,
    /// Colour by a scalar: a built-in name (angle-defect, gaussian-curvature, mean-curvature,
    /// area-distortion, angle-distortion, x, y, z), a text file with one value per vertex
    /// (or per face), or a METRIC.json from `ricci flow` (key `u`, else `K`; choose with
    /// FILE.json:KEY).
    #[arg(long, value_name = "NAME|FILE")]
    pub scalar: Option<String>,
    /// Reflection lines (zebra stripes) to judge the smoothness of the surface.
    #[arg(long)]
    pub zebra: bool,
    /// Draw the triangle edges.
    #[arg(long)]
    pub wireframe: bool,
    /// Draw the boundary loops of the mesh (one colour per loop).
    #[arg(long)]
    pub boundary: bool,
    /// Direction from the object towards the camera.
    #[arg(long, value_name = "X,Y,Z", default_value = "0.4,0.3,1")]
    pub view: String,
    /// Up direction on screen.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,1,0")]
    pub up: String,
    /// Perspective camera with this vertical field of view in degrees (default orthographic).
    #[arg(long, value_name = "DEG", num_args = 0..=1, default_missing_value = "35")]
    pub perspective: Option<f64>,
    /// Image width and height in pixels (a square picture).
    #[arg(long, value_name = "N", default_value_t = 1024)]
    pub size: u32,
    /// Image width (overrides --size).
    #[arg(long, value_name = "W")]
    pub width: Option<u32>,
    /// Image height (overrides --size).
    #[arg(long, value_name = "H")]
    pub height: Option<u32>,
    /// Samples per pixel along each axis (anti-aliasing).
    #[arg(long, value_name = "S", default_value_t = 3)]
    pub supersample: u32,
    /// Checks across the layout: N checks (or circles) along the longer side of the UVs'
    /// bounding box, whatever the layout's scale [default: 16].
    #[arg(long, value_name = "N")]
    pub checker: Option<f64>,
    /// Circles instead of checks (conformal maps keep small circles round).
    #[arg(long)]
    pub circles: bool,
    /// Colormap: viridis, coolwarm or grays (default: coolwarm for signed fields, viridis
    /// otherwise).
    #[arg(long, value_name = "NAME")]
    pub colormap: Option<String>,
    /// Colour range: `auto` (clip the 1% extremes), `full` (min to max) or `LO,HI`.
    #[arg(
        long,
        value_name = "auto|full|LO,HI",
        default_value = "auto",
        allow_hyphen_values = true
    )]
    pub range: String,
    /// Number of isolines of the scalar field.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub isolines: u32,
    /// No colour bar.
    #[arg(long)]
    pub no_legend: bool,
    /// No lighting: pure paint colours.
    #[arg(long)]
    pub unlit: bool,
    /// Transparent background (default white).
    #[arg(long)]
    pub transparent: bool,
    /// Output picture (.png) or glTF binary (.glb).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

fn usage(msg: impl Into<String>) -> anyhow::Error {
    anyhow::Error::new(UsageError(msg.into()))
}

fn parse_vec3(s: &str, what: &str) -> anyhow::Result<[f64; 3]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| usage(format!("--{what} '{s}' must be three numbers x,y,z")))?;
    if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
        return Err(usage(format!(
            "--{what} '{s}' must be three finite numbers x,y,z"
        )));
    }
    if v.iter().all(|x| *x == 0.0) {
        return Err(usage(format!("--{what} must not be the zero vector")));
    }
    Ok([v[0], v[1], v[2]])
}

enum Output {
    Png,
    Glb,
}

/// Texture coordinates found for the mesh.
enum FoundUvs {
    PerVertex(Vec<[f64; 2]>),
    PerCorner(Vec<[f64; 2]>),
}

impl FoundUvs {
    fn as_uvs(&self) -> Uvs<'_> {
        match self {
            FoundUvs::PerVertex(v) => Uvs::PerVertex(v),
            FoundUvs::PerCorner(v) => Uvs::PerCorner(v),
        }
    }
    fn per_vertex(&self) -> Option<&[[f64; 2]]> {
        match self {
            FoundUvs::PerVertex(v) => Some(v),
            FoundUvs::PerCorner(_) => None,
        }
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    // Arguments first (exit code 2), then data (exit code 1).
    let output = match a
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .as_deref()
    {
        Some("png") => Output::Png,
        Some("glb") => Output::Glb,
        _ => {
            return Err(usage(format!(
                "--out {}: the file must end in .png (picture) or .glb (glTF binary)",
                a.out.display()
            )))
        }
    };
    if a.zebra && a.scalar.is_some() {
        return Err(usage(
            "--zebra and --scalar paint the surface differently; choose one",
        ));
    }
    let eye = parse_vec3(&a.view, "view")?;
    let up = parse_vec3(&a.up, "up")?;
    let (w, h) = (a.width.unwrap_or(a.size), a.height.unwrap_or(a.size));
    if !(16..=16384).contains(&w) || !(16..=16384).contains(&h) {
        return Err(usage(format!(
            "the image size {w}x{h} must be between 16 and 16384 pixels per side"
        )));
    }
    if !(1..=8).contains(&a.supersample) {
        return Err(usage(format!(
            "--supersample {} must be between 1 and 8",
            a.supersample
        )));
    }
    let checks = a.checker.unwrap_or(16.0);
    if !(checks.is_finite() && checks > 0.0) {
        return Err(usage(format!(
            "--checker {checks} must be a positive number of checks across the layout"
        )));
    }
    // The folder of the output file must exist (nothing is created outside it).
    if let Some(dir) = a.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !a
            .out
            .to_string_lossy()
            .starts_with(crate::util::MEMORY_PREFIX)
            && !dir.is_dir()
        {
            return Err(usage(format!(
                "--out {}: the folder {} does not exist; try: mkdir -p {}",
                a.out.display(),
                dir.display(),
                dir.display()
            )));
        }
    }
    let projection = match a.perspective {
        None => Projection::Orthographic,
        Some(f) if (5.0..=120.0).contains(&f) => Projection::Perspective { fov_y_deg: f },
        Some(f) => {
            return Err(usage(format!(
                "--perspective {f}: the field of view must be between 5 and 120 degrees"
            )))
        }
    };
    let colormap =
        match &a.colormap {
            None => None,
            Some(n) => Some(Colormap::from_name(n).ok_or_else(|| {
                usage(format!("--colormap '{n}': use viridis, coolwarm or grays"))
            })?),
        };
    let range_arg = parse_range(&a.range)?;

    let (surface, _report) = read_surface(&a.mesh)?;
    // A UV file on another triangulation of the same surface (the refined or cut mesh that
    // `ricci layout` writes, with its own 3D positions): render that triangulation.
    let surface = match &a.uv {
        Some(path) => match uv_file_surface(path, &surface)? {
            Some(s) => {
                eprintln!(
                    "note: {} has {} faces where {} has {}; rendering the UV file's own \
                     triangulation of the surface",
                    path.display(),
                    s.mesh.n_faces(),
                    a.mesh.display(),
                    surface.mesh.n_faces()
                );
                s
            }
            None => surface,
        },
        None => surface,
    };
    let positions = &surface.positions;
    let triangles = surface.mesh.faces();

    let uvs: Option<FoundUvs> = match &a.uv {
        Some(path) => Some(uvs_from_file(path, &surface)?),
        // The mesh's own `vt`: per vertex, or per corner across seams (a layout's uv.obj).
        None => match &surface.uvs {
            Some(uv) => Some(FoundUvs::PerVertex(uv.clone())),
            None if has_corner_uvs(&a.mesh) => Some(uvs_from_file(&a.mesh, &surface)?),
            None => None,
        },
    };

    // Checks per UV unit: `--checker N` across the longer side of the UVs' bounding box (a
    // layout in the Poincaré disk spans ~2, a flat one any size: ±84 on face.off).
    let uv_extent = uvs.as_ref().map_or(1.0, |u| {
        let pts: &[[f64; 2]] = match u {
            FoundUvs::PerVertex(v) | FoundUvs::PerCorner(v) => v,
        };
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in pts.iter().filter(|p| p[0].is_finite() && p[1].is_finite()) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let e = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        if e.is_finite() && e > 0.0 {
            e
        } else {
            1.0
        }
    });
    let frequency = checks / uv_extent;

    // The scalar field, if any: values, where they live, its name and whether it is signed.
    let scalar = match &a.scalar {
        None => None,
        Some(s) => Some(scalar_field(s, &surface, uvs.as_ref())?),
    };

    let paint_name;
    let paint = if a.zebra {
        paint_name = "zebra";
        Paint::Zebra(Zebra::default())
    } else if let Some(sf) = &scalar {
        paint_name = "scalar";
        let map = colormap.unwrap_or(if sf.signed {
            Colormap::CoolWarm
        } else {
            Colormap::Viridis
        });
        let range = match range_arg {
            RangeArg::Fixed(lo, hi) => ScalarRange::Fixed(lo, hi),
            RangeArg::Full if map.is_diverging() => ScalarRange::Symmetric,
            RangeArg::Full => ScalarRange::MinMax,
            RangeArg::Auto => ScalarRange::Percentile {
                p: 0.01,
                symmetric: map.is_diverging(),
            },
        };
        Paint::Scalar(Scalar {
            values: &sf.values,
            location: sf.location,
            colormap: map,
            range,
            isolines: a.isolines,
            label: sf.name.clone(),
        })
    } else if let Some(u) = &uvs {
        if a.circles {
            paint_name = "circles";
            Paint::Circles(Circles::new(u.as_uvs(), frequency))
        } else {
            paint_name = "checker";
            Paint::Checker(Checker::new(u.as_uvs(), frequency))
        }
    } else if a.checker.is_some() || a.circles {
        return Err(anyhow::anyhow!(
            "{}: no texture coordinates to draw {} with: the file has no `vt` and no --uv \
             FILE was given (a spherical layout's uv.obj holds positions on the unit sphere, \
             not UVs); try: ricci render {} --scalar z --out {}",
            a.uv.as_ref().unwrap_or(&a.mesh).display(),
            if a.circles { "--circles" } else { "--checker" },
            a.mesh.display(),
            a.out.display()
        ));
    } else {
        paint_name = "solid";
        Paint::default()
    };

    let polylines = if a.boundary {
        surface
            .mesh
            .boundary_loops()
            .iter()
            .enumerate()
            .map(|(k, lp)| Polyline {
                points: lp.iter().map(|&v| positions[v as usize]).collect(),
                color: ricci_render::color::categorical(k),
                width: 2.5,
                closed: true,
            })
            .collect()
    } else {
        Vec::new()
    };

    let view = View {
        eye_direction: eye,
        up,
        projection,
        margin: 1.08,
    };
    let mut report = json!({
        "file": a.mesh.display().to_string(),
        "out": a.out.display().to_string(),
        "vertices": positions.len(),
        "faces": triangles.len(),
        "paint": paint_name,
        "uv": uvs.as_ref().map(|u| match u { FoundUvs::PerVertex(_) => "per-vertex", FoundUvs::PerCorner(_) => "per-corner" }),
        "uv_extent": uvs.as_ref().map(|_| uv_extent),
        "checks_across": checks,
    });
    if let Some(sf) = &scalar {
        let finite: Vec<f64> = sf
            .values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .collect();
        report["scalar"] = json!({
            "name": sf.name,
            "location": if sf.location == ScalarLocation::Vertex { "vertex" } else { "face" },
            "min": finite.iter().copied().fold(f64::INFINITY, f64::min),
            "max": finite.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            "missing": sf.values.len() - finite.len(),
        });
    }

    match output {
        Output::Png => {
            let style = Style {
                paint,
                wireframe: a.wireframe.then(Wireframe::default),
                polylines,
                legend: !a.no_legend,
            };
            let opts = RenderOptions {
                width: w,
                height: h,
                supersample: a.supersample,
                view,
                background: if a.transparent {
                    Background::Transparent
                } else {
                    Background::White
                },
                lighting: if a.unlit {
                    Lighting::Unlit
                } else {
                    Lighting::Studio
                },
                line_offset: 0.01,
            };
            let r = render(positions, triangles, &style, &opts)?;
            let png = r.png()?;
            write_atomic(&a.out, &png)?;
            report["format"] = json!("png");
            report["width"] = json!(w);
            report["height"] = json!(h);
            report["coverage"] = json!(r.coverage);
            if let (Some((lo, hi)), Some(s)) = (r.scalar_range, report.get_mut("scalar")) {
                s["range"] = json!([lo, hi]);
            }
            report["bytes"] = json!(png.len());
        }
        Output::Glb => {
            if a.zebra || a.wireframe || a.boundary {
                return Err(usage("--zebra, --wireframe and --boundary are picture options; a .glb carries the mesh, its UVs and colours"));
            }
            let colors = match &paint {
                Paint::Scalar(s) if s.location == ScalarLocation::Vertex => {
                    let (lo, hi) = s.range.resolve(s.values).unwrap_or((0.0, 1.0));
                    Some(ricci_render::plot::face_colors(
                        s.values,
                        s.colormap,
                        (lo, hi),
                    ))
                }
                Paint::Scalar(_) => {
                    bail!("per-face scalars cannot be written to glTF yet; render a .png instead")
                }
                _ => None,
            };
            let bytes = gltf::glb(
                positions,
                triangles,
                &gltf::GlbOptions {
                    uvs: uvs.as_ref().map(|u| u.as_uvs()),
                    checker_frequency: Some(frequency),
                    colors: colors.as_deref(),
                    name: a.mesh.file_stem().map(|s| s.to_string_lossy().to_string()),
                },
            )?;
            write_atomic(&a.out, &bytes)?;
            report["format"] = json!("glb");
            report["bytes"] = json!(bytes.len());
        }
    }
    report["seconds"] = json!(t0.elapsed().as_secs_f64());
    if a.json {
        print_json(&report);
    } else {
        println!(
            "{}: {} faces, {} → {}",
            a.mesh.display(),
            triangles.len(),
            paint_name,
            a.out.display()
        );
    }
    Ok(())
}

enum RangeArg {
    Auto,
    Full,
    Fixed(f64, f64),
}

fn parse_range(s: &str) -> anyhow::Result<RangeArg> {
    match s {
        "auto" => Ok(RangeArg::Auto),
        "full" => Ok(RangeArg::Full),
        _ => {
            let v: Vec<f64> = s
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| usage(format!("--range '{s}': use auto, full or LO,HI")))?;
            match v[..] {
                [lo, hi] if lo.is_finite() && hi.is_finite() && lo < hi => {
                    Ok(RangeArg::Fixed(lo, hi))
                }
                _ => Err(usage(format!(
                    "--range '{s}': LO,HI must be two finite numbers with LO < HI"
                ))),
            }
        }
    }
}

struct Field {
    values: Vec<f64>,
    location: ScalarLocation,
    name: String,
    signed: bool,
}

fn scalar_field(spec: &str, s: &Surface, uvs: Option<&FoundUvs>) -> anyhow::Result<Field> {
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
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let (values, name) = if is_json {
        let v: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| anyhow::anyhow!("{}: not valid JSON: {e}", path.display()))?;
        let keys: Vec<&str> = match key {
            Some(k) => vec![k],
            None => vec!["u", "K"],
        };
        let (k, arr) = keys
            .iter()
            .find_map(|k| v.get(*k).and_then(|a| a.as_array()).map(|a| (*k, a)))
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: no array under the key {}",
                    path.display(),
                    keys.join(" or ")
                )
            })?;
        let vals = arr
            .iter()
            .enumerate()
            .map(|(i, x)| {
                x.as_f64()
                    .or(if x.is_null() { Some(f64::NAN) } else { None })
                    .ok_or_else(|| {
                        anyhow::anyhow!("{}: entry {i} of \"{k}\" is not a number", path.display())
                    })
            })
            .collect::<anyhow::Result<Vec<f64>>>()?;
        (vals, k.to_string())
    } else {
        let mut vals = Vec::new();
        for (ln, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("");
            for tok in line
                .split(|c: char| c.is_whitespace() || c == ',')
                .filter(|t| !t.is_empty())
            {
                let x: f64 = tok.parse().map_err(|_| {
                    anyhow::anyhow!(
                        "{}, line {}: '{tok}' is not a number",
                        path.display(),
                        ln + 1
                    )
                })?;
                vals.push(x);
            }
        }
        (
            vals,
            path.file_stem()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_default(),
        )
    };
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

/// Whether `path` is an OBJ file whose every face corner has a `vt`.
fn has_corner_uvs(path: &Path) -> bool {
    let is_obj = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    is_obj
        && ricci::mesh::io::read_soup(path)
            .map(|s| s.corner_uvs.is_some())
            .unwrap_or(false)
}

/// Texture coordinates for `mesh` from a UV file whose faces match it face by face: its `vt`
/// (or, for a planar mesh without `vt`, its x and y) at the corner with the same position,
/// or at the same corner when positions differ (a layout written with planar positions).
/// The surface of a UV file whose faces differ from the mesh's but which carries 3D
/// positions of its own (not a flat layout) and texture coordinates: `ricci layout` writes
/// the UVs on the triangulation it laid out (refined near the cut), with that triangulation's
/// positions on the input surface. `None` when the file has the mesh's face count (the
/// usual case) or is flat.
fn uv_file_surface(path: &Path, mesh: &Surface) -> anyhow::Result<Option<Surface>> {
    let soup = ricci::mesh::io::read_soup(path)?;
    let has_uv = soup.corner_uvs.is_some() || soup.uvs.is_some();
    let (u, _) = ricci::mesh::build_surface(soup)?;
    if u.mesh.n_faces() == mesh.mesh.n_faces() || !has_uv {
        return Ok(None);
    }
    let d = u.diagonal().max(f64::MIN_POSITIVE);
    let flat = u.positions.iter().all(|p| p[2].abs() <= 1e-9 * d);
    // The same surface: the same area (a refinement or common subdivision has the input's
    // area exactly; a piece of the surface or another surface does not).
    let (a0, a1) = (embedded_area(mesh), embedded_area(&u));
    let same = (a1 - a0).abs() <= 1e-6 * a0.max(f64::MIN_POSITIVE);
    Ok((!flat && same).then_some(u))
}

/// Area of an embedded surface from its positions.
fn embedded_area(s: &Surface) -> f64 {
    s.mesh
        .faces()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| s.positions[v as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let x = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            0.5 * (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt()
        })
        .sum()
}

fn uvs_from_file(path: &Path, mesh: &Surface) -> anyhow::Result<FoundUvs> {
    let soup = ricci::mesh::io::read_soup(path)?;
    let (in_polygons, in_corner_uvs) = (soup.polygons.clone(), soup.corner_uvs.clone());
    let (u, report) = ricci::mesh::build_surface(soup)?;
    let (nf, unf) = (mesh.mesh.n_faces(), u.mesh.n_faces());
    if nf != unf {
        bail!(
            "{}: {unf} faces, but the mesh has {nf}; the UV file must have the same faces in the same order",
            path.display()
        );
    }
    let planar = {
        let d = u.diagonal().max(f64::MIN_POSITIVE);
        u.positions.iter().all(|p| p[2].abs() <= 1e-9 * d)
    };
    // One UV per corner of the UV file's faces: its per-vertex `vt`, else its per-corner `vt`
    // (a layout of a cut surface has seams: `f v/vt` with several `vt` per vertex), else x, y.
    let per_vertex = |coords: &[[f64; 2]]| -> Vec<[f64; 2]> {
        u.mesh
            .faces()
            .iter()
            .flat_map(|t| t.map(|v| coords[v as usize]))
            .collect()
    };
    let ucorner: Vec<[f64; 2]> = match (&u.uvs, &in_corner_uvs, planar) {
        (Some(uv), _, _) => per_vertex(uv),
        (None, Some(cuv), _) => {
            let mut start = Vec::with_capacity(in_polygons.len());
            let mut acc = 0usize;
            for p in &in_polygons {
                start.push(acc);
                acc += p.len();
            }
            let mut out = Vec::with_capacity(3 * unf);
            for (f, t) in u.mesh.faces().iter().enumerate() {
                let p = report.face_origin[f] as usize;
                for &v in t {
                    let vin = report.vertex_origin[v as usize];
                    let k = in_polygons[p]
                        .iter()
                        .position(|&w| w == vin)
                        .ok_or_else(|| {
                            anyhow::anyhow!(
                                "{}: face {f} lost track of its corners",
                                path.display()
                            )
                        })?;
                    out.push(cuv[start[p] + k]);
                }
            }
            out
        }
        (None, None, true) => {
            let xy: Vec<[f64; 2]> = u.positions.iter().map(|p| [p[0], p[1]]).collect();
            per_vertex(&xy)
        }
        (None, None, false) => bail!(
            "{}: no texture coordinates (vt lines) and not a planar layout",
            path.display()
        ),
    };
    let tol = 1e-9 * mesh.diagonal().max(f64::MIN_POSITIVE);
    let same = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() <= tol);
    let mf = mesh.mesh.faces();
    let uf = u.mesh.faces();
    let mut corner = Vec::with_capacity(3 * nf);
    let mut matched_positions = 0usize;
    for f in 0..nf {
        let (mt, ut) = (mf[f], uf[f]);
        for i in 0..3 {
            let p = mesh.positions[mt[i] as usize];
            let j = (0..3).find(|&j| same(u.positions[ut[j] as usize], p));
            if j.is_some() {
                matched_positions += 1;
            }
            corner.push(ucorner[3 * f + j.unwrap_or(i)]);
        }
    }
    if matched_positions != 0 && matched_positions != 3 * nf {
        bail!(
            "{}: only {matched_positions} of {} corners have the position of the mesh's corner; the faces do not match",
            path.display(),
            3 * nf
        );
    }
    // Per vertex when every vertex has one UV.
    let mut per_vertex: Vec<Option<[f64; 2]>> = vec![None; mesh.positions.len()];
    let mut consistent = true;
    for (c, uv) in corner.iter().enumerate() {
        let v = mf[c / 3][c % 3] as usize;
        match per_vertex[v] {
            None => per_vertex[v] = Some(*uv),
            Some(old) if old != *uv => {
                consistent = false;
                break;
            }
            _ => {}
        }
    }
    Ok(if consistent {
        FoundUvs::PerVertex(
            per_vertex
                .into_iter()
                .map(|x| x.unwrap_or([0.0; 2]))
                .collect(),
        )
    } else {
        FoundUvs::PerCorner(corner)
    })
}
