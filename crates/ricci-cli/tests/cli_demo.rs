//! `ricci demo` end to end: one run from scratch into a fresh folder (shared by the tests
//! below), then checks that come from elsewhere — every link of `index.html` resolves to a
//! non-empty file, the PNGs decode with the sizes the page advertises, the files read back
//! with the library and the glTF crate, and the numbers satisfy Gauss–Bonnet, the closed-form
//! hyperbolic area, the hyperbolic cosine law recomputed here, the symplectic intersection
//! form and the length inequalities between loops, deck generators and geodesics. Bad
//! arguments exit 2, an output folder that cannot be written exits 1 with one sentence.

#![allow(clippy::needless_range_loop)] // (i, j) loops over a matrix read best with indices

use ricci_render::Image;
use serde_json::Value;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::OnceLock;

fn bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_ricci"))
}

fn tmp() -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci-cli-demo-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn ricci(args: &[&str]) -> Output {
    Command::new(bin()).args(args).output().expect("run ricci")
}

/// The demo, run once with `--json` into a folder that does not exist yet.
fn demo() -> &'static (PathBuf, Value) {
    static RUN: OnceLock<(PathBuf, Value)> = OnceLock::new();
    RUN.get_or_init(|| {
        let dir = tmp().join("fresh").join("demo-out");
        assert!(!dir.exists());
        let out = Command::new(bin())
            .args(["demo", "--json", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "ricci demo failed: {stderr}");
        let text = String::from_utf8(out.stdout).unwrap();
        let v: Value = serde_json::from_str(&text)
            .unwrap_or_else(|e| panic!("stdout is not one JSON object ({e}): {text}"));
        (dir, v)
    })
}

fn stage<'a>(v: &'a Value, id: &str) -> &'a Value {
    let s = &v["stages"][id];
    assert_eq!(s["status"], "ok", "stage {id}: {s}");
    s
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Attribute values `name="…"` of every occurrence in `html`.
fn attributes(html: &str, name: &str) -> Vec<String> {
    let pat = format!(" {name}=\"");
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(i) = rest.find(&pat) {
        let after = &rest[i + pat.len()..];
        let end = after.find('"').expect("unterminated attribute");
        out.push(after[..end].to_string());
        rest = &after[end..];
    }
    out
}

/// Every `<img …>` tag as a map of its attributes.
fn img_tags(html: &str) -> Vec<HashMap<String, String>> {
    let mut out = Vec::new();
    for piece in html.split("<img ").skip(1) {
        let tag = &piece[..piece.find('>').expect("unterminated img")];
        let mut m = HashMap::new();
        for name in ["src", "width", "height", "alt"] {
            if let Some(v) = attributes(&format!(" {tag}"), name).first() {
                m.insert(name.to_string(), v.clone());
            }
        }
        out.push(m);
    }
    out
}

