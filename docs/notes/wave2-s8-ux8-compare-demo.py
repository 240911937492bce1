import json, sys, os, filecmp
a, b = sys.argv[1], sys.argv[2]
skip = {'seconds', 'cpu_seconds', 'timings', 'out'}
worst = [0.0, None]; n = [0]
def walk(x, y, path):
    if isinstance(x, dict):
        assert set(x) == set(y), (path, set(x) ^ set(y))
        for k in x:
            if k in skip: continue
            walk(x[k], y[k], path + '.' + k)
    elif isinstance(x, list):
        assert len(x) == len(y), path
        for i, (p, q) in enumerate(zip(x, y)): walk(p, q, f'{path}[{i}]')
    elif isinstance(x, (int, float)) and not isinstance(x, bool):
        n[0] += 1
        r = abs(x - y) / max(abs(x), abs(y), 1e-300) if x != y else 0.0
        if r > worst[0]: worst[:] = [r, path]
    else:
        assert x == y, (path, x, y)
walk(json.load(open(a + '/demo.json')), json.load(open(b + '/demo.json')), '')
print('numbers compared', n[0], 'worst relative difference', worst)
same = diff = 0
for f in sorted(os.listdir(a)):
    if f in ('demo.json', 'index.html'): continue
    if filecmp.cmp(os.path.join(a, f), os.path.join(b, f), shallow=False): same += 1
    else: diff += 1; print('differs:', f)
print('files identical', same, 'different', diff)
