#!/usr/bin/env bash
# Compact k-d tree RBF vs dense global RBF: the rotating ellipse O-mesh (60°, four sizes) and
# the 3D box bump of rbf_bench (three sizes), moved by SciPy's RBFInterpolator (thin plate
# spline, Debian python3-scipy through /usr/bin/python3), by dense Eigen RBF in the same
# program (our RbfMover's global thin plate spline path, and the Wendland C2 interpolant solved
# densely) and by our compact Wendland C2 mover; ratio = seconds / our compact seconds.
# Installs python3-scipy with apt-get when absent; a missing peer is reported.
#
#   benchmarks/dense_rbf_peer.sh [BUILD_DIR=build] [WORK_DIR=/tmp/meshmotion_dense_rbf_peer] [CASES...]
set -u
# One thread for every tool (ours, Eigen, OpenBLAS under SciPy; OpenFOAM runs serial): on a
# shared, loaded machine OpenMP threads that wait on each other make timings meaningless.
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
build=${1:-build}
work=${2:-/tmp/meshmotion_dense_rbf_peer}
shift $(($# < 2 ? $# : 2))
cases=("$@")
((${#cases[@]})) || cases=(ellipse:64:60 ellipse:128:60 ellipse:256:60 ellipse:512:60 box:12 box:20 box:28 box:40)
bench="$build/benchmarks/motion_peer_bench"
python=/usr/bin/python3  # Debian's interpreter, where python3-scipy installs
if [[ ! -x "$bench" ]]; then
  echo "dense_rbf_peer: $bench not built (configure with -DMESHMOTION_BUILD_BENCHMARKS=ON, build target motion_peer_bench)" >&2
  exit 1
fi
mkdir -p "$work"
if ! "$python" -c 'import scipy.interpolate' >/dev/null 2>&1; then
  echo "dense_rbf_peer: SciPy not found for $python; installing Debian's python3-scipy with apt-get"
  if [[ $(id -u) -eq 0 ]] && command -v apt-get >/dev/null 2>&1; then
    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-scipy python3-numpy) >"$work.apt.log" 2>&1 ||
      echo "dense_rbf_peer: apt-get install python3-scipy failed (log: $work.apt.log)"
  else
    echo "dense_rbf_peer: cannot install (needs root and apt-get)"
  fi
fi
have_scipy=0
"$python" -c 'import scipy.interpolate' >/dev/null 2>&1 && have_scipy=1
echo "dense_rbf_peer: SciPy $( ((have_scipy)) && "$python" -c 'import scipy; print(scipy.__version__)' || echo MISSING)," \
  "threads $OMP_NUM_THREADS, load $(cut -d' ' -f1-3 /proc/loadavg), $(nproc --all) cores"

# Fits RBFInterpolator to the exported centres and values, evaluates it at every node and
# writes the displacements and the fit + evaluation seconds (file reading excluded).
scipy_rbf() {
  "$python" - "$1" "$2" <<'EOF'
import sys, time
import numpy as np
from scipy.interpolate import RBFInterpolator
folder, kernel = sys.argv[1], sys.argv[2]
dim, n, m = (int(v) for v in open(folder + "/shape.txt").read().split())
points = np.fromfile(folder + "/points.f64").reshape(n, dim)
centres = np.fromfile(folder + "/centres.f64").reshape(m, dim)
values = np.fromfile(folder + "/values.f64").reshape(m, dim)
start = time.perf_counter()
u = RBFInterpolator(centres, values, kernel=kernel, degree=1)(points)
seconds = time.perf_counter() - start
u.astype(np.float64).tofile(folder + "/scipy_" + kernel + ".f64")
open(folder + "/scipy_" + kernel + ".seconds", "w").write("%.6f\n" % seconds)
EOF
}

for case in "${cases[@]}"; do
  dir="$work/${case//:/_}"
  rm -rf "$dir"
  "$bench" rbf-export "$case" "$dir" || continue
  if ((have_scipy)); then
    scipy_rbf "$dir" thin_plate_spline || echo "dense_rbf_peer: scipy thin_plate_spline failed on $case"
  fi
  "$bench" rbf-judge "$case" "$dir"
done
