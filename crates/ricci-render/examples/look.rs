//! Scratch: write a few pictures to look at (dev aid).
use ricci_render::*;
fn main() {
    let out = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or("/tmp".into()));
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
}
