#!/usr/bin/env python3
"""Prints the speed targets of the issues against a run_all.sh results file: this build's
figure, the baseline build's (rows tagged "build": "baseline" by run_all.sh --baseline) and
their ratio, and whether the target is met. A target whose benchmark case did not run (a quick
run skips the full sizes; ../shared/data may be absent) is listed as "not run".

  targets.py RESULTS.jsonl [--json]

--json also prints one {"target": ...} line per target.
"""
import argparse
import json
import math
import statistics
import sys

from plot_results import read_rows


def per_cell_growth(small, large):
    """P1 -> P2 time per cell at the `large` box over the `small` one (1 = linear)."""
    def value(rows, build):
        a = figure(rows, {"bench": "conversion", "case": small}, "median_s", build)
        b = figure(rows, {"bench": "conversion", "case": large}, "median_s", build)
        cells_a = figure(rows, {"bench": "conversion", "case": small}, "cells", build)
        cells_b = figure(rows, {"bench": "conversion", "case": large}, "cells", build)
        if None in (a, b, cells_a, cells_b):
            return None
        return (b / cells_b) / (a / cells_a)
    return value


def distributed_setup_growth(ranks):
    """The distributed RBF's setup on the box (automatic boundary solve) at `ranks` ranks over
    one rank's (1 = no growth with the ranks): run_all.sh runs 1, 2 and 4 ranks in rounds, and
    the k-th run at `ranks` is paired with the k-th at 1 rank; the median of the rounds' ratios."""
    def value(rows, build):
        def setups(r):
            return [row["setup_seconds"] for row in rows
                    if row.get("build", "current") == build and row.get("method") == "rbf" and row.get("ranks") == r
                    and str(row.get("case", "")).startswith("box") and "setup_seconds" in row]
        ratios = [many / one for one, many in zip(setups(1), setups(ranks))]
        return statistics.median(ratios) if ratios else None
    return value


def defaults_against_tuned(field, worst):
    """The worst over the defaults_bench cases of the defaults' figure over the hand-set one
    (`worst`: min or max)."""
    def value(rows, build):
        ratios = [row[field] for row in rows
                  if row.get("build", "current") == build and row.get("bench") == "defaults" and row.get(field) is not None]
        return worst(ratios) if ratios else None
    return value


def plugin_against_laplacian(rows, build):
    """The worst over the openfoam_plugin cases of the largest angle the plugin's defaults keep
    valid over displacementLaplacian's."""
    ours, peer = {}, {}
    for row in rows:
        if row.get("build", "current") != build or row.get("bench") != "openfoam_plugin":
            continue
        if row["solver"] == "displacementLaplacian":
            peer[row["case"]] = row["largest_valid_deg"]
        elif row["options"] == "(defaults)":
            ours[row["case"]] = row["largest_valid_deg"]
    ratios = [ours[case] / peer[case] for case in ours if peer.get(case)]
    return min(ratios) if ratios else None


def python_mpi_overhead(rows, build):
    """The worst Python / C++ ratio per call of python_overhead.py's MPI rows (moves and reverse
    derivatives, every rank count)."""
    ratios = [row["ratio"] for row in rows
              if row.get("build", "current") == build and row.get("benchmark") == "python_overhead"
              and row.get("case") in ("mpi_move_into", "mpi_derivative_reverse")]
    return max(ratios) if ratios else None


def rbf_gradient_error(rows, build):
    """The worst relative error of the RBF gradient against finite differences over
    conditioning_bench.py's rows with the default condition_limit (every radius); infinite when
    one of them failed to set up, warp or differentiate."""
    errors = [row.get("derivative_error") if row.get("setup") != "error" and row.get("warp") == "ok" else None
              for row in rows
              if row.get("build", "current") == build and row.get("bench") == "conditioning"
              and row.get("condition_limit") == "default"]
    if not errors:
        return None
    return max(float("inf") if e is None else e for e in errors)


