#!/usr/bin/env bash
# The plugin inside OpenFOAM's own time loop (moveDynamicMesh, `motionSolver meshmotion;`)
# against OpenFOAM's displacementLaplacian (inverseDistance diffusivity from the body, GAMG to
# 1e-8 with minIter 3) on the same cases: a plate turning in a 2D box and a block turning in a
# 3D box (blockMesh, made here), each turned over 8 steps to its final angle. Per case and
# motion solver: the largest angle of 10, 20, ..., 90 degrees at which every step's mesh passes
# OpenFOAM's own check, the time per step and the peak memory at 30 degrees, and the maximum
# non-orthogonality there. The plugin's row without options (its defaults) is the one that
# counts; `sle` stands beside it. One table, and one JSON line per case and solver:
# {"bench": "openfoam_plugin", "case", "solver", "largest_valid_deg", "seconds_per_step",
#  "max_rss_mb", "non_orthogonality", "time_ratio"} (time_ratio: per step, over
# displacementLaplacian's). Then the cost at a solver's size (issue 69): the 3D block meshed
# with 79,080 hexahedra, turned to 30 degrees over 20 steps once per motion solver: the whole
# run's wall time (setups included), its peak memory, the last step's non-orthogonality and
# whether every step passed the check, with both ratios over displacementLaplacian's
# ({"bench": "openfoam_plugin_large", ..., "wall_seconds", "wall_ratio", "memory_ratio"}).
# The same for a deforming boundary (terrain_72k): a 60 x 40 x 30 box of 72,000 hexahedra (6 x 4
# x 3 km at map coordinates of order 1e6 m) whose flat bottom is raised onto hills of up to
# 440 m over 20 steps (timeVaryingMappedFixedValue, linear in time), its top held and its four
# sides fixedNormalSlip; the Laplacian's diffusivity is quadratic inverseDistance from the
# bottom. Every large case's defaults then run decomposed in two (decomposePar, simple 2 1 1)
# under mpirun with -parallel: the whole run's wall time against the serial run's, the largest
# rank's memory, and the largest distance of the reconstructed points from the serial ones
# (mesh_info --compare; {"bench": "openfoam_plugin_large", "ranks": 2, ...,
# "largest_difference_from_serial", "wall_ratio_to_serial"}).
#
#   benchmarks/openfoam_plugin.sh [BUILD_DIR=build] [WORK_DIR=/tmp/meshmotion_openfoam_plugin]
#
# Skipped with a message when the plugin was not built or Debian's openfoam is missing.
set -euo pipefail
build=$(realpath "${1:-build}")
work=$(realpath -m "${2:-/tmp/meshmotion_openfoam_plugin}")
lib="$build/libmeshmotionFoam.so"
if [[ ! -f "$lib" ]]; then
  echo "openfoam_plugin: $lib not built (Debian's openfoam and the OpenFOAM plugin, docs/openfoam_plugin.md): skipped"
  exit 0
fi
if [[ -f /usr/share/openfoam/etc/bashrc ]]; then
  set +eu  # it reads unset variables and ends on a failing test
  # shellcheck disable=SC1091
  source /usr/share/openfoam/etc/bashrc >/dev/null 2>&1
  set -eu
fi
command -v moveDynamicMesh >/dev/null || { echo "openfoam_plugin: moveDynamicMesh not found (Debian's openfoam): skipped"; exit 0; }
# OpenFOAM runs serial; the plugin's threads would otherwise compete with nothing but noise.
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
# OpenFOAM's applications run as their users start them: without glibc's huge-page heap, which
# run_all.sh exports for the library's own programs (a solver does not set it, and the plugin, a
# library inside the solver's process, cannot). With it, `sle`'s setup on the terrain took
# 9.5-14.4 s against 3.5 s without on this machine on 2026-12-04 (docs/openfoam_plugin.md).
if [[ -n "${GLIBC_TUNABLES:-}" ]]; then
  GLIBC_TUNABLES=$(tr ':' '\n' <<< "$GLIBC_TUNABLES" | grep -v '^glibc\.malloc\.hugetlb=' | paste -sd: - || true)
  if [[ -n "$GLIBC_TUNABLES" ]]; then export GLIBC_TUNABLES; else unset GLIBC_TUNABLES; fi
