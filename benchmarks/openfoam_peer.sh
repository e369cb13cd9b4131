#!/usr/bin/env bash
# Mesh motion vs OpenFOAM: the SU2 deforming bump (`interface` rises by 0.05 sin²) and the
# rotating ellipse O-mesh (30° and 60°) moved by OpenFOAM's moveMesh (dynamicMotionSolverFvMesh,
# displacementLaplacian, inverseDistance diffusivity from the moving patch) and by our RBF,
# elasticity and spring movers; every result judged by our quality layer.
# Installs Debian's `openfoam` with apt-get when moveMesh is absent; a missing peer is reported.
#
#   benchmarks/openfoam_peer.sh [BUILD_DIR=build] [WORK_DIR=/tmp/meshmotion_openfoam_peer]
set -u
# One thread for every tool (ours, Eigen, OpenBLAS under SciPy; OpenFOAM runs serial): on a
# shared, loaded machine OpenMP threads that wait on each other make timings meaningless.
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
build=${1:-build}
work=${2:-/tmp/meshmotion_openfoam_peer}
bench="$build/benchmarks/motion_peer_bench"
if [[ ! -x "$bench" ]]; then
  echo "openfoam_peer: $bench not built (configure with -DMESHMOTION_BUILD_BENCHMARKS=ON, build target motion_peer_bench)" >&2
  exit 1
fi

if ! command -v moveMesh >/dev/null 2>&1; then
  echo "openfoam_peer: moveMesh not found; installing Debian's openfoam with apt-get"
  if [[ $(id -u) -eq 0 ]] && command -v apt-get >/dev/null 2>&1; then
    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq openfoam) >"$work.apt.log" 2>&1 ||
      echo "openfoam_peer: apt-get install openfoam failed (log: $work.apt.log)"
  else
    echo "openfoam_peer: cannot install (needs root and apt-get)"
  fi
fi
# Debian installs the applications in /usr/bin; its bashrc sets WM_PROJECT_DIR and the library
# paths (it reads unset variables, hence set +u around it).
if [[ -f /usr/share/openfoam/etc/bashrc ]]; then
  set +u
  # shellcheck disable=SC1091
  source /usr/share/openfoam/etc/bashrc >/dev/null 2>&1
  set -u
fi
have_foam=0
command -v moveMesh >/dev/null 2>&1 && have_foam=1
echo "openfoam_peer: OpenFOAM $( ((have_foam)) && dpkg-query -W -f='${Version}' openfoam 2>/dev/null || echo MISSING)," \
  "threads $OMP_NUM_THREADS, load $(cut -d' ' -f1-3 /proc/loadavg), $(nproc --all) cores"

# The case dictionaries shared by every case; the mesh and 0/pointDisplacement come from
# motion_peer_bench foam-export.
write_dicts() {
  local dir=$1 patch=$2
  mkdir -p "$dir/system" "$dir/constant"
  local header='FoamFile { version 2.0; format ascii; class dictionary; object'
  cat >"$dir/system/controlDict" <<EOF
$header controlDict; }
application     moveMesh;
startFrom       startTime;
startTime       0;
stopAt          endTime;
endTime         1;
deltaT          1;
writeControl    timeStep;
writeInterval   1;
writeFormat     ascii;
writePrecision  17;
writeCompression off;
timeFormat      general;
timePrecision   6;
runTimeModifiable false;
EOF
  cat >"$dir/system/fvSchemes" <<EOF
$header fvSchemes; }
ddtSchemes { default steadyState; }
gradSchemes { default Gauss linear; }
divSchemes { default none; }
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
EOF
  cat >"$dir/system/fvSolution" <<EOF
$header fvSolution; }
solvers
{
    cellDisplacement
    {
        solver          GAMG;
        smoother        GaussSeidel;
        tolerance       1e-08;
        relTol          0;
        maxIter         1000;
        // inverseDistance makes the diffusivity ~1e5 at the 1e-5 wall cells of the O-mesh, and
        // OpenFOAM's normalised residual then reads ~1e-15 after one sweep although the far
        // field is not converged; 20 sweeps give the converged field (100 and 400 change nothing).
        minIter         20;
    }
}
EOF
  cat >"$dir/constant/dynamicMeshDict" <<EOF