# (name, rows' fields to match or a function of (rows, build), field, "<=" or ">=", limit, unit)
def setups_per_doubling(rows, build):
    """rbf_bench's one-setup run: set-ups again over the doublings of the motion past what the
    setup's radius covered (at most one each)."""
    for row in rows:
        if row.get("build", "current") == build and row.get("case") == "one_setup_move_cost":
            return row["setups_again"] / max(1.0, math.ceil(row["doublings"]))
    return None


def plate_turn(field, ranks):
    """plate_turn_bench.py's defaults: the worst step's `field` at `ranks` ranks."""
    def value(rows, build):
        found = [row[field] for row in rows if row.get("build", "current") == build and row.get("bench") == "plate_turn"
                 and row.get("options") == "(defaults)" and row.get("ranks") == ranks and field in row]
        return max(found) if found else None
    return value


def plugin_large_against_laplacian(case, field):
    """openfoam_plugin.sh's large `case`: the serial defaults' `field` over displacementLaplacian's."""
    def value(rows, build):
        def pick(solver, options=None):
            found = [row[field] for row in rows if row.get("build", "current") == build and row.get("bench") == "openfoam_plugin_large"
                     and row.get("case") == case and row.get("solver") == solver and row.get("ranks") == 1
                     and (options is None or row.get("options") == options) and field in row]
            return found[-1] if found else None
        ours, peer = pick("meshmotion", "(defaults)"), pick("displacementLaplacian")
        return ours / peer if ours is not None and peer else None
    return value


def plugin_large_targets(case, label):
    """Issue 69's targets on one of openfoam_plugin.sh's large cases (its JSON `case`, and how the
    table names it): the defaults' time and memory over displacementLaplacian's, 2 ranks against
    serial, and sle's time."""
    row = {"bench": "openfoam_plugin_large", "case": case}
    return [
        (f"OpenFOAM plugin, {label}, 20 steps, defaults: wall / displacementLaplacian's",
         {**row, "options": "(defaults)"}, "wall_ratio", "<=", 1.0, "x"),
        (f"OpenFOAM plugin, {label}, 20 steps, defaults: peak memory / displacementLaplacian's",
         {**row, "options": "(defaults)"}, "memory_ratio", "<=", 2.0, "x"),
        (f"OpenFOAM plugin, {label}, decomposed in 2, defaults: largest distance from the serial points",
         {**row, "ranks": 2}, "largest_difference_from_serial", "<=", 1e-10, "m"),
        (f"OpenFOAM plugin, {label}, decomposed in 2, defaults: wall / the serial run's",
         {**row, "ranks": 2}, "wall_ratio_to_serial", "<=", 1.0, "x"),
        (f"OpenFOAM plugin, {label}, 20 steps, sle: wall / displacementLaplacian's",
         {**row, "options": "method sle"}, "wall_ratio", "<=", 2.0, "x"),
    ]


def wing_targets(order):
    """Issue 71's swept wing at one order: the defaults' invalid cells, and their minimum and time
    over Gmsh's HighOrderOptimize 2 on the same mesh (wing_vs_gmsh.py)."""
    row = {"bench": "wing_vs_gmsh", "case": "target", "order": order}
    return [
        (f"swept wing on its STEP model, P{order}, defaults: invalid cells", row, "invalid", "<=", 0, "cells"),
        (f"swept wing, P{order}: defaults' min / Gmsh HighOrderOptimize 2's", row, "min_over_gmsh", ">=", 1.0, "x"),
        (f"swept wing, P{order}: curve_mesh's whole run / Gmsh HighOrderOptimize 2's", row, "time_over_gmsh", "<=", 1.0,
         "x"),
    ]


