#!/usr/bin/python3
"""The RBF's conditioning on a RANS grid (issue 34): the RAE2822 hybrid mesh (../shared/data,
a blunt trailing edge whose nodes are micrometres apart) warped by Python's Warp at the
default radius and at 2, 20, 100 and 1000 chords, with the default condition_limit (systems
thinned past 1e10) beside condition_limit=0 (the system as it is).

Each row: the condition estimate, the centres thinned, the setup time, whether a non-smooth
surface change (the upper surface's last fifth lifted by a ramp, the lower one held, so the
trailing edge's two sides part) warps without error, and the relative error of the gradient
(warp_derivative) against central finite differences (Warp.verify_derivative). One JSON line
per row; targets.py takes the worst error of the default rows.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/conditioning_bench.py [--data ../shared/data]
"""

import argparse
import json
import pathlib
import sys
import time
import warnings

import numpy as np

import meshmotion as mm

CASE = "su2_rae2822_rans_hybrid.su2"


def row(mesh, radius, limit):
    options = {"support_radius": radius}
    if limit is not None:
        options["condition_limit"] = limit
    out = {"bench": "conditioning", "case": "rae2822-rans", "radius": radius or "default",
           "condition_limit": "default" if limit is None else limit}
    start = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # the condition is in the row
            w = mm.Warp(mesh, design=["AIRFOIL"], fixed=["FARFIELD"], **options)
    except mm.SolverError as e:
        out.update(setup="error", error=str(e))
        return out
    out.update(setup_s=time.perf_counter() - start, condition=w.condition,
               thinned=int(w._mover.stats["thinned_centres"]))
    surface = w.surface_coordinates()
    x, y = surface[:, 0], surface[:, 1]
    ramp = np.where(y > 0.0, 2e-3 * np.clip((x - 0.8) / 0.2, 0.0, 1.0), 0.0)
    w.set_surface_coordinates(np.column_stack([x, y + ramp]))
    try:
        moved = w.warp()
        out["warp"] = "ok" if np.all(np.isfinite(moved)) else "non-finite"
    except mm.SolverError as e:
        out.update(warp="error", error=str(e))
    w.set_surface_coordinates(surface)
    try:
        out["derivative_error"] = w.verify_derivative(verbose=False)
    except mm.SolverError as e:
        out.update(derivative_error=None, error=str(e))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", default=str(pathlib.Path(__file__).resolve().parents[2] / "shared" / "data"))
    args = parser.parse_args()
    file = pathlib.Path(args.data) / CASE
    if not file.exists():
        print(f"conditioning_bench.py: {file} is absent: skipped", file=sys.stderr)
        return 0
    mesh = mm.read_mesh(str(file))
    rows = [row(mesh, radius, limit) for radius in (0.0, 2.0, 20.0, 100.0, 1000.0) for limit in (None, 0.0)]
    print(f"{'radius':>8} {'limit':>8} {'condition':>10} {'thinned':>8} {'setup s':>8} {'warp':>6} {'gradient error':>15}")
    for r in rows:
        condition = format(r["condition"], ".2e") if "condition" in r else "-"
        error = r.get("derivative_error")
        print(f"{str(r['radius']):>8} {str(r['condition_limit']):>8} {condition:>10} {r.get('thinned', '-'):>8} "
              f"{(format(r['setup_s'], '.3f') if 'setup_s' in r else 'error'):>8} {r.get('warp', '-'):>6} "
              f"{(format(error, '.2e') if error is not None else 'error'):>15}")
    for r in rows:
        print(json.dumps(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