#[test]
fn every_link_of_the_page_is_a_local_non_empty_file() {
    let (dir, v) = demo();
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.trim_end().ends_with("</html>"));
    let mut links: Vec<String> = attributes(&html, "src");
    links.extend(attributes(&html, "href"));
    let anchors: Vec<&String> = links.iter().filter(|l| l.starts_with('#')).collect();
    let files: Vec<&String> = links.iter().filter(|l| !l.starts_with('#')).collect();
    assert!(files.len() >= 25, "only {} file links", files.len());
    for l in &files {
        // No network: only relative paths inside the folder.
        assert!(
            !l.contains(':') && !l.starts_with('/') && !l.contains(".."),
            "{l} is not a local relative link"
        );
        let p = dir.join(l);
        let len = std::fs::metadata(&p)
            .unwrap_or_else(|e| panic!("{l}: {e}"))
            .len();
        assert!(len > 0, "{l} is empty");
    }
    // Every anchor names a section of the page.
    for a in anchors {
        assert!(
            html.contains(&format!("id=\"{}\"", &a[1..])),
            "dangling {a}"
        );
    }
    assert!(!html.contains("<script"), "the page must not need scripts");
    // The JSON file list matches the folder, and nothing else (no staging folder) is left.
    let listed: Vec<&str> = v["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    for name in &listed {
        assert!(dir.join(name).is_file(), "{name} is listed but missing");
    }
    for e in std::fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().to_string();
        assert!(
            listed.contains(&name.as_str()),
            "{name} is not in the file list"
        );
    }
    // Each stage has its section, in order, and the placeholders for the stages to come.
    let order: Vec<&str> = v["stage_order"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert_eq!(
        order,
        [
            "surface",
            "flow",
            "cone",
            "loops",
            "layout",
            "spectrum",
            "atlas",
            "spline",
            "pou",
            "param",
            "tspline",
            "forms",
            "geodesics"
        ]
    );
    // The file list is in the order of the stages, also for the stages that ran on a thread
    // of their own beside the others (the spline): each stage's files come after those of
    // the stages before it.
    // (Inside a stage the order is the order of writing, which its file descriptions need
    // not follow.)
    let mut last = 0;
    for id in &order {
        let at: Vec<usize> = v["stages"][*id]["files"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| listed.iter().position(|x| Some(*x) == f.as_str()).unwrap())
            .collect();
        if let (Some(&lo), Some(&hi)) = (at.iter().min(), at.iter().max()) {
            assert!(
                lo >= last,
                "a file of stage {id} is listed before one of an earlier stage"
            );
            last = hi;
        }
    }
    let mut at = 0;
    for id in order {
        let i = html[at..]
            .find(&format!("<section id=\"{id}\""))
            .unwrap_or_else(|| panic!("no section {id} (or out of order)"));
        at += i + 1;
    }
    assert!(html.contains("Affine atlas") && html.contains("Manifold spline"));
    assert_eq!(v["ok"], true);
}

/// Item 9: every link below a picture says which file it opens — no two links of one caption
/// read the same (the atlas chart's caption read "· SVG · SVG" for two different drawings).
#[test]
fn links_below_a_picture_have_distinct_labels() {
    let (dir, _) = demo();
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let mut captions = 0;
    for cap in html.split("<figcaption>").skip(1) {
        let cap = cap.split("</figcaption>").next().unwrap_or("");
        captions += 1;
        let labels: Vec<&str> = cap
            .split("</a>")
            .filter_map(|x| x.rsplit_once('>').map(|(_, t)| t))
            .filter(|t| !t.is_empty())
            .collect();
        let mut seen = std::collections::BTreeSet::new();
        for l in &labels {
            assert!(
                seen.insert(*l),
                "two links labelled {l:?} below one picture: {cap}"
            );
        }
    }
    assert!(captions >= 20, "only {captions} captions");
}

#[test]
fn pictures_decode_with_the_advertised_sizes() {
    let (dir, _) = demo();
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let imgs = img_tags(&html);
    // The pictures the issues ask for are all on the page.
    for want in [
        "surface.png",
        "flow-residuals.png",
        "curvature-before.png",
        "curvature-after.png",
        "cone-residuals.png",
        "loops.png",
        "polygon.png",
        "tiling.png",
        "checker.png",
    ] {
        assert!(imgs.iter().any(|t| t["src"] == want), "no picture {want}");
    }
    for t in &imgs {
        let src = &t["src"];
        assert!(src.ends_with(".png"), "{src}");
        assert!(!t["alt"].is_empty(), "{src} has no alt text");
        let img = Image::from_png(&std::fs::read(dir.join(src)).unwrap())
            .unwrap_or_else(|e| panic!("{src} does not decode: {e}"));
        assert_eq!(img.width.to_string(), t["width"], "{src} width");
        assert_eq!(img.height.to_string(), t["height"], "{src} height");
        // Not blank: more than one colour.
        let first = &img.data[..4];
        assert!(
            img.data.chunks_exact(4).any(|p| p != first),
            "{src} is one colour"
        );
    }
}

