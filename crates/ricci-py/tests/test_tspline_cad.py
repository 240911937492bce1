"""`ricci tspline` files read back by Open CASCADE (issue 18): the STEP (AP214,
B_SPLINE_SURFACE_WITH_KNOTS faces) and IGES (entity 128) files open without errors, have one
face per Bézier patch, every face passes BRepCheck, and the surfaces Open CASCADE builds agree
with our own T-spline evaluation (samples.json, written by the CLI) to 1e-9. Genus 1 (torus,
kitten), genus 2 (generated, eight) and genus 3 (generated: the default spline on the quad mesh of the glued strips
of a holomorphic 1-form's cylinders, one Bézier patch per Bézier element: the cells merged
where the spline is one polynomial).

Needs the `cadquery-ocp-novtk` wheel (.ci/run installs it when it can); skipped otherwise."""

import json

import pytest

from conftest import cli, shared

OCP = pytest.importorskip(
    "OCP",
    reason="the cadquery-ocp-novtk wheel (Open CASCADE for Python) is not installed; "
    "pip install cadquery-ocp-novtk to check the STEP/IGES files",
)

from OCP.BRep import BRep_Tool  # noqa: E402
from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.BRepTools import BRepTools  # noqa: E402
from OCP.IFSelect import IFSelect_RetDone  # noqa: E402
from OCP.IGESControl import IGESControl_Reader  # noqa: E402
from OCP.STEPControl import STEPControl_Reader  # noqa: E402
from OCP.TopAbs import TopAbs_FACE  # noqa: E402
from OCP.TopExp import TopExp_Explorer  # noqa: E402
from OCP.TopoDS import TopoDS  # noqa: E402

_face = getattr(TopoDS, "Face_s", None) or TopoDS.Face


def read_faces(path):
    reader = STEPControl_Reader() if path.suffix == ".step" else IGESControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone, f"Open CASCADE could not read {path}"
    assert reader.TransferRoots() > 0, f"{path}: nothing transferred"
    shape = reader.OneShape()
    faces = []
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        faces.append(_face(exp.Current()))
        exp.Next()
    return faces


