#!/usr/bin/env python3
"""Flip sweep of `ricci param` over meshes x cone counts x seams (issue 16, must-show 1:
"0 flipped faces, every time").

    python3 examples/param_flip_sweep.py target/release/ricci $RICCI_MESHES /tmp/sweep \\
        camel.off kitten.nf20k.off botijo.off ... > sweep.txt

For every mesh: the default, `--cones N` for N = 0..10 and `--cones auto`, each with
`--seams rigid` and `--seams free`, and `--sphere`. One line per run: mesh, arguments, then a
JSON object with the exit code (and the last stderr line when it failed: refusals such as
"needs cones" or "--sphere needs genus 0" are expected), `flipped` (the JSON's
flipped_faces), `obj_flipped` (UV triangles with signed area <= 0 recounted here from the
written OBJ's vt lines), `tris`, `uv` (input / common_subdivision), `seams` and `cones` used
per chart, `fallback` (whether a chart was recomputed, `ricci::param` ladder), sigma(log
area), qc p95 and user CPU seconds. The last line sums it up: runs, refusals, other failures,
runs with flipped triangles.
"""
import json
import os
import resource
import subprocess
import sys


def obj_flips(path):
    vt, bad, n = [], 0, 0
    with open(path) as fh:
        for line in fh:
            if line.startswith('vt '):
                x = line.split()
                vt.append((float(x[1]), float(x[2])))
            elif line.startswith('f '):
                n += 1
                q = [vt[int(c.split('/')[1]) - 1] for c in line.split()[1:4]]
                a = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - \
                    (q[2][0] - q[0][0]) * (q[1][1] - q[0][1])
                if not a > 0:
                    bad += 1
    return bad, n


def run(binary, mesh, args, out):
    if os.path.exists(out):
        os.remove(out)
    cmd = [binary, 'param', mesh, '--out', out, '--json'] + args
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    p = subprocess.run(cmd, capture_output=True, text=True)
    cpu = round(resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - r0, 2)
    if p.returncode != 0:
        return dict(rc=p.returncode, err=(p.stderr.strip().splitlines() or [''])[-1], cpu=cpu)
    d = json.loads(p.stdout)
    if d.get('mode') == 'sphere':
        return dict(rc=0, flipped=d['flipped_faces'], obj_flipped=None, uv=d['uv_faces'],
                    sigma=d['log_area_sigma'], p95=d['qc_p95'], cpu=cpu)
    bad, n = obj_flips(out)
    charts = d.get('chart_details', [])
    return dict(rc=0, flipped=d['flipped_faces'], obj_flipped=bad, tris=n, uv=d['uv_faces'],
                seams=[c.get('seams') for c in charts],
                cones=[len(c.get('cones', [])) for c in charts],
                fallback=any(c.get('fallback') for c in charts),
                sigma=round(d['log_area_sigma'], 4), p95=round(d['qc_p95'], 4), cpu=cpu)


def main():
    binary, mdir, odir = sys.argv[1:4]
    os.makedirs(odir, exist_ok=True)
    out = os.path.join(odir, 'sweep.obj')
    total = refused = failed = flipped = 0
    for m in sys.argv[4:]:
        path = os.path.join(mdir, m)
        variants = [[]] + [['--cones', str(k)] for k in range(11)] + [['--cones', 'auto']]
        runs = [v + ['--seams', s] for v in variants for s in ('rigid', 'free')] + [['--sphere']]
        for a in runs:
            r = run(binary, path, a, out)
            total += 1
            if r['rc'] != 0:
                e = r['err']
                if 'needs' in e or 'not supported' in e:
                    refused += 1
                else:
                    failed += 1
            elif r['flipped'] or r.get('obj_flipped'):
                flipped += 1
            print(m, ' '.join(a) or '(default)', json.dumps(r), flush=True)
    print(f'# {total} runs: {refused} refused (input), {failed} failed, '
          f'{flipped} with flipped triangles', flush=True)


if __name__ == '__main__':
    main()