#[test]
fn surface_is_the_genus_two_surface_it_claims() {
    let (dir, v) = demo();
    let s = stage(v, "surface");
    let (nv, ne, nf) = (
        s["vertices"].as_i64().unwrap(),
        s["edges"].as_i64().unwrap(),
        s["faces"].as_i64().unwrap(),
    );
    assert_eq!(s["genus"], 2);
    assert_eq!(s["euler_characteristic"].as_i64().unwrap(), nv - ne + nf);
    assert_eq!(nv - ne + nf, -2);
    assert_eq!(3 * nf, 2 * ne, "a closed triangle mesh has 3F = 2E");
    // Gauss–Bonnet of the embedding: the angle defects add up to 2πχ.
    assert!((f(&s["total_angle_defect"]) + 4.0 * PI).abs() < 1e-9);
    // The written file reads back with the library, with the same counts and topology.
    let (surf, _) = ricci::mesh::io::read_surface(&dir.join("surface.off")).unwrap();
    let t = ricci::mesh::topology(&surf.mesh);
    assert_eq!(surf.mesh.n_vertices() as i64, nv);
    assert_eq!(surf.mesh.n_faces() as i64, nf);
    assert_eq!(
        (t.genus(), t.boundary_loops(), t.components.len()),
        (2, 0, 1)
    );
    // info.json is what `ricci info` says about the same file.
    let info: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("info.json")).unwrap()).unwrap();
    let out = ricci(&["info", "--json", dir.join("surface.off").to_str().unwrap()]);
    assert!(out.status.success());
    let direct: Value = serde_json::from_slice(&out.stdout).unwrap();
    for k in [
        "vertices",
        "edges",
        "faces",
        "genus",
        "euler_characteristic",
        "min_angle_deg",
    ] {
        assert_eq!(info[k], direct[k], "{k}");
    }
}

/// Angle at the vertex between sides b and c opposite side a, hyperbolic cosine law.
fn hyperbolic_angle(a: f64, b: f64, c: f64) -> f64 {
    ((b.cosh() * c.cosh() - a.cosh()) / (b.sinh() * c.sinh()))
        .clamp(-1.0, 1.0)
        .acos()
}

#[test]
fn hyperbolic_metric_is_flat_in_angle_sums_and_has_area_four_pi() {
    let (dir, v) = demo();
    let s = stage(v, "flow");
    assert_eq!(s["converged"], true);
    assert!(f(&s["max_curvature_error"]) <= 1e-10, "{s}");
    assert!(f(&s["gauss_bonnet_error"]) < 1e-9);
    // Gauss–Bonnet with K = 0 at every vertex: area = −2πχ = 4π.
    assert!(
        (f(&s["area"]) - 4.0 * PI).abs() < 1e-8,
        "area {}",
        s["area"]
    );
    let hist = s["history"].as_array().unwrap();
    assert!(hist.len() >= 2);
    assert!(f(&hist.last().unwrap()["max_curvature_error"]) < f(&hist[0]["max_curvature_error"]));
    // Recompute the angles from the lengths in the metric file with the hyperbolic cosine
    // law: every vertex has angle sum 2π, and the triangle areas (π − angle sum) add to 4π.
    let (surf, _) = ricci::mesh::io::read_surface(&dir.join("surface.off")).unwrap();
    let m: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("hyperbolic-metric.json")).unwrap())
            .unwrap();
    assert_eq!(m["geometry"], "hyperbolic");
    let mut len: HashMap<(u64, u64), f64> = HashMap::new();
    for (e, l) in m["edge_vertices"]
        .as_array()
        .unwrap()
        .iter()
        .zip(m["lengths"].as_array().unwrap())
    {
        let (a, b) = (e[0].as_u64().unwrap(), e[1].as_u64().unwrap());
        len.insert((a.min(b), a.max(b)), f(l));
    }
    let get = |a: u32, b: u32| len[&((a.min(b)) as u64, (a.max(b)) as u64)];
    let mut sum = vec![0.0; surf.mesh.n_vertices()];
    let mut area = 0.0;
    for t in surf.mesh.faces() {
        let [i, j, k] = *t;
        let (li, lj, lk) = (get(j, k), get(k, i), get(i, j));
        let (ai, aj, ak) = (
            hyperbolic_angle(li, lj, lk),
            hyperbolic_angle(lj, lk, li),
            hyperbolic_angle(lk, li, lj),
        );
        sum[i as usize] += ai;
        sum[j as usize] += aj;
        sum[k as usize] += ak;
        area += PI - ai - aj - ak;
    }
    let worst = sum.iter().map(|s| (s - 2.0 * PI).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-9, "largest |2π − Σθ| = {worst:e}");
    assert!((area - 4.0 * PI).abs() < 1e-8, "area {area}");
}

