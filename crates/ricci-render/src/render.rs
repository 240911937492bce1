//! The software renderer: z-buffered triangles with supersampling, smooth shading and paints.
//!
//! Pipeline (all at `supersample²` samples per pixel):
//! 1. smooth vertex normals (angle-weighted face normals), camera framing ([`Camera::frame`]);
//! 2. **visibility pass**: triangles are binned into horizontal bands and rasterized in
//!    parallel with edge functions; each sample keeps the nearest face id and a depth key that
//!    is affine in screen space (−depth for orthographic, 1/depth for perspective cameras);
//! 3. **overlay pass**: polylines are drawn as capsules, depth-tested against the visibility
//!    buffer after moving them towards the camera by a small offset (no z-fighting);
//! 4. **shading pass** (parallel over rows): per sample, perspective-correct barycentrics give
//!    the normal, UV or scalar; the paint gives the albedo (checkerboard and circles are
//!    box-filtered analytically with the UV footprint of the sample); two-sided Lambert +
//!    Blinn–Phong lighting in linear light; the wireframe is the screen-space distance to the
//!    triangle's edges (so it is depth-tested and anti-aliased for free); samples are averaged
//!    in linear light and stored as 8-bit sRGB;
//! 5. the legend (colour bar with min/max labels) is drawn in a strip on the right.

use crate::camera::{self, Camera, View};
use crate::color::{self, normalize, Colormap, Rgb, ScalarRange};
use crate::font;
use crate::image::Image;
use crate::{check_mesh, input_err, Result};
use rayon::prelude::*;

mod legend;
mod shade;

use legend::Legend;
use shade::{Resolve, Shader, SrgbLut};

/// Texture coordinates: one per vertex, or one per corner (corner `3f + i` is vertex `i` of
/// face `f`, as in OBJ files whose `vt` indices differ from the `v` indices at seams).
#[derive(Debug, Clone, Copy)]
pub enum Uvs<'a> {
    PerVertex(&'a [[f64; 2]]),
    PerCorner(&'a [[f64; 2]]),
}

impl Uvs<'_> {
    #[inline]
    fn corner(&self, tris: &[[u32; 3]], f: usize, i: usize) -> [f64; 2] {
        match self {
            Uvs::PerVertex(uv) => uv[tris[f][i] as usize],
            Uvs::PerCorner(uv) => uv[3 * f + i],
        }
    }

    fn check(&self, n_vertices: usize, n_faces: usize) -> Result<()> {
        let (uv, want, what) = match self {
            Uvs::PerVertex(uv) => (uv, n_vertices, "vertex"),
            Uvs::PerCorner(uv) => (uv, 3 * n_faces, "corner"),
        };
        if uv.len() != want {
            return input_err(format!(
                "there are {} texture coordinates, but the mesh has {want} {what}s",
                uv.len()
            ));
        }
        if let Some(i) = uv
            .iter()
            .position(|p| !p[0].is_finite() || !p[1].is_finite())
        {
            return input_err(format!("texture coordinate of {what} {i} is not finite"));
        }
        Ok(())
    }
}

/// The classic checkerboard texture of conformal parameterizations (paper 001 Fig. 4f, 7c).
#[derive(Debug, Clone, Copy)]
pub struct Checker<'a> {
    pub uvs: Uvs<'a>,
    /// Checks per unit of UV (the square [0,1]² shows `frequency²` checks).
    pub frequency: f64,
    pub dark: Rgb,
    pub light: Rgb,
}

impl<'a> Checker<'a> {
    /// Black and white checks.
    pub fn new(uvs: Uvs<'a>, frequency: f64) -> Self {
        Checker {
            uvs,
            frequency,
            dark: [0.06, 0.06, 0.06],
            light: [1.0, 1.0, 1.0],
        }
    }
}

/// Circles on a square lattice in UV space, the picture of conformality of paper 001 Fig. 1:
/// conformal maps send small circles to small circles.
#[derive(Debug, Clone, Copy)]
pub struct Circles<'a> {
    pub uvs: Uvs<'a>,
    /// Circles per unit of UV.
    pub frequency: f64,
    /// Radius relative to the lattice spacing (0.5 = touching circles).
    pub radius: f64,
    pub ink: Rgb,
    pub paper: Rgb,
}

