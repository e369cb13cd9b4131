#!/usr/bin/env bash
# The plugin inside OpenFOAM's own time loop: Debian's moveDynamicMesh on a cube whose lid
# follows a uniformFixedValue table, whose side walls are fixed and whose front slips, with
# `motionSolver meshmotion;`. Checks: the lid's points where the table puts them, the front's in
# their plane, the walls' still, every step's mesh valid (OpenFOAM's own checks), one set-up for
# the four steps; the same in a 2D case turned by angularOscillatingDisplacement; each case
# decomposed on 2 ranks (`-parallel`) giving the serial points to 1e-12, with the points two
# ranks share identical; pimpleFoam running a 2D channel whose wall turns, serially and on 2
# ranks; stiffened elasticity through the cube's hexahedra and through the polyhedra of its
# dual mesh; a sphere cut out of a box by snappyHexMesh, translated and swung, serially and on
# 2 ranks; stiffened elasticity through hexahedra and polyhedra on 2 ranks as serial; the
# front as fixedNormalSlip and as surfaceSlipDisplacement kept in its plane, a box's four
# fixedNormalSlip sides in their planes and their edges' points along the edges, a point patch field
# type the plugin does not know refused naming the patch, the options read from
# dynamicMeshDict's top level without meshmotionCoeffs, each step's time and memory logged; an
# unknown option refused with its name, and a method through the cells that has no distributed
# mover refused on a decomposed case.
#
#   plugin_test.sh LIBMESHMOTIONFOAM WORK_DIR [MPIEXEC [FLAGS...]]
#
# Without MPIEXEC (a plugin built without meshmotion's parallel layer) the decomposed runs are
# skipped with a message.
set -euo pipefail
lib=$(realpath "$1")
here=$(dirname "$(realpath "$0")")
work=$(realpath -m "$2")
shift 2
mpiexec=("$@")
if [[ -f /usr/share/openfoam/etc/bashrc ]]; then
  # It reads unset variables and ends on a failing test.
  set +eu
  # shellcheck disable=SC1091
  source /usr/share/openfoam/etc/bashrc >/dev/null 2>&1
  set -eu
fi
command -v moveDynamicMesh >/dev/null || { echo "plugin_test: moveDynamicMesh not found (Debian's openfoam)"; exit 1; }
header='FoamFile { version 2.0; format ascii; class dictionary; object'
# system/controlDict for application $1: steps of $3 up to time $2, each written.
control_dict() {
  cat > system/controlDict <<EOD
$header controlDict; }
application $1; startFrom startTime; startTime 0; stopAt endTime; endTime $2; deltaT $3;
writeControl timeStep; writeInterval 1; writeFormat ascii; writePrecision 17; writeCompression off;
timeFormat general; timePrecision 6; runTimeModifiable false;
EOD
}
# A case in folder $1 from blockMesh: vertices $2, block $3, patches $4, point patch fields $5,
# curved edges $6 (optional).
make_case() {
  mkdir -p "$1/system" "$1/constant" "$1/0"
  cd "$1"
  cat > system/blockMeshDict <<EOD
$header blockMeshDict; }
convertToMeters 1;
vertices ($2);
blocks (hex (0 1 2 3 4 5 6 7) $3 simpleGrading (1 1 1));
edges (${6:-});
boundary ($4);
EOD
  control_dict moveDynamicMesh 4 1
  cat > system/fvSchemes <<EOD
$header fvSchemes; }
ddtSchemes { default Euler; } gradSchemes { default Gauss linear; } divSchemes { default none; }
laplacianSchemes { default Gauss linear corrected; } interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
EOD
  echo "$header fvSolution; } solvers {}" > system/fvSolution
  cat > 0/pointDisplacement <<EOD
