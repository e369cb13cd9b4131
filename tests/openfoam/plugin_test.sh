#!/usr/bin/env bash
# The plugin inside OpenFOAM's own time loop: Debian's moveDynamicMesh on a cube whose lid
# follows a uniformFixedValue table, whose side walls are fixed and whose front slips, with
# `motionSolver meshmotion;`. Checks: the lid's points where the table puts them, the front's in
# their plane, the walls' still, every step's mesh valid (OpenFOAM's own checks), one set-up for
# the four steps; the same in a 2D case turned by angularOscillatingDisplacement; an unknown
# option refused with its name, and a method that needs cells.
#
#   plugin_test.sh LIBMESHMOTIONFOAM WORK_DIR
set -euo pipefail
lib=$(realpath "$1")
work=$(realpath -m "$2")
if [[ -f /usr/share/openfoam/etc/bashrc ]]; then
  # It reads unset variables and ends on a failing test.
  set +eu
  # shellcheck disable=SC1091
  source /usr/share/openfoam/etc/bashrc >/dev/null 2>&1
  set -eu
fi
command -v moveDynamicMesh >/dev/null || { echo "plugin_test: moveDynamicMesh not found (Debian's openfoam)"; exit 1; }
header='FoamFile { version 2.0; format ascii; class dictionary; object'
# A case in folder $1 from blockMesh: vertices $2, block $3, patches $4, point patch fields $5.
make_case() {
  mkdir -p "$1/system" "$1/constant" "$1/0"
  cd "$1"
  cat > system/blockMeshDict <<EOD
$header blockMeshDict; }
convertToMeters 1;
vertices ($2);
blocks (hex (0 1 2 3 4 5 6 7) $3 simpleGrading (1 1 1));
boundary ($4);
EOD
  cat > system/controlDict <<EOD
$header controlDict; }
application moveDynamicMesh; startFrom startTime; startTime 0; stopAt endTime; endTime 4; deltaT 1;
writeControl timeStep; writeInterval 1; writeFormat ascii; writePrecision 17; writeCompression off;
timeFormat general; timePrecision 6; runTimeModifiable false;
EOD
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
meshmotionCoeffs { method rbf; $1 }
EOD
}
# The four steps with meshmotionCoeffs options $1: one set-up, OpenFOAM's mesh check passed at
# every step, and the set-up's line matching $2.
move() {
  write_dynamic "$1"
  moveDynamicMesh > log.move 2>&1 || { tail -20 log.move; exit 1; }
  local setups valid
  setups=$(grep -c "meshmotion: rbf set up" log.move || true)
  valid=$(grep -c "^Mesh OK" log.move || true)
  [[ $setups == 1 ]] || { echo "FAIL: $setups set-ups for 4 steps (expected 1)"; exit 1; }
  [[ $valid -ge 4 ]] || { echo "FAIL: OpenFOAM's mesh check passed $valid times (expected every step)"; tail -30 log.move; exit 1; }
  grep -q "$2" log.move || { echo "FAIL: no set-up line matching '$2'"; grep meshmotion log.move; exit 1; }
}
rm -rf "$work"
make_case "$work" "(0 0 0) (1 0 0) (1 1 0) (0 1 0) (0 0 1) (1 0 1) (1 1 1) (0 1 1)" "(10 10 10)" \
  "lid { type wall; faces ((4 5 6 7)); }
   walls { type wall; faces ((0 3 2 1) (0 4 7 3) (1 2 6 5) (3 7 6 2)); }
   front { type wall; faces ((0 1 5 4)); }" \
  "lid { type uniformFixedValue; uniformValue table ((0 (0 0 0)) (4 (0.04 0 -0.2))); }
   walls { type fixedValue; value uniform (0 0 0); }
   front { type slip; }"
move "support_radius 2;" "set up on .* boundary points of 1331"
/usr/bin/python3 - <<'EOD'
import re
def points(path):
    return [tuple(map(float, p)) for p in re.findall(r"\(([-0-9.e+]+) ([-0-9.e+]+) ([-0-9.e+]+)\)", open(path).read())]
p0 = points("constant/polyMesh/points")
worst = {"lid": 0.0, "front": 0.0, "walls": 0.0}
for t in (1, 2, 3, 4):
    p = points(f"{t}/polyMesh/points")
    assert len(p) == len(p0)
    lid = (0.01 * t, 0.0, -0.05 * t)
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
# An option the mover does not have: OpenFOAM's fatal error, naming it.
rm -rf 1 2 3 4
write_dynamic "no_such_option 1;"
if moveDynamicMesh > log.bad 2>&1; then echo "FAIL: an unknown option was accepted"; exit 1; fi
grep -q "no_such_option" log.bad || { echo "FAIL: the error does not name the option"; tail -20 log.bad; exit 1; }
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
move "" "set up on 240 boundary points of 1722"
/usr/bin/python3 - <<'EOD'
import math, re
def points(path):
    return [tuple(map(float, p)) for p in re.findall(r"\(([-0-9.e+]+) ([-0-9.e+]+) ([-0-9.e+]+)\)", open(path).read())]
p0 = points("constant/polyMesh/points")
for t in (1, 2, 3, 4):
    p = points(f"{t}/polyMesh/points")
    angle = 0.2 * math.sin(0.5 * t)
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
cd "$work"
# A method that needs the cells the plugin does not pass yet: refused, saying so.
sed -i 's/method rbf;/method elasticity;/' constant/dynamicMeshDict
if moveDynamicMesh > log.bad 2>&1; then echo "FAIL: a method needing cells was accepted"; exit 1; fi
grep -q "needs the mesh's cells" log.bad || { echo "FAIL: the error does not say why"; tail -20 log.bad; exit 1; }
echo "plugin_test: passed"
