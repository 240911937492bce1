//! The shading and resolve passes of the renderer: per sample, the paint's albedo, two-sided
//! Lambert + Blinn–Phong lighting in linear light and the wireframe; per pixel, the samples
//! averaged in linear light with the lines and the background, stored as 8-bit sRGB.

use super::*;

/// The resolve pass: every pixel's samples shaded, blended with the lines and the
/// background, and stored as 8-bit sRGB.
pub(super) struct Resolve<'a> {
    pub(super) ids: &'a [u32],
    pub(super) lines: Option<&'a LineBuffer>,
    pub(super) shader: &'a Shader<'a>,
    /// Background colour (linear) and alpha.
    pub(super) bg: (Rgb, f32),
    pub(super) lut: SrgbLut,
    /// Supersampling factor, supersampled width, image width.
    pub(super) ss: usize,
    pub(super) sw: usize,
    pub(super) w: usize,
}

impl Resolve<'_> {
    /// Row `py` of the image; the number of its samples covered by the surface.
    pub(super) fn row(&self, py: usize, row: &mut [u8]) -> usize {
        let (ss, sw, w, bg) = (self.ss, self.sw, self.w, self.bg);
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
                    let f = self.ids[sy * sw + sx];
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
                    let col = self.shader.shade(faces[j], sum[j][0] / c, sum[j][1] / c);
                    colors[j] = col;
                    for q in 0..3 {
                        acc[q] += col[q] * c;
                    }
                    acc[3] += c;
                }
            }
            if let Some(l) = self.lines {
                if let Some(a) = self.with_lines(l, px, py, &faces, &group, &colors) {
                    acc = a;
                }
            }
            let o = &mut row[4 * px..4 * px + 4];
            if acc[3] > 0.0 {
                for q in 0..3 {
                    o[q] = self.lut.encode(acc[q] / acc[3]);
                }
            }
            o[3] = fround(acc[3] * inv_n * 255.0) as u8;
        }
        covered
    }

    /// Pixel `(px, py)` redone per sample where a line covers it (`None` where none does):
    /// the accumulated premultiplied colour and alpha.
    pub(super) fn with_lines(
        &self,
        l: &LineBuffer,
        px: usize,
        py: usize,
        faces: &[u32; 64],
        group: &[u8; 64],
        colors: &[Rgb; 64],
    ) -> Option<[f32; 4]> {
        let (ss, sw, bg) = (self.ss, self.sw, self.bg);
        let mut any = false;
        for sy in py * ss..(py + 1) * ss {
            for sx in px * ss..(px + 1) * ss {
                any |= l.coverage[sy * sw + sx] > 0.0;
            }
        }
        if !any {
            return None;
        }
        let mut k = 0usize;
        let mut acc = [0.0f32; 4];
        {
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
        Some(acc)
    }
}

/// Linear light → 8-bit sRGB through a table.
pub(super) struct SrgbLut(pub(super) Vec<u8>);

impl SrgbLut {
    const N: usize = 4096;
    pub(super) fn new() -> Self {
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
    pub(super) fn encode(&self, c: f32) -> u8 {
        let i = (c.clamp(0.0, 1.0) * (Self::N - 1) as f32 + 0.5) as usize;
        self.0[i.min(Self::N - 1)]
    }
}

/// Colormap tabulated in linear light for fast lookup.
pub(super) struct LinearMap(pub(super) Vec<Rgb>);

impl LinearMap {
    pub(super) fn new(map: Colormap) -> Self {
        LinearMap(
            (0..=1024)
                .map(|i| color::to_linear(map.eval(i as f64 / 1024.0)))
                .collect(),
        )
    }
    #[inline]
    pub(super) fn eval(&self, t: f32) -> Rgb {
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

pub(super) struct Shader<'a> {
    pub(super) paint: &'a Paint<'a>,
    pub(super) wire: Option<Wireframe>,
    pub(super) wire_color: Rgb,
    pub(super) verts: &'a [ScreenVertex],
    pub(super) tris: &'a [[u32; 3]],
    pub(super) setups: &'a [Option<Setup>],
    pub(super) perspective: bool,
    pub(super) lit: bool,
    pub(super) ss: f32,
    pub(super) two_colors: [Rgb; 2],
    pub(super) map: Option<LinearMap>,
    pub(super) range: (f64, f64),
    pub(super) light1: [f32; 3],
    pub(super) light2: [f32; 3],
}

pub(super) const NAN_COLOR: Rgb = [0.25, 0.25, 0.25];

impl<'a> Shader<'a> {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
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
    pub(super) fn shade(&self, f: u32, x: f32, y: f32) -> Rgb {
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

        let (mut albedo, shiny) = self.albedo(fi, t, &s, lp, n, ndv, view);
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

    /// The paint's colour (linear) at the sample with perspective-correct barycentrics `lp`
    /// in face `fi` (corners `t`), and whether it gets a specular highlight; `n` is the
    /// shading normal facing the viewer, `view` the direction to the eye, `ndv` their dot.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn albedo(
        &self,
        fi: usize,
        t: [u32; 3],
        s: &Setup,
        lp: [f32; 3],
        n: [f32; 3],
        ndv: f32,
        view: [f32; 3],
    ) -> (Rgb, bool) {
        match self.paint {
            Paint::Solid(_) => (self.two_colors[0], true),
            Paint::FaceColors(c) => (color::to_linear(c[fi]), true),
            Paint::Checker(c) => {
                let (uv, fw) = self.uv_and_footprint(&c.uvs, fi, s, lp, c.frequency);
                let a = checker(uv[0], fw[0]) * checker(uv[1], fw[1]);
                let m = 0.5 + 0.5 * a;
                (mix(self.two_colors[0], self.two_colors[1], m), true)
            }
            Paint::Circles(c) => {
                let (uv, fw) = self.uv_and_footprint(&c.uvs, fi, s, lp, c.frequency);
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
                        let g = screen_gradient(s, vals);
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
        }
    }

    /// UV (scaled by the frequency) at the sample and the size of the sample's footprint in
    /// those units along u and v.
    #[inline]
    pub(super) fn uv_and_footprint(
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
pub(super) fn checker(x: f32, w: f32) -> f32 {
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
pub(super) fn screen_gradient(s: &Setup, vals: [f32; 3]) -> f32 {
    let gx = s.a[0] * vals[0] + s.a[1] * vals[1] + s.a[2] * vals[2];
    let gy = s.b[0] * vals[0] + s.b[1] * vals[1] + s.b[2] * vals[2];
    (gx * gx + gy * gy).sqrt()
}

#[inline]
pub(super) fn face_normal(v: [&ScreenVertex; 3]) -> [f32; 3] {
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
pub(super) fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(super) fn mix(a: Rgb, b: Rgb, t: f32) -> Rgb {
    [
        a[0] + t * (b[0] - a[0]),
        a[1] + t * (b[1] - a[1]),
        a[2] + t * (b[2] - a[2]),
    ]
}
