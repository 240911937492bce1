"""examples/dask_corpus.py on a LocalCluster with 2 workers processes the shared meshes and
gives the same lines as `ricci batch` (the same statuses and sentences, the same reports to
the last digit; only wall-clock times differ)."""

import json
import re
import subprocess
import sys

import pytest

from conftest import REPO, cli, ricci_bin, shared


def strip_timing(v):
    if isinstance(v, dict):
        return {k: strip_timing(x) for k, x in v.items() if k != "seconds"}
    if isinstance(v, list):
        return [strip_timing(x) for x in v]
    return v


def strip_try(error):
    return None if error is None else re.sub(r"; try: .*$", "", error)


def test_dask_local_cluster_equals_batch(tmp_path):
    pytest.importorskip("dask.distributed")
    meshes = shared("kitten.nf20k.off").parent
    batch_out = tmp_path / "batch"
    _, summary, _ = cli("batch", meshes, "--out", batch_out, "--jobs", "2", "--timeout", "600",
                        "--json", "--", "flow")
    assert summary["ran"] == summary["meshes"] > 0
    dask_out = tmp_path / "dask.jsonl"
    r = subprocess.run(
        [sys.executable, str(REPO / "examples" / "dask_corpus.py"), str(meshes),
         "--out", str(dask_out), "--workers", "2", "--", "flow"],
        capture_output=True, text=True, timeout=900,
    )
    assert r.returncode == 0, r.stderr
    batch = [json.loads(l) for l in (batch_out / "results.jsonl").read_text().splitlines()]
    dask = [json.loads(l) for l in dask_out.read_text().splitlines()]
    assert len(dask) == len(batch) == summary["meshes"]
    for b, d in zip(batch, dask):
        assert d["mesh"] == b["mesh"]
        assert d["status"] == b["status"], d["mesh"]
        # The CLI (batch) ends a refusal with a shell command to try; Python has the sentence.
        assert strip_try(d["error"]) == strip_try(b["error"]), d["mesh"]
        assert d["exit_code"] == b["exit_code"], d["mesh"]
        assert strip_timing(d["result"]) == strip_timing(b["result"]), d["mesh"]
    assert sum(d["status"] == "ok" for d in dask) == summary["ok"] >= 1
