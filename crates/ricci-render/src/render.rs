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
    let verts: Vec<ScreenVertex> = positions
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
        .collect();

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
    let lut = SrgbLut::new();
    let (w, h) = (opts.width as usize, opts.height as usize);
    let mut data = vec![0u8; 4 * w * h];
    let covered: usize = data
        .par_chunks_mut(4 * w)
        .enumerate()
        .map(|(py, row)| {
            let mut covered = 0usize;
            let n = ss * ss;
            let inv_n = 1.0 / n as f32;
            let mut faces = [0u32; 64];
            let mut count = [0u32; 64];
            let mut sum = [[0.0f32; 2]; 64];
            let mut group = [0u8; 64];
            let mut colors = [[0.0f32; 3]; 64];
            for px in 0..w {
                let mut nd = 0usize;
                let mut k = 0usize;
                for sy in py * ss..(py + 1) * ss {
                    for sx in px * ss..(px + 1) * ss {
                        let f = ids[sy * sw + sx];
                        let j = match faces[..nd].iter().position(|&g| g == f) {
                            Some(j) => j,
                            None => {
                                faces[nd] = f;
                                count[nd] = 0;
                                sum[nd] = [0.0; 2];
                                nd += 1;
                                nd - 1
                            }
                        };
                        count[j] += 1;
                        sum[j][0] += sx as f32 + 0.5;
                        sum[j][1] += sy as f32 + 0.5;
                        group[k] = j as u8;
                        k += 1;
                    }
                }
                let mut acc = [0.0f32; 4];
                for j in 0..nd {
                    let c = count[j] as f32;
                    if faces[j] == NO_FACE {
                        colors[j] = bg.0;
                        for q in 0..3 {
                            acc[q] += bg.0[q] * bg.1 * c;
                        }
                        acc[3] += bg.1 * c;
                    } else {
                        covered += count[j] as usize;
                        let col = shader.shade(faces[j], sum[j][0] / c, sum[j][1] / c);
                        colors[j] = col;
                        for q in 0..3 {
                            acc[q] += col[q] * c;
                        }
                        acc[3] += c;
                    }
                }
                if let Some(l) = &lines {
                    // Redo the pixel per sample where a line covers it.
                    let mut k = 0usize;
                    let mut any = false;
                    for sy in py * ss..(py + 1) * ss {
                        for sx in px * ss..(px + 1) * ss {
                            any |= l.coverage[sy * sw + sx] > 0.0;
                        }
                    }
                    if any {
                        acc = [0.0; 4];
                        for sy in py * ss..(py + 1) * ss {
                            for sx in px * ss..(px + 1) * ss {
                                let i = sy * sw + sx;
                                let j = group[k] as usize;
                                k += 1;
                                let mut c = colors[j];
                                let mut a = if faces[j] == NO_FACE { bg.1 } else { 1.0 };
                                let cov = l.coverage[i];
                                if cov > 0.0 {
                                    let lc = l.colors[l.color_index[i] as usize];
                                    for q in 0..3 {
                                        c[q] = c[q] * a + cov * (lc[q] - c[q] * a);
                                    }
                                    a += cov * (1.0 - a);
                                    if a > 0.0 {
                                        c = c.map(|x| x / a);
                                    }
                                }
                                for q in 0..3 {
                                    acc[q] += c[q] * a;
                                }
                                acc[3] += a;
                            }
                        }
                    }
                }
                let o = &mut row[4 * px..4 * px + 4];
                if acc[3] > 0.0 {
                    for q in 0..3 {
                        o[q] = lut.encode(acc[q] / acc[3]);
                    }
                }
                o[3] = fround(acc[3] * inv_n * 255.0) as u8;
            }
            covered
        })
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

/// Linear light → 8-bit sRGB through a table.
struct SrgbLut(Vec<u8>);

impl SrgbLut {
    const N: usize = 4096;
    fn new() -> Self {
        SrgbLut(
            (0..Self::N)
                .map(|i| {
                    let c = i as f32 / (Self::N - 1) as f32;
                    (color::linear_to_srgb(c) * 255.0).round() as u8
                })
                .collect(),
        )
    }
    #[inline]
    fn encode(&self, c: f32) -> u8 {
        let i = (c.clamp(0.0, 1.0) * (Self::N - 1) as f32 + 0.5) as usize;
        self.0[i.min(Self::N - 1)]
    }
}

