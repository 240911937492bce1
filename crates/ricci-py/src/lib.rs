//! `ricci._native`: the Rust half of the Python package `ricci` (the Python half,
//! `python/ricci/__init__.py`, turns numpy arrays into bytes and JSON into result objects).
//!
//! Every analysis runs the CLI's own subcommand (`ricci_cli::cmd::*::run`) with its arguments
//! parsed by the CLI's own clap definitions, under a [`ricci_cli::util::Capture`]: the report
//! that `--json` would print is kept and returned as JSON text, output files under
//! `<memory>/` are returned as bytes, and a mesh given as arrays is validated by the library's
//! builder (`ricci::mesh::build_surface`, the same checks as a file) and handed to the command
//! in place of reading a file. So a Python result is the CLI's JSON to the last digit, every
//! option of the CLI is available, and there is one place where each report is built.
//!
//! The GIL is released (`Python::detach`) for everything but the argument conversion. Errors
//! are `ricci.RicciError` (bad input; the CLI's one sentence, exit code 1) and
//! `ricci.UsageError` (bad arguments; exit code 2); a panic becomes a `RicciError` too.

use pyo3::create_exception;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use ricci::mesh::{build_surface, BuildReport, PolygonSoup, Surface};
use ricci_cli::cmd;
use ricci_cli::util::{sentence, with_capture, Capture, UsageError as CliUsageError};
use std::path::{Path, PathBuf};

create_exception!(
    _native,
    RicciError,
    pyo3::exceptions::PyValueError,
    "The library refused the input: the message is its one sentence (the CLI's exit code 1)."
);
create_exception!(
    _native,
    UsageError,
    RicciError,
    "Bad arguments (unknown option, malformed value): the CLI's exit code 2."
);

/// Why a call failed, before it becomes a Python exception (made with the GIL held).
enum Failure {
    Input(String),
    Usage(String),
}

impl Failure {
    fn into_py(self) -> PyErr {
        match self {
            Failure::Input(s) => RicciError::new_err(s),
            Failure::Usage(s) => UsageError::new_err(s),
        }
    }
}

fn from_anyhow(e: anyhow::Error) -> Failure {
    if e.downcast_ref::<CliUsageError>().is_some() {
        Failure::Usage(sentence(&e))
    } else {
        Failure::Input(sentence(&e))
    }
}

/// Parse `argv` (without a program name) with the subcommand's own clap definition.
fn parse<A: clap::Args + clap::FromArgMatches>(name: &str, argv: &[String]) -> Result<A, Failure> {
    let command = A::augment_args(clap::Command::new("ricci").no_binary_name(true));
    let usage = |e: clap::Error| {
        let text = e.render().to_string();
        let first = text
            .split("\n\n")
            .next()
            .unwrap_or("")
            .trim()
            .trim_start_matches("error: ")
            .to_string();
        Failure::Usage(format!("ricci {name}: {first}"))
    };
    let matches = command.try_get_matches_from(argv).map_err(usage)?;
    A::from_arg_matches(&matches).map_err(usage)
}

/// The subcommands the package runs, by name.
const COMMANDS: [&str; 12] = [
    "info", "flow", "layout", "spectrum", "cut", "atlas", "spline", "pou", "render", "generate",
    "param", "tspline",
];

fn dispatch(command: &str, argv: &[String]) -> Result<(), Failure> {
    let r = match command {
        "info" => cmd::info::run(parse(command, argv)?),
        "flow" => cmd::flow::run(parse(command, argv)?),
        "layout" => cmd::layout::run(parse(command, argv)?),
        "spectrum" => cmd::spectrum::run(parse(command, argv)?),
        "cut" => cmd::cut::run(parse(command, argv)?),
        "atlas" => cmd::atlas::run(parse(command, argv)?),
        "spline" => cmd::spline::run(parse(command, argv)?),
        "pou" => cmd::pou::run_cmd(parse(command, argv)?),
        "render" => cmd::render::run(parse(command, argv)?),
        "generate" => cmd::generate::run(parse(command, argv)?),
        "param" => cmd::param::run(parse(command, argv)?),
        "tspline" => cmd::tspline::run_cmd(parse(command, argv)?),
        _ => {
            return Err(Failure::Usage(format!(
                "unknown command {command:?}; the package runs {}",
                COMMANDS.join(", ")
            )))
        }
    };
    r.map_err(from_anyhow)
}

fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    let what = p
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    format!("internal error (a bug in ricci, please report it): {what}")
}

