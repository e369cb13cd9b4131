#!/usr/bin/env bash
# Configure with benchmarks on, build every benchmark, run them all, then the peer comparisons
# (OpenFOAM, dense RBF; Gmsh runs inside curving_bench), collect their JSON lines into one file
# and draw the SVG plots beside it. Default sizes finish in a few minutes each on a 2-core
# machine; --full runs the sizes the issues ask for (>= 1M elements/nodes: much longer).
#
#   benchmarks/run_all.sh [--full] [--build-dir DIR] [--out FILE] [--jobs N] [--no-build] [--no-peers]
#                         [--baseline GIT_REF] [--only NAME,NAME...]
#
# The output file holds, per benchmark, a {"benchmark_run": ...} line (program, arguments, load
# average before it, exit code, wall seconds) followed by that program's own JSON lines. The
# readable tables go to the terminal and to FILE.log. At the end, targets.py prints the speed
# targets of the issues with this build's figures.
#
# --baseline GIT_REF builds the library of that commit (git archive into BUILD/baseline-src)
# with this tree's benchmarks, and runs each benchmark against it right after this build's run,
# so both see the same machine state; its JSON lines carry "build":"baseline" and the targets
# table shows its figures and the ratios. A benchmark that does not compile against the older
# library is reported and skipped.
#
# --only runs the named benchmarks alone (e.g. --only conversion_bench,io_bench,curve_mesh_program,demo_orders,move_mesh_section,defaults_bench,wing_vs_gmsh,conditioning_bench,openfoam_plugin).
#
# Programs and benchmarks run with glibc's huge-page heap (GLIBC_TUNABLES, see
# include/meshmotion/core/process_memory.hpp) for both builds; MESHMOTION_HUGE_PAGES=0 runs
# without.
set -uo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source_dir="$(dirname "$here")"
build_dir="$source_dir/build-bench"
full=0
build=1
peers=1
jobs=1
out=""
baseline=""
only=""

while [[ $# -gt 0 ]]; do
  case "$1" in
    --full) full=1 ;;
    --no-build) build=0 ;;
    --no-peers) peers=0 ;;
    --build-dir) build_dir="$2"; shift ;;
    --out) out="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    --baseline) baseline="$2"; shift ;;
    --only) only=",$2,"; shift ;;
    -h|--help) sed -n '2,28p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
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
  [conversion_bench]="--quick"
  [pu_rbf_bench]="--quick"
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
  [conversion_bench]=""
  [pu_rbf_bench]=""
  [quality_bench]=""
  [delaunay_bench]="100000 1000000"
  [rbf_bench]="126"
  [interpolation_bench]=""
  [elasticity_bench]=""
  [curving_bench]=""
  [bump3d_bench]="0 1 2"
  [cholmod_bench]="126 3"
)
order=(io_bench conversion_bench pu_rbf_bench quality_bench rbf_bench interpolation_bench elasticity_bench delaunay_bench curving_bench bump3d_bench cholmod_bench)
# Peer scripts: they take the build folder and a work folder, install their peer with apt-get
# when it is absent, and report it missing when that fails.
peer_scripts=(openfoam_peer dense_rbf_peer)

benches=()
for name in "${order[@]}"; do
  [[ -f "$here/$name.cpp" ]] && [[ -z "$only" || "$only" == *",$name,"* ]] && benches+=("$name")
done
targets=("${benches[@]}" curve_mesh)
[[ $peers == 1 && -z "$only" ]] && targets+=(motion_peer_bench python_overhead_peer python_mpi_overhead_peer meshmotion_python)
# The parallel layer's benchmark exists when MPI, PETSc and METIS were found at configure time.
mpi_targets=(mpi_bench)

{
  echo "# $(date -u +%FT%TZ)  nproc=$(nproc)  $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')"
  echo "# $(c++ --version | head -1)  mode=$([[ $full == 1 ]] && echo full || echo quick)"
} | tee -a "$log"

# Both builds get the huge-page heap the programs ask for, so their ratio is the code's.
if [[ "${MESHMOTION_HUGE_PAGES:-1}" != 0 ]] && grep -q '\[madvise\]' /sys/kernel/mm/transparent_hugepage/enabled 2>/dev/null; then
  export GLIBC_TUNABLES="${GLIBC_TUNABLES:+$GLIBC_TUNABLES:}glibc.malloc.hugetlb=1"
