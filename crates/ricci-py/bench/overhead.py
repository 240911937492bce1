#!/usr/bin/env python3
"""Overhead of the Python call over the library call, on one mesh (default: kitten).

    python crates/ricci-py/bench/overhead.py [MESH] [--repeats N]

Library call: `read_surface` + `ricci_flow` (the CLI's default options) timed in Rust in this
same process (`ricci._native._library_flow_seconds`). Python calls: `ricci.flow(path)` (the
metric returned as numpy arrays), `ricci.flow(path, arrays=False)` (report only) and
`ricci.flow(vertices, faces)` (arrays in: validated by the same builder instead of parsing a
file, compared with the same library call). Calls are interleaved and repeated;
the medians and minima are printed, and the overhead is the ratio of medians minus one. The
library call is timed from Python around `_library_flow_seconds(path, 1)` with the same clock
(one call across the boundary: microseconds). Default clock: the calling thread's CPU time —
the flow is single-threaded on the calling thread, and CPU time does not count the time other
processes on a loaded machine take.
"""

import argparse
import os
import statistics
import time

import ricci
from ricci import _native


def main():
    p = argparse.ArgumentParser()
    default = os.path.join(os.environ.get("RICCI_MESHES", "../shared/meshes"), "kitten.nf20k.off")
    p.add_argument("mesh", nargs="?", default=default)
    p.add_argument("--repeats", type=int, default=15)
    p.add_argument("--clock", choices=["cpu", "wall"], default="cpu",
                   help="cpu: this thread's CPU time (robust on a shared machine; the library "
                   "runs on the calling thread); wall: perf_counter")
    a = p.parse_args()
    mesh = ricci.read_mesh(a.mesh)
    t = {"library": [], "read": [], "flow(path)": [], "flow(path, arrays=False)": [], "flow(V, F)": []}
    # warm up
    ricci.flow(a.mesh)
    _native._library_flow_seconds(a.mesh, 1)
    clock = time.thread_time if a.clock == "cpu" else time.perf_counter
    for _ in range(a.repeats):
        t0 = clock()
        _, err = _native._library_flow_seconds(a.mesh, 1)
        t["library"].append(clock() - t0)
        t0 = clock()
        ricci.read_mesh(a.mesh)
        t["read"].append(clock() - t0)
        for key, call in [
            ("flow(path)", lambda: ricci.flow(a.mesh)),
            ("flow(path, arrays=False)", lambda: ricci.flow(a.mesh, arrays=False)),
            ("flow(V, F)", lambda: ricci.flow(mesh.vertices, mesh.faces)),
        ]:
            t0 = clock()
            r = call()
            t[key].append(clock() - t0)
            assert r.max_curvature_error == err, (r.max_curvature_error, err)
    med = {k: statistics.median(v) for k, v in t.items()}
    print(f"{a.mesh}: {mesh.vertices.shape[0]} vertices, {mesh.faces.shape[0]} faces, {a.repeats} repeats")
    for k, v in t.items():
        print(f"  {k:26s} median {med[k] * 1e3:8.2f} ms   min {min(v) * 1e3:8.2f} ms")
    lib = med["library"]
    print(f"  overhead flow(path)               {100 * (med['flow(path)'] / lib - 1):+6.2f} %")
    print(f"  overhead flow(path, arrays=False) {100 * (med['flow(path, arrays=False)'] / lib - 1):+6.2f} %")
    print(f"  overhead flow(V, F)               {100 * (med['flow(V, F)'] / lib - 1):+6.2f} %  (arrays validated instead of a file read)")


if __name__ == "__main__":
    main()