FoamFile { version 2.0; format ascii; class pointVectorField; object pointDisplacement; }
dimensions [0 1 0 0 0 0 0];
internalField uniform (0 0 0);
boundaryField { $5 }
EOD
  blockMesh > log.blockMesh 2>&1 || { tail -5 log.blockMesh; exit 1; }
}
write_dynamic() {
  cat > constant/dynamicMeshDict <<EOD
$header dynamicMeshDict; }
dynamicFvMesh dynamicMotionSolverFvMesh;
motionSolverLibs ("libfvMotionSolvers.so" "$lib");
motionSolver meshmotion;
meshmotionCoeffs { $1 }
EOD
}
# The four steps with meshmotionCoeffs options $1: one set-up, OpenFOAM's mesh check passed at
# every step, and the set-up's line matching $2.
move() {
  write_dynamic "$1"
  moveDynamicMesh > log.move 2>&1 || { tail -20 log.move; exit 1; }
  local setups valid
  setups=$(grep -c "meshmotion: [a-z0-9]* set up" log.move || true)
  valid=$(grep -c "^Mesh OK" log.move || true)
  [[ $setups == 1 ]] || { echo "FAIL: $setups set-ups for 4 steps (expected 1)"; exit 1; }
  [[ $valid -ge 4 ]] || { echo "FAIL: OpenFOAM's mesh check passed $valid times (expected every step)"; tail -30 log.move; exit 1; }
  grep -q "$2" log.move || { echo "FAIL: no set-up line matching '$2'"; grep meshmotion log.move; exit 1; }
}
# The current case decomposed on 2 ranks and run by application $1 with -parallel: every rank's
# points at every written time equal the serial run's (already in the case) to $2 (default
# 1e-12; the elasticity's PETSc solve stops at its tolerance), and a point two ranks share is
# the same on both.
parallel_equals_serial() {
  if [[ ${#mpiexec[@]} == 0 ]]; then
    echo "plugin_test: $1 -parallel skipped: the plugin was built without meshmotion's parallel layer"
    return
  fi
  cat > system/decomposeParDict <<EOD
$header decomposeParDict; }
numberOfSubdomains 2; method simple; coeffs { n (2 1 1); }
EOD
  decomposePar -force > log.decompose 2>&1 || { tail -5 log.decompose; exit 1; }
  "${mpiexec[@]}" -np 2 "$1" -parallel > log.parallel 2>&1 || { tail -20 log.parallel; exit 1; }
  grep -q "meshmotion: [a-z0-9]* set up .* on 2 ranks" log.parallel || { echo "FAIL: no set-up on 2 ranks"; tail -20 log.parallel; exit 1; }
  TOLERANCE=${2:-1e-12} /usr/bin/python3 - <<'EOD'
import glob, os, re
def vectors(path):
    return [tuple(map(float, p)) for p in re.findall(r"\(([-0-9.e+]+) ([-0-9.e+]+) ([-0-9.e+]+)\)", open(path).read())]
def labels(path):
    text = open(path).read()
    return [int(x) for x in text[text.index("(", text.index("}")) + 1:text.rindex(")")].split()]
times = sorted(os.path.dirname(p).split("/")[1] for p in glob.glob("processor0/*/polyMesh/points") if "constant" not in p)
assert times, "the decomposed run wrote no moved points"
worst = apart = 0.0
for t in times:
    serial = vectors(f"{t}/polyMesh/points")
    seen = {}
    for rank in (0, 1):
        address = labels(f"processor{rank}/constant/polyMesh/pointProcAddressing")
        local = vectors(f"processor{rank}/{t}/polyMesh/points")
        assert len(local) == len(address)
        for a, x in zip(address, local):
            worst = max(worst, max(abs(x[k] - serial[a][k]) for k in range(3)))
            if a in seen:
                apart = max(apart, max(abs(x[k] - seen[a][k]) for k in range(3)))
            seen[a] = x
print(f"2 ranks against serial at times {' '.join(times)}: largest difference {worst:.3g}, shared points apart {apart:.3g}")
assert worst < float(os.environ["TOLERANCE"]) and apart == 0.0, (worst, apart)
EOD
}
rm -rf "$work"
make_case "$work" "(0 0 0) (1 0 0) (1 1 0) (0 1 0) (0 0 1) (1 0 1) (1 1 1) (0 1 1)" "(10 10 10)" \
  "lid { type wall; faces ((4 5 6 7)); }
   walls { type wall; faces ((0 3 2 1) (0 4 7 3) (1 2 6 5) (3 7 6 2)); }
   front { type wall; faces ((0 1 5 4)); }" \
  "lid { type uniformFixedValue; uniformValue table ((0 (0 0 0)) (4 (0.04 0 -0.2))); }
   walls { type fixedValue; value uniform (0 0 0); }
   front { type slip; }"
# The cube's boundary where its patch fields put it at each of the four steps (the lid's table
# scaled by $1), its interior moved.
cube_check() {
  SCALE=$1 /usr/bin/python3 - <<'EOD'
import os, re
def points(path):
    return [tuple(map(float, p)) for p in re.findall(r"\(([-0-9.e+]+) ([-0-9.e+]+) ([-0-9.e+]+)\)", open(path).read())]
p0 = points("constant/polyMesh/points")
worst = {"lid": 0.0, "front": 0.0, "walls": 0.0}
for t in (1, 2, 3, 4):
    p = points(f"{t}/polyMesh/points")
    assert len(p) == len(p0)
    scale = float(os.environ["SCALE"])
    lid = (0.01 * t * scale, 0.0, -0.05 * t * scale)
    interior_moved = 0
    for a, b in zip(p0, p):
        d = [b[k] - a[k] for k in range(3)]
        if abs(a[2] - 1.0) < 1e-12 and not (a[0] < 1e-12 or a[0] > 1 - 1e-12 or a[1] > 1 - 1e-12):
            worst["lid"] = max(worst["lid"], max(abs(d[k] - lid[k]) for k in range(3)))
        elif abs(a[1]) < 1e-12:
            worst["front"] = max(worst["front"], abs(d[1]))
        elif a[0] < 1e-12 or a[0] > 1 - 1e-12 or a[1] > 1 - 1e-12 or a[2] < 1e-12:
            worst["walls"] = max(worst["walls"], max(abs(x) for x in d))
        else:
            interior_moved += abs(d[2]) > 1e-6
    assert interior_moved > 0, f"step {t}: the interior did not move"
print("largest deviations:", worst)
assert worst["lid"] < 1e-12, worst
assert worst["front"] < 1e-12, worst
assert worst["walls"] < 1e-12, worst
EOD
}
move "method rbf; support_radius 2;" "rbf set up on .* boundary points of 1331"
cube_check 1
! grep -q "set up again for" log.move || { echo "FAIL: a given radius was changed"; exit 1; }
parallel_equals_serial moveDynamicMesh
# A method through the cells without a distributed mover (springs): on the decomposed case the
# ranks gather the case on the first one, which moves it with the serial mover.
rm -rf 1 2 3 4
sed -i 's/(4 (0.04 0 -0.2))/(4 (0.02 0 -0.1))/' 0/pointDisplacement
move "method spring;" "spring set up on .* boundary points of 1331"
cube_check 0.5
parallel_equals_serial moveDynamicMesh 1e-8
# Stiffened elasticity through the cube's hexahedra, then through polyhedra (OpenFOAM's dual
# of the cube: 300 polyhedra, their faces' centres on the boundary prescribed or sliding), the
# lid moving half as far, then a quarter (further, elasticity folds cells at the lid's fixed
# edges, where the RBF's smoother field does not: a limit of the method, the same with the
# faces' centres left free).
rm -rf 1 2 3 4
move "method sle;" "sle set up on .* boundary points of 1331 in [0-9.e+-]* s, resident memory [0-9]* MB"
cube_check 0.5
parallel_equals_serial moveDynamicMesh 1e-8
# The front as fixedNormalSlip (n along y): it slides in its plane under stiffened elasticity
# too (read as interior before, elasticity's Poisson effect pushed it out), and a point patch
# field type the plugin does not know stops the run naming the patch and the type.
rm -rf 1 2 3 4
sed -i 's/front { type slip; }/front { type fixedNormalSlip; n (0 2 0); }/' 0/pointDisplacement
move "method sle;" "sle set up on .* boundary points of 1331"
cube_check 0.5
grep -q "meshmotion: moved in [0-9.e+-]* s (set up again [0-9.e+-]* s, solve [0-9.e+-]* s, evaluation [0-9.e+-]* s), .*resident memory [0-9]* MB" log.move \
  || { echo "FAIL: no per-step time split and memory in the log"; grep meshmotion log.move; exit 1; }
# Elasticity's step is its solve: a step whose solve reads zero lost it to the evaluation.
grep -Eq "meshmotion: moved in .*solve ([1-9]|0\.0*[1-9])" log.move \
  || { echo "FAIL: sle's steps log no solve time"; grep meshmotion log.move; exit 1; }
# The front as surfaceSlipDisplacement on the plane y = 0: sliding, then projected by its field.
rm -rf 1 2 3 4
surface='front { type surfaceSlipDisplacement; projectMode nearest; projectDirection (0 1 0); geometry { frontPlane { type searchablePlane; planeType pointAndNormal; pointAndNormalDict { point (0 0 0); normal (0 1 0); } } } }'
sed -i "s/front { type fixedNormalSlip; n (0 2 0); }/$surface/" 0/pointDisplacement
move "method sle;" "sle set up on .* boundary points of 1331"
cube_check 0.5
rm -rf 1 2 3 4
sed -i "s/$surface/front { type calculated; value uniform (0 0 0); }/" 0/pointDisplacement
if moveDynamicMesh > log.bad 2>&1; then echo "FAIL: a point patch field type the plugin does not know was accepted"; exit 1; fi
grep -q "patch front has pointDisplacement type calculated" log.bad \
  || { echo "FAIL: the error does not name the patch and its type"; tail -20 log.bad; exit 1; }
sed -i 's/front { type calculated; value uniform (0 0 0); }/front { type slip; }/' 0/pointDisplacement
# dynamicMeshDict without meshmotionCoeffs: the options from its top level, OpenFOAM's own
# entries and other solvers' coefficients left to OpenFOAM; the minimal dictionary runs.
cat > constant/dynamicMeshDict <<EOD
$header dynamicMeshDict; }
dynamicFvMesh dynamicMotionSolverFvMesh;
motionSolverLibs ("libfvMotionSolvers.so" "$lib");
motionSolver meshmotion;
method sle;
displacementLaplacianCoeffs { diffusivity uniform; }
EOD
moveDynamicMesh > log.move 2>&1 || { echo "FAIL: the options at dynamicMeshDict's top level were not taken"; tail -20 log.move; exit 1; }
grep -q "meshmotion: sle set up" log.move || { echo "FAIL: method sle at the top level was not taken"; grep meshmotion log.move; exit 1; }
cube_check 0.5
# An option the mover does not have: OpenFOAM's fatal error, naming it.
rm -rf 1 2 3 4
write_dynamic "method rbf; no_such_option 1;"
if moveDynamicMesh > log.bad 2>&1; then echo "FAIL: an unknown option was accepted"; exit 1; fi
grep -q "no_such_option" log.bad || { echo "FAIL: the error does not name the option"; tail -20 log.bad; exit 1; }
polyDualMesh 80 -overwrite -concaveMultiCells > log.dual 2>&1 || { tail -5 log.dual; exit 1; }
checkMesh > log.check 2>&1 || { tail -20 log.check; exit 1; }
grep -q "polyhedra: *300" log.check || { echo "FAIL: the dual mesh has not the expected 300 polyhedra"; grep -A8 "cells:" log.check; exit 1; }
sed -i 's/(4 (0.02 0 -0.1))/(4 (0.01 0 -0.05))/' 0/pointDisplacement
move "method sle;" "sle set up on .* boundary points of 2052"
cube_check 0.25
# On 2 ranks the faces between them are polygons: their centres, held by both ranks, are one
# node of the distributed system.
parallel_equals_serial moveDynamicMesh 1e-8
# Springs on the polyhedra: the case gathered from 2 ranks is the serial case, each face
# between the ranks once.
rm -rf 1 2 3 4
move "method spring;" "spring set up on .* boundary points of 2052"
parallel_equals_serial moveDynamicMesh 1e-8
# A 3D body from snappyHexMesh: a sphere (OpenFOAM's analytic searchableSphere, no surface
# file) cut out of a blockMesh box, 288 polyhedra where the castellated cells were split. The
# sphere translates by a uniformFixedValue table, then swings about an axis beside its centre
# by angularOscillatingDisplacement; the box stays. Checks: the sphere's points where the
# patch field puts them, the box's still, every step's mesh valid, 2 ranks as serial.
make_case "$work/sphere" "(-1 -1 -1) (1 -1 -1) (1 1 -1) (-1 1 -1) (-1 -1 1) (1 -1 1) (1 1 1) (-1 1 1)" "(12 12 12)" \
  "box { type wall; faces ((4 5 6 7) (0 3 2 1) (0 4 7 3) (1 2 6 5) (3 7 6 2) (0 1 5 4)); }" \
  "sphere { type uniformFixedValue; uniformValue table ((0 (0 0 0)) (4 (0.2 0.08 0))); }
   box { type fixedValue; value uniform (0 0 0); }"
# The sphere cut out as the move benchmarks cut theirs, the box's cells refined once around it.
bash "$here/../../benchmarks/snappy_sphere_case.sh" "$work/sphere" 12 1
checkMesh > log.check 2>&1 || { tail -20 log.check; exit 1; }
grep -q "polyhedra: *[1-9]" log.check || { echo "FAIL: snappyHexMesh made no polyhedra"; grep -A8 "cells:" log.check; exit 1; }
# The sphere's points where the patch field puts them at each step ($1: "translate" or
# "swing"), the box's still, the interior moved.
sphere_check() {
  MOTION=$1 /usr/bin/python3 - <<'EOD'
import math, os, re
def points(path):
    return [tuple(map(float, p)) for p in re.findall(r"\(([-0-9.e+]+) ([-0-9.e+]+) ([-0-9.e+]+)\)", open(path).read())]
def patch_points(name):
    boundary = open("constant/polyMesh/boundary").read()
    block = re.search(name + r"\s*\{([^}]*)\}", boundary).group(1)
    start, count = (int(re.search(key + r"\s+(\d+)", block).group(1)) for key in ("startFace", "nFaces"))
    faces = re.findall(r"\d+\(([\d ]+)\)", open("constant/polyMesh/faces").read())
    return {int(v) for f in faces[start:start + count] for v in f.split()}
p0 = points("constant/polyMesh/points")
sphere, box = patch_points("sphere"), patch_points("box")
assert sphere and box
for t in (1, 2, 3, 4):
    p = points(f"{t}/polyMesh/points")
    if os.environ["MOTION"] == "translate":
        target = lambda a: (a[0] + 0.05 * t, a[1] + 0.02 * t, a[2])
    else:
        angle = 0.3 * math.sin(0.39269908169872414 * t)
        c, s = math.cos(angle), math.sin(angle)
        target = lambda a: (0.1 + c * (a[0] - 0.1) - s * a[1], s * (a[0] - 0.1) + c * a[1], a[2])
    on_sphere = max(max(abs(x - y) for x, y in zip(p[v], target(p0[v]))) for v in sphere)
    on_box = max(max(abs(x - y) for x, y in zip(p[v], p0[v])) for v in box)
    moved = sum(1 for v in range(len(p0)) if v not in sphere and v not in box and p[v] != p0[v])
    assert on_sphere < 1e-12 and on_box == 0.0 and moved > 0, (t, on_sphere, on_box, moved)
print(f"sphere ({len(sphere)} points) on its {os.environ['MOTION']}, box ({len(box)} points) still")
EOD
}
# The box is held (a fixedValue of zero): the sphere's ball clears it, so each move's rigid part
# is blended first.
move "method rbf;" "rbf set up on.*each move's rigid part blended first"
sphere_check translate
rm -rf 1 2 3 4
sed -i 's/sphere { type uniformFixedValue; uniformValue table ((0 (0 0 0)) (4 (0.2 0.08 0))); }/sphere { type angularOscillatingDisplacement; axis (0 0 1); origin (0.1 0 0); angle0 0; amplitude 0.3; omega 0.39269908169872414; value uniform (0 0 0); }/' 0/pointDisplacement
grep -q angularOscillating 0/pointDisplacement || { echo "FAIL: the swing was not set"; exit 1; }
move "method rbf;" "rbf set up on"
sphere_check swing
parallel_equals_serial moveDynamicMesh
# A box whose four sides are fixedNormalSlip, each its own patch, under a rising lid: the points
# of each side stay in its plane, and those on an edge where two sides meet move along it only
# (such a point has two planes: it slides on their line; the bridge once gave it no normal and
# the run stopped at setup).
make_case "$work/sides" "(0 0 0) (1 0 0) (1 1 0) (0 1 0) (0 0 1) (1 0 1) (1 1 1) (0 1 1)" "(8 8 8)" \
  "lid { type wall; faces ((4 5 6 7)); }
   floor { type wall; faces ((0 3 2 1)); }
   west { type wall; faces ((0 4 7 3)); }
   east { type wall; faces ((1 2 6 5)); }
   south { type wall; faces ((0 1 5 4)); }
   north { type wall; faces ((3 7 6 2)); }" \
  "lid { type uniformFixedValue; uniformValue table ((0 (0 0 0)) (4 (0 0 0.2))); }
   floor { type fixedValue; value uniform (0 0 0); }
   west { type fixedNormalSlip; n (-1 0 0); value uniform (0 0 0); }
   east { type fixedNormalSlip; n (1 0 0); value uniform (0 0 0); }
   south { type fixedNormalSlip; n (0 -1 0); value uniform (0 0 0); }
   north { type fixedNormalSlip; n (0 1 0); value uniform (0 0 0); }"
for method in rbf sle; do
  rm -rf 1 2 3 4
  move "method $method;" "$method set up on"
  /usr/bin/python3 - <<'EOD'
import re
def points(path):
    return [tuple(map(float, p)) for p in re.findall(r"\(([-0-9.e+]+) ([-0-9.e+]+) ([-0-9.e+]+)\)", open(path).read())]
p0 = points("constant/polyMesh/points")
off = moved = 0.0
for t in (1, 2, 3, 4):
    for a, b in zip(p0, points(f"{t}/polyMesh/points")):
        for k in (0, 1):  # a side's points keep their x (west, east) or y (south, north)
            if a[k] < 1e-12 or a[k] > 1 - 1e-12:
                off = max(off, abs(b[k] - a[k]))
        if 1e-12 < a[2] < 1 - 1e-12 and (a[0] < 1e-12 or a[0] > 1 - 1e-12) and (a[1] < 1e-12 or a[1] > 1 - 1e-12):
            moved = max(moved, abs(b[2] - a[2]))  # an edge between two sides: along it
print(f"sides' points off their planes: {off:.3g}; edges' points moved along them up to {moved:.3g}")
assert off < 1e-12 and moved > 0.01, (off, moved)
EOD
done
# A 2D case (one cell thick, front and back `empty`) whose bottom wall turns by
# angularOscillatingDisplacement: the bottom's points where the rotation puts them, the mesh
# still 2D with front and back moved alike, only the walls' points as the mover's boundary.
make_case "$work/2d" "(0 0 0) (2 0 0) (2 1 0) (0 1 0) (0 0 0.1) (2 0 0.1) (2 1 0.1) (0 1 0.1)" "(40 20 1)" \
  "bottom { type wall; faces ((0 1 5 4)); }
   walls { type wall; faces ((3 7 6 2) (0 4 7 3) (1 2 6 5)); }
   frontAndBack { type empty; faces ((0 3 2 1) (4 5 6 7)); }" \
  "bottom { type angularOscillatingDisplacement; axis (0 0 1); origin (1 0 0); angle0 0; amplitude 0.2;
            omega 0.5; value uniform (0 0 0); }
   walls { type fixedValue; value uniform (0 0 0); }
   frontAndBack { type empty; }"
# The 2D case's bottom on its rotation (amplitude $1), its front and back moved alike, its z
# unchanged.
two_d_check() {
  AMPLITUDE=$1 /usr/bin/python3 - <<'EOD'
import math, os, re
def points(path):
    return [tuple(map(float, p)) for p in re.findall(r"\(([-0-9.e+]+) ([-0-9.e+]+) ([-0-9.e+]+)\)", open(path).read())]
p0 = points("constant/polyMesh/points")
for t in (1, 2, 3, 4):
    p = points(f"{t}/polyMesh/points")
    angle = float(os.environ["AMPLITUDE"]) * math.sin(0.5 * t)
    c, s = math.cos(angle), math.sin(angle)
    bottom = off_plane = 0.0
    by_column = {}
    for a, b in zip(p0, p):
        off_plane = max(off_plane, abs(b[2] - a[2]))
        by_column.setdefault((round(a[0], 9), round(a[1], 9)), []).append((b[0] - a[0], b[1] - a[1]))
        if abs(a[1]) < 1e-12 and 1e-12 < a[0] < 2 - 1e-12:
            x, y = a[0] - 1.0, a[1]
            bottom = max(bottom, math.hypot(b[0] - (1.0 + c * x - s * y), b[1] - (s * x + c * y)))
    apart = max(abs(v[0][0] - v[1][0]) + abs(v[0][1] - v[1][1]) for v in by_column.values())
    assert bottom < 1e-12 and off_plane == 0.0 and apart < 1e-12, (t, bottom, off_plane, apart)
print("2D case: bottom on its rotation, front and back alike, z unchanged")
EOD
}
move "method rbf;" "set up on 240 boundary points of 1722"
# No radius given: the default one (ten boundary spacings, 0.5, before any motion) grows with the
# motion, once here: to ten times the largest displacement of the step that outgrew it (the
# bottom's ends touch the held walls: its turn is interpolated whole, not blended).
[[ $(grep -c "meshmotion: set up again for the motion's size (support radius 1.59" log.move) == 1 ]] \
  || { echo "FAIL: the default radius did not grow once with the motion"; grep meshmotion log.move; exit 1; }
two_d_check 0.2
parallel_equals_serial moveDynamicMesh
# Stiffened elasticity through the slab of hexahedra: its front and back, free in the mover,
# kept in their planes (the Poisson effect moved them out, and the mesh collapsed). A tenth of
# the turn: the bottom's second point moves further than its cell's height, which folds the
# corner cell under elasticity (not under the RBF).
rm -rf 1 2 3 4
sed -i 's/amplitude 0.2;/amplitude 0.02;/' 0/pointDisplacement
move "method sle;" "sle set up on 240 boundary points of 1722"
two_d_check 0.02
parallel_equals_serial moveDynamicMesh 1e-8
# pimpleFoam on a 2D channel whose bottom wall turns (the wall's velocity its motion's) under a
# curved top that slips: the plugin moves the mesh inside the solver's time loop, serially and
# on 2 ranks. The ranks meet at the top's crest, where each holds the faces of one side only:
# the plane a point slides in is the serial one only when the ranks' normals are summed.
make_case "$work/pimple" "(0 0 0) (2 0 0) (2 1 0) (0 1 0) (0 0 0.1) (2 0 0.1) (2 1 0.1) (0 1 0.1)" "(20 10 1)" \
  "bottom { type wall; faces ((0 1 5 4)); }
   top { type wall; faces ((3 7 6 2)); }
   inlet { type patch; faces ((0 4 7 3)); }
   outlet { type patch; faces ((1 2 6 5)); }
   frontAndBack { type empty; faces ((0 3 2 1) (4 5 6 7)); }" \
  "bottom { type angularOscillatingDisplacement; axis (0 0 1); origin (0.4 0 0); angle0 0; amplitude 0.1;
            omega 20; value uniform (0 0 0); }
   \"(inlet|outlet)\" { type fixedValue; value uniform (0 0 0); }
   top { type slip; }
   frontAndBack { type empty; }" \
  "arc 3 2 (1 1.2 0) arc 7 6 (1 1.2 0.1)"
write_dynamic "method rbf; support_radius 3;"
control_dict pimpleFoam 0.04 0.01
cat > system/fvSchemes <<EOD
$header fvSchemes; }
ddtSchemes { default Euler; } gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) Gauss linearUpwind grad(U); div((nuEff*dev2(T(grad(U))))) Gauss linear; }
laplacianSchemes { default Gauss linear corrected; } interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
EOD
cat > system/fvSolution <<EOD
$header fvSolution; }
solvers {
  "(p|pFinal|pcorr|pcorrFinal)" { solver PCG; preconditioner DIC; tolerance 1e-8; relTol 0; }
  "(U|UFinal)" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-8; relTol 0; }
}
PIMPLE { correctPhi yes; nOuterCorrectors 1; nCorrectors 2; nNonOrthogonalCorrectors 0; }
EOD
echo "$header transportProperties; } transportModel Newtonian; nu 0.01;" > constant/transportProperties
echo "$header turbulenceProperties; } simulationType laminar;" > constant/turbulenceProperties
cat > 0/U <<EOD
FoamFile { version 2.0; format ascii; class volVectorField; object U; }
dimensions [0 1 -1 0 0 0 0]; internalField uniform (1 0 0);
boundaryField { inlet { type fixedValue; value uniform (1 0 0); } outlet { type zeroGradient; }
  bottom { type movingWallVelocity; value uniform (0 0 0); } top { type slip; } frontAndBack { type empty; } }
