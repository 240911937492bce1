//! Automatic singularity placement (paper 000 §4 Step 1) against the paper's brute force
//! (one full single-cone flow per vertex, on every vertex): the estimator's choice must be
//! within the best 5% of the brute-force ranking, and the linearized distortion must rank
//! the vertices like the full flows do (Spearman rank correlation > 0.8).

use ricci::atlas::placement::{brute_force, estimate, place, PlacementOptions};
use ricci::atlas::AtlasOptions;
use ricci::mesh::io::read_surface;
use ricci::mesh::{generate, Surface};
use ricci::metric::IntrinsicMetric;
use ricci::metric::Scheme;
use ricci::progress::NoProgress;
use std::path::PathBuf;

fn mesh_dir() -> Option<PathBuf> {
    let d = ricci_meshes()?;
    d.is_dir().then_some(d)
}

fn ranks(x: &[f64]) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..x.len()).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let mut r = vec![0.0; x.len()];
    for (k, &i) in idx.iter().enumerate() {
        r[i] = k as f64;
    }
    r
}

fn spearman(x: &[f64], y: &[f64]) -> f64 {
    let (rx, ry) = (ranks(x), ranks(y));
    let n = x.len() as f64;
    let m = (n - 1.0) / 2.0;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for i in 0..x.len() {
        sxy += (rx[i] - m) * (ry[i] - m);
        sxx += (rx[i] - m).powi(2);
        syy += (ry[i] - m).powi(2);
    }
    sxy / (sxx * syy).sqrt()
}

/// Brute force over `candidates` ∪ {the automatic choice}; returns (rank of the choice
/// among them, 0-based; number ranked; Spearman of estimate vs measured).
fn compare(name: &str, s: &Surface, candidates: Vec<u32>) -> (usize, usize, f64) {
    let lengths = s.edge_lengths();
    let opts = AtlasOptions::default();
    let p = place(
        s,
        &IntrinsicMetric::euclidean(lengths.to_vec()),
        &opts,
        &mut NoProgress,
    )
    .unwrap();
    let (est, _) = estimate(
        &s.mesh,
        &IntrinsicMetric::euclidean(lengths.to_vec()),
        Scheme::Thurston,
        &PlacementOptions::default(),
    )
    .unwrap();
    let mut cand = candidates;
    if !cand.contains(&p.chosen) {
        cand.push(p.chosen);
    }
    let bf = brute_force(
        &s.mesh,
        &IntrinsicMetric::euclidean(lengths.to_vec()),
        &cand,
        Scheme::Thurston,
        &mut NoProgress,
    );
    let ok: Vec<(u32, f64)> = bf.iter().filter_map(|&(v, d)| d.map(|d| (v, d))).collect();
    assert!(
        ok.len() * 10 >= cand.len() * 9,
        "{name}: too many flows failed"
    );
    let chosen = ok
        .iter()
        .find(|x| x.0 == p.chosen)
        .map(|x| x.1)
        .expect("the chosen vertex's flow converges");
    let rank = ok.iter().filter(|x| x.1 < chosen).count();
    let (e, m): (Vec<f64>, Vec<f64>) = ok
        .iter()
        .filter(|x| est[x.0 as usize].is_finite())
        .map(|x| (est[x.0 as usize], x.1))
        .unzip();
    let rho = spearman(&e, &m);
    let best = ok.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
    eprintln!(
        "{name}: choice {} (distortion {chosen:.4}) ranks {rank} of {} (best {best:.4}); \
         Spearman(estimate, measured) = {rho:.3}",
        p.chosen,
        ok.len()
    );
    (rank, ok.len(), rho)
}

fn every(s: &Surface, step: usize) -> Vec<u32> {
    (0..s.mesh.n_vertices() as u32)
        .filter(|&v| !s.mesh.is_boundary_vertex(v))
        .step_by(step)
        .collect()
}

/// Every vertex of a generated genus-2 surface (429 interior vertices) and of eight.off
/// (766): about 10 s in release mode.
#[test]
fn brute_force_every_vertex() {
    let mut cases = vec![("genus2".to_string(), generate::genus(2, 24).unwrap())];
    if let Some(dir) = mesh_dir() {
        cases.push((
            "eight".into(),
            read_surface(&dir.join("eight.off")).unwrap().0,
        ));
    }
    for (name, s) in cases {
        let (rank, n, rho) = compare(&name, &s, every(&s, 1));
        assert!(rank as f64 <= 0.05 * n as f64, "{name}: rank {rank} of {n}");
        assert!(rho > 0.8, "{name}: Spearman {rho}");
    }
}

mod ricci_meshes;
use ricci_meshes::ricci_meshes;
