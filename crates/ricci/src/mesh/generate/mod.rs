//! Procedural surfaces of good triangle quality: the built-in inputs of `ricci demo` and of the
//! tests (conformal invariants at several resolutions).
//!
//! Every generator is deterministic, validates its parameters (returning
//! [`Error::InvalidInput`] with one sentence), and takes a resolution that controls the face
//! count:
//!
//! | generator | resolution means | faces | min angle at the default |
//! |---|---|---|---|
//! | [`icosphere`]`(s)` | subdivision levels `s` (default 3) | `20·4^s` | 54° |
//! | [`torus`](fn@torus)`(R, r, n)` | segments around the major circle (default 48) | `2 n n_w` | 56° (R = 1, r = 0.5) |
//! | [`disk`]`(n)` | boundary segments (default 64) | ≈ `0.18 n²` | 37° |
//! | [`annulus`]`(r_in, r_out, n)` | segments on the outer circle (default 64) | ≈ `0.18 n² (1 − r_in²/r_out²)` | 37° |
//! | [`pair_of_pants`]`(n)` | segments on the outer circle (default 64) | ≈ `0.16 n²` | 37° |
//! | [`genus`]`(g, n)` | edges around each handle's centre circle (default 40) | ≈ `0.76 g n²` | 40° |
//!
//! (Measured; `tests/generate.rs` asserts ≥ 30° at the defaults.)
//!
//! Constructions:
//! * icosphere — [`sphere`]: 1→4 subdivision of the icosahedron projected to the unit sphere;
//! * torus of revolution — [`torus`](mod@torus): equilateral staggered grid in conformal
//!   coordinates, so the mesh is conformal to the rectangle of side ratio `r / √(R² − r²)`;
//! * disk, annulus, pair of pants — [`planar`]: uniform boundary sampling, constrained
//!   Delaunay triangulation and optimal-Delaunay smoothing;
//! * genus g — [`implicit`] + [`remesh`]: a chain of g tori blended by a smooth minimum,
//!   marching tetrahedra, isotropic remeshing (Botsch–Kobbelt) with projection onto the
//!   implicit surface, and an angle-improving pass;
//! * re-triangulations of a surface (midpoint subdivision, random off-centre face splits) and
//!   an irregular torus — [`retriangulate`]: the test inputs of re-triangulation invariance.

pub(crate) mod implicit;
pub(crate) mod planar;
pub(crate) mod remesh;
pub(crate) mod retriangulate;
pub(crate) mod sphere;
pub mod torus;

mod geom;

use crate::error::{Error, Result};
use crate::mesh::Surface;
use crate::progress::{NoProgress, Progress};
use std::f64::consts::PI;

pub use implicit::ToriChain;
pub use remesh::Implicit;
pub use retriangulate::{
    bumpy_split_disk, irregular_torus, midpoint_subdivision, random_face_splits, split_off_centre,
};
pub use sphere::icosphere;
pub use torus::{torus, torus_grid};

/// Largest number of faces a generator agrees to produce.
pub const MAX_FACES: u64 = 50_000_000;

pub(crate) fn too_many_faces(what: &str, faces: u64) -> Error {
    let n = if faces == u64::MAX {
        "too many".to_string()
    } else {
        faces.to_string()
    };
    Error::input(format!(
        "{what}: the requested resolution would give {n} faces, more than the limit of {MAX_FACES}"
    ))
}

/// Default subdivision level of the icosphere (1280 faces).
pub const DEFAULT_SUBDIVISIONS: u32 = 3;
/// Default major and minor radius of the torus.
pub const DEFAULT_MAJOR: f64 = 1.0;
pub const DEFAULT_MINOR: f64 = 0.5;
/// Default inner and outer radius of the annulus.
pub const DEFAULT_INNER: f64 = 0.5;
pub const DEFAULT_OUTER: f64 = 1.0;

/// Default resolution of each kind (see the table in the module docs).
pub fn default_resolution(kind: &GeneratorKind) -> u32 {
    match kind {
        GeneratorKind::Sphere => DEFAULT_SUBDIVISIONS,
        GeneratorKind::Torus => 48,
        GeneratorKind::Disk | GeneratorKind::Annulus | GeneratorKind::Pants => 64,
        GeneratorKind::Genus(_) => 40,
    }
}

fn check_resolution(what: &str, resolution: u32, min: u32) -> Result<()> {
    if resolution < min {
        return Err(Error::input(format!(
            "{what}: resolution = {resolution} is too small (at least {min})"
        )));
    }
    Ok(())
}

