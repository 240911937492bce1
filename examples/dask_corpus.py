#!/usr/bin/env python3
"""Fan a mesh corpus out over a Dask cluster with the `ricci` Python package; JSON lines.

    python examples/dask_corpus.py MANIFEST --out results.jsonl [--workers 2] \
        [--scheduler tcp://HOST:8786] -- COMMAND [ARGS]

MANIFEST and `-- COMMAND [ARGS]` mean what they mean for `ricci batch` (a text file with one
mesh path a line, relative to the manifest's folder, `#` comments; or a folder of mesh files),
and every line of the output is the batch's line for that mesh: `mesh`, `status` (`ok`,
`error` with the library's sentence, `crashed` when the worker died), `error`, `result` (the
command's JSON report, the CLI's to the last digit), `exit_code` and `seconds`, in manifest
order. The output is written atomically (temporary file, then rename) when all meshes are done.

Where it runs:
- without `--scheduler`: a `LocalCluster` on this machine with `--workers` worker processes of
  one thread each (what CI runs);
- on a real cluster: start `dask scheduler` on one host and `dask worker tcp://HOST:8786` on
  the others, then pass `--scheduler tcp://HOST:8786` — nothing else changes. Every worker
  needs the package (`pip install ./crates/ricci-py`, see README "From Python") and the meshes
  under the same paths as in the manifest (a shared file system), and the output files that
  ARGS ask for land on the workers' file system.

Why Dask (dask.distributed) and not Ray: the work is a flat map of independent, CPU-bound
calls that release the GIL, with small results (a JSON object per mesh); Dask's futures
(`client.map` + `as_completed`) express exactly that, `distributed` is a small pure-Python
install (no object store, no own runtime — Ray's wheel is hundreds of MB and starts a
plasma store and a dashboard per node, heavy for a 2-core CI machine), a `LocalCluster` and a
real cluster are the same `Client` API with a different address, and a worker that dies is
reported as a failed future (`KilledWorker`) instead of stopping the run.

The ricci call itself: `ricci.run_cli([COMMAND, MESH, *ARGS])` runs the CLI's subcommand in
the worker process (the GIL is released while it computes). Unlike `ricci batch`, a mesh
cannot be stopped after a time limit (Dask cannot kill a running task); a mesh that crashes
its worker is retried by Dask on another worker up to `distributed.scheduler.allowed-failures`
times (set to 1 here) and then recorded as `crashed`.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

MESH_EXTENSIONS = {".obj", ".off", ".ply", ".stl"}


def manifest_meshes(manifest: str) -> list[str]:
    """The meshes of a manifest file or folder, as `ricci batch` reads them."""
    if os.path.isdir(manifest):
        names = sorted(
            n
            for n in os.listdir(manifest)
            if os.path.isfile(os.path.join(manifest, n))
            and os.path.splitext(n)[1].lower() in MESH_EXTENSIONS
        )
        return [os.path.join(manifest, n) for n in names]
    base = os.path.dirname(manifest)
    out = []
    for line in Path(manifest).read_text().splitlines():
        line = line.strip()
        if line and not line.startswith("#"):
            out.append(line if os.path.isabs(line) else os.path.join(base, line))
    return out


def process(mesh: str, command: list[str]) -> dict:
    """One mesh on a worker: the JSON line of `ricci batch`."""
    import ricci  # imported on the worker

    t0 = time.perf_counter()
    line = {"mesh": mesh, "status": "ok", "error": None, "result": None, "exit_code": 0}
    try:
        line["result"] = ricci.run_cli([command[0], mesh, *command[1:]]).to_dict()
    except ricci.UsageError as e:
        line.update(status="error", error=str(e), exit_code=2)
    except ricci.RicciError as e:
        line.update(status="error", error=str(e), exit_code=1)
    line["seconds"] = time.perf_counter() - t0
    return line


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if "--" not in argv:
        print("usage: dask_corpus.py MANIFEST --out FILE [--workers N] [--scheduler ADDR] -- COMMAND [ARGS]",
              file=sys.stderr)
        return 2
    k = argv.index("--")
    own, command = argv[:k], argv[k + 1:]
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("manifest")
    p.add_argument("--out", required=True, help="JSON-lines output file")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://HOST:8786)")
    a = p.parse_args(own)
    if not command:
        p.error("give the command after `--`")

    import dask
    from dask.distributed import Client, LocalCluster, as_completed

    meshes = manifest_meshes(a.manifest)
    dask.config.set({"distributed.scheduler.allowed-failures": 1})
    cluster = None
    if a.scheduler:
        client = Client(a.scheduler)
    else:
        cluster = LocalCluster(
            n_workers=a.workers, threads_per_worker=1, processes=True, dashboard_address=None
        )
        client = Client(cluster)
    t0 = time.perf_counter()
    try:
        futures = client.map(process, meshes, command=command, key=[f"ricci-{i}" for i in range(len(meshes))])
        index = {f.key: i for i, f in enumerate(futures)}
        lines: list[dict | None] = [None] * len(meshes)
        done = failed = 0
        for f in as_completed(futures):
            i = index[f.key]
            try:
                lines[i] = f.result()
            except Exception as e:  # the worker died (KilledWorker) or the task could not run
                lines[i] = {"mesh": meshes[i], "status": "crashed", "error": f"{type(e).__name__}: {e}",
                            "result": None, "exit_code": None, "seconds": None}
            if lines[i]["status"] == "ok":
                done += 1
            else:
                failed += 1
            left = len(meshes) - done - failed
            rate = (time.perf_counter() - t0) / max(done + failed, 1)
            print(f"\rdone {done}, failed {failed}, remaining {left}, ETA {left * rate:.0f} s   ",
                  end="", file=sys.stderr, flush=True)
        print(file=sys.stderr)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    out = Path(a.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp{os.getpid()}")
    tmp.write_text("".join(json.dumps(l, sort_keys=True, ensure_ascii=False) + "\n" for l in lines), encoding="utf-8")
    os.replace(tmp, out)
    print(f"{len(meshes)} meshes: {done} ok, {failed} failed; {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