#[test]
fn single_cone_carries_all_the_curvature() {
    let (dir, v) = demo();
    let chi = v["stages"]["surface"]["euler_characteristic"]
        .as_i64()
        .unwrap() as f64;
    let s = stage(v, "cone");
    assert_eq!(s["converged"], true);
    assert_eq!(s["geometry"], "euclidean");
    // 2πχ = −4π on one vertex, nothing elsewhere.
    assert!(
        (f(&s["cone_curvature"]) - 2.0 * PI * chi).abs() < 1e-9,
        "{s}"
    );
    assert!((f(&s["cone_curvature"]) + 4.0 * PI).abs() < 1e-9);
    assert!(f(&s["max_curvature_elsewhere"]) < 1e-9);
    // Chow–Luo: a cone of K̄ needs valence ≥ 4 − 2K̄/π = 12.
    assert!(s["valence_after"].as_u64().unwrap() >= 12);
    assert!(s["valence_before"].as_u64().unwrap() < s["valence_after"].as_u64().unwrap());
    // On the unrefined surface the same target is refused, for Chow–Luo's reason.
    let refusal = s["refused_without_refinement"].as_str().expect("a refusal");
    assert!(refusal.contains("Chow–Luo"), "{refusal}");
    assert!(
        refusal.contains(&format!("vertex {}", s["cone_vertex"])),
        "{refusal}"
    );
    // The metric file: Gauss–Bonnet (λ = 0) over all vertices, the cone where it is said.
    let m: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("cone-metric.json")).unwrap())
            .unwrap();
    let k: Vec<f64> = m["curvature"].as_array().unwrap().iter().map(f).collect();
    assert_eq!(k.len() as u64, s["refined_vertices"].as_u64().unwrap());
    assert!((k.iter().sum::<f64>() - 2.0 * PI * chi).abs() < 1e-9);
    let v0 = s["cone_vertex"].as_u64().unwrap() as usize;
    assert!((k[v0] + 4.0 * PI).abs() < 1e-9);
    assert!(m["lengths"].as_array().unwrap().iter().all(|l| f(l) > 0.0));
    // The residual history was drawn.
    assert!(s["history"].as_array().unwrap().len() >= 2);
    assert!(dir.join("cone-residuals.png").is_file());
}

#[test]
fn loops_deck_group_and_spectrum_are_consistent() {
    let (dir, v) = demo();
    let lp = stage(v, "loops");
    assert_eq!(lp["genus"], 2);
    assert_eq!(lp["polygon_sides"], 8);
    assert_eq!(lp["boundary_word"], "a1 b1 a1^-1 b1^-1 a2 b2 a2^-1 b2^-1");
    assert_eq!(lp["boundary_word"].as_str().unwrap().split(' ').count(), 8);
    assert_eq!(lp["disk"], true);
    // The intersection form of a canonical system: a_i · b_i = ±1, everything else 0.
    let im: Vec<Vec<i64>> = lp["intersection_matrix"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_i64().unwrap())
                .collect()
        })
        .collect();
    assert_eq!(im.len(), 4);
    for i in 0..4 {
        for j in 0..4 {
            assert_eq!(im[i][j], -im[j][i], "not antisymmetric");
            let paired = i / 2 == j / 2 && i != j;
            assert_eq!(im[i][j].abs(), paired as i64, "entry ({i}, {j})");
        }
    }
    // The cut mesh read back is a disk.
    let (cut, _) = ricci::mesh::io::read_surface(&dir.join("cut.obj")).unwrap();
    let t = ricci::mesh::topology(&cut.mesh);
    assert_eq!(
        (t.genus(), t.boundary_loops(), t.euler_characteristic()),
        (0, 1, 1)
    );

    let lay = stage(v, "layout");
    assert!(
        f(&lay["relation_error"]) <= 1e-9,
        "{}",
        lay["relation_error"]
    );
    assert_eq!(lay["flipped_faces"], 0);
    assert!(lay["tiles"].as_u64().unwrap() >= 200);
    let gens = lay["deck_generators"].as_array().unwrap();
    assert_eq!(gens.len(), 4);
    let mut translation: HashMap<String, f64> = HashMap::new();
    for g in gens {
        let (a, b) = (&g["a"], &g["b"]);
        let det = f(&a[0]).powi(2) + f(&a[1]).powi(2) - f(&b[0]).powi(2) - f(&b[1]).powi(2);
        assert!((det - 1.0).abs() < 1e-9, "|a|² − |b|² = {det}");
        // Hyperbolic elements, with ℓ = 2 acosh(|tr|/2).
        let tr = f(&g["trace"]);
        assert!(tr.abs() > 2.0);
        let l = f(&g["translation_length"]);
        assert!((l - 2.0 * (tr.abs() / 2.0).acosh()).abs() < 1e-9);
        translation.insert(g["letter"].as_str().unwrap().to_string(), l);
    }
    // A loop of mesh edges is a closed curve in the class of its generator: it is at least
    // as long as the closed geodesic of that class (the generator's translation length).
    for l in lp["loops"].as_array().unwrap() {
        let name = l["label"].as_str().unwrap();
        let len = f(&l["length"]);
        assert!(
            len >= translation[name] - 1e-9,
            "loop {name} has length {len} < translation length {}",
            translation[name]
        );
    }
    let sp = stage(v, "spectrum");
    let lengths: Vec<f64> = sp["lengths"].as_array().unwrap().iter().map(f).collect();
    assert!(lengths.len() >= 5);
    assert!(lengths[0] > 0.0);
    assert!(
        lengths.windows(2).all(|w| w[0] <= w[1] + 1e-12),
        "{lengths:?}"
    );
    // The generators are closed geodesics too: the shortest one is not shorter than the
    // systole, and the systole is at most the shortest generator.
    let shortest_gen = translation.values().copied().fold(f64::INFINITY, f64::min);
    assert!(lengths[0] <= shortest_gen + 1e-9);
    for (name, l) in &translation {
        assert!(*l >= lengths[0] - 1e-9, "generator {name}");
    }
    // The double of the systole's class is a class too: 2ℓ₁ appears when it is in range.
    let complete = f(&sp["complete_up_to"]);
    if 2.0 * lengths[0] < complete.min(*lengths.last().unwrap()) {
        assert!(
            lengths.iter().any(|l| (l - 2.0 * lengths[0]).abs() < 1e-7),
            "2ℓ₁ = {} missing from {lengths:?}",
            2.0 * lengths[0]
        );
    }
}