/// A validated surface from raw arrays: `vertices` n×3 float64, `faces` m×3 int64, both
/// C-contiguous in native byte order.
fn surface_from_bytes(vertices: &[u8], faces: &[u8]) -> ricci::Result<(Surface, BuildReport)> {
    if !vertices.len().is_multiple_of(24) || !faces.len().is_multiple_of(24) {
        return Err(ricci::Error::input(
            "vertices must be an (n, 3) float64 array and faces an (m, 3) int64 array",
        ));
    }
    let positions: Vec<[f64; 3]> = vertices
        .chunks_exact(24)
        .map(|c| {
            let x = |k: usize| f64::from_ne_bytes(c[8 * k..8 * k + 8].try_into().unwrap_or([0; 8]));
            [x(0), x(1), x(2)]
        })
        .collect();
    let mut polygons = Vec::with_capacity(faces.len() / 24);
    for (f, c) in faces.chunks_exact(24).enumerate() {
        let mut tri = Vec::with_capacity(3);
        for k in 0..3 {
            let i = i64::from_ne_bytes(c[8 * k..8 * k + 8].try_into().unwrap_or([0; 8]));
            let v = u32::try_from(i)
                .ok()
                .filter(|&v| (v as usize) < positions.len());
            match v {
                Some(v) => tri.push(v),
                None => {
                    return Err(ricci::Error::invalid_mesh(format!(
                        "face {f} refers to vertex {i}, but the vertices are numbered 0 to {}",
                        positions.len() as i64 - 1
                    )))
                }
            }
        }
        polygons.push(tri);
    }
    build_surface(PolygonSoup {
        positions,
        polygons,
        ..Default::default()
    })
}

/// What a run returns before it becomes Python objects: the report's JSON text, the capture
/// and the metric files as arrays.
type Outcome = (String, Capture, Vec<(String, MetricArrays)>);

/// Run a subcommand: `argv` are its arguments (the mesh path first). With `vertices` and
/// `faces`, the mesh is those arrays under the path `name`. Returns the JSON report (text; the
/// empty string when the command printed none) and the files written under `<memory>/`
/// (bytes; a metric file as `(other keys as JSON, [u, curvature, target_curvature, lengths,
/// edge_vertices] as bytes)`).
#[pyfunction]
#[pyo3(signature = (command, argv, name=None, vertices=None, faces=None))]
fn run<'py>(
    py: Python<'py>,
    command: &str,
    argv: Vec<String>,
    name: Option<String>,
    vertices: Option<&[u8]>,
    faces: Option<&[u8]>,
) -> PyResult<(String, Bound<'py, PyDict>)> {
    let outcome = py.detach(|| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(
            || -> Result<Outcome, Failure> {
                let mut capture = Capture::default();
                if let (Some(v), Some(f)) = (vertices, faces) {
                    let label = name.clone().unwrap_or_else(|| "<array>".into());
                    let (s, r) = surface_from_bytes(v, f)
                        .map_err(|e| Failure::Input(e.in_file(&label).to_string()))?;
                    capture.input = Some((PathBuf::from(label), s, r));
                }
                let (r, mut captured) = with_capture(capture, || dispatch(command, &argv));
                r?;
                // JSON files kept as values: metrics become arrays, anything else text.
                let mut metrics = Vec::new();
                for (path, v) in std::mem::take(&mut captured.json_files) {
                    if v.get("edge_vertices").is_some() && v.get("u").is_some() {
                        metrics.push((path, metric_arrays(v).map_err(Failure::Input)?));
                    } else {
                        let text = serde_json::to_string(&v)
                            .map_err(|e| Failure::Input(format!("JSON: {e}")))?;
                        captured.files.insert(path, text.into_bytes());
                    }
                }
                let json = match &captured.json {
                    Some(v) => serde_json::to_string(v)
                        .map_err(|e| Failure::Input(format!("JSON: {e}")))?,
                    None => String::new(),
                };
                Ok((json, captured, metrics))
            },
        ))
    });
    let (json, captured, metrics) = match outcome {
        Ok(Ok(x)) => x,
        Ok(Err(f)) => return Err(f.into_py()),
        Err(p) => return Err(RicciError::new_err(panic_message(p))),
    };
    let files = PyDict::new(py);
    for (k, v) in &captured.files {
        files.set_item(k, PyBytes::new(py, v))?;
    }
    for (k, (rest, arrays, ev)) in &metrics {
        let mut parts: Vec<Bound<'py, PyBytes>> =
            arrays.iter().map(|a| PyBytes::new(py, a)).collect();
        parts.push(PyBytes::new(py, ev));
        files.set_item(k, (rest.clone(), parts))?;
    }
    Ok((json, files))
}

/// Read and validate a mesh file: (vertices bytes, faces bytes (int64), uvs bytes or None,
/// build report JSON).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn read_mesh<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Option<Bound<'py, PyBytes>>,
    String,
)> {
    let r = py.detach(|| {
        let (s, report) = ricci::mesh::io::read_surface(&path).map_err(|e| e.to_string())?;
        let v: Vec<u8> = s
            .positions
            .iter()
            .flat_map(|p| p.iter().flat_map(|x| x.to_ne_bytes()))
            .collect();
        let f: Vec<u8> = s
            .mesh
            .faces()
            .iter()
            .flat_map(|t| t.iter().flat_map(|&i| (i as i64).to_ne_bytes()))
            .collect();
        let uv: Option<Vec<u8>> = s.uvs.as_ref().map(|uv| {
            uv.iter()
                .flat_map(|p| p.iter().flat_map(|x| x.to_ne_bytes()))
                .collect()
        });
        let report = serde_json::to_string(&report).map_err(|e| e.to_string())?;
        Ok::<_, String>((v, f, uv, report))
    });
    let (v, f, uv, report) = r.map_err(RicciError::new_err)?;
    Ok((
        PyBytes::new(py, &v),
        PyBytes::new(py, &f),
        uv.map(|uv| PyBytes::new(py, &uv)),
        report,
    ))
}

