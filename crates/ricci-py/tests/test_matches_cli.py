"""The Python results are the CLI's JSON for the same mesh and options, to the last digit.

Each test runs `ricci COMMAND MESH --json OPTIONS` as a subprocess and the Python function on
the same mesh (as a path, and as numpy arrays labelled with the same path) and compares the
two reports key by key with `==` on the parsed numbers (doubles printed shortest-round-trip,
so equal text ⇔ equal bits). Only times (`seconds`, the per-stage `timings` and `timings_wall`) are left out.
"""

import json

import numpy as np
import pytest
import ricci

from conftest import cli, shared

TIMING = {"seconds", "timings", "timings_wall"}


def strip_timing(v):
    if isinstance(v, dict):
        return {k: strip_timing(x) for k, x in v.items() if k not in TIMING}
    if isinstance(v, list):
        return [strip_timing(x) for x in v]
    return v


def assert_same(py, cli_json):
    a, b = strip_timing(py.to_dict()), strip_timing(cli_json)
    assert a.keys() == b.keys()
    for k in a:
        assert a[k] == b[k], f"{k}: python {a[k]!r} != cli {b[k]!r}"


def flow_cases(generated):
    yield generated["torus"], {}
    yield generated["genus"], {"geometry": "hyperbolic"}
    yield generated["disk"], {"target": "free-boundary", "scheme": "inversive"}
    yield generated["torus"], {"solver": "gradient", "max_iterations": 50, "step": 0.1}


def options_argv(opts):
    argv = []
    for k, v in opts.items():
        argv += ["--" + k.replace("_", "-"), repr(v) if isinstance(v, float) else str(v)]
    return argv


@pytest.mark.parametrize("case", range(4))
def test_flow_equals_cli(generated, tmp_path, case):
    path, opts = list(flow_cases(generated))[case]
    metric = tmp_path / "metric.json"
    _, want, _ = cli("flow", path, "--json", "--out", metric, *options_argv(opts))
    got = ricci.flow(path, out=metric, **opts)
    assert_same(got, want)
    # Without `out` the metric comes back as arrays, equal to the CLI's METRIC.json.
    got = ricci.flow(path, **opts)
    m = json.loads(metric.read_text())
    assert np.array_equal(got.u, np.array(m["u"]))
    assert np.array_equal(got.lengths, np.array(m["lengths"]))
    assert np.array_equal(got.curvature, np.array(m["curvature"]))
    assert np.array_equal(got.edge_vertices, np.array(m["edge_vertices"]))
    assert got.out is None and want["out"] == str(metric)
    # Arrays in, labelled with the file's path: the same report.
    mesh = ricci.read_mesh(path)
    got = ricci.flow(mesh.vertices, mesh.faces, name=str(path), out=metric, **opts)
    assert_same(got, want)


def test_flow_equals_cli_on_kitten(tmp_path):
    path = shared("kitten.nf20k.off")
    _, want, _ = cli("flow", path, "--json", "--tolerance", "1e-12")
    got = ricci.flow(path, tolerance=1e-12, arrays=False)
    assert_same(got, want)
    assert got.converged and got.max_curvature_error <= 1e-12


@pytest.mark.parametrize("mesh", ["torus", "genus", "disk", "sphere"])
def test_layout_equals_cli(generated, tmp_path, mesh):
    path = generated[mesh]
    uv = tmp_path / "uv.obj"
    _, want, _ = cli("layout", path, "--json", "--out", uv)
    got = ricci.layout(path, out=uv)
    assert_same(got, want)
    # The in-memory layout is the file's.
    got = ricci.layout(path)
    assert_same(got, want)
    text = uv.read_text().splitlines()
    if mesh == "sphere":
        pts = np.array([[float(x) for x in l.split()[1:]] for l in text if l.startswith("v ")])
        assert np.array_equal(got.positions, pts)
    else:
        vt = np.array([[float(x) for x in l.split()[1:]] for l in text if l.startswith("vt ")])
        assert np.array_equal(got.uv, vt)
        assert got.uv_faces.shape[1] == 3 and got.uv_faces.max() == len(vt) - 1