def check_file(path, samples, tol=1e-9):
    faces = read_faces(path)
    bounds = samples["patches"]
    assert len(faces) == len(bounds), f"{path}: {len(faces)} faces for {len(bounds)} patches"
    by_bounds = {}
    for f in faces:
        assert BRepCheck_Analyzer(f).IsValid(), f"{path}: invalid face"
        u0, u1, v0, v1 = BRepTools.UVBounds_s(f)
        by_bounds[(round(u0, 9), round(v0, 9))] = (BRep_Tool.Surface_s(f), (u0, u1, v0, v1))
    per = samples["samples_per_patch"]
    worst = 0.0
    for k, (u, v, x, y, z) in enumerate(samples["samples"]):
        pu0, pu1, pv0, pv1 = bounds[k // per]
        key = (round(pu0, 9), round(pv0, 9))
        assert key in by_bounds, f"{path}: no face over [{pu0}, {pu1}] x [{pv0}, {pv1}]"
        surf, (u0, u1, v0, v1) = by_bounds[key]
        assert abs(u1 - pu1) < 1e-9 and abs(v1 - pv1) < 1e-9
        p = surf.Value(u, v)
        worst = max(worst, abs(p.X() - x), abs(p.Y() - y), abs(p.Z() - z))
    assert worst <= tol, f"{path}: Open CASCADE's surface differs from our evaluation by {worst}"
    return worst


def run_tspline(mesh, out, *extra):
    _, rep, _ = cli("tspline", mesh, "--out", out, "--json", *extra)
    samples = json.loads((out / "samples.json").read_text())
    assert rep["bezier_patches"] == len(samples["patches"])
    return rep, samples


def test_generated_torus_step_and_iges_open_in_open_cascade(generated, tmp_path):
    rep, samples = run_tspline(generated["torus"], tmp_path, "--tolerance", "1%")
    assert rep["converged"] and rep["max_error_percent"] <= 1.0
    assert rep["continuity"]["class"] == "C2"
    for name in ("tspline.step", "tspline.igs"):
        check_file(tmp_path / name, samples)


def test_kitten_step_and_iges_open_in_open_cascade(tmp_path):
    rep, samples = run_tspline(shared("kitten.nf20k.off"), tmp_path, "--tolerance", "1%")
    assert rep["max_error_percent"] <= 1.0
    for name in ("tspline.step", "tspline.igs"):
        check_file(tmp_path / name, samples)


def check_genus_two(rep, samples, tol_percent, zeros=2):
    """Genus >= 2, the default: one spline on the quad mesh over the glued strips of the
    cylinders; continuity measured per class of cell sides (C2 on every side not at a zero,
    C1 in the translation chart, hence G1, at the zeros), the same surface point from both
    patches of every side. `zeros`: 2g - 2 simple zeros."""
    assert rep["spline"] == "domain_mesh"
    assert rep["converged"] and rep["max_error_percent"] <= tol_percent
    assert rep["control_points"] <= 20000
    cont = rep["continuity"]
    assert cont["extraordinary_points"] == zeros
    assert cont["at_zeros"]["class"] == "C1" and cont["at_zeros"]["sides"] > 0
    assert cont["elsewhere"]["class"] in ("C2", "C3") and cont["elsewhere"]["sides"] > 0
    assert cont["one_interval_from_zeros"]["class"] in ("C2", "C3")
    assert cont["chart_independence_percent"] <= 1e-10
    # one face per Bézier element: the cells merged where the spline is one polynomial
    assert rep["bezier_patches"] == rep["patches"] == rep["bezier_elements"]["elements"]
    assert rep["patches"] <= rep["cells"] == rep["bezier_elements"]["cells"]
    # every patch has its own parameter rectangle (the strips are offset in u)
    keys = {(round(p[0], 9), round(p[2], 9)) for p in samples["patches"]}
    assert len(keys) == len(samples["patches"])


def test_generated_genus_two_step_and_iges_open_in_open_cascade(generated, tmp_path):
    rep, samples = run_tspline(generated["genus"], tmp_path, "--tolerance", "1%")
    check_genus_two(rep, samples, 1.0)
    for name in ("tspline.step", "tspline.igs"):
        check_file(tmp_path / name, samples)


def test_generated_genus_three_step_and_iges_open_in_open_cascade(generated, tmp_path):
    # genus 3 (session 18): the strips of the cylinders glue into one quad mesh there too
    rep, samples = run_tspline(generated["genus3"], tmp_path, "--tolerance", "1%")
    check_genus_two(rep, samples, 1.0, zeros=4)
    for name in ("tspline.step", "tspline.igs"):
        check_file(tmp_path / name, samples)


def test_eight_step_and_iges_open_in_open_cascade(tmp_path):
    rep, samples = run_tspline(shared("eight.off"), tmp_path, "--tolerance", "1%")
    check_genus_two(rep, samples, 1.0)
    for name in ("tspline.step", "tspline.igs"):
        check_file(tmp_path / name, samples)


def test_eight_nested_blocks_step_and_iges_open_in_open_cascade(tmp_path):
    # The default tolerance (0.5 %): eight refines by a block nested in a block (session 17),
    # so the files carry knots at quarter intervals and T-junctions inside a block.
    rep, samples = run_tspline(shared("eight.off"), tmp_path)
    check_genus_two(rep, samples, 0.5)
    assert rep["block_levels"] >= 2, "eight at 0.5 % no longer nests blocks: pick another case"
    for name in ("tspline.step", "tspline.igs"):
        check_file(tmp_path / name, samples)


def test_other_topologies_are_refused_naming_the_missing_domain(generated, tmp_path):
    # two closed components: no domain (a disk has one since session 10: genus 0)
    two = tmp_path / "two.off"
    two.write_text(
        "OFF\n8 8 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 0\n4 0 0\n3 1 0\n3 0 1\n"
        "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n3 4 6 5\n3 4 5 7\n3 4 7 6\n3 5 6 7\n"
    )
    code, out, err = cli("tspline", two, "--json", check=False)
    assert code == 1
    assert "boundary loops" in out["error"] and "each component" in out["error"]
