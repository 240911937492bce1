//! `ricci render MESH [--uv FILE] [--scalar NAME|FILE] [--zebra] [--wireframe] [--view x,y,z]
//! [--size N] --out PIC.png|PIC.glb`: pictures of a surface (ricci-render's software
//! renderer) or a glTF binary with the checkerboard texture.
//!
//! What is painted: `--zebra` reflection lines; `--scalar` a field through a colormap with a
//! legend; otherwise a checkerboard (or `--circles`) when UVs are known (`--uv FILE`, or `vt`
//! in the mesh file itself); otherwise plain grey.

mod field;

use crate::util::read_surface;
use crate::util::{print_json, write_atomic, UsageError};
use anyhow::bail;
use field::{scalar_field, Field};
use ricci::mesh::io::uv_match::{has_corner_uvs, uv_file_surface, uvs_from_file, MatchedUvs};
use ricci::mesh::Surface;
use ricci_render::render::Uvs;
use ricci_render::{
    gltf, render, Background, Checker, Circles, Colormap, Lighting, Paint, Polyline, Projection,
    RenderOptions, Scalar, ScalarLocation, ScalarRange, Style, View, Wireframe, Zebra,
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

#[derive(Clone, Copy)]
enum Output {
    Png,
    Glb,
}

/// Texture coordinates found for the mesh.
enum FoundUvs {
    PerVertex(Vec<[f64; 2]>),
    PerCorner(Vec<[f64; 2]>),
}

impl From<MatchedUvs> for FoundUvs {
    fn from(m: MatchedUvs) -> FoundUvs {
        match m {
            MatchedUvs::PerVertex(v) => FoundUvs::PerVertex(v),
            MatchedUvs::PerCorner(v) => FoundUvs::PerCorner(v),
        }
    }
}

impl FoundUvs {
    fn as_uvs(&self) -> Uvs<'_> {
        match self {
            FoundUvs::PerVertex(v) => Uvs::PerVertex(v),
            FoundUvs::PerCorner(v) => Uvs::PerCorner(v),
        }
    }
    /// The longer side of the bounding box of the finite UVs (1 when there is none).
    fn extent(&self) -> f64 {
        let pts: &[[f64; 2]] = match self {
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
    }
    fn per_vertex(&self) -> Option<&[[f64; 2]]> {
        match self {
            FoundUvs::PerVertex(v) => Some(v),
            FoundUvs::PerCorner(_) => None,
        }
    }
}

/// The checked arguments of a `ricci render` call (usage errors, exit code 2, come from
/// here, before any data is read).
struct Settings {
    output: Output,
    eye: [f64; 3],
    up: [f64; 3],
    width: u32,
    height: u32,
    /// Checks across the longer side of the UVs' bounding box.
    checks: f64,
    projection: Projection,
    colormap: Option<Colormap>,
    range: RangeArg,
}

impl Settings {
    fn from_args(a: &Args) -> anyhow::Result<Settings> {
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
        check_out_folder(&a.out)?;
        let projection = match a.perspective {
            None => Projection::Orthographic,
            Some(f) if (5.0..=120.0).contains(&f) => Projection::Perspective { fov_y_deg: f },
            Some(f) => {
                return Err(usage(format!(
                    "--perspective {f}: the field of view must be between 5 and 120 degrees"
                )))
            }
        };
        let colormap = match &a.colormap {
            None => None,
            Some(n) => Some(Colormap::from_name(n).ok_or_else(|| {
                usage(format!("--colormap '{n}': use viridis, coolwarm or grays"))
            })?),
        };
        Ok(Settings {
            output,
            eye,
            up,
            width: w,
            height: h,
            checks,
            projection,
            colormap,
            range: parse_range(&a.range)?,
        })
    }
}

/// The folder of the output file must exist (nothing is created outside it).
fn check_out_folder(out: &Path) -> anyhow::Result<()> {
    if let Some(dir) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !out
            .to_string_lossy()
            .starts_with(crate::util::MEMORY_PREFIX)
            && !dir.is_dir()
        {
            return Err(usage(format!(
                "--out {}: the folder {} does not exist; try: mkdir -p {}",
                out.display(),
                dir.display(),
                dir.display()
            )));
        }
    }
    Ok(())
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    // Arguments first (exit code 2), then data (exit code 1).
    let set = Settings::from_args(&a)?;
    let (surface, _report) = read_surface(&a.mesh)?;
    let surface = uv_file_triangulation(&a, surface)?;
    let positions = &surface.positions;
    let triangles = surface.mesh.faces();
    let uvs: Option<FoundUvs> = match &a.uv {
        Some(path) => Some(uvs_from_file(path, &surface)?.into()),
        // The mesh's own `vt`: per vertex, or per corner across seams (a layout's uv.obj).
        None => match &surface.uvs {
            Some(uv) => Some(FoundUvs::PerVertex(uv.clone())),
            None if has_corner_uvs(&a.mesh) => Some(uvs_from_file(&a.mesh, &surface)?.into()),
            None => None,
        },
    };
    // Checks per UV unit: `--checker N` across the longer side of the UVs' bounding box (a
    // layout in the Poincaré disk spans ~2, a flat one any size: ±84 on face.off).
    let uv_extent = uvs.as_ref().map_or(1.0, FoundUvs::extent);
    let frequency = set.checks / uv_extent;
    // The scalar field, if any: values, where they live, its name and whether it is signed.
    let scalar = match &a.scalar {
        None => None,
        Some(s) => Some(scalar_field(s, &surface, uvs.as_ref())?),
    };
    let (paint, paint_name) = choose_paint(&a, &set, scalar.as_ref(), uvs.as_ref(), frequency)?;
    let mut report = json!({
        "file": a.mesh.display().to_string(),
        "out": a.out.display().to_string(),
        "vertices": positions.len(),
        "faces": triangles.len(),
        "paint": paint_name,
        "uv": uvs.as_ref().map(|u| match u { FoundUvs::PerVertex(_) => "per-vertex", FoundUvs::PerCorner(_) => "per-corner" }),
        "uv_extent": uvs.as_ref().map(|_| uv_extent),
        "checks_across": set.checks,
    });
    if let Some(sf) = &scalar {
        report["scalar"] = sf.report();
    }
    match set.output {
        Output::Png => write_png(&a, &set, &surface, paint, &mut report)?,
        Output::Glb => {
            let uvs = uvs.as_ref().map(|u| u.as_uvs());
            write_glb(&a, &surface, &paint, uvs, frequency, &mut report)?
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

/// A UV file on another triangulation of the same surface (the refined or cut mesh that
/// `ricci layout` writes, with its own 3D positions): render that triangulation.
fn uv_file_triangulation(a: &Args, surface: Surface) -> anyhow::Result<Surface> {
    let Some(path) = &a.uv else {
        return Ok(surface);
    };
    Ok(match uv_file_surface(path, &surface)? {
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
    })
}

/// What the surface is painted with, and its name in the report.
fn choose_paint<'f>(
    a: &Args,
    set: &Settings,
    scalar: Option<&'f Field>,
    uvs: Option<&'f FoundUvs>,
    frequency: f64,
) -> anyhow::Result<(Paint<'f>, &'static str)> {
    if a.zebra {
        return Ok((Paint::Zebra(Zebra::default()), "zebra"));
    }
    if let Some(sf) = scalar {
        let map = set.colormap.unwrap_or(if sf.signed {
            Colormap::CoolWarm
        } else {
            Colormap::Viridis
        });
        let range = match set.range {
            RangeArg::Fixed(lo, hi) => ScalarRange::Fixed(lo, hi),
            RangeArg::Full if map.is_diverging() => ScalarRange::Symmetric,
            RangeArg::Full => ScalarRange::MinMax,
            RangeArg::Auto => ScalarRange::Percentile {
                p: 0.01,
                symmetric: map.is_diverging(),
            },
        };
        let paint = Paint::Scalar(Scalar {
            values: &sf.values,
            location: sf.location,
            colormap: map,
            range,
            isolines: a.isolines,
            label: sf.name.clone(),
        });
        return Ok((paint, "scalar"));
    }
    if let Some(u) = uvs {
        return Ok(if a.circles {
            (
                Paint::Circles(Circles::new(u.as_uvs(), frequency)),
                "circles",
            )
        } else {
            (
                Paint::Checker(Checker::new(u.as_uvs(), frequency)),
                "checker",
            )
        });
    }
    if a.checker.is_some() || a.circles {
        return Err(anyhow::anyhow!(
            "{}: no texture coordinates to draw {} with: the file has no `vt` and no --uv \
             FILE was given (a spherical layout's uv.obj holds positions on the unit sphere, \
             not UVs); try: ricci render {} --scalar z --out {}",
            a.uv.as_ref().unwrap_or(&a.mesh).display(),
            if a.circles { "--circles" } else { "--checker" },
            a.mesh.display(),
            a.out.display()
        ));
    }
    Ok((Paint::default(), "solid"))
}

/// The boundary loops of the mesh as polylines, one colour per loop (`--boundary`).
fn boundary_polylines(surface: &Surface) -> Vec<Polyline> {
    surface
        .mesh
        .boundary_loops()
        .iter()
        .enumerate()
        .map(|(k, lp)| Polyline {
            points: lp.iter().map(|&v| surface.positions[v as usize]).collect(),
            color: ricci_render::color::categorical(k),
            width: 2.5,
            closed: true,
        })
        .collect()
}

/// Render the picture and write it to `--out`; its keys into `report`.
fn write_png(
    a: &Args,
    set: &Settings,
    surface: &Surface,
    paint: Paint,
    report: &mut serde_json::Value,
) -> anyhow::Result<()> {
    let polylines = if a.boundary {
        boundary_polylines(surface)
    } else {
        Vec::new()
    };
    let style = Style {
        paint,
        wireframe: a.wireframe.then(Wireframe::default),
        polylines,
        legend: !a.no_legend,
    };
    let opts = RenderOptions {
        width: set.width,
        height: set.height,
        supersample: a.supersample,
        view: View {
            eye_direction: set.eye,
            up: set.up,
            projection: set.projection,
            margin: 1.08,
        },
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
    let r = render(&surface.positions, surface.mesh.faces(), &style, &opts)?;
    let png = r.png()?;
    write_atomic(&a.out, &png)?;
    report["format"] = json!("png");
    report["width"] = json!(set.width);
    report["height"] = json!(set.height);
    report["coverage"] = json!(r.coverage);
    if let (Some((lo, hi)), Some(s)) = (r.scalar_range, report.get_mut("scalar")) {
        s["range"] = json!([lo, hi]);
    }
    report["bytes"] = json!(png.len());
    Ok(())
}

/// Write the glTF binary (mesh, UVs with the checker texture, per-vertex scalar colours) to
/// `--out`; its keys into `report`.
fn write_glb(
    a: &Args,
    surface: &Surface,
    paint: &Paint,
    uvs: Option<Uvs>,
    frequency: f64,
    report: &mut serde_json::Value,
) -> anyhow::Result<()> {
    if a.zebra || a.wireframe || a.boundary {
        return Err(usage("--zebra, --wireframe and --boundary are picture options; a .glb carries the mesh, its UVs and colours"));
    }
    let colors = match paint {
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
        &surface.positions,
        surface.mesh.faces(),
        &gltf::GlbOptions {
            uvs,
            checker_frequency: Some(frequency),
            colors: colors.as_deref(),
            name: a.mesh.file_stem().map(|s| s.to_string_lossy().to_string()),
        },
    )?;
    write_atomic(&a.out, &bytes)?;
    report["format"] = json!("glb");
    report["bytes"] = json!(bytes.len());
    Ok(())
}

#[derive(Clone, Copy)]
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