def test_layout_equals_cli_on_shared_mesh():
    path = shared("eight.off")
    _, want, _ = cli("layout", path, "--json")
    assert_same(ricci.layout(path, arrays=False), want)


@pytest.mark.parametrize("mesh,count", [("torus", 6), ("genus", 5)])
def test_spectrum_equals_cli(generated, mesh, count):
    path = generated[mesh]
    _, want, _ = cli("spectrum", path, "--json", "--count", count)
    got = ricci.spectrum(path, count=count)
    assert_same(got, want)
    assert len(got.lengths) == count


def test_spectrum_equals_cli_on_shared_torus():
    path = shared("torus.off")
    _, want, _ = cli("spectrum", path, "--json", "--count", "8")
    assert_same(ricci.spectrum(path, count=8), want)


def test_spectrum_of_a_bordered_surface_is_its_doubles_as_in_the_cli(generated, tmp_path):
    """A surface with boundary (not a disk): the spectrum of its double, as `ricci spectrum`
    gives it (spec11), from a path and from arrays. Values from elsewhere: the round annulus
    0.5 < |z| < 1 is a cylinder of circumference 2π and height h = log 2, so its double is the
    flat torus R²/(2πZ × 2hZ), whose closed geodesics have lengths |a·2π + i b·2h|."""
    path = tmp_path / "annulus.off"
    cli("generate", "annulus", "--inner", "0.5", "--outer", "1", "--resolution", "96",
        "--out", path)
    count = 6
    _, want, _ = cli("spectrum", path, "--json", "--count", count)
    got = ricci.spectrum(path, count=count)
    assert_same(got, want)
    assert got.spectrum_of == "double" and got.genus == 1
    assert got.double["surface_genus"] == 0 and got.double["boundary_loops"] == 2
    mesh = ricci.read_mesh(path)
    assert_same(ricci.spectrum(mesh.vertices, mesh.faces, name=str(path), count=count), want)
    h = np.log(2.0)
    closed = sorted(
        np.hypot(a * 2 * np.pi, b * 2 * h)
        for a in range(0, 4)
        for b in range(-20, 21)
        if a > 0 or b > 0
    )[:count]
    closed = np.array(closed) / closed[0]
    assert np.allclose(got.normalized, closed, rtol=5e-3, atol=0), (got.normalized, closed)
    # A closed surface reports itself; a disk (whose double is a sphere) is refused.
    assert ricci.spectrum(generated["torus"], count=2).spectrum_of == "surface"
    with pytest.raises(ricci.RicciError, match="not a disk"):
        ricci.spectrum(generated["disk"], count=2)


def test_info_and_cut_equal_cli(generated, tmp_path):
    path = generated["genus"]
    _, want, _ = cli("info", path, "--json")
    assert_same(ricci.info(path), want)
    out = tmp_path / "cut.obj"
    _, want, _ = cli("cut", path, "--json", "--out", out)
    got = ricci.cut(path, out=out)
    assert_same(got, want)
    mem = ricci.cut(path)
    assert_same(mem, want)
    assert np.array_equal(mem.mesh.vertices, ricci.read_mesh(out).vertices)


def test_generic_run_takes_every_cli_option(generated):
    r = ricci.run("flow", generated["torus"], tolerance=1e-9, max_iterations=3)
    assert r.tolerance == 1e-9 and r.iterations <= 3
    assert isinstance(r, ricci.FlowResult)


def test_pou_equals_cli(generated):
    # The partition-of-unity surface (paper 004) through the generic runner: the same report
    # as the CLI's (times aside), C∞ across chart boundaries at rounding level.
    path = generated["genus"]
    opts = {"samples": 200, "continuity_edges": 300, "tessellation": 3}
    _, want, _ = cli("pou", path, "--json", *options_argv(opts))
    got = ricci.run("pou", path, **opts)
    a = strip_timing(got.to_dict())
    b = strip_timing(want)
    for k in ("control_points", "rms_error_percent", "max_error_percent", "continuity"):
        assert a[k] == b[k], f"{k}: python {a[k]!r} != cli {b[k]!r}"
    assert max(a["continuity"]["relative_jumps"]) < 1e-10
