//! `ricci` — the command-line tool. Argument parsing, progress, JSON reports and error
//! messages for people; no math lives here (docs/DESIGN.md §2, §4).
//!
//! Exit codes: 0 success, 1 bad input (the library refused the data), 2 bad arguments.

use ricci_cli::{cmd, util};

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "ricci",
    version,
    about = "Discrete surface Ricci flow, surface structures and manifold splines"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a mesh and report its topology and triangle quality.
    Info(cmd::info::Args),
    /// Procedural test surfaces: sphere, torus, disk, annulus, pants, genus-g.
    Generate(cmd::generate::Args),
    /// Canonical fundamental group generators through a base vertex; slice the mesh into a disk.
    Cut(cmd::cut::Args),
    /// Render a surface to PNG (checkerboard from UVs, scalar fields, zebra) or export glTF.
    Render(Box<cmd::render::Args>),

    /// Discrete Ricci flow: a flat, hyperbolic or spherical metric with prescribed curvature.
    Flow(cmd::flow::Args),
    /// Cut to a disk, lay out isometrically (plane / Poincaré disk / sphere), deck group.
    Layout(cmd::layout::Args),
    /// Conformal UV map with cones and seams on the input's own faces (or onto the sphere).
    Param(cmd::param::Args),
    /// Geodesic length spectrum of a closed surface of genus ≥ 1.
    Spectrum(cmd::spectrum::Args),
    /// Holomorphic 1-forms: period matrix, zeros, conformal net (genus ≥ 1).
    Forms(cmd::forms::Args),
    /// Teichmüller coordinates (Fenchel–Nielsen, length) of genus ≥ 2 surfaces and distances.
    Teichmuller(cmd::teichmuller::Args),
    /// The whole pipeline on the built-in genus-2 surface: pictures, tables, DIR/index.html.
    Demo(cmd::demo::Args),
    /// Affine atlas with a single extraordinary point (flat cone metric, charts, transitions).
    Atlas(cmd::atlas::Args),
    /// Manifold triangular B-spline surface with at most one extraordinary point.
    Spline(cmd::spline::Args),
    /// One subcommand over many meshes in parallel: JSON lines, resumable.
    Batch(cmd::batch::Args),
    /// Partition-of-unity surface over the hyperbolic structure: C∞, no extraordinary point.
    Pou(cmd::pou::Args),
    /// Cubic T-spline over the domain manifold, fitted adaptively; STEP / IGES export.
    Tspline(cmd::tspline::Args),
}

fn main() {
    // With `--json`, a failure also prints `{"error": "..."}` on stdout (docs/DESIGN.md §4), so a
    // script always gets one JSON object.
    let json = std::env::args_os().any(|a| a == "--json");
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            if json && e.use_stderr() {
                let text = e.to_string();
                let first = text.lines().next().unwrap_or("bad arguments");
                util::print_error_json(first.trim_start_matches("error: "));
            }
            e.exit()
        }
    };
    // For the README test (crates/ricci-cli/tests/readme.rs): check that a command line
    // parses, without running it.
    if std::env::var_os("RICCI_PARSE_ONLY").is_some() {
        return;
    }
    let result = match cli.command {
        Command::Info(a) => cmd::info::run(a),
        Command::Generate(a) => cmd::generate::run(a),
        Command::Cut(a) => cmd::cut::run(a),
        Command::Render(a) => cmd::render::run(*a),

        Command::Flow(a) => cmd::flow::run(a),
        Command::Layout(a) => cmd::layout::run(a),
        Command::Param(a) => cmd::param::run(a),
        Command::Spectrum(a) => cmd::spectrum::run(a),
        Command::Forms(a) => cmd::forms::run(a),
        Command::Teichmuller(a) => cmd::teichmuller::run(a),
        Command::Demo(a) => cmd::demo::run(a),
        Command::Atlas(a) => cmd::atlas::run(a),
        Command::Spline(a) => cmd::spline::run(a),
        Command::Batch(a) => cmd::batch::run(a),
        Command::Pou(a) => cmd::pou::run_cmd(a),
        Command::Tspline(a) => cmd::tspline::run_cmd(a),
    };
    if let Err(e) = result {
        // The mesh: the first argument after the subcommand, when it is not an option.
        let args: Vec<String> = std::env::args().collect();
        let sub = args.get(1).map_or("", String::as_str);
        let mesh = args
            .get(2)
            .filter(|a| !a.starts_with('-') && !matches!(sub, "batch" | "demo" | "generate"));
        let sentence = if util::exit_code(&e) == 1 {
            util::refusal(sub, mesh.map(String::as_str), util::sentence(&e))
        } else {
            util::sentence(&e)
        };
        if json {
            util::print_error_json(&sentence);
        }
        eprintln!("error: {sentence}");
        std::process::exit(util::exit_code(&e));
    }
}