impl<'a> Circles<'a> {
    pub fn new(uvs: Uvs<'a>, frequency: f64) -> Self {
        Circles {
            uvs,
            frequency,
            radius: 0.42,
            ink: [0.13, 0.33, 0.62],
            paper: [0.97, 0.96, 0.92],
        }
    }
}

/// Whether a scalar field has one value per vertex (interpolated) or per face (constant).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScalarLocation {
    Vertex,
    Face,
}

/// A scalar field shown through a colormap.
#[derive(Debug, Clone)]
pub struct Scalar<'a> {
    pub values: &'a [f64],
    pub location: ScalarLocation,
    pub colormap: Colormap,
    pub range: ScalarRange,
    /// Number of isolines drawn across the range (0 = none).
    pub isolines: u32,
    /// Name shown above the legend.
    pub label: String,
}

impl<'a> Scalar<'a> {
    /// Per-vertex values, min–max range (symmetric around 0 for diverging maps).
    pub fn per_vertex(values: &'a [f64], colormap: Colormap) -> Self {
        Scalar {
            values,
            location: ScalarLocation::Vertex,
            colormap,
            range: if colormap.is_diverging() {
                ScalarRange::Symmetric
            } else {
                ScalarRange::MinMax
            },
            isolines: 0,
            label: String::new(),
        }
    }

    /// Per-face values.
    pub fn per_face(values: &'a [f64], colormap: Colormap) -> Self {
        Scalar {
            location: ScalarLocation::Face,
            ..Scalar::per_vertex(values, colormap)
        }
    }
}

/// Reflection lines: the surface mirrors an environment of parallel light stripes fixed to the
/// view, so discontinuities of the normal (C¹ defects) show as kinks and breaks in the stripes
/// and curvature discontinuities (C² defects) as kinks in their width.
#[derive(Debug, Clone, Copy)]
pub struct Zebra {
    /// Number of black/white stripe pairs over a half turn of the reflected direction.
    pub stripes: f64,
    pub dark: Rgb,
    pub light: Rgb,
}

impl Default for Zebra {
    fn default() -> Self {
        Zebra {
            stripes: 10.0,
            dark: [0.05, 0.05, 0.05],
            light: [0.98, 0.98, 0.98],
        }
    }
}

/// What colour the surface has before lighting.
#[derive(Debug, Clone)]
pub enum Paint<'a> {
    Solid(Rgb),
    Checker(Checker<'a>),
    Circles(Circles<'a>),
    Scalar(Scalar<'a>),
    Zebra(Zebra),
    /// One sRGB colour per face (atlas charts, patches, spline pieces; see
    /// [`crate::color::categorical`]).
    FaceColors(&'a [Rgb]),
}

impl Default for Paint<'_> {
    fn default() -> Self {
        Paint::Solid([0.78, 0.80, 0.84])
    }
}

/// Triangle edges drawn on the visible surface.
#[derive(Debug, Clone, Copy)]
pub struct Wireframe {
    pub color: Rgb,
    /// Line width in output pixels.
    pub width: f32,
    /// Opacity in [0, 1].
    pub opacity: f32,
}

impl Default for Wireframe {
    fn default() -> Self {
        Wireframe {
            color: [0.08, 0.08, 0.1],
            width: 1.0,
            opacity: 0.75,
        }
    }
}

/// A polyline on (or near) the surface: cut loops, patch boundaries, geodesics.
#[derive(Debug, Clone)]
pub struct Polyline {
    pub points: Vec<[f64; 3]>,
    pub color: Rgb,
    /// Width in output pixels.
    pub width: f32,
    /// Join the last point to the first.
    pub closed: bool,
}

/// Everything drawn on the mesh.
#[derive(Debug, Clone, Default)]
pub struct Style<'a> {
    pub paint: Paint<'a>,
    pub wireframe: Option<Wireframe>,
    pub polylines: Vec<Polyline>,
    /// Draw a colour bar for scalar paints.
    pub legend: bool,
}

/// Behind the object.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Background {
    #[default]
    White,
    Transparent,
    Color(Rgb),
}

