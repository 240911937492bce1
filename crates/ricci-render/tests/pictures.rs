//! Properties of rendered pictures that can be checked pixel by pixel.

use ricci_render::render::Uvs;
use ricci_render::*;

fn opts(size: u32, view: View) -> RenderOptions {
    RenderOptions {
        width: size,
        height: size,
        supersample: 3,
        view,
        background: Background::Transparent,
        lighting: Lighting::Unlit,
        line_offset: 0.01,
    }
}

fn luminance(p: [u8; 4]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// Luminance in linear light (0..1): proportional to the area of white inside a pixel, since
/// the renderer averages samples in linear light.
fn linear_luminance(p: [u8; 4]) -> f64 {
    let l = |c: u8| color::srgb_to_linear(c as f32 / 255.0) as f64;
    0.2126 * l(p[0]) + 0.7152 * l(p[1]) + 0.0722 * l(p[2])
}

type Mesh = (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<[f64; 2]>);

fn flat_square(n: usize) -> Mesh {
    let g = shapes::grid(n, 1.0);
    let uv = g.positions.iter().map(|p| [p[0], p[1]]).collect();
    (g.positions, g.triangles, uv)
}

#[test]
fn checkerboard_on_flat_square_head_on_is_half_black_half_white() {
    let (p, t, uv) = flat_square(10);
    for (lighting, projection) in [
        (Lighting::Unlit, Projection::Orthographic),
        (Lighting::Studio, Projection::Orthographic),
        (Lighting::Unlit, Projection::Perspective { fov_y_deg: 30.0 }),
    ] {
        let style = Style {
            paint: Paint::Checker(Checker::new(Uvs::PerVertex(&uv), 8.0)),
            ..Default::default()
        };
        let mut o = opts(
            512,
            View {
                projection,
                ..View::front()
            },
        );
        o.lighting = lighting;
        let r = render(&p, &t, &style, &o).unwrap();
        let img = &r.image;
        let (mut black, mut white) = (0usize, 0usize);
        let mut lum = Vec::new();
        for y in 0..img.height {
            for x in 0..img.width {
                let px = img.pixel(x, y);
                if px[3] == 255 {
                    lum.push(linear_luminance(px));
                }
            }
        }
        let (lo, hi) = lum
            .iter()
            .fold((255.0f64, 0.0f64), |a, &l| (a.0.min(l), a.1.max(l)));
        let mid = 0.5 * (lo + hi);
        for l in &lum {
            if *l > mid {
                white += 1;
            } else {
                black += 1;
            }
        }
        let ratio = black as f64 / white as f64;
        assert!(
            (ratio - 1.0).abs() <= 0.02,
            "{lighting:?} {projection:?}: black/white = {black}/{white} = {ratio}"
        );
        assert!(hi - lo > 0.6, "checks are not contrasted: {lo}..{hi}");
        // 8 checks across: 7 colour changes along the middle row inside the square.
        let y = img.height / 2;
        let row: Vec<bool> = (0..img.width)
            .filter(|&x| img.pixel(x, y)[3] == 255)
            .map(|x| linear_luminance(img.pixel(x, y)) > mid)
            .collect();
        let changes = row.windows(2).filter(|w| w[0] != w[1]).count();
        assert_eq!(changes, 7, "{lighting:?} {projection:?}");
    }
}

fn object_box(img: &Image) -> (u32, u32, u32, u32, usize) {
    let (mut x0, mut y0, mut x1, mut y1, mut n) = (u32::MAX, u32::MAX, 0, 0, 0);
    for y in 0..img.height {
        for x in 0..img.width {
            if img.pixel(x, y)[3] > 0 {
                x0 = x0.min(x);
                y0 = y0.min(y);
                x1 = x1.max(x);
                y1 = y1.max(y);
                n += 1;
            }
        }
    }
    (x0, y0, x1, y1, n)
}

#[test]
fn objects_are_framed_without_touching_the_edges() {
    let torus = shapes::torus(3.0, 1.0, 60, 30);
    let mut sphere = shapes::icosphere(3);
    for p in &mut sphere.positions {
        *p = [p[0] * 5.0 + 100.0, p[1] * 5.0 - 7.0, p[2] * 5.0 + 1e3];
    }
    let views = [
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.3, -1.0, 0.4],
        [-1.0, -1.0, -1.0],
    ];
    for (name, s) in [("torus", &torus), ("sphere", &sphere)] {
        for dir in views {
            for projection in [
                Projection::Orthographic,
                Projection::Perspective { fov_y_deg: 40.0 },
            ] {
                for (w, h) in [(300u32, 300u32), (400, 240)] {
                    let mut o = opts(w, View::default());
                    o.height = h;
                    o.view = View {
                        eye_direction: dir,
                        up: [0.0, 0.0, 1.0],
                        projection,
                        margin: 1.08,
                    };
                    let r = render(&s.positions, &s.triangles, &Style::default(), &o).unwrap();
                    let (x0, y0, x1, y1, n) = object_box(&r.image);
                    let what = format!("{name} from {dir:?} {projection:?} {w}x{h}");
                    assert!(
                        x0 > 0 && y0 > 0 && x1 < w - 1 && y1 < h - 1,
                        "{what} touches an edge: {x0} {y0} {x1} {y1}"
                    );
                    let fill = n as f64 / (w * h) as f64;
                    // A flat torus seen edge-on cannot fill a square; every other view must.
                    let edge_on = name == "torus"
                        && dir[2].abs() < 0.5 * (dir[0] * dir[0] + dir[1] * dir[1]).sqrt();
                    if !edge_on {
                        assert!(fill >= 0.30, "{what} fills only {fill}");
                    }
                    // Tight: the object spans at least 85% of the image in one direction.
                    let span =
                        ((x1 - x0 + 1) as f64 / w as f64).max((y1 - y0 + 1) as f64 / h as f64);
                    assert!(span > 0.85, "{what} spans {span}");
                    assert!(
                        (r.coverage - fill).abs() < 0.02,
                        "{what}: coverage {} vs {fill}",
                        r.coverage
                    );
                }
            }
        }
    }
}