#[test]
fn gltf_and_uv_obj_carry_the_hyperbolic_layout() {
    let (dir, v) = demo();
    let faces = v["stages"]["loops"]["cut_faces"].as_u64().unwrap() as usize;
    let bytes = std::fs::read(dir.join("surface.glb")).unwrap();
    let g = gltf::Gltf::from_slice(&bytes).expect("surface.glb parses");
    let blob = g.blob.as_deref().expect("binary chunk");
    let mesh = g.meshes().next().expect("a mesh");
    let prim = mesh.primitives().next().unwrap();
    let reader = prim.reader(|_| Some(blob));
    let idx: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    assert_eq!(idx.len(), 3 * faces);
    let pos: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    assert!(idx.iter().all(|&i| (i as usize) < pos.len()));
    let uv: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
    assert_eq!(uv.len(), pos.len());
    // Poincaré-disk coordinates stored as (u, 1 − v): inside the unit disk around (0, 1).
    for t in &uv {
        let r2 = t[0] * t[0] + (1.0 - t[1]) * (1.0 - t[1]);
        assert!(r2 < 1.0, "uv {t:?} is outside the disk");
    }
    assert_eq!(g.textures().count(), 1);
    // uv.obj reads back with the same faces.
    let (s, _) = ricci::mesh::io::read_surface(&dir.join("uv.obj")).unwrap();
    assert_eq!(s.mesh.n_faces(), faces);
}