/// How the surface is lit.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Lighting {
    /// Key and fill lights (Lambert) with a Blinn–Phong highlight, two-sided.
    #[default]
    Studio,
    /// No lighting: every sample shows its paint colour exactly ("shading-free").
    Unlit,
}

/// Image size, camera, background, lighting and anti-aliasing.
#[derive(Debug, Clone, Copy)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel along each axis (1 = no anti-aliasing; 3 = 9 samples).
    pub supersample: u32,
    pub view: View,
    pub background: Background,
    pub lighting: Lighting,
    /// Polylines are moved towards the camera by this fraction of the bounding radius.
    pub line_offset: f64,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 1024,
            height: 1024,
            supersample: 3,
            view: View::default(),
            background: Background::White,
            lighting: Lighting::Studio,
            line_offset: 0.01,
        }
    }
}

/// A rendered picture with what was measured while making it.
#[derive(Debug, Clone)]
pub struct Rendered {
    pub image: Image,
    /// The camera used (its viewport excludes the legend strip).
    pub camera: Camera,
    /// Fraction of the image covered by the object (from the visibility samples).
    pub coverage: f64,
    /// Range used for the scalar colour scale, if any.
    pub scalar_range: Option<(f64, f64)>,
}

impl Rendered {
    /// The picture as PNG bytes.
    pub fn png(&self) -> Result<Vec<u8>> {
        self.image.to_png()
    }
}

const NO_FACE: u32 = u32::MAX;
/// Upper bound on supersampled pixels (8 bytes each in the visibility buffers: 2 GiB).
const MAX_SAMPLES: u64 = 1 << 28;
const BAND: usize = 32;

/// Render a triangle mesh and encode it as PNG bytes (see [`render`]).
pub fn render_png(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    style: &Style,
    opts: &RenderOptions,
) -> Result<Vec<u8>> {
    render(positions, triangles, style, opts)?.png()
}

/// Render a triangle mesh.
pub fn render(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    style: &Style,
    opts: &RenderOptions,
) -> Result<Rendered> {
    let scalar_range = check_inputs(positions, triangles, style, opts)?;

    // Legend strip on the right.
    let legend = match (&style.paint, style.legend, scalar_range) {
        (Paint::Scalar(s), true, Some(r)) => Some(Legend::new(s, r, opts.width, opts.height)),
        _ => None,
    };
    let strip = legend.as_ref().map_or(0, |l| l.strip_width);
    let viewport = [0.0, 0.0, (opts.width - strip) as f64, opts.height as f64];
    let cam = Camera::frame(positions, &opts.view, viewport)?;
    let ss = opts.supersample as usize;
    let scam = cam.scaled(ss as f64);
    let (sw, sh) = (opts.width as usize * ss, opts.height as usize * ss);

    // Per-vertex screen data and camera-space normals.
    let normals = vertex_normals(positions, triangles);
    let perspective = matches!(cam.projection, camera::Projection::Perspective { .. });
    let verts = screen_vertices(positions, &normals, &cam, &scam, perspective);

    // 2. Visibility.
    let setups: Vec<Option<Setup>> = triangles
        .par_iter()
        .map(|t| {
            let v = t.map(|i| &verts[i as usize]);
            if v[0].valid && v[1].valid && v[2].valid {
                Setup::new(v)
            } else {
                None
            }
        })
        .collect();
    let (ids, depth) = rasterize(&verts, triangles, &setups, sw, sh);

    // 3. Polylines.
    let lines = if style.polylines.is_empty() {
        None
    } else {
        Some(draw_polylines(
            &style.polylines,
            &scam,
            perspective,
            opts.line_offset * cam.radius,
            &depth,
            &ids,
            sw,
            sh,
            ss,
        ))
    };

    // 4. Shading and resolve. Each pixel shades every distinct face among its samples once,
    // at the centroid of that face's samples (centroid sampling), and weights it by the
    // number of samples; textures and lines are filtered analytically over the pixel.
    let shader = Shader::new(
        style,
        opts,
        &verts,
        triangles,
        &setups,
        perspective,
        scalar_range,
        ss,
    );
    let bg = match opts.background {
        Background::White => ([1.0f32, 1.0, 1.0], 1.0f32),
        Background::Transparent => ([0.0, 0.0, 0.0], 0.0),
        Background::Color(c) => (color::to_linear(c), 1.0),
    };
    let (w, h) = (opts.width as usize, opts.height as usize);
    let mut data = vec![0u8; 4 * w * h];
    let resolve = Resolve {
        ids: &ids,
        lines: lines.as_ref(),
        shader: &shader,
        bg,
        lut: SrgbLut::new(),
        ss,
        sw,
        w,
    };
    let covered: usize = data
        .par_chunks_mut(4 * w)
        .enumerate()
        .map(|(py, row)| resolve.row(py, row))
        .sum();
    let mut image = Image {
        width: opts.width,
        height: opts.height,
        data,
    };
    if let (Some(l), Paint::Scalar(s)) = (&legend, &style.paint) {
        l.draw(&mut image, s, opts.background);
    }
    Ok(Rendered {
        image,
        camera: cam,
        coverage: covered as f64 / (sw * sh) as f64,
        scalar_range,
    })
}