#[test]
fn constant_scalar_field_renders_one_colour() {
    let t = shapes::torus(2.0, 0.6, 40, 20);
    let vals = vec![0.7; t.positions.len()];
    let face_vals = vec![-3.0; t.triangles.len()];
    for (scalar, map) in [
        (
            Scalar::per_vertex(&vals, Colormap::Viridis),
            Colormap::Viridis,
        ),
        (
            Scalar::per_face(&face_vals, Colormap::CoolWarm),
            Colormap::CoolWarm,
        ),
    ] {
        let style = Style {
            paint: Paint::Scalar(scalar),
            wireframe: None,
            ..Default::default()
        };
        let r = render(
            &t.positions,
            &t.triangles,
            &style,
            &opts(256, View::default()),
        )
        .unwrap();
        // Min-max range of a constant is degenerate (centre of the map); the symmetric range
        // of a diverging map puts -3 at its blue end.
        let (lo, hi) = r.scalar_range.unwrap();
        let v = if map == Colormap::Viridis { 0.7 } else { -3.0 };
        let want = map
            .eval(color::normalize(v, lo, hi))
            .map(|c| (c * 255.0).round() as i32);
        let mut seen = 0;
        for y in 0..256 {
            for x in 0..256 {
                let p = r.image.pixel(x, y);
                if p[3] == 0 {
                    continue;
                }
                seen += 1;
                for k in 0..3 {
                    assert!(
                        (p[k] as i32 - want[k]).abs() <= 1,
                        "pixel ({x},{y}) = {p:?}, want {want:?}"
                    );
                }
            }
        }
        assert!(seen > 10_000);
    }
}