$header dynamicMeshDict; }
dynamicFvMesh   dynamicMotionSolverFvMesh;
motionSolverLibs ("libfvMotionSolvers.so");
motionSolver    displacementLaplacian;
displacementLaplacianCoeffs
{
    diffusivity inverseDistance ($patch);
}
EOF
}

run_case() {
  local case=$1 patch=$2
  local dir="$work/${case//:/_}"
  rm -rf "$dir"
  "$bench" foam-export "$case" "$dir" || return 1
  write_dicts "$dir" "$patch"
  local seconds=0 note="OpenFOAM not installed"
  if ((have_foam)); then
    local start end
    start=$(date +%s.%N)
    if moveMesh -case "$dir" >"$dir/log.moveMesh" 2>&1; then
      end=$(date +%s.%N)
      seconds=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.4f", b - a }')
      local iterations
      iterations=$(grep -o 'No Iterations [0-9]*' "$dir/log.moveMesh" | awk '{ s += $3 } END { print s + 0 }')
      local cpu
      cpu=$(grep -o 'ExecutionTime = [0-9.e+-]*' "$dir/log.moveMesh" | tail -1 | awk '{ printf "%.2f", $3 }')
      # The same run without the motion step (endTime 0): start-up, reading and set-up only.
      sed -i 's/^endTime .*/endTime         0;/' "$dir/system/controlDict"
      start=$(date +%s.%N)
      moveMesh -case "$dir" >"$dir/log.startup" 2>&1
      end=$(date +%s.%N)
      sed -i 's/^endTime .*/endTime         1;/' "$dir/system/controlDict"
      local startup
      startup=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }')
      note="moveMesh wall time; its ExecutionTime $cpu s; start-up only $startup s; $iterations GAMG iterations (x+y)"
    else
      note="moveMesh failed, see $dir/log.moveMesh"
      tail -5 "$dir/log.moveMesh"
    fi
  fi
  "$bench" foam-judge "$case" "$dir" "$seconds" "$note"
}

# The rotation spread over STEPS moveMesh runs, as OpenFOAM users move a body through a large
# angle: each run starts from the previous one's moved points and prescribes the increment of
# the wall's rotation (inverseDistance diffusivity and the Laplacian on the current mesh).
run_steps() {
  local around=$1 degrees=$2 steps=$3 patch=$4
  local case="ellipse:$around:$degrees" dir="$work/ellipse_${around}_${degrees}_steps$steps"
  local points="$work/points.previous" seconds=0 iterations=0 k
  ((have_foam)) || { "$bench" foam-judge "$case" "$dir" 0 "OpenFOAM not installed"; return; }
  for ((k = 1; k <= steps; ++k)); do
    local to from start end
    to=$(awk -v d="$degrees" -v k="$k" -v n="$steps" 'BEGIN { printf "%.12g", d * k / n }')
    from=$(awk -v d="$degrees" -v k="$k" -v n="$steps" 'BEGIN { printf "%.12g", d * (k - 1) / n }')
    rm -rf "$dir"
    "$bench" foam-export "ellipse:$around:$to" "$dir" "ellipse:$around:$from" >/dev/null || return 1
    write_dicts "$dir" "$patch"
    ((k > 1)) && cp "$points" "$dir/constant/polyMesh/points"
    start=$(date +%s.%N)
    if ! moveMesh -case "$dir" >"$dir/log.moveMesh" 2>&1; then
      tail -5 "$dir/log.moveMesh"
      "$bench" foam-judge "$case" "$dir" 0 "moveMesh failed at step $k of $steps"
      return
    fi
    end=$(date +%s.%N)
    seconds=$(awk -v s="$seconds" -v a="$start" -v b="$end" 'BEGIN { printf "%.4f", s + b - a }')
    iterations=$((iterations + $(grep -o 'No Iterations [0-9]*' "$dir/log.moveMesh" | awk '{ s += $3 } END { print s + 0 }')))
    cp "$dir/1/polyMesh/points" "$points"
  done
  "$bench" foam-judge "$case" "$dir" "$seconds" "moveMesh wall time summed over $steps runs of ${degrees}/$steps deg; $iterations GAMG iterations (x+y)"
}

mkdir -p "$work"
run_case bump interface
run_case ellipse:128:30 wall
run_case ellipse:128:60 wall
run_steps 128 60 10 wall
