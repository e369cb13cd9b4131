#!/usr/bin/env bash
# Configure with benchmarks on, build every benchmark, run them all, then the peer comparisons
# (OpenFOAM, dense RBF; Gmsh runs inside curving_bench), collect their JSON lines into one file
# and draw the SVG plots beside it. Default sizes finish in a few minutes each on a 2-core
# machine; --full runs the sizes the issues ask for (>= 1M elements/nodes: much longer).
#
#   benchmarks/run_all.sh [--full] [--build-dir DIR] [--out FILE] [--jobs N] [--no-build] [--no-peers]
#
# The output file holds, per benchmark, a {"benchmark_run": ...} line (program, arguments, load
# average before it, exit code, wall seconds) followed by that program's own JSON lines. The
# readable tables go to the terminal and to FILE.log.
set -uo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source_dir="$(dirname "$here")"
build_dir="$source_dir/build-bench"
full=0
build=1
peers=1
jobs=1
out=""

while [[ $# -gt 0 ]]; do
  case "$1" in
    --full) full=1 ;;
    --no-build) build=0 ;;
    --no-peers) peers=0 ;;
    --build-dir) build_dir="$2"; shift ;;
    --out) out="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    -h|--help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "run_all.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

build_dir="$(mkdir -p "$build_dir" && cd "$build_dir" && pwd)"
[[ -n "$out" ]] || out="$build_dir/benchmark_results_$(date -u +%Y%m%dT%H%M%SZ)$([[ $full == 1 ]] && echo _full).jsonl"
log="$out.log"
: > "$out"
: > "$log"

# name and arguments per benchmark: quick sizes, then full sizes.
declare -A quick_args=(
  [io_bench]="60"
  [quality_bench]="--quick"
  [delaunay_bench]="100000"
  [rbf_bench]="64"
  [interpolation_bench]=""
  [elasticity_bench]="--quick"
  [curving_bench]="--quick"
  [bump3d_bench]="0 1"
  [cholmod_bench]="64 1"
)
declare -A full_args=(
  [io_bench]="100"
  [quality_bench]=""
  [delaunay_bench]="100000 1000000"
  [rbf_bench]="126"
  [interpolation_bench]=""
  [elasticity_bench]=""
  [curving_bench]=""
  [bump3d_bench]="0 1 2"
  [cholmod_bench]="126 3"
)
order=(io_bench quality_bench rbf_bench interpolation_bench elasticity_bench delaunay_bench curving_bench bump3d_bench cholmod_bench)
# Peer scripts: they take the build folder and a work folder, install their peer with apt-get
# when it is absent, and report it missing when that fails.
peer_scripts=(openfoam_peer dense_rbf_peer)

benches=()
for name in "${order[@]}"; do
  [[ -f "$here/$name.cpp" ]] && benches+=("$name")
done
targets=("${benches[@]}")
[[ $peers == 1 ]] && targets+=(motion_peer_bench python_overhead_peer meshmotion_python)
# The parallel layer's benchmark exists when MPI, PETSc and METIS were found at configure time.
mpi_targets=(mpi_bench)

{
  echo "# $(date -u +%FT%TZ)  nproc=$(nproc)  $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')"
  echo "# $(c++ --version | head -1)  mode=$([[ $full == 1 ]] && echo full || echo quick)"
} | tee -a "$log"

if [[ $build == 1 ]]; then
  cmake -S "$source_dir" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DMESHMOTION_BUILD_BENCHMARKS=ON \
    >> "$log" 2>&1 || { echo "run_all.sh: configure failed, see $log" >&2; exit 1; }
  cmake --build "$build_dir" --target "${targets[@]}" -j"$jobs" >> "$log" 2>&1 \
    || { echo "run_all.sh: build failed, see $log" >&2; exit 1; }
  cmake --build "$build_dir" --target "${mpi_targets[@]}" -j"$jobs" >> "$log" 2>&1 \
    || echo "run_all.sh: mpi_bench not built (parallel layer skipped at configure time?)" | tee -a "$log" >&2
fi

status=0
# run NAME COMMAND...: runs one benchmark, its tables to the terminal and the log, its JSON
# lines (after a benchmark_run line) to the results file.
run() {
  local name="$1" args="${*:3}"
  shift
  local load start rc milliseconds
  load="$(cut -d' ' -f1-3 /proc/loadavg)"
  echo "== $name $args   (load average $load)" | tee -a "$log"
  start=$(date +%s%N)
  "$@" > "$build_dir/$name.out" 2>&1
  rc=$?
  milliseconds=$(( ($(date +%s%N) - start) / 1000000 ))
  tee -a "$log" < "$build_dir/$name.out" | grep -v '^{'
  printf '{"benchmark_run":"%s","arguments":"%s","load_average":"%s","exit_code":%d,"wall_seconds":%d.%03d}\n' \
    "$name" "$args" "$load" "$rc" $((milliseconds / 1000)) $((milliseconds % 1000)) >> "$out"
  grep '^{' "$build_dir/$name.out" >> "$out"
  [[ $rc == 0 ]] || { echo "run_all.sh: $name exited with $rc" | tee -a "$log" >&2; status=1; }
}

for name in "${benches[@]}"; do
  if [[ $full == 1 ]]; then args="${full_args[$name]}"; else args="${quick_args[$name]}"; fi
  if [[ ! -x "$build_dir/benchmarks/$name" ]]; then
    echo "run_all.sh: $build_dir/benchmarks/$name is not built" | tee -a "$log" >&2
    status=1
    continue
  fi
  # shellcheck disable=SC2086  # args is a word list on purpose
  run "$name" "$build_dir/benchmarks/$name" $args
done
# The distributed movers at 1, 2 and 4 ranks (4 is oversubscribed on two cores and says so),
# each against the serial mover in the same process.
if [[ -x "$build_dir/benchmarks/mpi_bench" ]]; then
  mpi_flags=()
  mpiexec --version 2>&1 | grep -q "Open MPI" && mpi_flags=(--oversubscribe --allow-run-as-root)
  for ranks in 1 2 4; do
    run "mpi_bench_$ranks" mpiexec "${mpi_flags[@]}" -n "$ranks" "$build_dir/benchmarks/mpi_bench" \
      "$([[ $full == 1 ]] && echo 126 || echo 64)"
  done
fi
if [[ $peers == 1 ]]; then
  for name in "${peer_scripts[@]}"; do
    run "$name" "$here/$name.sh" "$build_dir" "$build_dir/$name"
  done
  # Python against C++ on the same job, for Debian's interpreter (docs/python.md).
  if [[ -f "$build_dir/python/meshmotion/__init__.py" ]]; then
    run python_overhead env PYTHONPATH="$build_dir/python" /usr/bin/python3 "$here/python_overhead.py" \
      --peer "$build_dir/benchmarks/python_overhead_peer"
  else
    echo "run_all.sh: the Python module was not built (pybind11 absent?): python_overhead skipped" | tee -a "$log" >&2
  fi
fi

python3 "$here/plot_results.py" "$out" --out-dir "$build_dir/plots" | tee -a "$log"
echo "JSON lines: $out" | tee -a "$log"
echo "tables:     $log"
exit $status
