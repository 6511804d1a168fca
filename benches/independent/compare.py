#!/usr/bin/env python3
"""Runs psmpm (`mpm-cli run`) and the independent implementation (b4.py) on the
same B4 case (the mesh psmpm writes, the same particles) and prints both RMS
position errors (paper eq. (47)), their relative difference, and the largest
differences of the final particle positions, velocities and stresses.

    python3 benches/independent/compare.py --basis ps,pl --edge-length 0.25 \\
        --particles 256 --t-end 0.02

With --psmpm-dir DIR, no mpm-cli run: DIR holds the output of an earlier
`mpm-cli run ... --out DIR` of the same case (summary.json, mesh.vtu, frames);
the basis, particle count and steps are taken from it (used by
tests/cli/independent.rs).
"""

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
sys.dont_write_bytecode = True  # no __pycache__ beside the sources
import b4  # noqa: E402

LADDER = os.path.join(ROOT, "scenes", "studies", "b4-ladder.toml")


def write_scene(path, edge_length, particles):
    """The ladder scene with another edge length and particle count."""
    text = open(LADDER).read()
    text, n1 = re.subn(r"(?m)^count = \[256, 256\]$", f"count = [{particles}, {particles}]", text)
    text, n2 = re.subn(r"(?m)^edge_length = 0\.25$", f"edge_length = {edge_length!r}", text)
    assert n1 == 1 and n2 == 1, "the ladder scene changed: update compare.py"
    with open(path, "w") as f:
        f.write(text)


def run_psmpm(cli, scene, basis, steps, out, split="incentre"):
    cmd = [
        cli, "run", scene, "--basis", basis, "--split", split, "--t-end", repr(steps * b4.DT),
        "--out", out, "--out-every", "0", "--threads", "1", "--overwrite", "--diag-every", "0",
    ]
    clock = time.time()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.time() - clock


def frames(out):
    """(time, file) of the frames of particles.pvd, in order."""
    root = ET.parse(os.path.join(out, "particles.pvd")).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def read_frame(out, name):
    import meshio

    m = meshio.read(os.path.join(out, name))
    d = m.point_data
    return dict(
        x=m.points[:, :2],
        v=d["velocity"][:, :2],
        u=d["displacement"][:, :2],
        sigma=d["stress"].reshape(-1, 3, 3)[:, :2, :2],
        vol=d["volume"],
        mass=d["mass"],
    )


def compare_dir(out, split="incentre"):
    """Runs b4.py on the case of psmpm's output DIR and compares (`split`: the
    independent run's PS split points; psmpm's are those of its run)."""
    summary = json.load(open(os.path.join(out, "summary.json")))
    assert summary["scene"] == "b4-ladder" and summary["mass"] == "consistent", summary
    basis_name, steps = summary["basis"], summary["steps"]
    fr = frames(out)
    first, last = read_frame(out, fr[0][1]), read_frame(out, fr[-1][1])
    n = int(round(math.sqrt(summary["particles"])))
    x0, vol0 = b4.lattice(n)
    # the same particles: positions, volumes and masses at t = 0, bit for bit
    assert np.array_equal(first["x"], x0), "particle positions differ at t = 0"
    assert np.array_equal(first["vol"], vol0), "particle volumes differ at t = 0"
    assert np.allclose(first["mass"], b4.RHO0 * vol0, rtol=1e-15, atol=0), "particle masses differ"
    assert abs(summary["dt"] - b4.DT) < 1e-20 * b4.DT, summary["dt"]
    assert abs(fr[-1][0] - steps * b4.DT) < 1e-9 * b4.DT, (fr[-1][0], steps)
    mesh = b4.read_mesh(os.path.join(out, "mesh.vtu"))
    basis = b4.make_basis(basis_name, mesh, split)
    assert basis.n == summary["functions"], (basis.n, summary["functions"])
    clock = time.time()
    rms, state = b4.simulate(basis, mesh, x0, vol0, steps)
    secs = time.time() - clock
    ref = summary["error"]
    smax = np.abs(last["sigma"]).max()
    return dict(
        basis=basis_name,
        split=split if basis_name == "ps" else None,
        functions=basis.n,
        particles=len(x0),
        steps=steps,
        error_psmpm=ref,
        error_independent=rms,
        error_rel_diff=abs(rms - ref) / abs(ref),
        digits=-math.log10(max(abs(rms - ref) / abs(ref), 1e-17)),
        max_position_diff=float(np.abs(state["x"] - last["x"]).max()),
        max_displacement=float(np.abs(last["u"]).max()),
        max_velocity_diff=float(np.abs(state["v"] - last["v"]).max()),
        max_velocity=float(np.abs(last["v"]).max()),
        max_stress_rel_diff=float(np.abs(state["sigma"] - last["sigma"]).max() / smax),
        max_volume_rel_diff=float(np.abs(state["vol"] - last["vol"]).max() / last["vol"].max()),
        seconds_psmpm=summary.get("seconds"),
        seconds_independent=secs,
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--psmpm-dir", help="compare against this existing `mpm-cli run --out` directory")
    ap.add_argument("--basis", default="ps,pl")
    ap.add_argument("--edge-length", type=float, default=0.25)
    ap.add_argument("--particles", type=int, default=256, help="N × N particles")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--steps", type=int)
    g.add_argument("--t-end", type=float, default=0.02)
    ap.add_argument("--mpm-cli", default=os.path.join(ROOT, "target", "release", "mpm-cli"))
    ap.add_argument("--workdir", help="keep psmpm's output here (default: a temporary directory)")
    ap.add_argument("--json", action="store_true", help="print one JSON object per basis")
    ap.add_argument("--split", choices=["incentre", "centroid"], default="incentre",
                    help="PS split points of both runs (with --psmpm-dir: of the independent run only)")
    args = ap.parse_args()
    if args.psmpm_dir:
        results = [compare_dir(args.psmpm_dir, args.split)]
    else:
        steps = args.steps if args.steps is not None else int(round(args.t_end / b4.DT))
        work = args.workdir or tempfile.mkdtemp(prefix="b4-compare-")
        os.makedirs(work, exist_ok=True)
        scene = os.path.join(work, "scene.toml")
        write_scene(scene, args.edge_length, args.particles)
        results = []
        for name in args.basis.split(","):
            out = os.path.join(work, name)
            run_psmpm(args.mpm_cli, scene, name, steps, out, args.split)
            results.append(compare_dir(out, args.split))
    for r in results:
        if args.json:
            print(json.dumps(r))
        else:
            print(
                f"{r['basis']}: {r['functions']} functions, {r['particles']} particles, {r['steps']} steps\n"
                f"  rms error psmpm       {r['error_psmpm']:.12e}  ({r['seconds_psmpm']:.1f} s)\n"
                f"  rms error independent {r['error_independent']:.12e}  ({r['seconds_independent']:.1f} s)\n"
                f"  relative difference   {r['error_rel_diff']:.2e}  ({r['digits']:.1f} digits)\n"
                f"  max |Δx|              {r['max_position_diff']:.2e}  (max |u| {r['max_displacement']:.2e})\n"
                f"  max |Δv|              {r['max_velocity_diff']:.2e}  (max |v| {r['max_velocity']:.2e})\n"
                f"  max |Δσ| / max |σ|    {r['max_stress_rel_diff']:.2e}\n"
                f"  max |ΔV| / max V      {r['max_volume_rel_diff']:.2e}"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