/// Colormap tabulated in linear light for fast lookup.
struct LinearMap(Vec<Rgb>);

impl LinearMap {
    fn new(map: Colormap) -> Self {
        LinearMap(
            (0..=1024)
                .map(|i| color::to_linear(map.eval(i as f64 / 1024.0)))
                .collect(),
        )
    }
    #[inline]
    fn eval(&self, t: f32) -> Rgb {
        let x = t.clamp(0.0, 1.0) * 1024.0;
        let i = (x as usize).min(1023);
        let f = x - i as f32;
        let (a, b) = (self.0[i], self.0[i + 1]);
        [
            a[0] + f * (b[0] - a[0]),
            a[1] + f * (b[1] - a[1]),
            a[2] + f * (b[2] - a[2]),
        ]
    }
}

struct Shader<'a> {
    paint: &'a Paint<'a>,
    wire: Option<Wireframe>,
    wire_color: Rgb,
    verts: &'a [ScreenVertex],
    tris: &'a [[u32; 3]],
    setups: &'a [Option<Setup>],
    perspective: bool,
    lit: bool,
    ss: f32,
    two_colors: [Rgb; 2],
    map: Option<LinearMap>,
    range: (f64, f64),
    light1: [f32; 3],
    light2: [f32; 3],
}

const NAN_COLOR: Rgb = [0.25, 0.25, 0.25];

