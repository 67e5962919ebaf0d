"""Timings of the Python package (scripts/python-test.sh builds it; run with its venv):
1,000,000 platform points, every branch and the working branch alone; the path follower on
100,000 tool poses; the per-call overhead of a one-row call. Best of 3, wall clock.

    target/py-venv/bin/python crates/verne-py/bench/bench.py
"""

import time

import numpy as np

import verne


def best(f, repeat=3):
    t = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        t.append(time.perf_counter() - t0)
    return min(t)


m = verne.Machine.default()
rng = np.random.default_rng(1)
n = 1_000_000
pts = np.column_stack(
    [rng.uniform(-300, 300, n), rng.uniform(-300, 300, n), rng.uniform(700, 1300, n)]
)
t_all = best(lambda: verne.module_ik(m, pts))
t_compact = best(lambda: verne.module_ik_compact(m, pts))
t_work = best(lambda: verne.module_ik_working(m, pts))
k = 100_000
s = np.linspace(0, 20 * np.pi, k)
tips = np.column_stack([80 * np.cos(s), 80 * np.sin(s), 40 + 10 * np.sin(3 * s)])
tilt = np.radians(15)
axes = np.column_stack(
    [np.sin(tilt) * np.cos(s), np.sin(tilt) * np.sin(s), np.full(k, np.cos(tilt))]
)
t_path = best(lambda: verne.ik_path(m, tips, axes))
one = pts[:1].copy()
reps = 20_000
t0 = time.perf_counter()
for _ in range(reps):
    verne.module_ik_working(m, one)
t_one = (time.perf_counter() - t0) / reps
print(f"module_ik, every branch, {n:,} points: {t_all:.3f} s")
print(f"module_ik_compact, every branch, {n:,} points: {t_compact:.3f} s")
print(f"module_ik_working, {n:,} points: {t_work:.3f} s")
print(f"ik_path, {k:,} tool poses: {t_path:.3f} s ({k / t_path:,.0f} rows/s)")
print(f"module_ik_working, one point per call: {t_one * 1e6:.2f} us per call")