fi
exec /usr/bin/python3 - "$lib" "$work" "$build" <<'EOF'
import json, math, os, re, shutil, subprocess, sys, time

lib, work, build = sys.argv[1], sys.argv[2], sys.argv[3]
HEADER = "FoamFile { version 2.0; format ascii; class dictionary; object %s; }\n"
STEPS = 8
ANGLES = [10, 20, 30, 45, 60, 75, 90]
REFERENCE = 30  # the angle of the time, memory and non-orthogonality columns

# Blocks of a box around a body: breaks along each axis, the middle block of each axis the body's
# (a hole), `cells` per block and axis. 2D: one layer in z, front and back empty.
CASES = {
    "plate2d": dict(breaks=[(-5, -1, 1, 5), (-5, -0.1, 0.1, 5), (0, 0.1)], cells=[(20, 20, 20), (20, 4, 20), (1,)]),
    "block3d": dict(breaks=[(-3, -1, 1, 3), (-3, -0.3, 0.3, 3), (-3, -0.5, 0.5, 3)],
                    cells=[(8, 12, 8), (8, 4, 8), (8, 6, 8)]),
}
# The cost case: block3d's blocks, 79,080 cells.
BLOCK_79K = dict(breaks=CASES["block3d"]["breaks"], cells=[(15, 22, 15), (15, 8, 15), (15, 11, 15)])
LARGE_STEPS = 20
# The deforming case: a box over terrain, at map coordinates.
TERRAIN_ORIGIN = (452000.0, 5213000.0)
TERRAIN_CELLS = (60, 40, 30)
TERRAIN_SIZE = (6000.0, 4000.0, 3000.0)
SOLVERS = [
    ("meshmotion", "(defaults)", "motionSolverLibs (\"libfvMotionSolvers.so\" \"%s\");\nmotionSolver meshmotion;\nmeshmotionCoeffs { }\n" % lib),
    ("meshmotion", "method sle", "motionSolverLibs (\"libfvMotionSolvers.so\" \"%s\");\nmotionSolver meshmotion;\nmeshmotionCoeffs { method sle; }\n" % lib),
    ("displacementLaplacian", "inverseDistance (body)",
     "motionSolverLibs (\"libfvMotionSolvers.so\");\nmotionSolver displacementLaplacian;\n"
     "displacementLaplacianCoeffs { diffusivity inverseDistance (body); }\n"),
]


def block_mesh(case, spec):
    xs, ys, zs = spec["breaks"]
    two_d = len(zs) == 2
    index = {}
    vertices = []
    for k, z in enumerate(zs):
        for j, y in enumerate(ys):
            for i, x in enumerate(xs):
                index[i, j, k] = len(vertices)
                vertices.append(f"({x} {y} {z})")
    blocks, faces = [], {"outer": [], "body": [], "frontAndBack": []}
    nk = 1 if two_d else 3
    hole = (1, 1, 0 if two_d else 1)
    for k in range(nk):
        for j in range(3):
            for i in range(3):
                if (i, j, k) == hole:
                    continue
                v = [index[i, j, k], index[i + 1, j, k], index[i + 1, j + 1, k], index[i, j + 1, k],
                     index[i, j, k + 1], index[i + 1, j, k + 1], index[i + 1, j + 1, k + 1], index[i, j + 1, k + 1]]
                nz = spec["cells"][2][0] if two_d else spec["cells"][2][k]
                blocks.append(f"hex ({' '.join(map(str, v))}) ({spec['cells'][0][i]} {spec['cells'][1][j]} {nz}) simpleGrading (1 1 1)")
                # Each face of the block, outward, and what lies beyond it.
                for (di, dj, dk), face in [((-1, 0, 0), (v[0], v[4], v[7], v[3])), ((1, 0, 0), (v[1], v[2], v[6], v[5])),
                                           ((0, -1, 0), (v[0], v[1], v[5], v[4])), ((0, 1, 0), (v[3], v[7], v[6], v[2])),
                                           ((0, 0, -1), (v[0], v[3], v[2], v[1])), ((0, 0, 1), (v[4], v[5], v[6], v[7]))]:
                    beyond = (i + di, j + dj, k + dk)
                    text = f"({' '.join(map(str, face))})"
                    if dk != 0 and two_d:
                        faces["frontAndBack"].append(text)
                    elif beyond == hole:
                        faces["body"].append(text)
                    elif not all(0 <= c < 3 for c in beyond[:2]) or not (0 <= beyond[2] < nk):
                        faces["outer"].append(text)
    types = {"outer": "wall", "body": "wall", "frontAndBack": "empty"}
    boundary = "".join(f"{name} {{ type {types[name]}; faces ({' '.join(f)}); }}\n" for name, f in faces.items() if f)
    os.makedirs(f"{case}/system", exist_ok=True)
    with open(f"{case}/system/blockMeshDict", "w") as out:
        out.write(HEADER % "blockMeshDict" + "convertToMeters 1;\nvertices (" + " ".join(vertices) + ");\nblocks (\n" +
                  "\n".join(blocks) + "\n);\nedges ();\nboundary (\n" + boundary + ");\n")
    return two_d