fi
echo "# GLIBC_TUNABLES=${GLIBC_TUNABLES:-}" | tee -a "$log"

baseline_dir="$build_dir/baseline"
if [[ -n "$baseline" && $build == 1 ]]; then
  # The older library with this tree's benchmarks, so both builds run the same benchmark code.
  base_src="$build_dir/baseline-src"
  rm -rf "$base_src" && mkdir -p "$base_src"
  git -C "$source_dir" archive "$baseline" | tar -x -C "$base_src" \
    || { echo "run_all.sh: cannot export $baseline from git" >&2; exit 1; }
  rm -rf "$base_src/benchmarks" && cp -r "$here" "$base_src/benchmarks"
  echo "# baseline: $baseline = $(git -C "$source_dir" rev-parse --short "$baseline")" | tee -a "$log"
  cmake -S "$base_src" -B "$baseline_dir" -DCMAKE_BUILD_TYPE=Release -DMESHMOTION_BUILD_BENCHMARKS=ON \
    -DMESHMOTION_SHARED_DATA_DIR="$source_dir/../shared/data" >> "$log" 2>&1 \
    || { echo "run_all.sh: baseline configure failed, see $log" >&2; exit 1; }
  for target in "${targets[@]}"; do
    cmake --build "$baseline_dir" --target "$target" -j"$jobs" >> "$log" 2>&1 \
      || echo "run_all.sh: $target does not build against $baseline: no baseline figures for it" | tee -a "$log" >&2
  done
fi

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
  if [[ "$name" == baseline:* ]]; then
    grep '^{' "$build_dir/$name.out" | sed 's/^{/{"build":"baseline",/' >> "$out"
  else
    grep '^{' "$build_dir/$name.out" >> "$out"
  fi
  [[ $rc == 0 ]] || { echo "run_all.sh: $name exited with $rc" | tee -a "$log" >&2; status=1; }
}

# curve_mesh on the 30P30N mesh, the whole program with its .msh and .vtu outputs: the median
# wall time of 9 runs (single runs on a shared virtual machine spread over ±30%), as one JSON line.
program_case() {
  local program="$1" data="$source_dir/../shared/data/su2_30p30n_rans_L1_coarse.su2" work times=()
  if [[ ! -f "$data" ]]; then echo "program_case: $data not found, skipped"; return 0; fi
  work="$(mktemp -d)"
  for _ in 1 2 3 4 5 6 7 8 9; do
    local start=$(date +%s%N)
    "$program" "$data" -o "$work/curved.msh" > /dev/null || { rm -rf "$work"; return 1; }
    times+=($(( ($(date +%s%N) - start) / 1000 )))
  done
  rm -rf "$work"
  local median
  median=$(printf '%s\n' "${times[@]}" | sort -n | sed -n 5p)
  printf 'curve_mesh 30P30N (.msh + .vtu): median of 9 runs %d.%06d s\n' $((median / 1000000)) $((median % 1000000))
  printf '{"bench":"program","case":"curve_mesh-30p30n","median_s":%d.%06d}\n' $((median / 1000000)) $((median % 1000000))
}

# curve_mesh on its built-in demo at orders 2 and 4 to 8 (the whole program, .msh and .vtu
# written; order 4 first, the reference of the ratios): the median of 3 runs each, its ratio
# to order 4's, and the certified minimum and invalid count the program reports, one JSON
# line per order.
demo_orders_case() {
  local program="$1" work p4=0
  work="$(mktemp -d)"
  for order in 4 2 5 6 7 8; do
    local times=() median report
    for _ in 1 2 3; do
      local start=$(date +%s%N)
      report=$("$program" --demo --order "$order" -o "$work/demo.msh" --json) || { rm -rf "$work"; return 1; }
      times+=($(( ($(date +%s%N) - start) / 1000 )))
    done
    median=$(printf '%s\n' "${times[@]}" | sort -n | sed -n 2p)
    [[ $order == 4 ]] && p4=$median
    read -r min invalid < <(printf '%s' "$report" | python3 -c \
      'import json, sys; r = json.load(sys.stdin); print(r["min_scaled_jacobian"], r["invalid"])')
    printf 'curve_mesh --demo --order %d: median of 3 runs %d.%06d s, %d.%03d x order 4, min %s, invalid %s\n' "$order" \
      $((median / 1000000)) $((median % 1000000)) $((median / p4)) $(( (median * 1000 / p4) % 1000 )) "$min" "$invalid"
    printf '{"bench":"program","case":"curve_mesh-demo-p%d","median_s":%d.%06d,"ratio_to_p4":%d.%03d,"min_scaled_jacobian":%s,"invalid":%s}\n' \
      "$order" $((median / 1000000)) $((median % 1000000)) $((median / p4)) $(( (median * 1000 / p4) % 1000 )) "$min" "$invalid"
  done
  rm -rf "$work"
}

