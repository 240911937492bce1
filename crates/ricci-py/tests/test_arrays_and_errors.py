"""numpy ↔ mesh round trips; bad input raises with the library's sentence; the GIL is
released while the library computes."""

import re
import threading
import time

import numpy as np
import pytest
import ricci

from conftest import cli, shared


@pytest.mark.parametrize("ext", ["obj", "off", "ply"])
def test_round_trip_numpy_mesh_file(generated, tmp_path, ext):
    m = ricci.read_mesh(generated["genus"])
    # Coordinates that need all 17 digits, so a lossy writer would show.
    rng = np.random.default_rng(7)
    v = m.vertices + rng.standard_normal(m.vertices.shape) * 1e-3
    path = tmp_path / f"mesh.{ext}"
    report = ricci.write_mesh(path, v, m.faces)
    assert report["dropped_vertices"] == [] and report["reoriented_faces"] == 0
    back = ricci.read_mesh(path)
    assert back.vertices.dtype == np.float64 and back.faces.dtype == np.int64
    assert np.array_equal(back.vertices, v)
    assert np.array_equal(back.faces, m.faces)


def test_round_trip_stl_keeps_the_surface(generated, tmp_path):
    m = ricci.read_mesh(generated["torus"])
    path = tmp_path / "mesh.stl"
    ricci.write_mesh(path, m)
    back = ricci.read_mesh(path)
    # STL stores triangles by float32 corner positions: the same triangles at float32,
    # vertices welded again.
    tri = lambda mm: {
        tuple(sorted(map(tuple, mm.vertices.astype(np.float32)[f]))) for f in mm.faces
    }
    assert len(back.faces) == len(m.faces)
    assert tri(back) == tri(m)


def test_array_input_accepts_other_numeric_dtypes(generated):
    m = ricci.read_mesh(generated["torus"])
    a = ricci.info(m.vertices, m.faces.astype(np.int32))
    b = ricci.info(m.vertices.astype(np.float32).astype(np.float64), m.faces.astype(np.uint32))
    assert a.genus == b.genus == 1 and a.file == "<array>"
    assert ricci.info((m.vertices, m.faces), name="t").file == "t"
    assert ricci.info(m).faces == len(m.faces)


NON_MANIFOLD_OFF = """OFF
5 3 0
0 0 0
1 0 0
0 1 0
0 0 1
1 1 1
3 0 1 2
3 1 0 3
3 0 1 4
"""


def test_non_manifold_sentence_is_the_librarys(tmp_path):
    path = tmp_path / "bad.off"
    path.write_text(NON_MANIFOLD_OFF)
    code, _, stderr = cli("info", path, check=False)
    assert code == 1
    # The CLI ends its refusals with a shell command to try (`util::refusal`); the library's
    # sentence is what comes before it.
    sentence = re.sub(r"; try: .*$", "", stderr.strip().removeprefix("error: "))
    assert "non-manifold edge" in sentence
    with pytest.raises(ricci.RicciError) as e:
        ricci.info(path)
    assert str(e.value) == sentence
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], dtype=float)
    f = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    # Arrays have no lines: the same sentence without the file's line numbers.
    sentence = re.sub(r" \(line \d+\)", "", sentence)
    for call in (
        lambda: ricci.info(v, f, name=str(path)),
        lambda: ricci.flow(v, f, name=str(path)),
        lambda: ricci.validate(v, f, name=str(path)),
    ):
        with pytest.raises(ricci.RicciError) as e:
            call()
        assert str(e.value) == sentence
    with pytest.raises(ricci.RicciError) as e:
        ricci.write_mesh(tmp_path / "bad.off", v, f)
    assert str(e.value) == sentence


def test_refusals_carry_the_cli_sentence(generated):
    # A flat metric on a genus-2 surface (asked for explicitly: by default the surface gets
    # its hyperbolic metric) violates Gauss–Bonnet: the library's sentence.
    path = generated["genus"]
    code, _, stderr = cli("flow", path, "--geometry", "euclidean", check=False)
    assert code == 1
    with pytest.raises(ricci.RicciError) as e:
        ricci.flow(path, geometry="euclidean")
    assert str(e.value) == stderr.strip().removeprefix("error: ")
    assert "Gauss–Bonnet" in str(e.value)


def test_wrong_dtype_and_shape():
    v = np.zeros((4, 3))
    f = np.array([[0, 1, 2], [0, 2, 3]])
    with pytest.raises(ricci.ArrayError, match=r"vertices must be a real array.*complex128"):
        ricci.info(v.astype(complex), f)
    with pytest.raises(TypeError, match=r"faces must be an integer array.*float64"):
        ricci.info(v, f.astype(float))
    with pytest.raises(ricci.ArrayError, match=r"vertices must be an \(n, 3\) array; got shape \(4, 2\)"):
        ricci.flow(v[:, :2], f)
    with pytest.raises(ricci.ArrayError, match=r"faces must be an \(m, 3\) array.*\(2, 4\)"):
        ricci.info(v, np.zeros((2, 4), dtype=int))
    with pytest.raises(ricci.ArrayError):
        ricci.info(v.astype(bool), f)


def test_bad_values_name_the_vertex_or_face():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    with pytest.raises(ricci.RicciError, match=r"face 0 refers to vertex 7, but the vertices are numbered 0 to 2"):
        ricci.info(v, np.array([[0, 1, 7]]))
    with pytest.raises(ricci.RicciError, match=r"face 0 refers to vertex -1"):
        ricci.info(v, np.array([[0, 1, -1]]))
    v[1, 2] = np.nan
    with pytest.raises(ricci.RicciError, match=r"vertex 1 has a non-finite coordinate"):
        ricci.info(v, np.array([[0, 1, 2]]))


def test_bad_options_are_usage_errors(generated):
    with pytest.raises(ricci.UsageError, match="unknown geometry 'bogus'"):
        ricci.flow(generated["torus"], geometry="bogus")
    with pytest.raises(ricci.UsageError, match="--no-such-option"):
        ricci.run("flow", generated["torus"], no_such_option=1)
    with pytest.raises(ricci.UsageError, match="--count must be between"):
        ricci.spectrum(generated["torus"], count=0)
    assert issubclass(ricci.UsageError, ricci.RicciError)
    assert issubclass(ricci.RicciError, ValueError)


def test_gil_is_released_during_the_numerics():
    # While one thread runs a flow, another Python thread must keep running. With the GIL
    # held for the whole call, the counter could not move until the flow returned. botijo's
    # hyperbolic flow takes ~0.6 s here (kitten's, 0.09 s since session 14, was too short to
    # tell the two apart with 10 ms sleeps).
    path = shared("botijo.off")
    counts = []
    done = threading.Event()

    def count():
        n = 0
        while not done.is_set():
            n += 1
            time.sleep(0)
        counts.append(n)

    t = threading.Thread(target=count)
    t.start()
    seen = []
    worker = threading.Thread(target=lambda: seen.append(ricci.flow(path, tolerance=1e-12)))
    worker.start()
    time.sleep(0.05)
    during = []
    while worker.is_alive():
        during.append(1)
        time.sleep(0.01)
    done.set()
    t.join()
    worker.join()
    assert seen and seen[0].converged
    # The main thread woke up many times during the call (a ~0.6 s flow, 10 ms sleeps).
    assert len(during) >= 5, len(during)