impl<'a> Shader<'a> {
    #[allow(clippy::too_many_arguments)]
    fn new(
        style: &'a Style<'a>,
        opts: &RenderOptions,
        verts: &'a [ScreenVertex],
        tris: &'a [[u32; 3]],
        setups: &'a [Option<Setup>],
        perspective: bool,
        range: Option<(f64, f64)>,
        ss: usize,
    ) -> Self {
        let two = match &style.paint {
            Paint::Checker(c) => [c.dark, c.light],
            Paint::Circles(c) => [c.ink, c.paper],
            Paint::Zebra(z) => [z.dark, z.light],
            Paint::Solid(c) => [*c, *c],
            Paint::FaceColors(_) => [[0.0; 3], [0.0; 3]],
            Paint::Scalar(_) => [[0.0; 3], [0.0; 3]],
        };
        let map = match &style.paint {
            Paint::Scalar(s) => Some(LinearMap::new(s.colormap)),
            _ => None,
        };
        let n = |v: [f32; 3]| {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|c| c / l)
        };
        Shader {
            paint: &style.paint,
            wire: style.wireframe,
            wire_color: style
                .wireframe
                .map_or([0.0; 3], |w| color::to_linear(w.color)),
            verts,
            tris,
            setups,
            perspective,
            lit: opts.lighting == Lighting::Studio,
            ss: ss as f32,
            two_colors: two.map(color::to_linear),
            map,
            range: range.unwrap_or((0.0, 1.0)),
            light1: n([-0.45, 0.55, 0.75]),
            light2: n([0.7, -0.15, 0.6]),
        }
    }

    /// Linear-light colour of face `f` at sample position (x, y).
    #[inline]
    fn shade(&self, f: u32, x: f32, y: f32) -> Rgb {
        let fi = f as usize;
        let t = self.tris[fi];
        let v = t.map(|i| &self.verts[i as usize]);
        let Some(s) = self.setups[fi] else {
            return [0.5; 3];
        };
        let l = s.bary(x, y);
        // Perspective-correct barycentrics.
        let lp = if self.perspective {
            let w = [l[0] * v[0].w, l[1] * v[1].w, l[2] * v[2].w];
            let sum = w[0] + w[1] + w[2];
            if sum.abs() > 0.0 {
                w.map(|c| c / sum)
            } else {
                l
            }
        } else {
            l
        };
        let mut n = [0.0f32; 3];
        for k in 0..3 {
            n[k] = lp[0] * v[0].n[k] + lp[1] * v[1].n[k] + lp[2] * v[2].n[k];
        }
        let nl = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if nl > 1e-12 {
            n = n.map(|c| c / nl);
        } else {
            n = face_normal(v);
        }
        let view = if self.perspective {
            let mut p = [0.0f32; 3];
            for k in 0..3 {
                p[k] = lp[0] * v[0].p[k] + lp[1] * v[1].p[k] + lp[2] * v[2].p[k];
            }
            let pl = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt().max(1e-30);
            p.map(|c| -c / pl)
        } else {
            [0.0, 0.0, 1.0]
        };
        let mut ndv = n[0] * view[0] + n[1] * view[1] + n[2] * view[2];
        let back = ndv < 0.0
            && face_normal(v)
                .iter()
                .zip(view)
                .map(|(a, b)| a * b)
                .sum::<f32>()
                < 0.0;
        if ndv < 0.0 {
            n = n.map(|c| -c);
            ndv = -ndv;
        }

        let (mut albedo, shiny) = match self.paint {
            Paint::Solid(_) => (self.two_colors[0], true),
            Paint::FaceColors(c) => (color::to_linear(c[fi]), true),
            Paint::Checker(c) => {
                let (uv, fw) = self.uv_and_footprint(&c.uvs, fi, &s, lp, c.frequency);
                let a = checker(uv[0], fw[0]) * checker(uv[1], fw[1]);
                let m = 0.5 + 0.5 * a;
                (mix(self.two_colors[0], self.two_colors[1], m), true)
            }
            Paint::Circles(c) => {
                let (uv, fw) = self.uv_and_footprint(&c.uvs, fi, &s, lp, c.frequency);
                let (fx, fy) = (uv[0] - ffloor(uv[0]) - 0.5, uv[1] - ffloor(uv[1]) - 0.5);
                let d = (fx * fx + fy * fy).sqrt();
                let w = 0.5 * (fw[0] + fw[1]).max(1e-6);
                let inside = ((c.radius as f32 - d) / w + 0.5).clamp(0.0, 1.0);
                (mix(self.two_colors[1], self.two_colors[0], inside), true)
            }
            Paint::Scalar(sc) => {
                let value = match sc.location {
                    ScalarLocation::Face => sc.values[fi] as f32,
                    ScalarLocation::Vertex => {
                        let vals = t.map(|i| sc.values[i as usize] as f32);
                        lp[0] * vals[0] + lp[1] * vals[1] + lp[2] * vals[2]
                    }
                };
                if !value.is_finite() {
                    (NAN_COLOR, false)
                } else {
                    let tt = normalize(value as f64, self.range.0, self.range.1) as f32;
                    let mut c = self.map.as_ref().map_or([0.5; 3], |m| m.eval(tt));
                    if sc.isolines > 0
                        && sc.location == ScalarLocation::Vertex
                        && self.range.1 > self.range.0
                    {
                        let vals = t.map(|i| {
                            normalize(sc.values[i as usize], self.range.0, self.range.1) as f32
                                * sc.isolines as f32
                        });
                        let g = screen_gradient(&s, vals);
                        let z = tt * sc.isolines as f32;
                        let dist = (z - fround(z)).abs() / g.max(1e-9); // in samples
                        let cov = ((0.6 * self.ss - dist) / self.ss + 0.5).clamp(0.0, 1.0) * 0.7;
                        c = mix(c, [0.0; 3], cov);
                    }
                    (c, false)
                }
            }
            Paint::Zebra(z) => {
                // Reflected view direction; stripes are lines of constant angle about the
                // screen's horizontal axis.
                let r = [
                    2.0 * ndv * n[0] - view[0],
                    2.0 * ndv * n[1] - view[1],
                    2.0 * ndv * n[2] - view[2],
                ];
                let phi = r[1].atan2(r[2]) / std::f32::consts::PI; // in (-1, 1]
                let u = phi * z.stripes as f32;
                let fr = u - ffloor(u);
                let tri = (fr - 0.5).abs() * 2.0; // 1 at stripe borders, 0 in the middle
                let m = ((tri - 0.5) / 0.12 + 0.5).clamp(0.0, 1.0);
                (mix(self.two_colors[1], self.two_colors[0], m), false)
            }
        };
        if back && self.lit {
            albedo = [albedo[0] * 0.8, albedo[1] * 0.78, albedo[2] * 0.72];
        }
        let mut c = if self.lit {
            let d1 = dot3(n, self.light1).max(0.0);
            let d2 = dot3(n, self.light2).max(0.0);
            let diffuse = 0.16 + 0.78 * d1 + 0.24 * d2 + 0.06 * ndv;
            let mut c = albedo.map(|a| a * diffuse);
            if shiny {
                let h = {
                    let h = [
                        self.light1[0] + view[0],
                        self.light1[1] + view[1],
                        self.light1[2] + view[2],
                    ];
                    let l = dot3(h, h).sqrt();
                    h.map(|x| x / l)
                };
                let sp = 0.22 * dot3(n, h).max(0.0).powi(40);
                c = c.map(|x| x + sp);
            }
            c
        } else {
            albedo
        };
        if let Some(w) = &self.wire {
            // Screen distance (samples) to the nearest edge: λ_i times the altitude from v_i.
            let mut d = f32::MAX;
            for i in 0..3 {
                let g = (s.a[i] * s.a[i] + s.b[i] * s.b[i]).sqrt();
                if g > 0.0 {
                    d = d.min(l[i] / g);
                }
            }
            let cov = ((0.5 * w.width * self.ss - d) / self.ss + 0.5).clamp(0.0, 1.0) * w.opacity;
            c = mix(c, self.wire_color, cov);
        }
        c
    }

    /// UV (scaled by the frequency) at the sample and the size of the sample's footprint in
    /// those units along u and v.
    #[inline]
    fn uv_and_footprint(
        &self,
        uvs: &Uvs,
        f: usize,
        s: &Setup,
        lp: [f32; 3],
        freq: f64,
    ) -> ([f32; 2], [f32; 2]) {
        let c = [0, 1, 2].map(|i| uvs.corner(self.tris, f, i));
        let fr = freq as f32;
        let u = [0, 1, 2].map(|i| c[i][0] as f32 * fr);
        let v = [0, 1, 2].map(|i| c[i][1] as f32 * fr);
        let uv = [
            lp[0] * u[0] + lp[1] * u[1] + lp[2] * u[2],
            lp[0] * v[0] + lp[1] * v[1] + lp[2] * v[2],
        ];
        // Footprint from the affine (screen-space) derivatives.
        let du = [
            s.a[0] * u[0] + s.a[1] * u[1] + s.a[2] * u[2],
            s.b[0] * u[0] + s.b[1] * u[1] + s.b[2] * u[2],
        ];
        let dv = [
            s.a[0] * v[0] + s.a[1] * v[1] + s.a[2] * v[2],
            s.b[0] * v[0] + s.b[1] * v[1] + s.b[2] * v[2],
        ];
        // One pixel is `ss` samples wide.
        let px = self.ss;
        (
            uv,
            [
                px * (du[0].abs() + du[1].abs()),
                px * (dv[0].abs() + dv[1].abs()),
            ],
        )
    }
}