#[test]
fn linear_scalar_field_runs_through_the_colormap() {
    let (p, t, _) = flat_square(8);
    let x: Vec<f64> = p.iter().map(|q| 10.0 + 5.0 * q[0]).collect();
    let style = Style {
        paint: Paint::Scalar(Scalar::per_vertex(&x, Colormap::Viridis)),
        ..Default::default()
    };
    let r = render(&p, &t, &style, &opts(200, View::front())).unwrap();
    assert_eq!(r.scalar_range, Some((10.0, 15.0)));
    let y = 100;
    let row: Vec<u32> = (0..200)
        .filter(|&x| r.image.pixel(x, y)[3] == 255)
        .collect();
    let (first, last) = (row[0], *row.last().unwrap());
    let mut prev = -1.0;
    for x in first..=last {
        let q = r.image.pixel(x, y);
        let l = color::lightness([
            q[0] as f32 / 255.0,
            q[1] as f32 / 255.0,
            q[2] as f32 / 255.0,
        ]);
        assert!(l >= prev - 0.5, "lightness drops at x = {x}");
        prev = l;
    }
    // Pixel centres map to known values of x: compare with the colormap there.
    for x in [first + 2, (first + last) / 2, last - 2] {
        let t = (x as f64 + 0.5 - first as f64) / (last - first + 1) as f64;
        let want = Colormap::Viridis.eval(t).map(|c| c * 255.0);
        let got = r.image.pixel(x, y);
        for k in 0..3 {
            assert!(
                (got[k] as f32 - want[k]).abs() < 4.0,
                "x = {x}: {got:?} vs {want:?}"
            );
        }
    }
}

#[test]
fn perspective_texture_interpolation_is_correct() {
    // A square receding from a perspective camera: the checker boundary v = 1/2 must appear
    // at the projection of the 3D midpoint, not at the screen-space midpoint.
    let (p, t, uv) = flat_square(1);
    let view = View {
        eye_direction: [0.0, -1.0, 0.35],
        up: [0.0, 0.0, 1.0],
        projection: Projection::Perspective { fov_y_deg: 70.0 },
        margin: 1.05,
    };
    let style = Style {
        paint: Paint::Checker(Checker::new(Uvs::PerVertex(&uv), 2.0)),
        ..Default::default()
    };
    let r = render(&p, &t, &style, &opts(400, view)).unwrap();
    let cam = r.camera;
    let true_mid = cam.project([0.25, 0.5, 0.0]);
    let near = cam.project([0.25, 0.0, 0.0]);
    let far = cam.project([0.25, 1.0, 0.0]);
    let affine_mid = 0.5 * (near.y + far.y);
    assert!(
        (affine_mid - true_mid.y).abs() > 12.0,
        "the test camera is not perspective enough"
    );
    let x = true_mid.x.round() as u32;
    let lum = |y: f64| luminance(r.image.pixel(x, y.round() as u32));
    assert!((lum(true_mid.y - 4.0) - lum(true_mid.y + 4.0)).abs() > 150.0);
    let between = 0.5 * (true_mid.y + affine_mid);
    assert!(
        (lum(between) - lum(affine_mid)).abs() < 30.0,
        "the boundary is not at the projected midpoint"
    );
}

