#!/usr/bin/env python3
"""What a user gets without flags, beside what the benchmarks set by hand: curve_mesh run on
the same case with its defaults and with the hand-set options of curving_bench (or the thesis),
the certified minimum and the median wall time of each (whole program, outputs written; the two
run in turn, and time_ratio is the median of the paired ratios). A
case whose files are absent from ../shared/data, or that needs the CAD component this build
lacks, is skipped with a message.

  defaults_bench.py CURVE_MESH [--runs N] [--data DIR]

One table, and one JSON line per case: {"bench": "defaults", "case", "defaults_min",
"tuned_min", "defaults_s", "tuned_s", "quality_ratio", "time_ratio"}; targets.py holds the
defaults to 2% of the tuned minimum and 1.5x its time.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))

# (case, input file, CAD file or None, defaults' flags, hand-set flags: what the benchmarks set)
CASES = [
    ("sphere_step_p2", "meshopt_sphere_symmetry_linear_tet.msh", "meshopt_Sphere25CSymmetry.stp",
     ["--order", "2"], ["--order", "2", "--group", "7", "--sliding", "20"]),
    ("sphere_step_p3", "meshopt_sphere_symmetry_linear_tet.msh", "meshopt_Sphere25CSymmetry.stp",
     ["--order", "3"], ["--order", "3", "--group", "7", "--sliding", "20"]),
    ("rae2822_step_p3", "meshopt_rae2822_linear_tri.msh", "meshopt_rae2822Square.stp",
     ["--order", "3"], ["--order", "3", "--group", "6", "--group", "7"]),
    ("30p30n_p2", "su2_30p30n_rans_L1_coarse.su2", None,
     [], ["--method", "rbf", "--support-radius", "0.0022"]),
]


def timed(program, arguments, output):
    """The certified minimum, the invalid count and the wall time of one run."""
    start = time.perf_counter()
    done = subprocess.run([program, *arguments, "-o", output, "--json"], capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode not in (0, 2):
        raise RuntimeError(f"{' '.join(arguments)}: exit {done.returncode}: {done.stdout}{done.stderr}")
    report = json.loads(done.stdout)
    return report["min_scaled_jacobian"], report["invalid"], seconds


def compare(program, defaults, tuned, runs):
    """Both flag sets run in turn `runs` times, so that a burst of load on a shared machine falls
    on both alike (run one after the other, a 0.4 s case read 1.7x slower by defaults that took
    1.05x by hand). Returns each one's certified minimum, invalid count and median time, and the
    median of the paired time ratios."""
    with tempfile.TemporaryDirectory() as work:
        output = os.path.join(work, "curved.msh")
        pairs = [(timed(program, defaults, output), timed(program, tuned, output)) for _ in range(runs)]
    d, t = pairs[-1]
    return (d[0], d[1], statistics.median(p[0][2] for p in pairs), t[0], t[1], statistics.median(p[1][2] for p in pairs),
            statistics.median(p[0][2] / p[1][2] for p in pairs))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("program")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--data", default=os.environ.get("MESHMOTION_SHARED_DATA_DIR",
                                                         os.path.join(HERE, "..", "..", "shared", "data")))
    args = parser.parse_args()
    print(f"{'case':18} {'defaults min':>12} {'tuned min':>10} {'ratio':>6} {'defaults s':>10} {'tuned s':>8} {'ratio':>6}"
          "  hand-set flags")
    lines = []
    for name, mesh, cad, defaults, tuned in CASES:
        files = [os.path.join(args.data, f) for f in (mesh, cad) if f]
        if not all(os.path.exists(f) for f in files):
            print(f"{name:18} skipped: {' or '.join(files)} not found")
            continue
        base = [files[0]] + (["--geometry", files[1]] if cad else [])
        try:
            d_min, d_invalid, d_s, t_min, t_invalid, t_s, ratio = compare(args.program, base + defaults, base + tuned,
                                                                         args.runs)
        except RuntimeError as e:
            if cad and "CAD component" in str(e):
                print(f"{name:18} skipped: this build has no CAD component")
                continue
            raise
        line = {"bench": "defaults", "case": name, "defaults_min": d_min, "tuned_min": t_min,
                "defaults_invalid": d_invalid, "tuned_invalid": t_invalid, "defaults_s": d_s, "tuned_s": t_s,
                "quality_ratio": d_min / t_min if t_min > 0 else None, "time_ratio": ratio}
        print(f"{name:18} {d_min:12.4f} {t_min:10.4f} {d_min / t_min:6.3f} {d_s:10.3f} {t_s:8.3f} {ratio:6.2f}"
              f"  {' '.join(tuned)}")
        lines.append(line)
    for line in lines:
        print(json.dumps(line))
    return 0


if __name__ == "__main__":
    sys.exit(main())