def write_case(case, spec, angle, solver, steps=STEPS):
    """A fresh case turning the body to `angle` degrees over `steps` steps with `solver`."""
    shutil.rmtree(case, ignore_errors=True)
    two_d = block_mesh(case, spec)
    os.makedirs(f"{case}/constant", exist_ok=True)
    os.makedirs(f"{case}/0", exist_ok=True)
    write_controls(case, solver, steps)
    omega = math.pi / 2 / steps  # the angle reaches its amplitude at the last step
    empty = "frontAndBack { type empty; }" if two_d else ""
    with open(f"{case}/0/pointDisplacement", "w") as out:
        out.write("FoamFile { version 2.0; format ascii; class pointVectorField; object pointDisplacement; }\n"
                  "dimensions [0 1 0 0 0 0 0]; internalField uniform (0 0 0);\nboundaryField {\n"
                  f"body {{ type angularOscillatingDisplacement; axis (0 0 1); origin (0 0 0); angle0 0;"
                  f" amplitude {math.radians(angle)}; omega {omega}; value uniform (0 0 0); }}\n"
                  f"outer {{ type fixedValue; value uniform (0 0 0); }}\n{empty}\n}}\n")
    block_mesh_run(case)


def write_controls(case, solver, steps):
    """controlDict, fvSchemes, fvSolution and dynamicMeshDict (`solver`) of a case of `steps` steps."""
    with open(f"{case}/system/controlDict", "w") as out:
        out.write(HEADER % "controlDict" + f"application moveDynamicMesh; startFrom startTime; startTime 0; stopAt endTime;"
                  f" endTime {steps}; deltaT 1; writeControl timeStep; writeInterval {steps}; writeFormat binary;"
                  " writePrecision 17; writeCompression off; timeFormat general; timePrecision 6; runTimeModifiable false;\n")
    with open(f"{case}/system/fvSchemes", "w") as out:
        out.write(HEADER % "fvSchemes" + "ddtSchemes { default Euler; } gradSchemes { default Gauss linear; }"
                  " divSchemes { default none; } laplacianSchemes { default Gauss linear corrected; }"
                  " interpolationSchemes { default linear; } snGradSchemes { default corrected; }\n")
    with open(f"{case}/system/fvSolution", "w") as out:
        out.write(HEADER % "fvSolution" + "solvers { \"cellDisplacement.*\" { solver GAMG; smoother GaussSeidel;"
                  " tolerance 1e-8; relTol 0; minIter 3; } }\n")
    with open(f"{case}/constant/dynamicMeshDict", "w") as out:
        out.write(HEADER % "dynamicMeshDict" + "dynamicFvMesh dynamicMotionSolverFvMesh;\n" + solver)


def block_mesh_run(case):
    log = subprocess.run(["blockMesh"], cwd=case, capture_output=True, text=True)
    if log.returncode != 0:
        sys.exit(f"openfoam_plugin: blockMesh failed in {case}:\n{log.stdout[-2000:]}{log.stderr[-2000:]}")