#[test]
fn wireframe_is_hidden_behind_an_occluder() {
    // A wireframed grid at z = 0 and an opaque square (two triangles) in front of its middle.
    let g = shapes::grid(8, 1.0);
    let mut p = g.positions.clone();
    let mut t = g.triangles.clone();
    let base = p.len() as u32;
    p.extend([
        [0.25, 0.25, 1.0],
        [0.75, 0.25, 1.0],
        [0.75, 0.75, 1.0],
        [0.25, 0.75, 1.0],
    ]);
    t.push([base, base + 1, base + 2]);
    t.push([base, base + 2, base + 3]);
    let style = Style {
        paint: Paint::Solid([1.0; 3]),
        wireframe: Some(Wireframe {
            color: [0.0; 3],
            width: 1.5,
            opacity: 1.0,
        }),
        ..Default::default()
    };
    let r = render(&p, &t, &style, &opts(400, View::front())).unwrap();
    let cam = r.camera;
    let dark_in = |a: [f64; 3], b: [f64; 3], shrink: f64| {
        let (pa, pb) = (cam.project(a), cam.project(b));
        let mut n = 0;
        for y in (pa.y.min(pb.y) + shrink) as u32..(pa.y.max(pb.y) - shrink) as u32 {
            for x in (pa.x.min(pb.x) + shrink) as u32..(pa.x.max(pb.x) - shrink) as u32 {
                // Off the occluder's diagonal.
                let (u, v) = (
                    (x as f64 - pa.x) / (pb.x - pa.x),
                    (y as f64 - pa.y) / (pb.y - pa.y),
                );
                if (u - v).abs() > 0.06 && luminance(r.image.pixel(x, y)) < 128.0 {
                    n += 1;
                }
            }
        }
        n
    };
    let hidden = dark_in([0.25, 0.25, 1.0], [0.75, 0.75, 1.0], 6.0);
    let visible = dark_in([0.02, 0.02, 0.0], [0.24, 0.24, 0.0], 0.0);
    assert_eq!(hidden, 0, "grid edges show through the occluder");
    assert!(visible > 100, "grid edges are missing: {visible}");
}

#[test]
fn polylines_are_depth_tested() {
    let s = shapes::icosphere(4);
    let circle = |z: f64| Polyline {
        points: (0..96)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 96.0;
                let r = (1.0 - z * z).sqrt();
                [r * a.cos(), r * a.sin(), z]
            })
            .collect(),
        color: [1.0, 0.0, 0.0],
        width: 3.0,
        closed: true,
    };
    let red = |z: f64| {
        let style = Style {
            paint: Paint::Solid([0.7, 0.7, 0.7]),
            polylines: vec![circle(z)],
            ..Default::default()
        };
        let r = render(
            &s.positions,
            &s.triangles,
            &style,
            &opts(300, View::front()),
        )
        .unwrap();
        let mut n = 0;
        for y in 0..300 {
            for x in 0..300 {
                let p = r.image.pixel(x, y);
                if p[3] > 0 && p[0] as i32 > p[1] as i32 + 60 {
                    n += 1;
                }
            }
        }
        n
    };
    let front = red(0.6);
    assert!(front > 1500, "front circle shows {front} red pixels");
    assert_eq!(red(-0.6), 0, "a circle behind the sphere shows through");
}

#[test]
fn zebra_is_uniform_on_a_plane_and_striped_on_a_sphere() {
    let (p, t, _) = flat_square(4);
    let style = Style {
        paint: Paint::Zebra(Zebra::default()),
        ..Default::default()
    };
    let r = render(&p, &t, &style, &opts(120, View::front())).unwrap();
    let colors: std::collections::BTreeSet<[u8; 4]> = r
        .image
        .data
        .chunks_exact(4)
        .filter(|q| q[3] == 255)
        .map(|q| [q[0], q[1], q[2], q[3]])
        .collect();
    assert_eq!(colors.len(), 1, "a plane reflects one direction only");
    let s = shapes::icosphere(4);
    let r = render(
        &s.positions,
        &s.triangles,
        &style,
        &opts(200, View::front()),
    )
    .unwrap();
    let l: Vec<f64> = r
        .image
        .data
        .chunks_exact(4)
        .filter(|q| q[3] == 255)
        .map(|q| luminance([q[0], q[1], q[2], q[3]]))
        .collect();
    let dark = l.iter().filter(|&&x| x < 60.0).count() as f64 / l.len() as f64;
    let light = l.iter().filter(|&&x| x > 200.0).count() as f64 / l.len() as f64;
    assert!(
        dark > 0.2 && light > 0.2,
        "stripes: dark {dark}, light {light}"
    );
}