/// The checks of [`render`]'s inputs; the scalar paint's range when there is one.
fn check_inputs(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    style: &Style,
    opts: &RenderOptions,
) -> Result<Option<(f64, f64)>> {
    check_mesh(positions, triangles)?;
    if opts.width == 0 || opts.height == 0 || opts.width > 16384 || opts.height > 16384 {
        return input_err(format!(
            "image size {}x{} must be between 1 and 16384 pixels per side",
            opts.width, opts.height
        ));
    }
    if !(1..=8).contains(&opts.supersample) {
        return input_err(format!(
            "supersampling {} must be between 1 and 8",
            opts.supersample
        ));
    }
    let samples = (opts.width as u64 * opts.supersample as u64)
        * (opts.height as u64 * opts.supersample as u64);
    if samples > MAX_SAMPLES {
        return input_err(format!(
            "{}x{} pixels with {}x{} supersampling need {samples} samples, more than the {MAX_SAMPLES} this renderer allows; lower the size or the supersampling",
            opts.width, opts.height, opts.supersample, opts.supersample
        ));
    }
    let (nv, nf) = (positions.len(), triangles.len());
    let scalar_range = check_paint(&style.paint, nv, nf)?;
    for (k, pl) in style.polylines.iter().enumerate() {
        if let Some(i) = pl
            .points
            .iter()
            .position(|p| !p.iter().all(|x| x.is_finite()))
        {
            return input_err(format!("point {i} of polyline {k} is not finite"));
        }
    }
    Ok(scalar_range)
}

/// Per-vertex screen data (on the supersampled camera `scam`) and camera-space normals and
/// positions (on `cam`).
fn screen_vertices(
    positions: &[[f64; 3]],
    normals: &[[f64; 3]],
    cam: &Camera,
    scam: &Camera,
    perspective: bool,
) -> Vec<ScreenVertex> {
    positions
        .par_iter()
        .zip(normals.par_iter())
        .map(|(p, n)| {
            let s = scam.project(*p);
            let d = s.depth;
            let (q, w) = if perspective {
                (1.0 / d.max(1e-30), 1.0 / d.max(1e-30))
            } else {
                (-d, 1.0)
            };
            let rel = camera::sub(*p, cam.eye);
            ScreenVertex {
                x: s.x as f32,
                y: s.y as f32,
                q: q as f32,
                w: w as f32,
                valid: d > 1e-9 * cam.radius,
                n: [
                    camera::dot(*n, cam.right) as f32,
                    camera::dot(*n, cam.up) as f32,
                    camera::dot(*n, cam.back) as f32,
                ],
                p: [
                    camera::dot(rel, cam.right) as f32,
                    camera::dot(rel, cam.up) as f32,
                    camera::dot(rel, cam.back) as f32,
                ],
            }
        })
        .collect()
}