/// Unit disk with `resolution` segments on the boundary circle.
pub fn disk(resolution: u32) -> Result<Surface> {
    check_resolution("disk", resolution, 8)?;
    check_planar_size("disk", PI, 1.0, resolution)?;
    planar::mesh_domain(
        "disk",
        &planar::Domain {
            outer: 1.0,
            holes: vec![],
        },
        resolution,
    )
}

/// Smallest accepted ratio `r_in / r_out` of the annulus.
pub const MIN_ANNULUS_RATIO: f64 = 1e-3;

/// Annulus `r_in < |p| < r_out` with `resolution` segments on the outer circle (the inner
/// circle gets the same spacing, at least 8 segments). Meshed at `r_out = 1` and scaled, so
/// only the ratio `r_in / r_out` (at least [`MIN_ANNULUS_RATIO`]) matters.
pub fn annulus(r_in: f64, r_out: f64, resolution: u32) -> Result<Surface> {
    if !(r_in.is_finite() && r_out.is_finite()) || r_in <= 0.0 || r_out <= r_in {
        return Err(Error::input(format!(
            "annulus: the radii must satisfy 0 < inner < outer (got inner = {r_in}, outer = {r_out})"
        )));
    }
    let ratio = r_in / r_out;
    if ratio < MIN_ANNULUS_RATIO {
        return Err(Error::input(format!(
            "annulus: inner / outer = {ratio:e} is too small (at least {MIN_ANNULUS_RATIO})"
        )));
    }
    check_resolution("annulus", resolution, 8)?;
    let max_ratio = annulus_max_ratio(resolution);
    if ratio > max_ratio {
        return Err(Error::input(format!(
            "annulus: inner / outer = {ratio:.4} is too thin for {resolution} segments (at most \
             {max_ratio:.4}: the inner circle must stay a fifth of a segment inside the outer \
             polygon); use more segments or a smaller inner radius"
        )));
    }
    check_planar_size("annulus", PI * (1.0 - ratio * ratio), 1.0, resolution)?;
    let mut s = planar::mesh_domain(
        "annulus",
        &planar::Domain {
            outer: 1.0,
            holes: vec![([0.0, 0.0], ratio)],
        },
        resolution,
    )?;
    for p in &mut s.positions {
        p[0] *= r_out;
        p[1] *= r_out;
    }
    Ok(s)
}

/// Largest inner / outer radius ratio [`annulus`] accepts with `resolution` segments on the
/// outer circle: the inner circle must stay clear of the outer polygon's edges (at distance
/// `cos(π/n)` from the centre) by a fifth of a segment (`2 sin(π/n)`). Thinner annuli could not
/// be triangulated (a boundary vertex shared by two boundary fans); measured on a grid of
/// ratios for n = 8…64, the first failure was at 0.035–0.123 of a segment.
pub fn annulus_max_ratio(resolution: u32) -> f64 {
    let t = PI / resolution.max(3) as f64;
    t.cos() - 0.2 * 2.0 * t.sin()
}

/// Radius and centres of the two holes of [`pair_of_pants`].
pub const PANTS_HOLE_RADIUS: f64 = 0.25;
pub const PANTS_HOLE_CENTERS: [[f64; 2]; 2] = [[-0.45, 0.0], [0.45, 0.0]];

/// Pair of pants: the unit disk minus two round holes of radius 0.25 centred at (±0.45, 0),
/// `resolution` segments on the outer circle (holes sampled with the same spacing, at least
/// 8 segments each).
pub fn pair_of_pants(resolution: u32) -> Result<Surface> {
    check_resolution("pair of pants", resolution, 16)?;
    let area = PI * (1.0 - 2.0 * PANTS_HOLE_RADIUS * PANTS_HOLE_RADIUS);
    check_planar_size("pair of pants", area, 1.0, resolution)?;
    planar::mesh_domain(
        "pair of pants",
        &planar::Domain {
            outer: 1.0,
            holes: PANTS_HOLE_CENTERS
                .iter()
                .map(|&c| (c, PANTS_HOLE_RADIUS))
                .collect(),
        },
        resolution,
    )
}

fn check_planar_size(what: &str, area: f64, outer: f64, resolution: u32) -> Result<()> {
    let h = 2.0 * PI * outer / resolution as f64;
    let faces = 2.0 * area / (3f64.sqrt() / 2.0 * h * h);
    if faces > MAX_FACES as f64 {
        return Err(too_many_faces(what, faces as u64));
    }
    Ok(())
}