/// Validate arrays as a mesh (the checks of a file) and write it; the format is chosen by
/// the extension (PLY and STL binary). Returns the build report JSON (what was changed).
#[pyfunction]
fn write_mesh(py: Python<'_>, path: PathBuf, vertices: &[u8], faces: &[u8]) -> PyResult<String> {
    py.detach(|| {
        let label = path.display().to_string();
        let (s, report) =
            surface_from_bytes(vertices, faces).map_err(|e| e.in_file(&label).to_string())?;
        ricci::mesh::io::write_surface(Path::new(&path), &s).map_err(|e| e.to_string())?;
        serde_json::to_string(&report).map_err(|e| e.to_string())
    })
    .map_err(RicciError::new_err)
}

/// Validate arrays as a mesh; the build report JSON, or `RicciError` with the sentence.
#[pyfunction]
#[pyo3(signature = (vertices, faces, name=None))]
fn validate(
    py: Python<'_>,
    vertices: &[u8],
    faces: &[u8],
    name: Option<String>,
) -> PyResult<String> {
    py.detach(|| {
        let label = name.unwrap_or_else(|| "<array>".into());
        let (_, report) =
            surface_from_bytes(vertices, faces).map_err(|e| e.in_file(&label).to_string())?;
        serde_json::to_string(&report).map_err(|e| e.to_string())
    })
    .map_err(RicciError::new_err)
}

/// A metric (`ricci flow --out` METRIC.json) as arrays: (the other keys as JSON, [u,
/// curvature, target_curvature (NaN for null), lengths] as float64 bytes, edge_vertices as
/// int64 bytes).
type MetricArrays = (String, Vec<Vec<u8>>, Vec<u8>);

fn metric_arrays(mut v: serde_json::Value) -> Result<MetricArrays, String> {
    let obj = v
        .as_object_mut()
        .ok_or_else(|| "the metric is not a JSON object".to_string())?;
    let mut floats = |key: &str| -> Result<Vec<u8>, String> {
        let a = obj.remove(key).unwrap_or_default();
        let a = a.as_array().ok_or_else(|| format!("no {key:?} array"))?;
        Ok(a.iter()
            .flat_map(|x| x.as_f64().unwrap_or(f64::NAN).to_ne_bytes())
            .collect())
    };
    let arrays = vec![
        floats("u")?,
        floats("curvature")?,
        floats("target_curvature")?,
        floats("lengths")?,
    ];
    let ev = obj.remove("edge_vertices").unwrap_or_default();
    let ev: Vec<u8> = ev
        .as_array()
        .ok_or_else(|| "no \"edge_vertices\" array".to_string())?
        .iter()
        .flat_map(|p| {
            let p = p.as_array().map(|p| &p[..]).unwrap_or(&[]);
            [0, 1].map(|k| p.get(k).and_then(|x| x.as_i64()).unwrap_or(-1))
        })
        .flat_map(|i| i.to_ne_bytes())
        .collect();
    let rest = serde_json::to_string(&v).map_err(|e| e.to_string())?;
    Ok((rest, arrays, ev))
}

/// Benchmark helper (`bench/overhead.py`): the library call that `flow(path)` wraps —
/// `read_surface` + `ricci_flow` with the CLI's default options, no progress, no report —
/// timed in Rust, `repeats` times. Returns (seconds per call, max curvature error of the last).
#[pyfunction]
fn _library_flow_seconds(
    py: Python<'_>,
    path: PathBuf,
    repeats: usize,
) -> PyResult<(Vec<f64>, f64)> {
    py.detach(|| {
        let mut times = Vec::with_capacity(repeats);
        let mut err = f64::NAN;
        for _ in 0..repeats {
            let t0 = std::time::Instant::now();
            let (s, _) = ricci::mesh::io::read_surface(&path).map_err(|e| e.to_string())?;
            let r = ricci::flow::ricci_flow(
                &s.mesh,
                &s.edge_lengths(),
                &ricci::flow::FlowOptions::default(),
                &mut ricci::progress::NoProgress,
            )
            .map_err(|e| e.to_string())?;
            times.push(t0.elapsed().as_secs_f64());
            err = r.max_curvature_error;
        }
        Ok::<_, String>((times, err))
    })
    .map_err(RicciError::new_err)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(_library_flow_seconds, m)?)?;
    m.add("RicciError", m.py().get_type::<RicciError>())?;
    m.add("UsageError", m.py().get_type::<UsageError>())?;
    m.add("COMMANDS", COMMANDS.to_vec())?;
    m.add("MEMORY_PREFIX", ricci_cli::util::MEMORY_PREFIX)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