/// Box-filtered square wave: the mean of s(x) = +1 on [0,1), −1 on [1,2) (period 2) over
/// [x − w/2, x + w/2], through its antiderivative, the triangle wave.
#[inline]
fn checker(x: f32, w: f32) -> f32 {
    let tri = |x: f32| {
        let m = x - 2.0 * ffloor(x * 0.5); // x mod 2
        1.0 - (m - 1.0).abs()
    };
    if w < 1e-4 {
        let m = x - 2.0 * ffloor(x * 0.5);
        if m < 1.0 {
            1.0
        } else {
            -1.0
        }
    } else {
        let w = w.min(4.0);
        (tri(x + 0.5 * w) - tri(x - 0.5 * w)) / w
    }
}

#[inline]
fn screen_gradient(s: &Setup, vals: [f32; 3]) -> f32 {
    let gx = s.a[0] * vals[0] + s.a[1] * vals[1] + s.a[2] * vals[2];
    let gy = s.b[0] * vals[0] + s.b[1] * vals[1] + s.b[2] * vals[2];
    (gx * gx + gy * gy).sqrt()
}

#[inline]
fn face_normal(v: [&ScreenVertex; 3]) -> [f32; 3] {
    let a = [
        v[1].p[0] - v[0].p[0],
        v[1].p[1] - v[0].p[1],
        v[1].p[2] - v[0].p[2],
    ];
    let b = [
        v[2].p[0] - v[0].p[0],
        v[2].p[1] - v[0].p[1],
        v[2].p[2] - v[0].p[2],
    ];
    let n = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let l = dot3(n, n).sqrt();
    if l > 0.0 {
        n.map(|c| c / l)
    } else {
        [0.0, 0.0, 1.0]
    }
}