/// Largest genus [`genus`] accepts.
pub const MAX_GENUS: u32 = 64;

/// Closed orientable surface of genus `g` (1 ≤ g ≤ [`MAX_GENUS`]): a chain of `g` tori
/// (centre circles of radius 1 in the plane z = 0, centred at `(2i − (g−1), 0, 0)`, tube
/// radius 0.4) blended smoothly where they meet; `resolution` is the number of edges around
/// each handle's centre circle (target edge length `2π / resolution`).
pub fn genus(g: u32, resolution: u32) -> Result<Surface> {
    genus_with_progress(g, resolution, &mut NoProgress)
}

/// [`genus`] reporting the remeshing iterations to `progress`.
pub fn genus_with_progress(
    g: u32,
    resolution: u32,
    progress: &mut dyn Progress,
) -> Result<Surface> {
    if g == 0 || g > MAX_GENUS {
        return Err(Error::input(format!(
            "genus: g = {g} is out of range (1 to {MAX_GENUS}; use the icosphere for genus 0)"
        )));
    }
    check_resolution("genus", resolution, 12)?;
    let field = implicit::ToriChain::new(g);
    let l = 2.0 * PI * field.major / resolution as f64;
    // Area of g tori, an upper bound for the blended surface.
    let area = g as f64 * 4.0 * PI * PI * field.major * field.minor;
    let faces = area / (3f64.sqrt() / 4.0 * l * l);
    if faces > MAX_FACES as f64 {
        return Err(too_many_faces("genus", faces as u64));
    }
    // Grid fine enough to resolve the tubes, the holes and the blends.
    let r = field.minor;
    let spacing = (2.0 * l).clamp(r / 20.0, r / 5.0);
    progress.report("marching", None, "polygonising the implicit surface");
    let (pos, tris) = implicit::marching_tetrahedra(&field, field.bounds(2.0 * spacing), spacing);
    let mut mesh = remesh::TriMesh::new(pos, tris)?;
    let params = remesh::RemeshParams {
        target_edge: l,
        iterations: 12,
        quality_rounds: 4,
    };
    remesh::remesh(&mut mesh, &field, &params, progress);
    let (pos, tris) = mesh.into_parts();
    Surface::new(pos, tris)
}

/// The kinds of procedural surfaces (the `KIND` argument of `ricci generate`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GeneratorKind {
    Sphere,
    Torus,
    Disk,
    Annulus,
    Pants,
    Genus(u32),
}

/// Optional parameters; `None` takes the kind's default. A parameter that a kind does not
/// use is refused by [`generate`].
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct GeneratorParams {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resolution: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdivisions: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub major: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub minor: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inner: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outer: Option<f64>,
}

impl GeneratorParams {
    /// The parameters [`generate`] uses for `kind`: the given ones, with the defaults filled
    /// in for the unset parameters that apply to the kind (for reports).
    pub fn with_defaults(&self, kind: GeneratorKind) -> GeneratorParams {
        let mut p = self.clone();
        match kind {
            GeneratorKind::Sphere => {
                p.subdivisions = p
                    .subdivisions
                    .or(p.resolution)
                    .or(Some(DEFAULT_SUBDIVISIONS));
                p.resolution = None;
            }
            GeneratorKind::Torus => {
                p.major = p.major.or(Some(DEFAULT_MAJOR));
                p.minor = p.minor.or(Some(DEFAULT_MINOR));
            }
            GeneratorKind::Annulus => {
                p.inner = p.inner.or(Some(DEFAULT_INNER));
                p.outer = p.outer.or(Some(DEFAULT_OUTER));
            }
            _ => {}
        }
        if kind != GeneratorKind::Sphere {
            p.resolution = p.resolution.or(Some(default_resolution(&kind)));
        }
        p
    }
}

