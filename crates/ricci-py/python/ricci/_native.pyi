"""Type stubs of the extension module `ricci._native` (Rust, PyO3). Use the functions of
`ricci` instead: they take numpy arrays and return result objects."""

from os import PathLike
from typing import Dict, List, Optional, Tuple, Union

__version__: str
COMMANDS: List[str]
MEMORY_PREFIX: str

class RicciError(ValueError):
    """The library refused the input; the message is its one sentence."""

class UsageError(RicciError):
    """Bad arguments (the CLI's exit code 2)."""

_Metric = Tuple[str, List[bytes]]

def run(
    command: str,
    argv: List[str],
    name: Optional[str] = None,
    vertices: Optional[bytes] = None,
    faces: Optional[bytes] = None,
) -> Tuple[str, Dict[str, Union[bytes, _Metric]]]:
    """Run the CLI subcommand with `argv` (mesh path first); (JSON report, in-memory files).

    `command` is one of COMMANDS: info, flow, layout, spectrum, cut, atlas, spline, pou,
    render, generate, param, tspline. For tspline with `--out <memory>/tspline`, the files are
    `<memory>/tspline/{tspline.step, tspline.igs, surface.obj, tmesh.svg, samples.json,
    spline.json, tspline.json}` (bytes; spline.json holds anchors, control, params, errors,
    scale, lattice, patch_bounds, patch_control)."""

def read_mesh(
    path: Union[str, PathLike[str]],
) -> Tuple[bytes, bytes, Optional[bytes], str]:
    """(vertices float64 bytes, faces int64 bytes, uvs float64 bytes or None, report JSON)."""

def write_mesh(path: Union[str, PathLike[str]], vertices: bytes, faces: bytes) -> str:
    """Validate and write; the build report JSON."""

def validate(vertices: bytes, faces: bytes, name: Optional[str] = None) -> str:
    """Validate; the build report JSON."""

def _library_flow_seconds(path: Union[str, PathLike[str]], repeats: int) -> Tuple[List[float], float]:
    """Benchmark helper: seconds of read_surface + ricci_flow per repeat, max curvature error."""