# move_mesh on the airFoil2D case (one cell thick, OpenFOAM's 2D), walls turned 15 degrees with
# linear elasticity: as its 2D section (the default) and in 3D (--keep-3d), in turn, 3 runs
# each; the medians and the median of the paired ratios, as one JSON line.
section_case() {
  local program="$1" data="$source_dir/../shared/data/openfoam_airFoil2D_polyMesh" work section=() in_3d=() ratios=()
  if [[ ! -d "$data" ]]; then echo "section_case: $data not found, skipped"; return 0; fi
  work="$(mktemp -d)"
  local flags=(--group walls --rotate 15 --fixed inlet --fixed outlet --method le)
  for _ in 1 2 3; do
    local start=$(date +%s%N) t2 t3
    "$program" "$data" -o "$work/moved.vtu" "${flags[@]}" --center 0.25,0 > /dev/null || { rm -rf "$work"; return 1; }
    t2=$(( ($(date +%s%N) - start) / 1000 ))
    start=$(date +%s%N)
    "$program" "$data" -o "$work/moved.vtu" "${flags[@]}" --center 0.25,0,0 --keep-3d > /dev/null || { rm -rf "$work"; return 1; }
    t3=$(( ($(date +%s%N) - start) / 1000 ))
    section+=("$t2"); in_3d+=("$t3"); ratios+=("$(( t2 * 1000000 / t3 ))")
  done
  rm -rf "$work"
  local s3 d3 r
  s3=$(printf '%s\n' "${section[@]}" | sort -n | sed -n 2p)
  d3=$(printf '%s\n' "${in_3d[@]}" | sort -n | sed -n 2p)
  r=$(printf '%s\n' "${ratios[@]}" | sort -n | sed -n 2p)
  printf 'move_mesh airFoil2D le 15 deg: as its 2D section %d.%06d s, in 3D %d.%06d s, ratio 0.%06d\n' \
    $((s3 / 1000000)) $((s3 % 1000000)) $((d3 / 1000000)) $((d3 % 1000000)) "$r"
  printf '{"bench":"program","case":"move_mesh-airfoil2d-le","section_s":%d.%06d,"in_3d_s":%d.%06d,"ratio":%d.%06d}\n' \
    $((s3 / 1000000)) $((s3 % 1000000)) $((d3 / 1000000)) $((d3 % 1000000)) $((r / 1000000)) $((r % 1000000))
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
  if [[ -n "$baseline" && -x "$baseline_dir/benchmarks/$name" ]]; then
    # shellcheck disable=SC2086
    run "baseline:$name" "$baseline_dir/benchmarks/$name" $args
  fi
done
if [[ -x "$build_dir/examples/curve_mesh" && ( -z "$only" || "$only" == *",curve_mesh_program,"* ) ]]; then
  run curve_mesh_program program_case "$build_dir/examples/curve_mesh"
  [[ -n "$baseline" && -x "$baseline_dir/examples/curve_mesh" ]] \
    && run "baseline:curve_mesh_program" program_case "$baseline_dir/examples/curve_mesh"
fi
if [[ -x "$build_dir/examples/curve_mesh" && ( -z "$only" || "$only" == *",demo_orders,"* ) ]]; then
  run demo_orders demo_orders_case "$build_dir/examples/curve_mesh"
fi
if [[ -x "$build_dir/examples/move_mesh" && ( -z "$only" || "$only" == *",move_mesh_section,"* ) ]]; then
  run move_mesh_section section_case "$build_dir/examples/move_mesh"
fi
# The programs' defaults beside the options the benchmarks set by hand, on the same cases
# (this build only: the comparison is within it).
if [[ -x "$build_dir/examples/curve_mesh" && ( -z "$only" || "$only" == *",defaults_bench,"* ) ]]; then
  move_mesh=()
  [[ -x "$build_dir/examples/move_mesh" ]] && move_mesh=(--move-mesh "$build_dir/examples/move_mesh")
  run defaults_bench python3 "$here/defaults_bench.py" "$build_dir/examples/curve_mesh" "${move_mesh[@]}" \
    --data "$source_dir/../shared/data"
fi
# The swept wing curved at orders 2 to 4 by the defaults and by Gmsh's HighOrderOptimize on the
# same linear mesh and model (issue 71; needs Gmsh's Python module, and says so without it).
if [[ -x "$build_dir/examples/curve_mesh" && ( -z "$only" || "$only" == *",wing_vs_gmsh,"* ) ]]; then
  wing_args=()
  [[ $full == 1 ]] && wing_args=(--full)
  run wing_vs_gmsh /usr/bin/python3 "$here/wing_vs_gmsh.py" "$build_dir/examples/curve_mesh" \
    "$build_dir/examples/mesh_quality" --work "$build_dir/wing_vs_gmsh" "${wing_args[@]}"
fi
# The RBF's conditioning on a RANS grid: thinned by default, beside the system as it is
# (needs the Python module, which --no-peers does not build: a build that has it runs it).
if [[ -f "$build_dir/python/meshmotion/__init__.py" && ( -z "$only" || "$only" == *",conditioning_bench,"* ) ]]; then
  run conditioning_bench env PYTHONPATH="$build_dir/python" /usr/bin/python3 "$here/conditioning_bench.py" \
    --data "$source_dir/../shared/data"
fi
# A plate turned to a half turn inside a held box from one setup (issue 68), serial and at 2
# ranks (needs the Python module, Gmsh's and mpi4py; it says what is missing).
if [[ -f "$build_dir/python/meshmotion/__init__.py" && ( -z "$only" || "$only" == *",plate_turn_bench,"* ) ]]; then
  plate_flags=()
  mpiexec --version 2>&1 | grep -qiE "open ?mpi|openrte" && plate_flags=(--oversubscribe --allow-run-as-root)
  run plate_turn_bench env PYTHONPATH="$build_dir/python" mpiexec "${plate_flags[@]}" -n 2 /usr/bin/python3 \
    "$here/plate_turn_bench.py"
  run plate_turn_programs env PYTHONPATH="$build_dir/python" /usr/bin/python3 "$here/plate_turn_bench.py" \
    --programs "$build_dir/examples"
fi
# The OpenFOAM plugin in OpenFOAM's time loop against displacementLaplacian (it says why when
# the plugin or OpenFOAM is missing).
if [[ -z "$only" || "$only" == *",openfoam_plugin,"* ]]; then
  run openfoam_plugin "$here/openfoam_plugin.sh" "$build_dir" "$build_dir/openfoam_plugin"
fi
# The distributed movers at 1, 2 and 4 ranks (4 is oversubscribed on two cores and says so),
# each against the serial mover in the same process. Rounds of the three, in turn: targets.py
# takes the median over rounds of N ranks' setup over 1 rank's in the same round (two separate
# runs on this machine swing by ±20%, and the 1-rank run is the denominator of every ratio).
if [[ -x "$build_dir/benchmarks/mpi_bench" && ( -z "$only" || "$only" == *",mpi_bench,"* ) ]]; then
  mpi_flags=()
  # Open MPI's mpiexec says "OpenRTE" or "Open MPI" depending on its version.
  mpiexec --version 2>&1 | grep -qiE "open ?mpi|openrte" && mpi_flags=(--oversubscribe --allow-run-as-root)
  for round in $(seq 1 "$([[ $full == 1 ]] && echo 3 || echo 5)"); do
    for ranks in 1 2 4; do
      run "mpi_bench_${ranks}_round$round" mpiexec "${mpi_flags[@]}" -n "$ranks" "$build_dir/benchmarks/mpi_bench" \
        "$([[ $full == 1 ]] && echo 126 || echo 64)"
    done
  done
fi
if [[ $peers == 1 && -z "$only" ]]; then
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
python3 "$here/targets.py" "$out" | tee -a "$log"
echo "JSON lines: $out" | tee -a "$log"
echo "tables:     $log"
exit $status
