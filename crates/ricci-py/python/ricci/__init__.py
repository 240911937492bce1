"""ricci — discrete surface Ricci flow, surface structures and manifold splines, from Python.

Every analysis runs the ``ricci`` command-line tool's own subcommand inside this process (no
subprocess, no temporary files) and returns its JSON report as a result object: the fields
are the CLI's JSON keys, with the same values to the last digit (``ricci flow MESH --json``
and ``ricci.flow(MESH)`` agree). A mesh is a file path, a :class:`Mesh`, or numpy arrays
``vertices`` (n, 3) float64 and ``faces`` (m, 3) integer. Keyword options are the CLI's
options (``max_iterations=40`` is ``--max-iterations 40``; ``True`` is a flag; ``None``
leaves the CLI's default). The GIL is released while the library computes.

Errors: :class:`RicciError` (a ``ValueError``) with the library's one sentence when the input
is refused (non-manifold, wrong topology, no convergence where one is needed, …);
:class:`UsageError` (a ``RicciError``) for bad options; :class:`ArrayError` (a ``RicciError``
and a ``TypeError``) for arrays of the wrong dtype or shape.

    >>> import ricci
    >>> mesh = ricci.read_mesh("torus.off")
    >>> r = ricci.flow(mesh.vertices, mesh.faces, geometry="euclidean")
    >>> r.converged, r.max_curvature_error, r.u.shape
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, Mapping, Optional, Tuple, Union

import numpy as np

from . import _native
from ._native import RicciError, UsageError

__version__: str = _native.__version__

__all__ = [
    "ArrayError",
    "AtlasResult",
    "CutResult",
    "FlowResult",
    "InfoResult",
    "LayoutResult",
    "Mesh",
    "Report",
    "RicciError",
    "SpectrumResult",
    "SplineResult",
    "TSplineResult",
    "UsageError",
    "atlas",
    "cut",
    "flow",
    "info",
    "layout",
    "read_mesh",
    "run",
    "run_cli",
    "spectrum",
    "spline",
    "tspline",
    "validate",
    "write_mesh",
]

PathLike = Union[str, "os.PathLike[str]"]


class ArrayError(RicciError, TypeError):
    """Arrays of the wrong dtype or shape (vertices must be (n, 3) real, faces (m, 3) integer)."""


@dataclass
class Mesh:
    """A triangle mesh as numpy arrays.

    ``vertices``: (n, 3) float64 positions; ``faces``: (m, 3) int64 vertex ids (0-based,
    counter-clockwise seen from outside); ``uvs``: (n, 2) float64 per-vertex texture
    coordinates when the file had them; ``report``: what the reader changed or noticed (the
    library's build report: dropped vertices, reoriented faces, zero-area faces, notes).
    """

    vertices: np.ndarray
    faces: np.ndarray
    uvs: Optional[np.ndarray] = None
    report: Dict[str, Any] = field(default_factory=dict)


MeshLike = Union[PathLike, Mesh, np.ndarray, Tuple[Any, Any]]


class Report(Mapping[str, Any]):
    """A command's JSON report: a read-only mapping of the CLI's JSON keys, each also an
    attribute (``r.converged`` is ``r["converged"]``). ``to_dict()`` is exactly the JSON the
    CLI prints with ``--json``. Output files that were kept in memory (no path given) are in
    ``files`` (name → bytes); subclasses also give them as numpy arrays."""

    command: str = ""

    def __init__(
        self,
        data: Dict[str, Any],
        files: Optional[Dict[str, bytes]] = None,
        memory: Optional[str] = None,
    ):
        self._data = data
        self.files: Dict[str, bytes] = dict(files or {})

    def __getattr__(self, key: str) -> Any:
        data = self.__dict__.get("_data", {})
        if key in data:
            return data[key]
        raise AttributeError(f"{type(self).__name__} has no field {key!r}")

    def __getitem__(self, key: str) -> Any:
        return self._data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __dir__(self):
        return sorted(set(super().__dir__()) | {k for k in self._data if k.isidentifier()})

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Report):
            return self._data == other._data
        if isinstance(other, Mapping):
            return self._data == dict(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        shown = ", ".join(
            f"{k}={v!r}" for k, v in self._data.items() if not isinstance(v, (list, dict))
        )
        return f"{type(self).__name__}({shown})"

    def to_dict(self) -> Dict[str, Any]:
        """The report as a dict (the CLI's ``--json`` object)."""
        return dict(self._data)

    def to_json(self) -> str:
        """The report as one line of JSON."""
        return json.dumps(self._data)


class InfoResult(Report):
    """``ricci info``: validation, topology per component, triangle quality."""

    command = "info"
    vertices: int
    edges: int
    faces: int
    components: int
    boundary_loops: int
    euler_characteristic: int
    genus: int
    orientable: bool
    manifold: bool
    min_angle_deg: float


class FlowResult(Report):
    """``ricci flow``: the Ricci flow's report; with the final metric as numpy arrays when no
    ``out`` path was given: ``u`` (per vertex), ``curvature``, ``target_curvature`` (NaN where
    the vertex was held fixed), ``lengths`` (per edge) and ``edge_vertices`` ((E, 2) int64)."""

    command = "flow"
    geometry: str
    scheme: str
    solver: str
    iterations: int
    max_curvature_error: float
    seconds: float
    converged: bool
    gauss_bonnet_error: float
    u: Optional[np.ndarray]
    curvature: Optional[np.ndarray]
    target_curvature: Optional[np.ndarray]
    lengths: Optional[np.ndarray]
    edge_vertices: Optional[np.ndarray]
    metric: Optional[Dict[str, Any]]  # METRIC.json's other keys (geometry, scheme, target, …)

    def __init__(self, data, files=None, memory=None):
        super().__init__(data, files)
        self.metric = self.u = self.curvature = None
        self.target_curvature = self.lengths = self.edge_vertices = None
        if memory and memory in self.files:
            rest, (u, k, target, lengths, edges) = self.files.pop(memory)
            f64 = lambda b: np.frombuffer(b, dtype=np.float64).copy()
            self.metric = json.loads(rest)
            self.u, self.curvature, self.target_curvature = f64(u), f64(k), f64(target)
            self.lengths = f64(lengths)
            self.edge_vertices = np.frombuffer(edges, dtype=np.int64).reshape(-1, 2).copy()


class LayoutResult(Report):
    """``ricci layout``: cut, isometric layout, deck group. Without an ``out`` path, the
    layout as arrays: ``uv`` ((k, 2) layout coordinates of the cut mesh's vertices; Poincaré
    disk for hyperbolic), ``uv_faces`` ((m, 3) into ``uv``), ``positions``/``faces`` (the 3D
    surface the faces refer to; on the unit sphere for spherical layouts, where ``uv`` is
    None)."""

    command = "layout"
    geometry: str
    flipped_faces: int
    deck_generators: list
    relation_error: Optional[float]
    seconds: float
    uv: Optional[np.ndarray]
    uv_faces: Optional[np.ndarray]
    positions: Optional[np.ndarray]

    def __init__(self, data, files=None, memory=None):
        super().__init__(data, files)
        self.uv = self.uv_faces = self.positions = None
        self.position_faces = None
        if memory and memory in self.files:
            v, f, vt, ft = _parse_obj(self.files[memory])
            self.positions, self.position_faces = v, f
            if vt is not None:
                self.uv, self.uv_faces = vt, ft


class SpectrumResult(Report):
    """``ricci spectrum``: the geodesic length spectrum of a closed surface of genus ≥ 1, or of
    the double of a surface with boundary that is not a disk (``spectrum_of`` is
    ``"surface"`` or ``"double"``; ``double`` then describes the double and ``genus`` is the
    double's, ``2g + b − 1``)."""

    command = "spectrum"
    spectrum_of: str
    double: Optional[dict]
    genus: int
    lengths: list
    normalized: list


class CutResult(Report):
    """``ricci cut``: canonical fundamental group generators and the cut mesh (``mesh``, a
    :class:`Mesh`, when no ``out`` path was given)."""

    command = "cut"
    genus: int
    loops: list
    polygon_sides: int
    boundary_word: str
    disk: bool
    intersection_matrix: list
    seconds: float
    mesh: Optional[Mesh]

    def __init__(self, data, files=None, memory=None):
        super().__init__(data, files)
        self.mesh = None
        if memory and memory in self.files:
            v, f, _, _ = _parse_obj(self.files[memory])
            self.mesh = Mesh(v, f)


class AtlasResult(Report):
    """``ricci atlas``: affine atlas with one extraordinary point (its files, SVG charts and
    JSON tables, are in ``files`` when no ``out`` folder was given)."""

    command = "atlas"
    singular_vertex: int
    charts: Any
    max_transition_error: float
    area_distortion: Any


class SplineResult(Report):
    """``ricci spline``: manifold triangular B-spline (the tessellated surface as ``surface``,
    a :class:`Mesh`, when no ``out`` folder was given; all its files in ``files``)."""

    command = "spline"
    control_points: int
    rms_error_percent: float
    max_error_percent: float
    continuity: Any
    seconds: float
    surface: Optional[Mesh]

    def __init__(self, data, files=None, memory=None):
        super().__init__(data, files)
        self.surface = None
        key = f"{memory}/surface.obj" if memory else None
        if key and key in self.files:
            v, f, _, _ = _parse_obj(self.files[key])
            self.surface = Mesh(v, f)


class TSplineResult(Report):
    """``ricci tspline``: cubic T-spline over the flat torus fitted to a genus-1 mesh (paper
    003). Without an ``out`` folder, its files are in ``files`` and as arrays:

    ``anchors`` (n, 2) parameters of the control points and ``control`` (n, 3) the control
    points; ``params`` (m, 2) the data points' parameters (corrected when
    ``parameter_correction`` > 0) and ``errors`` (m,) their distances ``|S(u_k) − p_k|``;
    ``patch_bounds`` (P, 4) ``[u0, u1, v0, v1]`` and ``patch_control`` (P, 4, 4, 3) the
    Bézier patches (``[i][j]``, ``i`` along ``u``); ``lattice`` (width, height, shift);
    ``surface`` (a :class:`Mesh`, the tessellation ``surface.obj``). ``evaluate(uv)`` gives
    the surface at any parameters."""

    command = "tspline"
    control_points: int
    rms_error_percent: float
    max_error_percent: float
    iterations: int
    continuity: Any
    seconds: float

    def __init__(self, data, files=None, memory=None):
        super().__init__(data, files)
        self.anchors = self.control = self.params = self.errors = None
        self.patch_bounds = self.patch_control = self.lattice = self.surface = None
        if not memory:
            return
        spline = self.files.get(f"{memory}/spline.json")
        if spline is not None:
            d = json.loads(spline)
            f64 = lambda x, *shape: np.array(x, dtype=np.float64).reshape(*shape)
            self.anchors, self.control = f64(d["anchors"], -1, 2), f64(d["control"], -1, 3)
            self.params, self.errors = f64(d["params"], -1, 2), f64(d["errors"], -1)
            self.patch_bounds = f64(d["patch_bounds"], -1, 4)
            self.patch_control = f64(d["patch_control"], -1, 4, 4, 3)
            lat = d["lattice"]
            self.lattice = (lat["width"], lat["height"], lat["shift"])
        obj = self.files.get(f"{memory}/surface.obj")
        if obj is not None:
            v, f, _, _ = _parse_obj(obj)
            self.surface = Mesh(v, f)

    def canonical(self, uv: Any) -> np.ndarray:
        """Representatives of parameters ``uv`` ((k, 2)) in ``[0, W) × [0, H)`` (the
        lattice's fundamental rectangle, the top side glued to the bottom shifted by ``s``)."""
        if self.lattice is None:
            raise RicciError("the spline's arrays are only kept without an out folder")
        w, h, s = self.lattice
        uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
        u, v = uv[:, 0].copy(), uv[:, 1].copy()
        n = np.floor(v / h)
        v -= n * h
        u -= n * s
        over = v >= h
        v[over] -= h
        u[over] -= s
        v[v < 0.0] = 0.0
        u -= np.floor(u / w) * w
        u[u >= w] -= w
        u[u < 0.0] = 0.0
        return np.stack([u, v], axis=1)

    def evaluate(self, uv: Any) -> np.ndarray:
        """The surface ``S(u, v)`` at parameters ``uv`` ((k, 2), any representatives): (k, 3),
        from the Bézier patches (NaN where no patch holds the point)."""
        c = self.canonical(uv)
        out = np.full((len(c), 3), np.nan)
        for b, ctrl in zip(self.patch_bounds, self.patch_control):
            u0, u1, v0, v1 = b
            m = (c[:, 0] >= u0) & (c[:, 0] <= u1) & (c[:, 1] >= v0) & (c[:, 1] <= v1)
            m &= np.isnan(out[:, 0])
            if not m.any():
                continue
            bu = _bernstein((c[m, 0] - u0) / (u1 - u0))
            bv = _bernstein((c[m, 1] - v0) / (v1 - v0))
            out[m] = np.einsum("ki,kj,ijd->kd", bu, bv, ctrl)
        return out


def _bernstein(t: np.ndarray) -> np.ndarray:
    s = 1.0 - t
    return np.stack([s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t], axis=1)


_RESULTS = {
    c.command: c
    for c in (
        InfoResult,
        FlowResult,
        LayoutResult,
        SpectrumResult,
        CutResult,
        AtlasResult,
        SplineResult,
        TSplineResult,
    )
}

# Output options kept in memory when no path is given: command → (option, memory name).
_MEMORY_OUT = {
    "flow": ("out", "metric.json"),
    "layout": ("out", "uv.obj"),
    "cut": ("out", "cut.obj"),
    "atlas": ("out", "atlas"),
    "spline": ("out", "spline"),
    "tspline": ("out", "tspline"),
}


def _parse_obj(data: bytes):
    """(v (n,3), f (m,3) into v, vt (k,2) or None, f's vt ids (m,3) or None) of an OBJ."""
    v, vt, f, ft = [], [], [], []
    for line in data.decode().splitlines():
        if line.startswith("v "):
            v.append(line[2:].split()[:3])
        elif line.startswith("vt "):
            vt.append(line[3:].split()[:2])
        elif line.startswith("f "):
            corners = [c.split("/") for c in line[2:].split()]
            f.append([c[0] for c in corners])
            if len(corners[0]) > 1 and corners[0][1]:
                ft.append([c[1] for c in corners])
    V = np.array(v, dtype=np.float64).reshape(-1, 3)
    F = np.array(f, dtype=np.int64).reshape(-1, 3) - 1
    VT = np.array(vt, dtype=np.float64).reshape(-1, 2) if vt else None
    FT = np.array(ft, dtype=np.int64).reshape(-1, 3) - 1 if ft and len(ft) == len(f) else None
    return V, F, VT, FT


def _vertices(a: Any) -> np.ndarray:
    a = np.asarray(a)
    if a.dtype == np.bool_ or not np.can_cast(a.dtype, np.float64, "safe"):
        raise ArrayError(f"vertices must be a real array (float64); got dtype {a.dtype}")
    if a.ndim != 2 or a.shape[1] != 3:
        raise ArrayError(f"vertices must be an (n, 3) array; got shape {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def _faces(a: Any) -> np.ndarray:
    a = np.asarray(a)
    if a.dtype.kind not in "iu":
        raise ArrayError(f"faces must be an integer array (vertex ids); got dtype {a.dtype}")
    if a.ndim != 2 or a.shape[1] != 3:
        raise ArrayError(f"faces must be an (m, 3) array of triangles; got shape {a.shape}")
    if a.dtype == np.uint64 and a.size and a.max() > np.iinfo(np.int64).max:
        raise ArrayError("faces hold a vertex id larger than 2^63")
    return np.ascontiguousarray(a, dtype=np.int64)


def _arrays(mesh: Any, faces: Any) -> Tuple[np.ndarray, np.ndarray]:
    if isinstance(mesh, Mesh):
        if faces is not None:
            raise UsageError("give faces only with a vertex array, not with a Mesh")
        return _vertices(mesh.vertices), _faces(mesh.faces)
    if isinstance(mesh, tuple) and len(mesh) == 2 and faces is None:
        return _vertices(mesh[0]), _faces(mesh[1])
    if faces is None:
        raise UsageError("a vertex array needs its faces: f(vertices, faces, ...)")
    return _vertices(mesh), _faces(faces)


def _format(value: Any) -> str:
    if isinstance(value, float):
        return repr(value)  # shortest text that reads back as the same double
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return str(value)


def _argv(options: Mapping[str, Any]) -> list:
    argv = []
    for key, value in options.items():
        if value is None or value is False:
            continue
        flag = "--" + key.replace("_", "-")
        if value is True:
            argv.append(flag)
        elif isinstance(value, (list, tuple)):
            argv += [flag, ",".join(_format(x) for x in value)]
        else:
            argv += [flag, _format(value)]
    return argv


def run(
    command: str,
    mesh: Optional[MeshLike] = None,
    faces: Any = None,
    *,
    name: Optional[str] = None,
    arrays: bool = True,
    **options: Any,
) -> Report:
    """Run the CLI subcommand ``command`` on ``mesh`` with the CLI's ``options``; its report.

    ``mesh`` is a path, a :class:`Mesh`, a ``(vertices, faces)`` pair or a vertex array with
    ``faces``; ``name`` labels array input in reports and error sentences (default
    ``"<array>"``). For commands whose ``out`` file or folder is optional here (flow, layout,
    cut, atlas, spline), leaving ``out`` unset keeps the output in memory and (``arrays``)
    gives it as numpy arrays on the result; the report's ``out`` is then ``None``.
    """
    vb = fb = None
    if mesh is None:
        first = []
    elif isinstance(mesh, (str, os.PathLike)):
        if faces is not None:
            raise UsageError("faces go with a vertex array, not with a mesh file")
        first = [os.fspath(mesh)]
    else:
        v, f = _arrays(mesh, faces)
        vb, fb = v.tobytes(), f.tobytes()
        first = [name or "<array>"]
    memory = None
    if arrays and command in _MEMORY_OUT:
        opt, file_name = _MEMORY_OUT[command]
        if options.get(opt) is None:
            memory = _native.MEMORY_PREFIX + file_name
            options = {**options, opt: memory}
    argv = first + _argv(options)
    if "--json" not in argv:
        argv.append("--json")
    text, files = _native.run(command, argv, first[0] if vb is not None else None, vb, fb)
    data = json.loads(text) if text else {}
    if memory is not None and isinstance(data.get("out"), str) and data["out"].startswith(
        _native.MEMORY_PREFIX
    ):
        data["out"] = None
    return _RESULTS.get(command, Report)(data, files, memory)


def run_cli(args: "list[str]") -> Report:
    """Run ``ricci ARGS --json`` in this process, arguments as on the command line
    (``run_cli(["flow", "kitten.off", "--geometry", "hyperbolic"])``); its report, exactly as
    the CLI prints it. Files are written where the arguments say; nothing is kept in memory."""
    args = [os.fspath(a) if isinstance(a, os.PathLike) else str(a) for a in args]
    if not args:
        raise UsageError("run_cli needs a command: run_cli(['info', 'mesh.off'])")
    argv = args[1:] + ([] if "--json" in args else ["--json"])
    text, files = _native.run(args[0], argv, None, None, None)
    return _RESULTS.get(args[0], Report)(json.loads(text) if text else {}, files)


def read_mesh(path: PathLike) -> Mesh:
    """Read and validate a mesh file (OBJ, OFF, PLY ascii/binary, STL): a :class:`Mesh`.

    Raises :class:`RicciError` with the library's sentence (file, line, vertex or face) when
    the file is not a valid oriented 2-manifold triangle mesh."""
    v, f, uv, report = _native.read_mesh(os.fspath(path))
    return Mesh(
        vertices=np.frombuffer(v, dtype=np.float64).reshape(-1, 3).copy(),
        faces=np.frombuffer(f, dtype=np.int64).reshape(-1, 3).copy(),
        uvs=None if uv is None else np.frombuffer(uv, dtype=np.float64).reshape(-1, 2).copy(),
        report=json.loads(report),
    )


def write_mesh(path: PathLike, mesh: Union[Mesh, np.ndarray], faces: Any = None) -> Dict[str, Any]:
    """Validate and write a mesh; the format is chosen by the extension (PLY and STL binary,
    OBJ and OFF with every double written exactly). Returns the library's build report.
    Raises :class:`RicciError` (non-manifold, …) or :class:`ArrayError` (dtype, shape)."""
    v, f = _arrays(mesh, faces)
    return json.loads(_native.write_mesh(os.fspath(path), v.tobytes(), f.tobytes()))


def validate(vertices: Any, faces: Any = None, *, name: Optional[str] = None) -> Dict[str, Any]:
    """Check arrays the way a mesh file is checked; the build report, or :class:`RicciError`
    with the library's sentence naming the vertex or face at fault."""
    v, f = _arrays(vertices, faces)
    return json.loads(_native.validate(v.tobytes(), f.tobytes(), name))


def info(mesh: MeshLike, faces: Any = None, *, name: Optional[str] = None) -> InfoResult:
    """``ricci info``: validate, topology (per component), triangle quality."""
    return run("info", mesh, faces, name=name)  # type: ignore[return-value]


def flow(
    mesh: MeshLike,
    faces: Any = None,
    *,
    geometry: Optional[str] = None,
    scheme: Optional[str] = None,
    target: Optional[str] = None,
    solver: Optional[str] = None,
    tolerance: Optional[float] = None,
    max_iterations: Optional[int] = None,
    step: Optional[float] = None,
    input_scale: Optional[float] = None,
    sphere_route: Optional[str] = None,
    widen_boundary: Optional[int] = None,
    refine_degenerate: Optional[int] = None,
    refined_out: Optional[PathLike] = None,
    out: Optional[PathLike] = None,
    name: Optional[str] = None,
    arrays: bool = True,
) -> FlowResult:
    """``ricci flow``: discrete Ricci flow to a metric with prescribed curvature.

    geometry: euclidean (default) | hyperbolic | spherical; scheme: thurston (default) |
    tangential | inversive | yamabe; target: uniform (default), ``cone:V=K,...``,
    ``single-cone[:V]``, free-boundary, round-boundary, geodesic-boundary, ``file:PATH``;
    solver: newton (default) | gradient; tolerance: max |K − K̄| (default 1e-10);
    max_iterations (30 Newton / 200000 gradient); step (gradient flow ε, 0.05); input_scale;
    sphere_route: auto | newton | puncture; widen_boundary / refine_degenerate (need
    refined_out); out: METRIC.json path (else the metric comes back as arrays)."""
    return run(  # type: ignore[return-value]
        "flow",
        mesh,
        faces,
        name=name,
        arrays=arrays,
        geometry=geometry,
        scheme=scheme,
        target=target,
        solver=solver,
        tolerance=tolerance,
        max_iterations=max_iterations,
        step=step,
        input_scale=input_scale,
        sphere_route=sphere_route,
        widen_boundary=widen_boundary,
        refine_degenerate=refine_degenerate,
        refined_out=refined_out,
        out=out,
    )


def layout(
    mesh: MeshLike,
    faces: Any = None,
    *,
    geometry: Optional[str] = None,
    target: Optional[str] = None,
    metric: Optional[PathLike] = None,
    base: Optional[int] = None,
    seed_face: Optional[int] = None,
    tiling: Optional[int] = None,
    out: Optional[PathLike] = None,
    svg: Optional[PathLike] = None,
    no_polish: bool = False,
    name: Optional[str] = None,
    arrays: bool = True,
) -> LayoutResult:
    """``ricci layout``: cut to a disk, lay out isometrically (plane / Poincaré disk /
    sphere), deck group. geometry defaults to the uniformization geometry; metric: a
    METRIC.json from ``flow(out=...)``; out: UV.obj (else ``uv``/``uv_faces`` arrays); svg:
    picture; tiling: copies of the fundamental polygon in the SVG."""
    return run(  # type: ignore[return-value]
        "layout",
        mesh,
        faces,
        name=name,
        arrays=arrays,
        geometry=geometry,
        target=target,
        metric=metric,
        base=base,
        seed_face=seed_face,
        tiling=tiling,
        out=out,
        svg=svg,
        no_polish=no_polish,
    )


def spectrum(
    mesh: MeshLike,
    faces: Any = None,
    *,
    count: Optional[int] = None,
    metric: Optional[PathLike] = None,
    base: Optional[int] = None,
    name: Optional[str] = None,
) -> SpectrumResult:
    """``ricci spectrum``: the ``count`` (default 8) shortest closed geodesics' lengths of a
    closed surface of genus ≥ 1 (normalized by the shortest for genus 1), or, for a surface
    with boundary that is not a disk, of its double (``spectrum_of == "double"``; the boundary
    loops and doubled orthogeodesics are among them). ``metric`` is for closed surfaces only."""
    return run(  # type: ignore[return-value]
        "spectrum", mesh, faces, name=name, count=count, metric=metric, base=base
    )


def cut(
    mesh: MeshLike,
    faces: Any = None,
    *,
    base: Optional[int] = None,
    metric: Optional[PathLike] = None,
    min_valence: Optional[int] = None,
    out: Optional[PathLike] = None,
    svg: Optional[PathLike] = None,
    name: Optional[str] = None,
    arrays: bool = True,
) -> CutResult:
    """``ricci cut``: canonical fundamental group generators through a base vertex; the mesh
    sliced open into a disk (``out`` CUT.obj, else ``mesh`` on the result)."""
    return run(  # type: ignore[return-value]
        "cut",
        mesh,
        faces,
        name=name,
        arrays=arrays,
        base=base,
        metric=metric,
        min_valence=min_valence,
        out=out,
        svg=svg,
    )


def atlas(
    mesh: MeshLike,
    faces: Any = None,
    *,
    singularity: Optional[str] = None,
    cones: Optional[str] = None,
    scheme: Optional[str] = None,
    tolerance: Optional[float] = None,
    out: Optional[PathLike] = None,
    name: Optional[str] = None,
    arrays: bool = True,
) -> AtlasResult:
    """``ricci atlas``: affine atlas with a single extraordinary point (singularity: auto
    (default) or a vertex id); out: folder for its pictures and tables (else ``files``)."""
    return run(  # type: ignore[return-value]
        "atlas",
        mesh,
        faces,
        name=name,
        arrays=arrays,
        singularity=singularity,
        cones=cones,
        scheme=scheme,
        tolerance=tolerance,
        out=out,
    )


def spline(
    mesh: MeshLike,
    faces: Any = None,
    *,
    degree: Optional[int] = None,
    fairness: Optional[int] = None,
    singularity: Optional[str] = None,
    fit: Optional[float] = None,
    charts: Optional[str] = None,
    tessellation: Optional[int] = None,
    out: Optional[PathLike] = None,
    name: Optional[str] = None,
    arrays: bool = True,
) -> SplineResult:
    """``ricci spline``: manifold triangular B-spline (degree 3, fairness 1 by default) with
    at most one extraordinary point; out: folder (else ``surface`` and ``files``)."""
    return run(  # type: ignore[return-value]
        "spline",
        mesh,
        faces,
        name=name,
        arrays=arrays,
        degree=degree,
        fairness=fairness,
        singularity=singularity,
        fit=fit,
        charts=charts,
        tessellation=tessellation,
        out=out,
    )


def tspline(
    mesh: MeshLike,
    faces: Any = None,
    *,
    tolerance: Optional[Union[str, float]] = None,
    rms_tolerance: Optional[Union[str, float]] = None,
    smoothing: Optional[float] = None,
    smoothing_decay: Optional[float] = None,
    initial_faces: Optional[int] = None,
    mark_fraction: Optional[float] = None,
    max_points_per_face: Optional[int] = None,
    parameter_correction: Optional[int] = None,
    correction_steps: Optional[int] = None,
    correction_gain: Optional[float] = None,
    rms_marks: Optional[int] = None,
    area_weights: bool = False,
    per_cylinder: bool = False,
    max_iterations: Optional[int] = None,
    max_control_points: Optional[int] = None,
    tessellation: Optional[int] = None,
    out: Optional[PathLike] = None,
    pictures: bool = False,
    name: Optional[str] = None,
    arrays: bool = True,
) -> TSplineResult:
    """``ricci tspline``: cubic T-spline over the domain manifold (genus 1: the flat torus)
    fitted with adaptive refinement until ``L∞ ≤ tolerance`` ("0.5%" or 0.005, of the longest
    bounding-box side) and, if given, ``rms ≤ rms_tolerance``. out: folder for STEP, IGES,
    OBJ, SVG, JSON (and with ``pictures`` the PNGs); without it the spline comes back as
    arrays (see :class:`TSplineResult`). Other options are the CLI's."""
    return run(  # type: ignore[return-value]
        "tspline",
        mesh,
        faces,
        name=name,
        arrays=arrays,
        tolerance=tolerance,
        rms_tolerance=rms_tolerance,
        smoothing=smoothing,
        smoothing_decay=smoothing_decay,
        initial_faces=initial_faces,
        mark_fraction=mark_fraction,
        max_points_per_face=max_points_per_face,
        parameter_correction=parameter_correction,
        correction_steps=correction_steps,
        correction_gain=correction_gain,
        rms_marks=rms_marks,
        area_weights=area_weights,
        per_cylinder=per_cylinder,
        max_iterations=max_iterations,
        max_control_points=max_control_points,
        tessellation=tessellation,
        out=out,
        no_pictures=not pictures,
    )