#[test]
fn bad_arguments_exit_2() {
    let dir = tmp().join("bad-args");
    let d = dir.to_str().unwrap();
    for args in [
        vec!["demo"],
        vec!["demo", "--out", d, "--resolution", "3"],
        vec!["demo", "--out", d, "--resolution", "many"],
        vec!["demo", "--out", d, "--frobnicate"],
    ] {
        let out = ricci(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    let out = ricci(&["demo", "--out", d, "--resolution", "3"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("--resolution 3"), "{err}");
    assert!(!dir.exists(), "nothing is written for bad arguments");
}

#[test]
fn an_output_folder_that_cannot_be_written_exits_1_with_one_sentence() {
    let file = tmp().join("not-a-folder");
    std::fs::write(&file, b"x").unwrap();
    for target in [file.clone(), file.join("below")] {
        let out = Command::new(bin())
            .args(["demo", "--json", "--out"])
            .arg(&target)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{}", target.display());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(
            err.starts_with("error: ") && err.contains("not-a-folder"),
            "{err}"
        );
        // --json: the failure is one JSON object on stdout with the same sentence.
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("{\"error\": …}");
        assert_eq!(
            format!("error: {}", v["error"].as_str().unwrap_or("")),
            err.trim()
        );
    }
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
}

/// Keep the helper honest: it finds every attribute, in order.
#[test]
fn attribute_parser_finds_every_link() {
    let html =
        r##"<a href="a.png"><img src="a.png" width="3" height="4" alt="x"></a> <a href="#s">"##;
    assert_eq!(attributes(html, "href"), ["a.png", "#s"]);
    let t = img_tags(html);
    assert_eq!(t.len(), 1);
    assert_eq!(t[0]["width"], "3");
    assert_eq!(t[0]["height"], "4");
}

#[test]
fn a_failed_stage_is_reported_in_the_page_and_the_exit_status() {
    let dir = tmp().join("failing");
    let out = Command::new(bin())
        .args(["demo", "--json", "--out"])
        .arg(&dir)
        .env("RICCI_DEMO_FAIL", "loops")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("loops") && err.contains("index.html"), "{err}");
    let v: Value = serde_json::from_slice(&out.stdout).expect("the JSON is still printed");
    assert_eq!(v["ok"], false);
    let st = |id: &str| v["stages"][id]["status"].as_str().unwrap().to_string();
    assert_eq!(st("surface"), "ok");
    assert_eq!(st("flow"), "ok");
    assert_eq!(st("cone"), "ok", "the cone does not need the loops");
    assert_eq!(st("loops"), "failed");
    assert_eq!(st("layout"), "skipped");
    assert_eq!(st("spectrum"), "skipped");
    // The page says so, and links nothing that is not there.
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    assert!(html.contains("badge failed") && html.contains("badge skipped"));
    assert!(html.contains("RICCI_DEMO_FAIL=loops"));
    for l in attributes(&html, "src")
        .into_iter()
        .chain(attributes(&html, "href"))
    {
        if !l.starts_with('#') {
            assert!(dir.join(&l).is_file(), "{l} is linked but missing");
        }
    }
    assert!(!dir.join("loops.png").exists() && !dir.join("polygon.png").exists());
}

/// The spline runs on a thread of its own beside the other stages: its failure is reported
/// like any other, its files are dropped, and the stages after it are not affected.
#[test]
fn a_failed_stage_that_ran_beside_the_others_is_reported_too() {
    let dir = tmp().join("failing-beside");
    let out = Command::new(bin())
        .args(["demo", "--json", "--out"])
        .arg(&dir)
        .env("RICCI_DEMO_FAIL", "spline")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("spline") && err.contains("index.html"),
        "{err}"
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("the JSON is still printed");
    let st = |id: &str| v["stages"][id]["status"].as_str().unwrap().to_string();
    assert_eq!(st("spline"), "failed");
    for id in ["surface", "atlas", "pou", "param", "forms", "geodesics"] {
        assert_eq!(st(id), "ok", "{id}");
    }
    assert!(!dir.join("spline.obj").exists() && !dir.join("spline-zebra.png").exists());
    assert!(dir.join("pou.obj").is_file());
    let files: Vec<&str> = v["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert!(!files.iter().any(|f| f.starts_with("spline")), "{files:?}");
    // Nothing is left of the staging folder.
    for e in std::fs::read_dir(&dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().to_string();
        assert!(!name.starts_with('.'), "{name} left in the folder");
    }
}

#[test]
fn the_commands_the_page_shows_work_in_a_copy_of_the_folder() {
    let (dir, _) = demo();
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let work = tmp().join("commands");
    std::fs::create_dir_all(&work).unwrap();
    for f in ["surface.off", "hyperbolic-metric.json"] {
        std::fs::copy(dir.join(f), work.join(f)).unwrap();
    }
    let mut ran = 0;
    for block in html.split("<pre>").skip(1) {
        let block = &block[..block.find("</pre>").unwrap()];
        for line in block.lines().filter(|l| !l.trim().is_empty()) {
            let words: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(words[0], "ricci", "{line}");
            // The spectrum repeats the demo's most expensive library call; skip it here.
            if words[1] == "spectrum" {
                continue;
            }
            let out = Command::new(bin())
                .args(&words[1..])
                .current_dir(&work)
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{line}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            ran += 1;
        }
    }
    assert!(ran >= 8, "only {ran} commands");
    // What they wrote agrees with the demo's files where it is deterministic.
    let (a, _) = ricci::mesh::io::read_surface(&dir.join("surface.off")).unwrap();
    let (b, _) = ricci::mesh::io::read_surface(&work.join("surface.off")).unwrap();
    assert_eq!(a.positions, b.positions);
    assert_eq!(a.mesh.faces(), b.mesh.faces());
}

#[test]
fn atlas_has_one_cone_and_rigid_transitions() {
    let (dir, v) = demo();
    let chi = v["stages"]["surface"]["euler_characteristic"]
        .as_i64()
        .unwrap() as f64;
    let s = stage(v, "atlas");
    assert!(s["singular_vertex"].is_u64(), "{s}");
    assert_eq!(s["flow_converged"], true);
    assert!(f(&s["max_curvature_error"]) <= 1e-10, "{s}");
    assert!(f(&s["gauss_bonnet_error"]) <= 1e-9, "{s}");
    // The cone's curvature, recomputed by the stage from the flat lengths with the cosine
    // law: all of 2πχ.
    assert!(
        (f(&s["cone_curvature"]) - 2.0 * PI * chi).abs() < 1e-8,
        "{s}"
    );
    assert!(f(&s["max_transition_error"]) <= 1e-9, "{s}");
    assert_eq!(s["flipped_faces"], 0);
    assert_eq!(s["faces_without_home"], 0);
    // A central chart plus at least one chart per cut curve (4g = 8 sides pair into 2g curves).
    assert!(s["charts"].as_u64().unwrap() > 4, "{s}");
    assert!(f(&s["area_distortion"]).is_finite());
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let imgs = img_tags(&html);
    for want in ["atlas-chart.png", "atlas-checker.png"] {
        assert!(imgs.iter().any(|t| t["src"] == want), "no picture {want}");
    }
    assert!(dir.join("atlas-overview.svg").is_file());
}

#[test]
fn spline_is_c2_with_a_g1_fill_and_close_to_the_surface() {
    let (dir, v) = demo();
    let s = stage(v, "spline");
    assert_eq!(s["degree"], 3);
    assert!(s["singular_vertex"].is_u64(), "{s}");
    let c = &s["continuity"];
    // C^{n−1} = C² measured across every interior domain edge; the jump of order n is not small
    // (the measurement can fail: a cubic spline is not C³).
    let jumps: Vec<f64> = c["relative_jumps"]
        .as_array()
        .unwrap()
        .iter()
        .map(f)
        .collect();
    assert_eq!(jumps.len(), 4);
    assert!(jumps[..3].iter().all(|&j| j <= 1e-6), "{c}");
    assert!(jumps[3] > 1e-4, "{c}");
    assert_eq!(c["seams"], 1);
    assert!(f(&c["max_seam_normal_jump_deg"]) <= 0.5, "{c}");
    // The spline stays near the input mesh (percent of the bounding-box diagonal).
    assert!(
        f(&s["rms_error_percent"]) < 1.0 && f(&s["max_error_percent"]) < 3.0,
        "{s}"
    );
    assert!(s["fill_triangles"].as_u64().unwrap() > 0);
    // The tessellation file holds what the summary says.
    let obj = std::fs::read_to_string(dir.join("spline.obj")).unwrap();
    let nv = obj.lines().filter(|l| l.starts_with("v ")).count() as u64;
    let nf = obj.lines().filter(|l| l.starts_with("f ")).count() as u64;
    assert_eq!(nv, s["tessellation_vertices"].as_u64().unwrap());
    assert_eq!(nf, s["tessellation_triangles"].as_u64().unwrap());
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let imgs = img_tags(&html);
    for want in ["spline-zebra.png", "spline-patches.png"] {
        assert!(imgs.iter().any(|t| t["src"] == want), "no picture {want}");
    }
}

#[test]
fn pou_surface_has_no_jumps_and_stays_close_to_the_surface() {
    // The partition-of-unity stage (paper 004): derivatives of orders 0–3 agree across chart
    // boundaries at rounding level (the spline's order-3 jump is O(1), see above), and the
    // surface is as close to the mesh as the spline.
    let (dir, v) = demo();
    let s = stage(v, "pou");
    let jumps: Vec<f64> = s["continuity"]["relative_jumps"]
        .as_array()
        .unwrap()
        .iter()
        .map(f)
        .collect();
    assert_eq!(jumps.len(), 4);
    assert!(jumps.iter().all(|&j| j <= 1e-10), "{s}");
    assert!(
        f(&s["rms_error_percent"]) < 1.0 && f(&s["max_error_percent"]) < 3.0,
        "{s}"
    );
    let obj = std::fs::read_to_string(dir.join("pou.obj")).unwrap();
    let nv = obj.lines().filter(|l| l.starts_with("v ")).count() as u64;
    assert_eq!(nv, s["tessellation_vertices"].as_u64().unwrap());
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let imgs = img_tags(&html);
    for want in ["pou-zebra.png", "pou-zebra-back.png"] {
        assert!(imgs.iter().any(|t| t["src"] == want), "no picture {want}");
    }
}

/// The `tspline` stage is the domain-mesh spline of the demo's own surface: its numbers are
/// those of `ricci tspline surface.off --tolerance 0.5% --smoothing 1e-3 --json` run here on the written file (the command the
/// page shows), and they fit the surface's topology (closed, χ = −2): control points − cells
/// = χ, Σ (valence − 4) over the zeros = −4χ so the sides at the zeros number 4·zeros + 8,
/// every cell has four sides each shared by two cells (2·cells sides in all); G¹ (class C1)
/// at the zeros, C² elsewhere, within the 0.5 % tolerance; both pictures on the page.
#[test]
fn tspline_stage_is_ricci_tspline_of_the_demo_surface() {
    let (dir, v) = demo();
    let s = stage(v, "tspline");
    let surface = dir.join("surface.off");
    let out = ricci(&[
        "tspline",
        surface.to_str().unwrap(),
        "--tolerance",
        "0.5%",
        "--smoothing",
        "1e-3",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cli: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(cli["spline"], "domain_mesh", "{cli}");
    for k in [
        "control_points",
        "cells",
        "bezier_patches",
        "iterations",
        "converged",
        "t_junctions",
    ] {
        assert_eq!(s[k], cli[k], "{k}");
    }
    for k in ["rms_error_percent", "max_error_percent"] {
        let (a, b) = (f(&s[k]), f(&cli[k]));
        assert!(
            (a - b).abs() <= 1e-9 * b.abs().max(1e-12),
            "{k}: stage {a}, ricci tspline {b}"
        );
    }
    let (c, cc) = (&s["continuity"], &cli["continuity"]);
    for k in ["at_zeros", "one_interval_from_zeros", "elsewhere"] {
        assert_eq!(c[k]["sides"], cc[k]["sides"], "{k}");
        assert_eq!(c[k]["class"], cc[k]["class"], "{k}");
    }
    let n = |x: &Value| x.as_i64().unwrap();
    assert_eq!(n(&s["mesh_vertices"]) - n(&s["cells"]), -2, "{s}");
    assert!(n(&s["control_points"]) <= n(&s["mesh_vertices"]), "{s}");
    let zeros = n(&c["extraordinary_points"]);
    assert_eq!(zeros, n(&s["zeros"]));
    assert_eq!(n(&c["at_zeros"]["sides"]), 4 * zeros + 8, "{c}");
    let all: i64 = ["at_zeros", "one_interval_from_zeros", "elsewhere"]
        .iter()
        .map(|k| n(&c[*k]["sides"]))
        .sum();
    assert_eq!(all, 2 * n(&s["cells"]));
    assert_eq!(c["at_zeros"]["class"], "C1", "{c}");
    for k in ["one_interval_from_zeros", "elsewhere"] {
        assert!(c[k]["class"] == "C2" || c[k]["class"] == "C3", "{k}: {c}");
    }
    assert_eq!(s["converged"], true);
    assert!(f(&s["max_error_percent"]) <= 0.5, "{s}");
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let imgs = img_tags(&html);
    for want in ["tspline-tmesh.png", "tspline-zebra.png"] {
        assert!(imgs.iter().any(|t| t["src"] == want), "no picture {want}");
    }
}