TARGETS = [
    ("P1->P2 30P30N quads (median)", {"bench": "conversion", "case": "30p30n-quads"}, "median_s", "<=", 0.015, "s"),
    ("P1->P2 30P30N quads (first call)", {"bench": "conversion", "case": "30p30n-quads"}, "first_s", "<=", 0.015, "s"),
    ("P1->P2 tets 0.66M -> 5.3M cells, per cell", per_cell_growth("box-tet4-48", "box-tet4-96"), None, "<=", 1.5, "x"),
    ("P1->P2 hexes 1M -> 5.4M cells, per cell", per_cell_growth("box-hex8-100", "box-hex8-175"), None, "<=", 1.5, "x"),
    ("msh 4.1 binary write", {"bench": "io", "case": "msh4.1-binary"}, "write_mb_s", ">=", 500, "MB/s"),
    ("msh 4.1 binary read", {"bench": "io", "case": "msh4.1-binary"}, "read_mb_s", ">=", 500, "MB/s"),
    ("msh 4.1 ASCII read", {"bench": "io", "case": "msh4.1-ascii"}, "read_mb_s", ">=", 150, "MB/s"),
    ("msh 2.2 ASCII read", {"bench": "io", "case": "msh2.2-ascii"}, "read_mb_s", ">=", 150, "MB/s"),
    ("SU2 ASCII read", {"bench": "io", "case": "su2-ascii"}, "read_mb_s", ">=", 150, "MB/s"),
    ("curve_mesh 30P30N, whole program", {"bench": "program", "case": "curve_mesh-30p30n"}, "median_s", "<=", 0.2, "s"),
    # A 2D case stored in 3D moves as its section by default: half the 3D time or less (0.1 when
    # found; 1 when the detection fails and it moves in 3D).
    ("move_mesh airFoil2D le, as its section / in 3D", {"bench": "program", "case": "move_mesh-airfoil2d-le"}, "ratio",
     "<=", 0.5, "x"),
    ("3D RBF setup, box 2M nodes (CHOLMOD)", {"case": "box rbf setup", "nodes": 2048383}, "supernodal_setup_seconds",
     "<=", 3.0, "s"),
    ("bump fine level, whole pipeline (thesis radius)", {"bench": "bump3d", "level": "fine", "case": "rbf thesis r"},
     "seconds", "<=", 4.0, "s"),
    ("distributed RBF box setup, 2 ranks / 1 rank", distributed_setup_growth(2), None, "<=", 1.2, "x"),
    ("distributed RBF box setup, 4 ranks (2 per core) / 1 rank", distributed_setup_growth(4), None, "<=", 1.2, "x"),
    ("defaults' minimum / hand-set's, worst case", defaults_against_tuned("quality_ratio", min), None, ">=", 0.98, "x"),
    ("defaults' time / hand-set's, worst case", defaults_against_tuned("time_ratio", max), None, "<=", 1.5, "x"),
    ("OpenFOAM plugin defaults' largest valid angle / displacementLaplacian's, worst case", plugin_against_laplacian,
     None, ">=", 1.0, "x"),
    ("plate turned to 180 deg in a held box from one setup, defaults: invalid cells, worst step", plate_turn("invalid", 1),
     None, "<=", 0, "cells"),
    ("plate turned to 180 deg, 2 ranks: largest distance from the serial points", plate_turn("largest_difference_from_serial", 2),
     None, "<=", 1e-10, ""),
    # One policy for every front end: the programs give Warp's time-loop points.
    ("plate, move_mesh --steps 12 to 180 deg: largest distance from Warp's points",
     {"bench": "plate_turn", "options": "move_mesh --steps 12 (defaults)"}, "largest_difference_from_warp", "<=", 1e-10, ""),
    ("plate, move_mesh_mpi on 2 ranks to 90 deg: largest distance from Warp's points",
     {"bench": "plate_turn", "options": "move_mesh_mpi -n 2 (defaults)"}, "largest_difference_from_warp", "<=", 1e-10, ""),
    *plugin_large_targets("block3d_79k", "79k cells"),
    *plugin_large_targets("terrain_72k", "terrain 72k cells, deforming"),
    ("OpenFOAM plugin, terrain 72k cells, defaults: last non-orthogonality / displacementLaplacian's",
     plugin_large_against_laplacian("terrain_72k", "non_orthogonality"), None, "<=", 1.0, "x"),
    ("OpenFOAM plugin, terrain 72k cells, defaults: last max skewness / displacementLaplacian's",
     plugin_large_against_laplacian("terrain_72k", "skewness"), None, "<=", 1.0, "x"),
    # A time loop's 3D elasticity: the defaults (CG on the nodes' factorization) against the
    # coupled factorization they replaced, setup and 20 moves. A body's motion (two fields)
    # must cost less; a motion that keeps changing shape at most twice (the iterations add up
    # to the factorization's estimated cost, then it is factorized: the rental's bound).
    ("sle time loop, 3D graded box, turning wall: defaults' time / the coupled factorization's",
     {"case": "sle time loop", "motion": "turning wall", "solver": "defaults"}, "ratio", "<=", 1.0, "x"),
    ("sle time loop, 3D graded box, travelling bump: defaults' time / the coupled factorization's",
     {"case": "sle time loop", "motion": "travelling bump", "solver": "defaults"}, "ratio", "<=", 2.0, "x"),
    ("Python over MPI / the C++ distributed mover, per call, worst rank count", python_mpi_overhead, None, "<=", 1.05,
     "x"),
    ("RBF gradient on a RANS grid, default limit, worst radius: error", rbf_gradient_error, None, "<=", 1e-6, ""),
    ("one RBF setup, 10 moves turning a ring's whole boundary 56 deg: invalid cells, defaults",
     {"case": "one_setup_many_moves", "options": "(defaults)"}, "invalid", "<=", 0, ""),
    ("one RBF setup: a move without a set-up again / the same radius given", {"case": "one_setup_move_cost"}, "ratio",
     "<=", 1.2, "x"),
    ("one RBF setup: set-ups again per doubling of the motion", setups_per_doubling, None, "<=", 1.0, ""),
    ("PU RBF, 1M centres and 10M nodes: peak", {"bench": "pu_rbf", "mesh": "flat-707", "method": "pu"}, "peak_mb",
     "<=", 24576, "MB"),
    ("curve_mesh demo P5: min scaled Jacobian", {"bench": "program", "case": "curve_mesh-demo-p5"}, "min_scaled_jacobian",
     ">=", 0.5, ""),
    ("curve_mesh demo P6: min scaled Jacobian", {"bench": "program", "case": "curve_mesh-demo-p6"}, "min_scaled_jacobian",
     ">=", 0.5, ""),
    ("curve_mesh demo P8: min scaled Jacobian", {"bench": "program", "case": "curve_mesh-demo-p8"}, "min_scaled_jacobian",
     ">=", 0.5, ""),
    *wing_targets(2),
    *wing_targets(3),
    *wing_targets(4),
    ("curve_mesh demo P6 / P4, whole program", {"bench": "program", "case": "curve_mesh-demo-p6"}, "ratio_to_p4", "<=",
     5.0, "x"),
]