def terrain_height(x, y):
    """The bottom's final height at (x, y): two hills and a ripple."""
    x, y = x - TERRAIN_ORIGIN[0], y - TERRAIN_ORIGIN[1]
    return (380.0 * math.exp(-((x - 2000) ** 2 + (y - 2000) ** 2) / 700.0 ** 2)
            + 250.0 * math.exp(-((x - 4300) ** 2 + (y - 1500) ** 2) / 500.0 ** 2)
            + 60.0 * math.sin(x / 400.0) * math.cos(y / 300.0))


def write_terrain(case, solver, steps=LARGE_STEPS):
    """A fresh terrain case whose bottom rises onto terrain_height over `steps` steps."""
    shutil.rmtree(case, ignore_errors=True)
    for d in ("system", "constant", "0"):
        os.makedirs(f"{case}/{d}", exist_ok=True)
    (x0, y0), (nx, ny, nz), (lx, ly, lz) = TERRAIN_ORIGIN, TERRAIN_CELLS, TERRAIN_SIZE
    corners = [(x0, y0, 0), (x0 + lx, y0, 0), (x0 + lx, y0 + ly, 0), (x0, y0 + ly, 0),
               (x0, y0, lz), (x0 + lx, y0, lz), (x0 + lx, y0 + ly, lz), (x0, y0 + ly, lz)]
    patches = {"bottom": "(0 3 2 1)", "top": "(4 5 6 7)", "west": "(0 4 7 3)", "east": "(1 2 6 5)",
               "south": "(0 1 5 4)", "north": "(3 7 6 2)"}
    with open(f"{case}/system/blockMeshDict", "w") as out:
        out.write(HEADER % "blockMeshDict" + "convertToMeters 1;\nvertices (" + " ".join(f"({a} {b} {c})" for a, b, c in corners)
                  + f");\nblocks (hex (0 1 2 3 4 5 6 7) ({nx} {ny} {nz}) simpleGrading (1 1 1));\nedges ();\nboundary (\n"
                  + "".join(f"{name} {{ type wall; faces ({face}); }}\n" for name, face in patches.items()) + ");\n")
    write_controls(case, solver, steps)
    # The bottom's points (blockMesh's grid at z = 0) and their displacement at the first and
    # the last time: timeVaryingMappedFixedValue interpolates linearly between them. Debian's
    # OpenFOAM reads these two files as bare lists. The points are the patch's own, taken by
    # `mapMethod nearest`: the default planar interpolation perturbs them by its own bounding box,
    # which a decomposed case's ranks see differently (their values differed by 1e-3 relative).
    points = [(x0 + lx * i / nx, y0 + ly * j / ny) for j in range(ny + 1) for i in range(nx + 1)]
    data = f"{case}/constant/boundaryData/bottom"
    with_list = lambda rows: f"{len(points)}\n(\n" + "\n".join(rows) + "\n)\n"
    os.makedirs(data)
    with open(f"{data}/points", "w") as out:
        out.write(with_list(f"({x!r} {y!r} 0)" for x, y in points))
    for t, scale in ((0, 0.0), (steps, 1.0)):
        os.makedirs(f"{data}/{t}")
        with open(f"{data}/{t}/pointDisplacement", "w") as out:
            out.write(with_list(f"(0 0 {scale * terrain_height(x, y)!r})" for x, y in points))
    sides = "".join(f"{name} {{ type fixedNormalSlip; n ({nx_} {ny_} 0); value uniform (0 0 0); }}\n"
                    for name, nx_, ny_ in (("west", -1, 0), ("east", 1, 0), ("south", 0, -1), ("north", 0, 1)))
    with open(f"{case}/0/pointDisplacement", "w") as out:
        out.write("FoamFile { version 2.0; format ascii; class pointVectorField; object pointDisplacement; }\n"
                  "dimensions [0 1 0 0 0 0 0]; internalField uniform (0 0 0);\nboundaryField {\n"
                  "bottom { type timeVaryingMappedFixedValue; mapMethod nearest; offset (0 0 0); setAverage false; value uniform (0 0 0); }\n"
                  "top { type fixedValue; value uniform (0 0 0); }\n" + sides + "}\n")
    block_mesh_run(case)