#[inline]
fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn mix(a: Rgb, b: Rgb, t: f32) -> Rgb {
    [
        a[0] + t * (b[0] - a[0]),
        a[1] + t * (b[1] - a[1]),
        a[2] + t * (b[2] - a[2]),
    ]
}

/// The colour bar strip: geometry in output pixels.
struct Legend {
    strip_width: u32,
    scale: u32,
    range: (f64, f64),
    labels: Vec<(f64, String)>,
}

impl Legend {
    fn new(s: &Scalar, range: (f64, f64), width: u32, height: u32) -> Legend {
        let scale = (height / 400).clamp(1, 4);
        let mut labels = vec![(range.1, font::format_number(range.1))];
        if s.colormap.is_diverging() && range.0 < 0.0 && range.1 > 0.0 {
            labels.push((0.0, "0".to_string()));
        } else if range.1 > range.0 {
            let m = 0.5 * (range.0 + range.1);
            labels.push((m, font::format_number(m)));
        }
        if range.1 > range.0 {
            labels.push((range.0, font::format_number(range.0)));
        }
        let px = Legend::px(scale);
        let label_w = labels
            .iter()
            .map(|l| font::text_width(&l.1, px))
            .max()
            .unwrap_or(0);
        let bar = 14 * scale as i64;
        let title_w = font::text_width(&s.label, px);
        let want = (bar + 6 * scale as i64 + label_w).max(title_w) + 12 * scale as i64;
        let strip_width = (want as u32).min(width / 2);
        Legend {
            strip_width,
            scale,
            range,
            labels,
        }
    }

    /// Text size in pixels at a legend scale.
    fn px(scale: u32) -> f32 {
        13.0 * scale as f32
    }

    fn draw(&self, img: &mut Image, s: &Scalar, bg: Background) {
        let sc = self.scale as i64;
        let (w, h) = (img.width as i64, img.height as i64);
        let x0 = w - self.strip_width as i64 + 6 * sc;
        let bar_w = 14 * sc;
        let top = (h as f64 * 0.2) as i64;
        let bot = (h as f64 * 0.8) as i64;
        let text = match bg {
            Background::Color(c) if color::lightness(c) < 50.0 => [0.95, 0.95, 0.95],
            _ => [0.1, 0.1, 0.1],
        };
        let halo = if text[0] > 0.5 { [0.0; 3] } else { [1.0; 3] };
        let cmap = s.colormap;
        let constant = self.range.1 <= self.range.0;
        for y in top..=bot {
            // A constant field has one colour (the centre of the map) and one label.
            let t = if constant {
                0.5
            } else {
                (bot - y) as f64 / (bot - top).max(1) as f64
            };
            img.fill_rect(x0, y, bar_w, 1, cmap.eval(t), 1.0);
        }
        // Frame.
        let frame = [0.2, 0.2, 0.2];
        img.fill_rect(x0 - 1, top - 1, bar_w + 2, 1, frame, 1.0);
        img.fill_rect(x0 - 1, bot + 1, bar_w + 2, 1, frame, 1.0);
        img.fill_rect(x0 - 1, top - 1, 1, bot - top + 3, frame, 1.0);
        img.fill_rect(x0 + bar_w, top - 1, 1, bot - top + 3, frame, 1.0);
        let px = Legend::px(self.scale);
        let th = font::text_height(px);
        for (value, label) in &self.labels {
            let t = normalize(*value, self.range.0, self.range.1);
            let y = bot - ((bot - top) as f64 * t).round() as i64;
            img.fill_rect(x0 + bar_w, y, 4 * sc, 1.max(sc / 2), frame, 1.0);
            font::draw_text_halo(
                img,
                x0 + bar_w + 6 * sc,
                y - th / 2,
                px,
                &label.replace('-', "−"),
                text,
                halo,
            );
        }
        if !s.label.is_empty() {
            let tw = font::text_width(&s.label, px);
            let tx = (x0 - 4 * sc).min(w - tw - 2).max(0);
            font::draw_text_halo(img, tx, top - th - 8 * sc, px, &s.label, text, halo);
        }
    }
}

// f32 floor/ceil/round without a libm call (the default x86-64 target has no SSE4.1 `roundss`);
// exact for |x| < 2^31.
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