def figure(rows, match, field, build):
    """The last matching row's field for one build ("current" rows carry no build field)."""
    value = None
    for row in rows:
        if row.get("build", "current") != build or field not in row:
            continue
        if all(row.get(k) == v for k, v in match.items()):
            value = row[field]
    return value


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("results")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    rows = read_rows(args.results, baseline=True)
    print(f"{'target':40} {'limit':>12} {'this build':>12} {'baseline':>12} {'ratio':>7}  met")
    lines = []
    for name, match, field, sense, limit, unit in TARGETS:
        if callable(match):
            now, before = match(rows, "current"), match(rows, "baseline")
        else:
            now, before = figure(rows, match, field, "current"), figure(rows, match, field, "baseline")
        if now is None:
            print(f"{name:40} {sense + ' ' + format(limit, 'g') + ' ' + unit:>12} {'not run':>12}")
            lines.append({"target": name, "limit": limit, "unit": unit, "run": False})
            continue
        met = now <= limit if sense == "<=" else now >= limit
        ratio = now / before if before else None
        print(f"{name:40} {sense + ' ' + format(limit, 'g') + ' ' + unit:>12} {now:12.4g} "
              f"{(format(before, '12.4g') if before is not None else 'n/a'):>12} "
              f"{(format(ratio, '7.3f') if ratio is not None else 'n/a'):>7}  {'yes' if met else 'NO'}")
        lines.append({"target": name, "limit": limit, "unit": unit, "run": True, "value": now, "baseline": before,
                      "ratio": ratio, "met": met})
    if args.json:
        for line in lines:
            print(json.dumps(line))
    return 0


if __name__ == "__main__":
    sys.exit(main())