def run(case, steps=STEPS, ranks=1):
    """moveDynamicMesh (on `ranks` ranks of a decomposed case): every step valid, seconds per
    step, peak memory (MB; the largest process's), last non-orthogonality, and the whole run's
    wall seconds."""
    command = ["moveDynamicMesh"]
    if ranks > 1:
        with open(f"{case}/system/decomposeParDict", "w") as out:
            out.write(HEADER % "decomposeParDict" + f"numberOfSubdomains {ranks}; method simple;"
                      f" simpleCoeffs {{ n ({ranks} 1 1); delta 0.001; }}\n")
        log = subprocess.run(["decomposePar", "-force"], cwd=case, capture_output=True, text=True)
        if log.returncode != 0:
            sys.exit(f"openfoam_plugin: decomposePar failed in {case}:\n{log.stdout[-2000:]}{log.stderr[-2000:]}")
        # From a processor folder with -case: Debian's OpenFOAM reads a decomposed case's
        # boundaryData at ../constant from the working folder, not from the processor's.
        command = ["mpirun", "--oversubscribe", "--allow-run-as-root", "-np", str(ranks), "moveDynamicMesh", "-parallel",
                   "-case", case]
    start = time.perf_counter()
    done = subprocess.run(["/usr/bin/time", "-f", "%M", *command], cwd=os.path.join(case, "processor0") if ranks > 1 else case,
                          capture_output=True, text=True)
    wall = time.perf_counter() - start
    log = done.stdout
    with open(f"{case}/log.moveDynamicMesh", "w") as out:
        out.write(log + done.stderr)
    ok = done.returncode == 0 and log.count("Mesh OK") >= steps and "Failed" not in log
    skewness = re.findall(r"Max skewness = ([0-9.eE+-]+)", log)
    times = [float(t) for t in re.findall(r"ExecutionTime = ([0-9.eE+-]+) s", log)]
    per_step = (times[-1] - times[0]) / (len(times) - 1) if len(times) > 1 else wall / steps
    rss = [int(x) for x in re.findall(r"^(\d+)$", done.stderr, re.M)]
    orthogonality = re.findall(r"Mesh non-orthogonality Max: ([0-9.eE+-]+)", log)
    return (ok, per_step, (rss[-1] / 1024 if rss else float("nan")), (float(orthogonality[-1]) if orthogonality else float("nan")),
            wall, float(skewness[-1]) if skewness else float("nan"))


print(f"openfoam_plugin: OpenFOAM {subprocess.run(['dpkg-query', '-W', '-f=${Version}', 'openfoam'], capture_output=True, text=True).stdout},"
      f" {STEPS} steps to the final angle, load {open('/proc/loadavg').read().split()[0]}")
print(f"{'case':9} {'motion solver':24} {'options':24} {'largest valid':>13} {'s/step @30':>10} {'MB @30':>7}"
      f" {'non-orth @30':>12} {'time ratio':>10}")
lines = []
for name, spec in CASES.items():
    rows = []
    for solver, options, dictionary in SOLVERS:
        case = os.path.join(work, name, solver + ("_" + options.split()[-1] if options.startswith("method") else ""))
        largest = 0
        for angle in ANGLES:
            write_case(case, spec, angle, dictionary)
            ok, *_ = run(case)
            if not ok:
                break
            largest = angle
        write_case(case, spec, REFERENCE, dictionary)
        ok, per_step, rss, orthogonality, *_ = run(case)
        rows.append(dict(bench="openfoam_plugin", case=name, solver=solver, options=options, largest_valid_deg=largest,
                         seconds_per_step=per_step, max_rss_mb=rss, non_orthogonality=orthogonality,
                         valid_at_reference=ok))
    peer = next(r for r in rows if r["solver"] == "displacementLaplacian")
    for r in rows:
        r["time_ratio"] = r["seconds_per_step"] / peer["seconds_per_step"] if peer["seconds_per_step"] > 0 else None
        print(f"{name:9} {r['solver']:24} {r['options']:24} {r['largest_valid_deg']:>11} deg {r['seconds_per_step']:10.4f}"
              f" {r['max_rss_mb']:7.0f} {r['non_orthogonality']:12.1f} {r['time_ratio']:10.2f}"
              + ("" if r["valid_at_reference"] else "  (invalid at 30 deg)"))
        lines.append(r)