EOD
cat > 0/p <<EOD
FoamFile { version 2.0; format ascii; class volScalarField; object p; }
dimensions [0 2 -2 0 0 0 0]; internalField uniform 0;
boundaryField { outlet { type fixedValue; value uniform 0; } "(inlet|top|bottom)" { type zeroGradient; }
  frontAndBack { type empty; } }
EOD
pimpleFoam > log.pimple 2>&1 || { tail -20 log.pimple; exit 1; }
[[ $(grep -c "meshmotion: rbf set up" log.pimple) == 1 ]] || { echo "FAIL: pimpleFoam did not set the plugin up once"; exit 1; }
[[ $(grep -c "^Courant Number" log.pimple) -ge 4 ]] || { echo "FAIL: pimpleFoam did not run its 4 steps"; tail -20 log.pimple; exit 1; }
checkMesh -latestTime > log.check 2>&1 || { tail -20 log.check; exit 1; }
grep -q "^Mesh OK" log.check || { echo "FAIL: checkMesh fails the moved mesh"; tail -20 log.check; exit 1; }
cmp -s constant/polyMesh/points 0.04/polyMesh/points && { echo "FAIL: pimpleFoam's mesh did not move"; exit 1; }
parallel_equals_serial pimpleFoam
echo "plugin_test: passed"