fn check_paint(paint: &Paint, nv: usize, nf: usize) -> Result<Option<(f64, f64)>> {
    let freq_ok = |f: f64| {
        if f.is_finite() && f > 0.0 {
            Ok(())
        } else {
            input_err(format!("the texture frequency {f} must be positive"))
        }
    };
    match paint {
        Paint::Checker(c) => {
            c.uvs.check(nv, nf)?;
            freq_ok(c.frequency)?;
        }
        Paint::Circles(c) => {
            c.uvs.check(nv, nf)?;
            freq_ok(c.frequency)?;
            if !(c.radius > 0.0 && c.radius <= 0.5) {
                return input_err(format!(
                    "the circle radius {} must be in (0, 0.5] of the lattice spacing",
                    c.radius
                ));
            }
        }
        Paint::Scalar(s) => {
            let (want, what) = match s.location {
                ScalarLocation::Vertex => (nv, "vertices"),
                ScalarLocation::Face => (nf, "faces"),
            };
            if s.values.len() != want {
                return input_err(format!(
                    "the scalar field has {} values, but the mesh has {want} {what}",
                    s.values.len()
                ));
            }
            let r = s.range.resolve(s.values).ok_or_else(|| {
                crate::Error::Input("the scalar field has no finite value".into())
            })?;
            return Ok(Some(r));
        }
        Paint::Zebra(z) => freq_ok(z.stripes)?,
        Paint::Solid(_) => {}
        Paint::FaceColors(c) => {
            if c.len() != nf {
                return input_err(format!(
                    "there are {} face colours, but the mesh has {nf} faces",
                    c.len()
                ));
            }
        }
    }
    Ok(None)
}

/// Angle-weighted vertex normals (Thürmer–Wüthrich); zero for isolated vertices.
pub fn vertex_normals(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut n = vec![[0.0f64; 3]; positions.len()];
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        let fnrm = match camera::normalize(camera::cross(
            camera::sub(p[1], p[0]),
            camera::sub(p[2], p[0]),
        )) {
            Some(v) => v,
            None => continue,
        };
        for i in 0..3 {
            let a = camera::sub(p[(i + 1) % 3], p[i]);
            let b = camera::sub(p[(i + 2) % 3], p[i]);
            let (la, lb) = (camera::norm(a), camera::norm(b));
            if la == 0.0 || lb == 0.0 {
                continue;
            }
            let ang = (camera::dot(a, b) / (la * lb)).clamp(-1.0, 1.0).acos();
            let v = &mut n[t[i] as usize];
            for k in 0..3 {
                v[k] += ang * fnrm[k];
            }
        }
    }
    for v in &mut n {
        *v = camera::normalize(*v).unwrap_or([0.0; 3]);
    }
    n
}

#[derive(Debug, Clone, Copy)]
struct ScreenVertex {
    x: f32,
    y: f32,
    /// Depth key, affine in screen space; larger is nearer.
    q: f32,
    /// 1 / depth for perspective cameras, 1 for orthographic ones.
    w: f32,
    valid: bool,
    /// Normal and position in camera coordinates (x right, y up, z towards the viewer).
    n: [f32; 3],
    p: [f32; 3],
}

/// Edge functions of a screen triangle: λ_i = a_i x + b_i y + c_i.
#[derive(Debug, Clone, Copy)]
struct Setup {
    a: [f32; 3],
    b: [f32; 3],
    c: [f32; 3],
}