#[test]
fn legend_shows_the_colormap_beside_the_object() {
    let t = shapes::torus(2.0, 0.6, 40, 20);
    let z: Vec<f64> = t.positions.iter().map(|p| p[2]).collect();
    let style = Style {
        paint: Paint::Scalar(Scalar {
            label: "height".into(),
            ..Scalar::per_vertex(&z, Colormap::Viridis)
        }),
        legend: true,
        ..Default::default()
    };
    let mut o = opts(600, View::front());
    o.height = 400;
    o.background = Background::White;
    let r = render(&t.positions, &t.triangles, &style, &o).unwrap();
    let strip = 600.0 - r.camera.viewport[2];
    assert!(strip > 40.0 && strip < 300.0, "legend strip {strip}");
    // The object stays left of the strip.
    let left_edge = r.camera.viewport[2] as u32;
    let bar_x = left_edge + 6 + 7; // inside the colour bar
    let top = r.image.pixel(bar_x, (400.0 * 0.2) as u32 + 2);
    let bottom = r.image.pixel(bar_x, (400.0 * 0.8) as u32 - 2);
    let hi = Colormap::Viridis.eval(1.0).map(|c| (c * 255.0) as i32);
    let lo = Colormap::Viridis.eval(0.0).map(|c| (c * 255.0) as i32);
    for k in 0..3 {
        assert!(
            (top[k] as i32 - hi[k]).abs() < 12,
            "top of bar {top:?} vs {hi:?}"
        );
        assert!(
            (bottom[k] as i32 - lo[k]).abs() < 12,
            "bottom of bar {bottom:?} vs {lo:?}"
        );
    }
}

#[test]
fn backgrounds_and_png_round_trip() {
    let s = shapes::icosphere(2);
    let mut o = opts(64, View::default());
    o.background = Background::White;
    let r = render(&s.positions, &s.triangles, &Style::default(), &o).unwrap();
    assert_eq!(r.image.pixel(0, 0), [255, 255, 255, 255]);
    let png = r.png().unwrap();
    assert_eq!(Image::from_png(&png).unwrap(), r.image);
    o.background = Background::Transparent;
    let r = render(&s.positions, &s.triangles, &Style::default(), &o).unwrap();
    assert_eq!(r.image.pixel(0, 0)[3], 0);
    assert_eq!(Image::from_png(&r.png().unwrap()).unwrap(), r.image);
}

#[test]
fn bad_input_is_refused_with_a_sentence() {
    let s = shapes::icosphere(1);
    let o = opts(32, View::default());
    let st = Style::default();
    let e = render(&s.positions, &[[0, 1, 999]], &st, &o)
        .unwrap_err()
        .to_string();
    assert!(e.contains("face 0") && e.contains("999"), "{e}");
    let mut p = s.positions.clone();
    p[3][1] = f64::NAN;
    assert!(render(&p, &s.triangles, &st, &o)
        .unwrap_err()
        .to_string()
        .contains("vertex 3"));
    let uv = vec![[0.0; 2]; 5];
    let st2 = Style {
        paint: Paint::Checker(Checker::new(Uvs::PerVertex(&uv), 4.0)),
        ..Default::default()
    };
    assert!(render(&s.positions, &s.triangles, &st2, &o).is_err());
    let vals = vec![f64::NAN; s.positions.len()];
    let st3 = Style {
        paint: Paint::Scalar(Scalar::per_vertex(&vals, Colormap::Viridis)),
        ..Default::default()
    };
    assert!(render(&s.positions, &s.triangles, &st3, &o).is_err());
    let mut o2 = o;
    o2.width = 0;
    assert!(render(&s.positions, &s.triangles, &st, &o2).is_err());
    let mut o3 = o;
    o3.view.eye_direction = [0.0; 3];
    assert!(render(&s.positions, &s.triangles, &st, &o3).is_err());
    assert!(render(&s.positions, &[], &st, &o).is_err());
}

