#!/usr/bin/env python3
"""What a body's travel through the mesh costs in accuracy, and what the default's
held lumped rows cost of it.

A free PS block (1 x 1, E = 1e4, rho = 1, 4 x 4 particles per block of 0.25)
breathes, started with the velocity v = v0 + G (x - c), G = I (1/s), in a 20 x 4
block mesh, and travels with v0 = (5, 0) m/s or rests (v0 = 0), to t = 0.2 (about
25 periods; the moving body crosses 4 elements). Its strain energy over time is
compared with that of the same body resting on a mesh refined twice (blocks of
0.125, 4 x 4 particles per block: 4 times the particles), with the default mass:
the RMS difference over the run relative to the reference's largest strain
energy, and the strain energy's first and eighth peaks (the breathing's
amplitude). The block also rests moved off the mesh's lines by (0.05, 0.025)
and (0.1, 0.05), and travels at 1 m/s. Prints a row per run: mass strategy, v0, error, peaks, the rows
lumped at the end and the functions the system held.

    python3 benches/travel_accuracy.py [--cli target/release/mpm-cli]

docs/stability.md, "Releasing the held rows of a travelling body".
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile


def scene(v0, blocks_per_unit, mass, shift=0.0):
    """The block, moved by (shift, shift / 2) off the mesh's lines."""
    x0, y0 = 2.0 + shift, 1.5 + shift / 2
    return f"""name = "breathing-block"
dim = 2
basis = "ps"
mass = "{mass}"
[mesh]
kind = "blocks"
x = [0.0, 20.0]
y = [0.0, 4.0]
blocks = [{20 * blocks_per_unit}, {4 * blocks_per_unit}]
[material]
young = 1e4
poisson = 0.3
density = 1.0
[[body]]
min = [{x0}, {y0}]
max = [{x0 + 1.0}, {y0 + 1.0}]
per_block = [4, 4]
[initial_velocity]
kind = "linear"
value = [{v0}, 0.0]
origin = [{x0 + 0.5}, {y0 + 0.5}]
gradient = [[1.0, 0.0], [0.0, 1.0]]
[time]
courant = 0.25
t_end = 0.2
"""


def run(cli, text, workdir, name):
    path = os.path.join(workdir, name + ".toml")
    with open(path, "w") as f:
        f.write(text)
    out = os.path.join(workdir, name)
    subprocess.run(
        [cli, "run", path, "--out", out, "--diag-every", "0", "--threads", "1"],
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    with open(os.path.join(out, "diagnostics.csv")) as f:
        rows = list(csv.DictReader(f))
    return rows


def series(rows):
    return [float(r["time"]) for r in rows], [float(r["strain"]) for r in rows]


def interpolate(t, ts, vs):
    """Linear interpolation of (ts, vs) at t (ts ascending)."""
    lo, hi = 0, len(ts) - 1
    if t <= ts[0]:
        return vs[0]
    if t >= ts[-1]:
        return vs[-1]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if ts[mid] <= t:
            lo = mid
        else:
            hi = mid
    w = (t - ts[lo]) / (ts[hi] - ts[lo])
    return (1 - w) * vs[lo] + w * vs[hi]


def peaks(s):
    top = max(s)
    return [
        s[i]
        for i in range(1, len(s) - 1)
        if s[i] > s[i - 1] and s[i] >= s[i + 1] and s[i] > 0.3 * top
    ]


def row(rows, ref_t, ref_s):
    """The error against the reference, the first and eighth strain-energy peaks
    (x 100) and the rows lumped at the end, of a run's diagnostics rows."""
    t, s = series(rows)
    err = math.sqrt(
        sum((si - interpolate(ti, ref_t, ref_s)) ** 2 for ti, si in zip(t, s)) / len(s)
    ) / max(ref_s)
    p = peaks(s)
    return (
        f"{err:14.3e}  {p[0] * 100:6.3f}  {p[7] * 100:6.3f}"
        f"  {rows[-1]['lumped_rows']}/{rows[-1]['active']}"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default="target/release/mpm-cli")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as workdir:
        ref_t, ref_s = series(run(args.cli, scene(0.0, 8, "default"), workdir, "reference"))
        print("mass      v0  shift  error(RMS/max)  peak 1  peak 8  lumped/held at the end")
        for mass in ("default", "lumped"):
            for v0, shift in ((0.0, 0.0), (5.0, 0.0), (1.0, 0.0), (0.0, 0.05), (0.0, 0.1)):
                rows = run(args.cli, scene(v0, 4, mass, shift), workdir, f"{mass}-{v0}-{shift}")
                print(f"{mass:8s} {v0:3.0f}  {shift:5.2f}  " + row(rows, ref_t, ref_s))
        rows = run(args.cli, scene(5.0, 8, "default"), workdir, "reference-moving")
        print("refined   5   0.00  " + row(rows, ref_t, ref_s))
        print(f"(reference at rest: peaks {peaks(ref_s)[0] * 100:.3f}, {peaks(ref_s)[7] * 100:.3f}; strain energies x 100)")


if __name__ == "__main__":
    sys.exit(main())