impl Setup {
    #[inline]
    fn new(v: [&ScreenVertex; 3]) -> Option<Setup> {
        let area2 = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[1].y - v[0].y) * (v[2].x - v[0].x);
        if area2.is_nan() || area2.abs() <= 1e-12 {
            return None;
        }
        let inv = 1.0 / area2;
        let mut s = Setup {
            a: [0.0; 3],
            b: [0.0; 3],
            c: [0.0; 3],
        };
        for i in 0..3 {
            // λ_i is the signed area of (v_{i+1}, v_{i+2}, p) over the total.
            let (p, q) = (v[(i + 1) % 3], v[(i + 2) % 3]);
            s.a[i] = -(q.y - p.y) * inv;
            s.b[i] = (q.x - p.x) * inv;
            s.c[i] = ((q.y - p.y) * p.x - (q.x - p.x) * p.y) * inv;
        }
        Some(s)
    }

    #[inline]
    fn bary(&self, x: f32, y: f32) -> [f32; 3] {
        [
            self.a[0] * x + self.b[0] * y + self.c[0],
            self.a[1] * x + self.b[1] * y + self.c[1],
            self.a[2] * x + self.b[2] * y + self.c[2],
        ]
    }
}

fn rasterize(
    verts: &[ScreenVertex],
    tris: &[[u32; 3]],
    setups: &[Option<Setup>],
    sw: usize,
    sh: usize,
) -> (Vec<u32>, Vec<f32>) {
    let nbands = sh.div_ceil(BAND);
    // Bin triangles by the bands their vertical extent overlaps.
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); nbands];
    for (f, t) in tris.iter().enumerate() {
        if setups[f].is_none() {
            continue;
        }
        let v = t.map(|i| &verts[i as usize]);
        let ymin = v[0].y.min(v[1].y).min(v[2].y);
        let ymax = v[0].y.max(v[1].y).max(v[2].y);
        if !(ymax >= 0.0 && ymin <= sh as f32) {
            continue;
        }
        let b0 = ((ymin - 0.5).max(0.0) as usize / BAND).min(nbands - 1);
        let b1 = ((ymax.max(0.0) as usize) / BAND).min(nbands - 1);
        for bin in &mut bins[b0..=b1] {
            bin.push(f as u32);
        }
    }
    let mut ids = vec![NO_FACE; sw * sh];
    let mut depth = vec![f32::NEG_INFINITY; sw * sh];
    ids.par_chunks_mut(BAND * sw)
        .zip(depth.par_chunks_mut(BAND * sw))
        .zip(bins.par_iter())
        .enumerate()
        .for_each(|(band, ((ids, depth), bin))| {
            let y0 = band * BAND;
            let y1 = (y0 + BAND).min(sh);
            const EPS: f32 = -1e-6;
            for &f in bin {
                let t = tris[f as usize];
                let v = t.map(|i| &verts[i as usize]);
                let Some(s) = setups[f as usize] else {
                    continue;
                };
                let ymin = v[0].y.min(v[1].y).min(v[2].y);
                let ymax = v[0].y.max(v[1].y).max(v[2].y);
                let xmin = v[0].x.min(v[1].x).min(v[2].x);
                let xmax = v[0].x.max(v[1].x).max(v[2].x);
                let ya = (fceil(ymin - 0.5).max(y0 as f32)) as usize;
                let yb = (ffloor(ymax - 0.5).min(y1 as f32 - 1.0)).max(-1.0);
                if yb < 0.0 || (yb as usize) < ya {
                    continue;
                }
                let yb = yb as usize;
                let xa0 = fceil(xmin - 0.5).max(0.0);
                let xb0 = ffloor(xmax - 0.5).min(sw as f32 - 1.0);
                if xb0 < xa0 {
                    continue;
                }
                // depth key plane
                let qa = s.a[0] * v[0].q + s.a[1] * v[1].q + s.a[2] * v[2].q;
                let qb = s.b[0] * v[0].q + s.b[1] * v[1].q + s.b[2] * v[2].q;
                let qc = s.c[0] * v[0].q + s.c[1] * v[1].q + s.c[2] * v[2].q;
                for y in ya..=yb {
                    let yc = y as f32 + 0.5;
                    // Row interval where all three λ_i ≥ EPS.
                    let (mut lo, mut hi) = (xa0, xb0);
                    for i in 0..3 {
                        let r = s.b[i] * yc + s.c[i];
                        let a = s.a[i];
                        if a > 0.0 {
                            lo = lo.max(fceil((EPS - r) / a - 0.5));
                        } else if a < 0.0 {
                            hi = hi.min(ffloor((EPS - r) / a - 0.5));
                        } else if r < EPS {
                            hi = -1.0;
                        }
                    }
                    if hi < lo {
                        continue;
                    }
                    let row = (y - y0) * sw;
                    for x in lo as usize..=hi as usize {
                        let xc = x as f32 + 0.5;
                        let q = qa * xc + qb * yc + qc;
                        let k = row + x;
                        if q > depth[k] {
                            depth[k] = q;
                            ids[k] = f;
                        }
                    }
                }
            }
        });
    (ids, depth)
}