impl GeneratorKind {
    /// The names accepted by [`GeneratorKind::parse`].
    pub const NAMES: &'static [&'static str] = &[
        "sphere", "torus", "disk", "annulus", "pants", "genus2", "genus3", "genus4", "genus",
    ];

    /// Parse a kind name: `sphere` (or `icosphere`), `torus`, `disk`, `annulus`, `pants` (or
    /// `pair-of-pants`), `genusN` for N ≥ 1, or `genus` together with `genus = Some(N)`.
    pub fn parse(name: &str, genus: Option<u32>) -> Result<GeneratorKind> {
        let lower = name.to_ascii_lowercase();
        let kind =
            match lower.as_str() {
                "sphere" | "icosphere" => GeneratorKind::Sphere,
                "torus" => GeneratorKind::Torus,
                "disk" | "disc" => GeneratorKind::Disk,
                "annulus" => GeneratorKind::Annulus,
                "pants" | "pair-of-pants" | "pair_of_pants" => GeneratorKind::Pants,
                "genus" => match genus {
                    Some(g) => GeneratorKind::Genus(g),
                    None => return Err(Error::input(
                        "the kind `genus` needs the genus (e.g. `--genus 3`, or write `genus3`)",
                    )),
                },
                s if s.starts_with("genus") => match s["genus".len()..].parse::<u32>() {
                    Ok(g) => GeneratorKind::Genus(g),
                    Err(_) => return Err(unknown_kind(name)),
                },
                _ => return Err(unknown_kind(name)),
            };
        if let (Some(g), GeneratorKind::Genus(k)) = (genus, kind) {
            if g != k {
                return Err(Error::input(format!(
                    "`{name}` asks for genus {k} but the genus parameter says {g}"
                )));
            }
        } else if genus.is_some() {
            return Err(Error::input(format!(
                "`{name}` does not take a genus parameter (it is for the kind `genus`)"
            )));
        }
        if let GeneratorKind::Genus(g) = kind {
            if g == 0 || g > MAX_GENUS {
                return Err(Error::input(format!(
                    "genus {g} is out of range (1 to {MAX_GENUS}; use `sphere` for genus 0)"
                )));
            }
        }
        Ok(kind)
    }

    /// Canonical name (`genus2`, `sphere`, …).
    pub fn name(&self) -> String {
        match self {
            GeneratorKind::Sphere => "sphere".into(),
            GeneratorKind::Torus => "torus".into(),
            GeneratorKind::Disk => "disk".into(),
            GeneratorKind::Annulus => "annulus".into(),
            GeneratorKind::Pants => "pants".into(),
            GeneratorKind::Genus(g) => format!("genus{g}"),
        }
    }

    /// The topology the generated surface has: (genus, boundary loops), one component.
    pub fn topology(&self) -> (u32, u32) {
        match self {
            GeneratorKind::Sphere => (0, 0),
            GeneratorKind::Torus => (1, 0),
            GeneratorKind::Disk => (0, 1),
            GeneratorKind::Annulus => (0, 2),
            GeneratorKind::Pants => (0, 3),
            GeneratorKind::Genus(g) => (*g, 0),
        }
    }
}

fn unknown_kind(name: &str) -> Error {
    Error::input(format!(
        "unknown surface kind `{name}` (expected one of: {})",
        GeneratorKind::NAMES.join(", ")
    ))
}

/// Generate a surface of the given kind; unset parameters take their defaults.
pub fn generate(
    kind: GeneratorKind,
    params: &GeneratorParams,
    progress: &mut dyn Progress,
) -> Result<Surface> {
    let name = kind.name();
    let refuse = |flag: &str| {
        Err(Error::input(format!(
            "`{name}` does not take the parameter {flag}"
        )))
    };
    let p = params;
    if !matches!(kind, GeneratorKind::Torus) && (p.major.is_some() || p.minor.is_some()) {
        return refuse(if p.major.is_some() { "major" } else { "minor" });
    }
    if !matches!(kind, GeneratorKind::Annulus) && (p.inner.is_some() || p.outer.is_some()) {
        return refuse(if p.inner.is_some() { "inner" } else { "outer" });
    }
    if matches!(kind, GeneratorKind::Sphere) {
        if p.resolution.is_some() && p.subdivisions.is_some() {
            return Err(Error::input(
                "`sphere` takes either resolution or subdivisions (they mean the same), not both",
            ));
        }
    } else if p.subdivisions.is_some() {
        return refuse("subdivisions");
    }
    let res = p.resolution.unwrap_or_else(|| default_resolution(&kind));
    match kind {
        GeneratorKind::Sphere => icosphere(p.subdivisions.unwrap_or(res)),
        GeneratorKind::Torus => torus(
            p.major.unwrap_or(DEFAULT_MAJOR),
            p.minor.unwrap_or(DEFAULT_MINOR),
            res,
        ),
        GeneratorKind::Disk => disk(res),
        GeneratorKind::Annulus => annulus(
            p.inner.unwrap_or(DEFAULT_INNER),
            p.outer.unwrap_or(DEFAULT_OUTER),
            res,
        ),
        GeneratorKind::Pants => pair_of_pants(res),
        GeneratorKind::Genus(g) => genus_with_progress(g, res, progress),
    }
}