#[test]
fn per_corner_uvs_allow_seams() {
    // A torus whose UVs wrap: per-corner UVs avoid the smeared seam of per-vertex UVs. With
    // per-corner UVs every face's UV triangle is small, so no pixel sees a huge footprint.
    let (n, m) = (32usize, 16usize);
    let t = shapes::torus(2.0, 0.7, n, m);
    let mut corner = Vec::new();
    for (f, tri) in t.triangles.iter().enumerate() {
        let (i, j) = ((f / 2) / m, (f / 2) % m);
        let _ = tri;
        let uv = |di: usize, dj: usize| [(i + di) as f64 / n as f64, (j + dj) as f64 / m as f64];
        if f % 2 == 0 {
            corner.extend([uv(0, 0), uv(1, 0), uv(1, 1)]);
        } else {
            corner.extend([uv(0, 0), uv(1, 1), uv(0, 1)]);
        }
    }
    let style = Style {
        paint: Paint::Checker(Checker::new(Uvs::PerCorner(&corner), 8.0)),
        ..Default::default()
    };
    let r = render(
        &t.positions,
        &t.triangles,
        &style,
        &opts(200, View::front()),
    )
    .unwrap();
    // Mostly clean black and white: few grey pixels.
    let l: Vec<f64> = r
        .image
        .data
        .chunks_exact(4)
        .filter(|q| q[3] == 255)
        .map(|q| luminance([q[0], q[1], q[2], q[3]]))
        .collect();
    let grey = l.iter().filter(|&&x| x > 60.0 && x < 190.0).count() as f64 / l.len() as f64;
    assert!(grey < 0.2, "{grey}");
}

#[test]
fn degenerate_and_far_away_meshes_do_not_break_the_renderer() {
    // All vertices at one point: nothing visible, no panic.
    let p = vec![[1.0, 2.0, 3.0]; 3];
    let r = render(
        &p,
        &[[0, 1, 2]],
        &Style::default(),
        &opts(32, View::default()),
    )
    .unwrap();
    assert_eq!(r.coverage, 0.0);
    // A needle far from the origin, and a triangle seen exactly edge-on.
    let p = vec![
        [1e8, 1e8, 1e8],
        [1e8 + 1.0, 1e8, 1e8],
        [1e8, 1e8 + 1e-6, 1e8],
    ];
    render(
        &p,
        &[[0, 1, 2]],
        &Style::default(),
        &opts(32, View::front()),
    )
    .unwrap();
    let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let side = View {
        eye_direction: [1.0, 0.0, 0.0],
        ..View::front()
    };
    render(&p, &[[0, 1, 2]], &Style::default(), &opts(32, side)).unwrap();
    // Too many samples is refused, not attempted.
    let mut o = opts(16384, View::default());
    o.supersample = 8;
    let e = render(&p, &[[0, 1, 2]], &Style::default(), &o)
        .unwrap_err()
        .to_string();
    assert!(e.contains("supersampling"), "{e}");
    // PNG shortcut.
    let png = render_png(
        &p,
        &[[0, 1, 2]],
        &Style::default(),
        &opts(32, View::front()),
    )
    .unwrap();
    assert!(png.starts_with(b"\x89PNG"));
}

#[test]
fn face_colours_are_shown_exactly_unlit() {
    let (p, t, _) = flat_square(2);
    // Left column of cells red, right column blue.
    let cols: Vec<Rgb> = t
        .iter()
        .map(|f| {
            let cx = f.iter().map(|&i| p[i as usize][0]).sum::<f64>() / 3.0;
            if cx < 0.5 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect();
    let style = Style {
        paint: Paint::FaceColors(&cols),
        ..Default::default()
    };
    let r = render(&p, &t, &style, &opts(100, View::front())).unwrap();
    assert_eq!(r.image.pixel(20, 50), [255, 0, 0, 255]);
    assert_eq!(r.image.pixel(80, 50), [0, 0, 255, 255]);
    let bad = Style {
        paint: Paint::FaceColors(&cols[..3]),
        ..Default::default()
    };
    assert!(render(&p, &t, &bad, &opts(100, View::front())).is_err());
}