struct LineBuffer {
    coverage: Vec<f32>,
    color_index: Vec<u16>,
    colors: Vec<Rgb>,
}

#[allow(clippy::too_many_arguments)]
fn draw_polylines(
    lines: &[Polyline],
    scam: &Camera,
    perspective: bool,
    offset: f64,
    depth: &[f32],
    ids: &[u32],
    sw: usize,
    sh: usize,
    ss: usize,
) -> LineBuffer {
    let mut buf = LineBuffer {
        coverage: vec![0.0; sw * sh],
        color_index: vec![0; sw * sh],
        colors: Vec::new(),
    };
    for (k, pl) in lines.iter().enumerate() {
        buf.colors.push(color::to_linear(pl.color));
        let ci = (k.min(u16::MAX as usize)) as u16;
        let hw = 0.5 * pl.width.max(0.1) * ss as f32;
        // Project each point after moving it towards the viewer.
        let pts: Vec<Option<(f32, f32, f32)>> = pl
            .points
            .iter()
            .map(|p| {
                let p = camera::add(*p, camera::scale(scam.to_viewer(*p), offset));
                let s = scam.project(p);
                (s.depth > 1e-9 * scam.radius).then(|| {
                    let q = if perspective { 1.0 / s.depth } else { -s.depth };
                    (s.x as f32, s.y as f32, q as f32)
                })
            })
            .collect();
        let n = pts.len();
        let nseg = if pl.closed && n > 2 {
            n
        } else {
            n.saturating_sub(1)
        };
        for i in 0..nseg {
            let (Some(a), Some(b)) = (pts[i], pts[(i + 1) % n]) else {
                continue;
            };
            let x0 = ((a.0.min(b.0) - hw - 1.0).floor().max(0.0)) as usize;
            let x1 = ((a.0.max(b.0) + hw + 1.0).ceil().min(sw as f32 - 1.0)).max(0.0) as usize;
            let y0 = ((a.1.min(b.1) - hw - 1.0).floor().max(0.0)) as usize;
            let y1 = ((a.1.max(b.1) + hw + 1.0).ceil().min(sh as f32 - 1.0)).max(0.0) as usize;
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let len2 = dx * dx + dy * dy;
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                    let t = if len2 > 0.0 {
                        (((px - a.0) * dx + (py - a.1) * dy) / len2).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    let (cx, cy) = (a.0 + t * dx - px, a.1 + t * dy - py);
                    let d = (cx * cx + cy * cy).sqrt();
                    let cov = (hw - d + 0.5).clamp(0.0, 1.0);
                    if cov <= 0.0 {
                        continue;
                    }
                    let k = y * sw + x;
                    let q = a.2 + t * (b.2 - a.2);
                    let visible = ids[k] == NO_FACE || q >= depth[k];
                    if visible && cov > buf.coverage[k] {
                        buf.coverage[k] = cov;
                        buf.color_index[k] = ci;
                    }
                }
            }
        }
    }
    buf
}

#[inline(always)]
fn ffloor(x: f32) -> f32 {
    let t = x as i32 as f32;
    if t > x {
        t - 1.0
    } else {
        t
    }
}
#[inline(always)]
fn fceil(x: f32) -> f32 {
    let t = x as i32 as f32;
    if t < x {
        t + 1.0
    } else {
        t
    }
}
#[inline(always)]
fn fround(x: f32) -> f32 {
    ffloor(x + 0.5)
}