# The large cases: each writer makes a fresh case for a dynamicMeshDict, and the Laplacian's
# dictionary (its diffusivity's distance from the moving patch).
LAPLACIAN = "motionSolverLibs (\"libfvMotionSolvers.so\");\nmotionSolver displacementLaplacian;\ndisplacementLaplacianCoeffs {{ diffusivity {}; }}\n"
LARGE = {
    "block3d_79k": (lambda case, dictionary: write_case(case, BLOCK_79K, REFERENCE, dictionary, LARGE_STEPS),
                    LAPLACIAN.format("inverseDistance (body)")),
    "terrain_72k": (write_terrain, LAPLACIAN.format("quadratic inverseDistance (bottom)")),
}
print(f"\n{'case':12} {'motion solver':24} {'options':24} {'valid':>5} {'wall s':>8} {'wall x':>7} {'MB':>7} {'MB x':>6}"
      f" {'non-orth':>8} {'skew':>6}   ({LARGE_STEPS} steps, setups included; the block to {REFERENCE} deg)")
for name, (write, laplacian) in LARGE.items():
    rows = []
    for solver, options, dictionary in SOLVERS:
        if solver == "displacementLaplacian":
            options, dictionary = laplacian.split("diffusivity ")[1].split(";")[0], laplacian
        case = os.path.join(work, name, solver + ("_" + options.split()[-1] if options.startswith("method") else ""))
        write(case, dictionary)
        ok, per_step, rss, orthogonality, wall, skewness = run(case, LARGE_STEPS)
        rows.append(dict(bench="openfoam_plugin_large", case=name, solver=solver, options=options, steps=LARGE_STEPS,
                         valid=ok, wall_seconds=wall, seconds_per_step=per_step, max_rss_mb=rss,
                         non_orthogonality=orthogonality, skewness=skewness, ranks=1))
    peer = next(r for r in rows if r["solver"] == "displacementLaplacian")
    for r in rows:
        r["wall_ratio"] = r["wall_seconds"] / peer["wall_seconds"]
        r["memory_ratio"] = r["max_rss_mb"] / peer["max_rss_mb"]
        print(f"{name:12} {r['solver']:24} {r['options']:24} {'yes' if r['valid'] else 'NO':>5} {r['wall_seconds']:8.1f}"
              f" {r['wall_ratio']:7.2f} {r['max_rss_mb']:7.0f} {r['memory_ratio']:6.2f} {r['non_orthogonality']:8.1f}"
              f" {r['skewness']:6.3f}")
        lines.append(r)
    # The defaults decomposed in two, against their serial run.
    serial = rows[0]
    solver, options, dictionary = SOLVERS[0]
    serial_case = os.path.join(work, name, solver)
    case = serial_case + "_2ranks"
    write(case, dictionary)
    ok, per_step, rss, orthogonality, wall, skewness = run(case, LARGE_STEPS, 2)
    rebuilt = subprocess.run(["reconstructPar", "-latestTime"], cwd=case, capture_output=True, text=True)
    compared = subprocess.run([os.path.join(build, "examples", "mesh_info"), serial_case, "--latest-time", "--compare", case,
                               "--json"], capture_output=True, text=True)
    try:
        difference = json.loads(compared.stdout)["compared"]["max_difference"] if rebuilt.returncode == 0 else None
    except (ValueError, KeyError):
        difference = None
    r = dict(bench="openfoam_plugin_large", case=name, solver=solver, options=options, steps=LARGE_STEPS,
             valid=ok, wall_seconds=wall, seconds_per_step=per_step, max_rss_mb=rss,
             non_orthogonality=orthogonality, skewness=skewness, ranks=2, wall_ratio_to_serial=wall / serial["wall_seconds"],
             largest_difference_from_serial=difference)
    print(f"{name:12} {solver:24} {options + ', 2 ranks':24} {'yes' if ok else 'NO':>5} {wall:8.1f}"
          f" {r['wall_ratio_to_serial']:7.2f} {rss:7.0f} {'':6} {orthogonality:8.1f} {skewness:6.3f}"
          f"   (x: over the serial run; points {difference if difference is not None else 'not compared'} from serial)")
    lines.append(r)
for line in lines:
    print(json.dumps(line))
EOF
