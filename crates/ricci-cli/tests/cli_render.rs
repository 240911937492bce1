//! `ricci render`: pictures and glTF through the command line, exit codes, JSON.

use ricci_render::{color, shapes, Image};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn ricci(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
        .args(args)
        .output()
        .expect("run ricci")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci_cli_render_{}_{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// OBJ text: `v` lines, optional `vt` lines (one per vertex) and `f a/a b/b c/c`.
fn obj(p: &[[f64; 3]], t: &[[u32; 3]], uv: Option<&[[f64; 2]]>) -> String {
    let mut s = String::new();
    for q in p {
        writeln!(s, "v {} {} {}", q[0], q[1], q[2]).unwrap();
    }
    if let Some(uv) = uv {
        for q in uv {
            writeln!(s, "vt {} {}", q[0], q[1]).unwrap();
        }
    }
    for f in t {
        if uv.is_some() {
            writeln!(s, "f {0}/{0} {1}/{1} {2}/{2}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap();
        } else {
            writeln!(s, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap();
        }
    }
    s
}

fn linear_luminance(p: [u8; 4]) -> f64 {
    let l = |c: u8| color::srgb_to_linear(c as f32 / 255.0) as f64;
    0.2126 * l(p[0]) + 0.7152 * l(p[1]) + 0.0722 * l(p[2])
}

fn json_of(out: &Output) -> serde_json::Value {
    let text = String::from_utf8(out.stdout.clone()).unwrap();
    serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("stdout is not one JSON object ({e}): {text}"))
}

fn opaque_pixels(path: &Path) -> Vec<[u8; 4]> {
    let img = Image::from_png(&std::fs::read(path).unwrap()).unwrap();
    img.data
        .chunks_exact(4)
        .filter(|q| q[3] == 255)
        .map(|q| [q[0], q[1], q[2], q[3]])
        .collect()
}

#[test]
fn checkerboard_from_vt_is_half_black_half_white() {
    let d = tmp("checker");
    let g = shapes::grid(8, 1.0);
    let uv: Vec<[f64; 2]> = g.positions.iter().map(|p| [p[0], p[1]]).collect();
    let mesh = d.join("square.obj");
    std::fs::write(&mesh, obj(&g.positions, &g.triangles, Some(&uv))).unwrap();
    let png = d.join("square.png");
    let out = ricci(&[
        "render",
        mesh.to_str().unwrap(),
        "--view",
        "0,0,1",
        "--checker",
        "6",
        "--size",
        "300",
        "--transparent",
        "--unlit",
        "--out",
        png.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j = json_of(&out);
    assert_eq!(j["paint"], "checker");
    assert_eq!(j["uv"], "per-vertex");
    assert_eq!(j["faces"], 128);
    assert_eq!(j["width"], 300);
    let lum: Vec<f64> = opaque_pixels(&png)
        .into_iter()
        .map(linear_luminance)
        .collect();
    let white = lum.iter().filter(|&&l| l > 0.5).count() as f64;
    let black = lum.len() as f64 - white;
    assert!(
        (black / white - 1.0).abs() <= 0.02,
        "black/white = {black}/{white}"
    );
}

#[test]
fn uv_file_of_a_cut_torus_gives_per_corner_uvs() {
    // The torus mesh is closed; its "layout" is the same grid cut open along two circles
    // (seam vertices duplicated), same faces in the same order, written with vt.
    let d = tmp("cut");
    let (n, m) = (24usize, 12usize);
    let t = shapes::torus(2.0, 0.7, n, m);
    let mesh = d.join("torus.obj");
    std::fs::write(&mesh, obj(&t.positions, &t.triangles, None)).unwrap();
    let id = |i: usize, j: usize| (i * (m + 1) + j) as u32;
    let mut cp = Vec::new();
    let mut cuv = Vec::new();
    for i in 0..=n {
        for j in 0..=m {
            cp.push(t.positions[(i % n) * m + (j % m)]);
            cuv.push([i as f64 / n as f64, j as f64 / m as f64]);
        }
    }
    let mut ct = Vec::new();
    for i in 0..n {
        for j in 0..m {
            ct.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            ct.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let cut = d.join("cut.obj");
    std::fs::write(&cut, obj(&cp, &ct, Some(&cuv))).unwrap();
    let png = d.join("torus.png");
    let out = ricci(&[
        "render",
        mesh.to_str().unwrap(),
        "--uv",
        cut.to_str().unwrap(),
        "--size",
        "200",
        "--out",
        png.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j = json_of(&out);
    assert_eq!(j["uv"], "per-corner");
    assert_eq!(j["paint"], "checker");
    // glTF too: a binary glTF header with the right length.
    let glb = d.join("torus.glb");
    let out = ricci(&[
        "render",
        mesh.to_str().unwrap(),
        "--uv",
        cut.to_str().unwrap(),
        "--out",
        glb.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let b = std::fs::read(&glb).unwrap();
    assert_eq!(&b[..4], b"glTF");
    assert_eq!(
        u32::from_le_bytes([b[8], b[9], b[10], b[11]]) as usize,
        b.len()
    );
    // A UV file with different faces is refused (exit 1), nothing written.
    let small = d.join("small.obj");
    std::fs::write(&small, obj(&cp, &ct[..10], Some(&cuv))).unwrap();
    let bad = d.join("bad.png");
    let out = ricci(&[
        "render",
        mesh.to_str().unwrap(),
        "--uv",
        small.to_str().unwrap(),
        "--out",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("faces"));
    assert!(!bad.exists());
}

#[test]
fn scalar_files_constant_field_is_one_colour() {
    let d = tmp("scalar");
    let s = shapes::icosphere(2);
    let mesh = d.join("sphere.obj");
    std::fs::write(&mesh, obj(&s.positions, &s.triangles, None)).unwrap();
    let vals = d.join("vals.txt");
    std::fs::write(
        &vals,
        "# constant\n".to_string() + &"0.25\n".repeat(s.positions.len()),
    )
    .unwrap();
    let png = d.join("const.png");
    let out = ricci(&[
        "render",
        mesh.to_str().unwrap(),
        "--scalar",
        vals.to_str().unwrap(),
        "--unlit",
        "--transparent",
        "--no-legend",
        "--size",
        "128",
        "--out",
        png.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j = json_of(&out);
    assert_eq!(j["scalar"]["location"], "vertex");
    assert_eq!(j["scalar"]["min"], 0.25);
    // Every pixel the sphere covers has one colour (straight alpha at the silhouette).
    let img = Image::from_png(&std::fs::read(&png).unwrap()).unwrap();
    let first = img.pixel(img.width / 2, img.height / 2);
    assert_eq!(first[3], 255);
    let mut n = 0;
    for y in 0..img.height {
        for x in 0..img.width {
            let p = img.pixel(x, y);
            if p[3] > 0 {
                n += 1;
                assert!(
                    (0..3).all(|k| (p[k] as i32 - first[k] as i32).abs() <= 1),
                    "{p:?} vs {first:?}"
                );
            }
        }
    }
    assert!(n > 1000);
    // METRIC.json with key u, per face values via a JSON key.
    let metric = d.join("metric.json");
    let u: Vec<f64> = s.positions.iter().map(|p| p[2]).collect();
    let k: Vec<f64> = (0..s.triangles.len()).map(|f| f as f64).collect();
    std::fs::write(&metric, serde_json::json!({"u": u, "F": k}).to_string()).unwrap();
    for spec in [
        metric.to_str().unwrap().to_string(),
        format!("{}:F", metric.display()),
    ] {
        let out = ricci(&[
            "render",
            mesh.to_str().unwrap(),
            "--scalar",
            &spec,
            "--size",
            "64",
            "--out",
            png.to_str().unwrap(),
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let j = json_of(&out);
        let want = if spec.ends_with(":F") {
            "face"
        } else {
            "vertex"
        };
        assert_eq!(j["scalar"]["location"], want);
        // z on the sphere is signed: a diverging map with a symmetric range.
        if want == "vertex" {
            let r = &j["scalar"]["range"];
            assert_eq!(r[0].as_f64().unwrap(), -r[1].as_f64().unwrap());
        }
    }
    // Wrong number of values: bad input.
    std::fs::write(&vals, "1 2 3").unwrap();
    let out = ricci(&[
        "render",
        mesh.to_str().unwrap(),
        "--scalar",
        vals.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("3 values"));
}

#[test]
fn builtin_fields_and_bad_arguments() {
    let d = tmp("args");
    let t = shapes::torus(2.0, 0.7, 30, 15);
    let mesh = d.join("torus.obj");
    std::fs::write(&mesh, obj(&t.positions, &t.triangles, None)).unwrap();
    let png = d.join("t.png");
    let m = mesh.to_str().unwrap();
    let p = png.to_str().unwrap();
    for name in ["angle-defect", "mean-curvature", "gaussian-curvature", "z"] {
        let out = ricci(&[
            "render",
            m,
            "--scalar",
            name,
            "--size",
            "96",
            "--isolines",
            "8",
            "--out",
            p,
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(json_of(&out)["scalar"]["name"], name);
    }
    // Picture options together.
    let out = ricci(&[
        "render",
        m,
        "--zebra",
        "--wireframe",
        "--boundary",
        "--perspective",
        "--size",
        "96",
        "--out",
        p,
    ]);
    assert!(out.status.success());
    // Bad arguments: exit code 2, nothing written.
    let bad = d.join("bad.png");
    let b = bad.to_str().unwrap();
    for args in [
        vec!["render", m, "--out", "x.jpg"],
        vec!["render", m, "--view", "0,0,0", "--out", b],
        vec!["render", m, "--view", "1,2", "--out", b],
        vec!["render", m, "--zebra", "--scalar", "z", "--out", b],
        vec!["render", m, "--scalar", "no-such-field", "--out", b],
        vec!["render", m, "--scalar", "area-distortion", "--out", b],
        vec!["render", m, "--range", "3,1", "--scalar", "z", "--out", b],
        vec!["render", m, "--size", "5", "--out", b],
        vec![
            "render",
            m,
            "--colormap",
            "jet",
            "--scalar",
            "z",
            "--out",
            b,
        ],
    ] {
        let out = ricci(&args);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(!bad.exists());
    }
    // Bad input: exit code 1.
    let out = ricci(&[
        "render",
        d.join("missing.obj").to_str().unwrap(),
        "--out",
        b,
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(!bad.exists());
}

#[test]
fn real_meshes_are_framed() {
    let Some(dir) = ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("note: RICCI_MESHES is not set; skipping real-mesh rendering");
        return;
    };
    let d = tmp("real");
    for (file, view) in [
        ("bunny.off", "0,0,1"),
        ("kitten.nf20k.off", "1,0.5,1"),
        ("camelhead.off", "0.4,0.3,1"),
    ] {
        let png = d.join(format!("{file}.png"));
        let out = ricci(&[
            "render",
            dir.join(file).to_str().unwrap(),
            "--view",
            view,
            "--size",
            "256",
            "--transparent",
            "--out",
            png.to_str().unwrap(),
            "--json",
        ]);
        assert!(
            out.status.success(),
            "{file}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let img = Image::from_png(&std::fs::read(&png).unwrap()).unwrap();
        let mut n = 0;
        for y in 0..img.height {
            for x in 0..img.width {
                if img.pixel(x, y)[3] > 0 {
                    n += 1;
                    assert!(
                        x > 0 && y > 0 && x < img.width - 1 && y < img.height - 1,
                        "{file} touches the edge"
                    );
                }
            }
        }
        assert!(n as f64 / (256.0 * 256.0) > 0.3, "{file} fills {n} pixels");
        assert!((json_of(&out)["coverage"].as_f64().unwrap() - n as f64 / 65536.0).abs() < 0.02);
    }
}

#[path = "../../ricci/tests/ricci_meshes/mod.rs"]
mod ricci_meshes;
use ricci_meshes::ricci_meshes;

/// A layout's uv.obj has texture seams (`f v/vt` with several `vt` per vertex along the cut):
/// rendering it with its own vt, or another OBJ with the same faces through `--uv`, uses the
/// per-corner coordinates; the checkerboard then covers the surface (no grey "no UV" faces).
#[test]
fn layout_uv_obj_with_seams_renders_per_corner() {
    let d = tmp("seams");
    let mesh = d.join("torus.off");
    let uv = d.join("uv.obj");
    assert!(ricci(&[
        "generate",
        "torus",
        "-n",
        "24",
        "--out",
        mesh.to_str().unwrap()
    ])
    .status
    .success());
    let o = ricci(&[
        "layout",
        mesh.to_str().unwrap(),
        "--out",
        uv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (file, extra) in [(&uv, None), (&mesh, Some(&uv))] {
        let png = d.join("chk.png");
        let mut args = vec![
            file.to_str().unwrap(),
            "--checker",
            "8",
            "--out",
            png.to_str().unwrap(),
            "--json",
        ];
        if let Some(u) = extra {
            args.extend(["--uv", u.to_str().unwrap()]);
        }
        let mut full = vec!["render"];
        full.extend(args);
        let o = ricci(&full);
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        if extra.is_some() && !o.status.success() {
            // The cut refines the torus around its base vertex, so the faces differ: refused
            // with a sentence that says so.
            assert!(err.contains("same faces"), "{err}");
            continue;
        }
        assert!(o.status.success(), "{err}");
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(j["paint"], "checker");
        assert_eq!(j["uv"], "per-corner");
    }
}
