#!/usr/bin/env python3
"""A case's error over a range of time steps, every mass strategy at the same steps.

Runs `mpm-cli run SCENE --mass M --dt DT` for every strategy M of --mass and every
DT of --dt (FIRST:LAST:COUNT, evenly spaced, or a comma-separated list), reads the
error of the scene's reference from the JSON summary, and prints one row per step
and then, per strategy, the mean, median, smallest and largest error and how often
it is the lowest of the strategies at a step.

Why: with `courant` in a scene each strategy runs at a step set by its own critical
step, so two strategies whose critical steps differ by 0.1 % run at different steps,
and an error that depends on the path to equilibrium (the rate form of the stress
update) moves with the step. Comparing at the same steps, over a range, separates
the strategy from that noise.

    python3 benches/dt_sweep.py --scene scenes/stability/b5c-1x4.toml \
        --mass default,partial,lumped --dt 3.6e-4:4.5e-4:10

Every step must lie below every strategy's critical step (`mpm-cli run` refuses
one above it).
"""
import argparse
import json
import statistics
import subprocess
import sys


def steps(spec):
    if ":" in spec:
        first, last, count = spec.split(":")
        first, last, count = float(first), float(last), int(count)
        if count < 1:
            sys.exit("--dt FIRST:LAST:COUNT needs COUNT >= 1")
        if count == 1:
            return [first]
        return [first + (last - first) * k / (count - 1) for k in range(count)]
    return [float(s) for s in spec.split(",")]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", required=True)
    ap.add_argument("--mass", default="default,partial,lumped")
    ap.add_argument("--dt", required=True, help="FIRST:LAST:COUNT or DT1,DT2,...")
    ap.add_argument("--cli", default="target/release/mpm-cli")
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    masses = args.mass.split(",")
    errors = {m: [] for m in masses}
    measure = None
    print("dt," + ",".join(masses))
    for dt in steps(args.dt):
        row = []
        for m in masses:
            run = subprocess.run(
                [args.cli, "run", args.scene, "--mass", m, "--dt", repr(dt),
                 "--diag-every", "0", "--format", "json", "--threads",
                 str(args.threads)],
                capture_output=True, text=True)
            out = run.stdout
            if run.returncode != 0 or "{" not in out:
                sys.exit(f"{m} at dt = {dt}: the run failed:\n{run.stderr}{out}")
            summary = json.loads(out[out.index("{"):])
            if summary.get("error") is None:
                sys.exit(f"{args.scene} has no reference error to compare")
            measure = summary.get("error_measure")
            errors[m].append(summary["error"])
            row.append(f"{summary['error']:.5e}")
        print(f"{dt:.5e}," + ",".join(row), flush=True)
    n = len(errors[masses[0]])
    wins = {m: 0 for m in masses}
    for k in range(n):
        best = min(masses, key=lambda m: errors[m][k])
        wins[best] += 1
    print(f"\n{measure} over {n} steps")
    print("mass,mean,median,min,max,lowest_at")
    for m in masses:
        e = errors[m]
        print(f"{m},{statistics.mean(e):.5e},{statistics.median(e):.5e},"
              f"{min(e):.5e},{max(e):.5e},{wins[m]}")


if __name__ == "__main__":
    main()
