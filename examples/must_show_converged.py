#!/usr/bin/env python3
"""Issue 15's must-show bullet "Converged ... with the default and no refinement flags ...; then
`ricci layout` with 0 flipped faces on the common subdivision": runs `ricci layout MESH --json
--out uv.obj` for the named cases and prints one table row per case (converged, max |K - K̄|,
degenerate faces, flipped faces from the report, route, CPU seconds of the child).

    RICCI_MESHES=../shared/meshes python3 examples/must_show_converged.py [target/release/ricci]

The full sweep of every shared mesh (with the flipped faces recounted from the OBJ) is the
ignored test `cargo test --release -p ricci-cli --test all sweep_meshes:: -- --ignored --nocapture`.
"""
import json, os, resource, subprocess, sys, tempfile

CASES = [
    ("seahorse2_100K.off", ["--geometry", "hyperbolic"]),
    ("horse.ply", ["--geometry", "spherical"]),
    ("rocker-arm.off", ["--geometry", "euclidean"]),
    ("face.off", ["--target", "round-boundary"]),
    ("camelhead.off", ["--target", "round-boundary"]),
    ("camelhead.off", ["--target", "free-boundary"]),
    ("beetle.off", []),
    ("bunny.off", ["--geometry", "euclidean", "--target", "free-boundary"]),
]


def cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def main():
    exe = sys.argv[1] if len(sys.argv) > 1 else "target/release/ricci"
    d = os.environ.get("RICCI_MESHES", "../shared/meshes")
    tmp = tempfile.mkdtemp(prefix="ricci-must-show-")
    print("| case | converged | max abs(K - K̄) | degenerate | flipped | route / uv on | CPU s |")
    print("|---|---|---:|---:|---:|---|---:|")
    for mesh, extra in CASES:
        case = " ".join([mesh] + extra)
        obj = os.path.join(tmp, case.replace(" ", "_").replace("/", "_") + ".obj")
        t0 = cpu()
        p = subprocess.run([exe, "layout", os.path.join(d, mesh), *extra, "--json", "--out", obj],
                           capture_output=True, text=True)
        t = cpu() - t0
        try:
            j = json.loads(p.stdout)
        except ValueError:
            print(f"| {case} | no JSON (exit {p.returncode}) | | | | | {t:.1f} |", flush=True)
            continue
        if p.returncode != 0:
            print(f"| {case} | refused: {j.get('error')} | | | | | {t:.1f} |", flush=True)
            continue
        m = j.get("metric", {})
        route = j.get("route", "surface") + " / " + str(j.get("uv", {}).get("on", ""))
        print(f"| {case} | {m.get('converged')} | {m.get('max_curvature_error', float('nan')):.2e} "
              f"| {j.get('degenerate_faces')} | {j.get('flipped_faces')} | {route} | {t:.1f} |",
              flush=True)


if __name__ == "__main__":
    main()
