"""Shared fixtures: the `ricci` binary (the CLI the results are compared with), the shared
meshes (RICCI_MESHES; tests that need them skip without it) and generated surfaces."""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]


def ricci_bin() -> Path:
    p = Path(os.environ.get("RICCI_BIN", REPO / "target" / "release" / "ricci"))
    if not p.exists():
        pytest.skip(f"the ricci binary {p} is not built (cargo build --release -p ricci-cli)")
    return p


def cli(*args, check=True):
    """Run the CLI; (exit code, stdout JSON or None, stderr)."""
    r = subprocess.run([str(ricci_bin()), *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"ricci {' '.join(map(str, args))} failed: {r.stderr}")
    out = json.loads(r.stdout) if "--json" in map(str, args) and r.stdout.strip() else None
    return r.returncode, out, r.stderr


def shared(name: str) -> Path:
    d = os.environ.get("RICCI_MESHES")
    if not d:
        pytest.skip("RICCI_MESHES is not set")
    p = Path(d) / name
    if not p.exists():
        pytest.skip(f"{p} is missing")
    return p


@pytest.fixture(scope="session")
def generated(tmp_path_factory):
    """Procedural surfaces made by `ricci generate` (no shared meshes needed)."""
    d = tmp_path_factory.mktemp("generated")
    out = {}
    kinds = [("torus", []), ("genus", ["--genus", "2"]), ("disk", []), ("sphere", [])]
    for kind, extra in kinds + [("genus3", ["-n", "30"])]:
        path = d / f"{kind}.off"
        cli("generate", kind, *extra, "--out", path)
        out[kind] = path
    return out
