#!/usr/bin/env python3
"""psmpm against a peer MPM step, particle-steps per second, side by side in one run.

Runs `mpm-cli throughput` (the B5a column refined to about N particles, 16 per
triangle) and the peer `peer_mpm88.py` (Taichi MLS-MPM, quadratic B-splines on a
dense grid, neo-Hookean, f64) at the same particle count, alternating them ROUNDS
times so that the load of a shared machine falls on both alike, and prints the
medians and the ratios psmpm / peer per variant.

    python3 benches/peer_ratio.py [--particles 100352] [--rounds 3] [--threads 1]
        [--peer ../shared/tools/peer_mpm88.py] [--cli target/release/mpm-cli]

Needs `pip install taichi` for the peer (the peer script installs it if missing).
"""
import argparse
import json
import statistics
import subprocess
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--particles", type=int, default=100352)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    # As many steps as the peer times (100, after its 20 of warm-up): over 10, the
    # first step and the watch's first checks of the critical step (at steps 4 and
    # 12, then every 32 at most) weigh more than in a run (docs/performance.md,
    # "Against a peer").
    ap.add_argument("--steps", type=int, default=100, help="psmpm steps per variant")
    ap.add_argument("--peer", default="../shared/tools/peer_mpm88.py")
    ap.add_argument("--cli", default="target/release/mpm-cli")
    args = ap.parse_args()
    # The peer's grid: half a particle per cell, its documented 1e5 set-up (448
    # cells per side for 100 352 particles).
    n_grid = max(16, int(round((args.particles * 2.0) ** 0.5)))
    ours = {}
    peer = []
    for r in range(args.rounds):
        out = subprocess.run(
            [args.cli, "throughput", "--sizes", str(args.particles), "--steps",
             str(args.steps), "--threads", str(args.threads), "--format", "json"],
            check=True, capture_output=True, text=True).stdout
        for m in json.loads(out)["measurements"]:
            ours.setdefault(m["variant"], []).append(m["particle_steps_per_second"])
        line = subprocess.run(
            [sys.executable, args.peer, "--n-grid", str(n_grid), "--particles",
             str(args.particles), "--f64", "--material", "neohookean", "--threads",
             str(args.threads), "--steps", "100"],
            check=True, capture_output=True, text=True).stdout.strip().splitlines()[-1]
        peer.append(json.loads(line)["particle_steps_per_s"])
        print(f"round {r + 1}: peer {peer[-1]:.3g}, "
              + ", ".join(f"{k} {v[-1]:.3g}" for k, v in ours.items()), file=sys.stderr)
    p = statistics.median(peer)
    print(f"peer (Taichi MLS-MPM, n_grid {n_grid}, {args.particles} particles, f64, "
          f"{args.threads} thread(s)): {p:.3g} particle-steps/s (median of {args.rounds})")
    print(f"{'variant':>14}  {'particle-steps/s':>16}  {'ratio to peer':>13}")
    for k, v in ours.items():
        m = statistics.median(v)
        print(f"{k:>14}  {m:16.3g}  {m / p:13.2f}")


if __name__ == "__main__":
    main()
