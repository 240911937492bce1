//! A gallery of what ricci-render draws, written to a folder (default: the temp directory):
//! solid, checkerboard, circles, scalar field with legend and isolines, zebra with wireframe
//! and a polyline, a Poincaré-disk layout with generator sides and a tiling copy, a
//! histogram, a log-scale line plot and a glTF file.
//!
//! `cargo run --release -p ricci-render --example gallery -- OUT_DIR`
use ricci_render::*;
fn main() {
    let out = std::path::PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| std::env::temp_dir().display().to_string()),
    );
    let t = shapes::torus(2.0, 0.8, 80, 40);
    let uv: Vec<[f64; 2]> = (0..t.positions.len())
        .map(|k| [(k / 40) as f64 / 80.0, (k % 40) as f64 / 40.0])
        .collect();
    let opts = RenderOptions {
        width: 600,
        height: 500,
        ..Default::default()
    };
    let r = render(&t.positions, &t.triangles, &Style::default(), &opts).unwrap();
    std::fs::write(out.join("solid.png"), r.png().unwrap()).unwrap();
    let st = Style {
        paint: Paint::Checker(Checker::new(render::Uvs::PerVertex(&uv), 8.0)),
        ..Default::default()
    };
    let r = render(&t.positions, &t.triangles, &st, &opts).unwrap();
    std::fs::write(out.join("checker.png"), r.png().unwrap()).unwrap();
    let z: Vec<f64> = t.positions.iter().map(|p| p[2]).collect();
    let st = Style {
        paint: Paint::Scalar(Scalar {
            label: "height z".into(),
            isolines: 10,
            ..Scalar::per_vertex(&z, Colormap::CoolWarm)
        }),
        legend: true,
        wireframe: None,
        ..Default::default()
    };
    let r = render(&t.positions, &t.triangles, &st, &opts).unwrap();
    std::fs::write(out.join("scalar.png"), r.png().unwrap()).unwrap();
    let s = shapes::icosphere(3);
    let st = Style {
        paint: Paint::Zebra(Zebra::default()),
        wireframe: Some(Wireframe::default()),
        polylines: vec![Polyline {
            points: (0..=64)
                .map(|i| {
                    let a = i as f64 * std::f64::consts::TAU / 64.0;
                    [a.cos(), a.sin(), 0.0]
                })
                .collect(),
            color: [0.9, 0.1, 0.1],
            width: 3.0,
            closed: true,
        }],
        ..Default::default()
    };
    let opts = RenderOptions {
        width: 500,
        height: 500,
        view: View {
            projection: Projection::Perspective { fov_y_deg: 35.0 },
            ..View::default()
        },
        ..Default::default()
    };
    let r = render(&s.positions, &s.triangles, &st, &opts).unwrap();
    std::fs::write(out.join("zebra.png"), r.png().unwrap()).unwrap();
    let st = Style {
        paint: Paint::Circles(Circles::new(render::Uvs::PerVertex(&uv), 8.0)),
        ..Default::default()
    };
    let r = render(
        &t.positions,
        &t.triangles,
        &st,
        &RenderOptions {
            width: 600,
            height: 500,
            ..Default::default()
        },
    )
    .unwrap();
    std::fs::write(out.join("circles.png"), r.png().unwrap()).unwrap();
    plots(&out);
    let glb = gltf::glb(
        &t.positions,
        &t.triangles,
        &gltf::GlbOptions {
            uvs: Some(render::Uvs::PerVertex(&uv)),
            checker_frequency: Some(8.0),
            ..Default::default()
        },
    )
    .unwrap();
    std::fs::write(out.join("torus.glb"), glb).unwrap();
    println!("pictures written to {}", out.display());
}

fn plots(out: &std::path::Path) {
    use ricci_render::plot::*;
    let n = 48;
    let mut uv = vec![[0.0, 0.0]];
    let mut tri = Vec::new();
    for r in 1..=6 {
        for k in 0..n {
            let a = k as f64 * std::f64::consts::TAU / n as f64;
            let rr = 0.85 * r as f64 / 6.0;
            uv.push([rr * a.cos(), rr * a.sin()]);
        }
    }
    let id = |r: usize, k: usize| {
        if r == 0 {
            0
        } else {
            (1 + (r - 1) * n + k % n) as u32
        }
    };
    for k in 0..n {
        tri.push([0, id(1, k), id(1, k + 1)]);
    }
    for r in 1..6 {
        for k in 0..n {
            tri.push([id(r, k), id(r + 1, k), id(r + 1, k + 1)]);
            tri.push([id(r, k), id(r + 1, k + 1), id(r, k + 1)]);
        }
    }
    let mut plot = LayoutPlot::new(LayoutCopy::new(&uv, &tri));
    plot.disk = true;
    plot.title = "fundamental domain (genus 2)".into();
    for (i, (name, g)) in canonical_side_names(2).into_iter().enumerate() {
        let pts = (0..=6).map(|j| uv[id(6, 6 * i + j) as usize]).collect();
        plot.sides.push(Side {
            points: pts,
            color: color::categorical(g),
            label: name,
        });
    }
    let uv2: Vec<[f64; 2]> = uv.iter().map(|p| [p[0] * 0.3 + 0.6, p[1] * 0.3]).collect();
    plot.copies.push(LayoutCopy::tinted(&uv2, &tri, 1));
    let fig = layout_figure(&plot).unwrap();
    std::fs::write(out.join("disk.svg"), fig.to_svg()).unwrap();
    std::fs::write(out.join("disk.png"), fig.to_png(1.0).unwrap()).unwrap();
    let v: Vec<f64> = (0..5000)
        .map(|i| {
            1.0 + 0.05 * ((i as f64 * 0.7).sin() + (i as f64 * 1.3).cos()) * (i % 7) as f64 / 7.0
        })
        .collect();
    let fig = histogram_figure(
        &v,
        &Histogram {
            title: "angle ratio".into(),
            x_label: "ratio".into(),
            reference: Some(1.0),
            ..Default::default()
        },
    )
    .unwrap();
    std::fs::write(out.join("hist.png"), fig.to_png(1.0).unwrap()).unwrap();
    let pts: Vec<[f64; 2]> = (0..12)
        .map(|k| [k as f64, 10f64.powf(-(k * k) as f64 / 8.0)])
        .collect();
    let fig = line_plot_figure(
        &[Series {
            name: "max |K - K*|".into(),
            points: pts,
            color: color::categorical(1),
        }],
        &LinePlot {
            log_y: true,
            title: "Newton".into(),
            x_label: "iteration".into(),
            y_label: "residual".into(),
            ..Default::default()
        },
    )
    .unwrap();
    std::fs::write(out.join("line.png"), fig.to_png(1.0).unwrap()).unwrap();
}
