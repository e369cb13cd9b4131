#!/usr/bin/env bash
# Times the compilation of a consumer translation unit (benchmarks/compile_time/consumer.cpp:
# read_mesh, RbfMover<3>, quality_report, curve_mesh) against the headers alone and against
# the compiled library meshmotion::compiled, at -O0 and -O2, alternating the two modes.
# Prints a table and one JSON line per case (median seconds, peak memory, ratio).
#
#   benchmarks/compile_time.sh [BUILD_DIR] [RUNS]     # BUILD_DIR holds libmeshmotion.a (default: build)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
runs="${2:-3}"
lib="$build/libmeshmotion.a"
if [[ ! -f "$lib" ]]; then
  echo "compile_time.sh: $lib not found (build the target meshmotion_compiled first)" >&2
  exit 1
fi
cxx="${CXX:-g++}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
flags=(-std=c++20 -fopenmp -I"$root/include" -isystem /usr/include/eigen3)

# seconds and peak kilobytes of one compile+link
measure() {
  local mode="$1" opt="$2" out="$work/consumer_${mode}_${opt}"
  local extra=()
  [[ "$mode" == compiled ]] && extra=(-DMESHMOTION_COMPILED "$lib")
  local start end
  start=$(date +%s.%N)
  /usr/bin/time -f "%M" -o "$work/mem" "$cxx" "${flags[@]}" "-$opt" "$root/benchmarks/compile_time/consumer.cpp" "${extra[@]}" -o "$out"
  end=$(date +%s.%N)
  echo "$(echo "$end - $start" | bc) $(cat "$work/mem")"
}

median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

printf "%-4s %-12s %10s %10s %8s\n" opt mode seconds peak_MB ratio
for opt in O0 O2; do
  : > "$work/header_only.s"; : > "$work/compiled.s"; : > "$work/header_only.m"; : > "$work/compiled.m"
  for ((r = 0; r < runs; ++r)); do
    for mode in header_only compiled; do
      read -r s m < <(measure "$mode" "$opt")
      echo "$s" >> "$work/$mode.s"
      echo "$m" >> "$work/$mode.m"
    done
  done
  h=$(median < "$work/header_only.s"); c=$(median < "$work/compiled.s")
  hm=$(median < "$work/header_only.m"); cm=$(median < "$work/compiled.m")
  ratio=$(printf "%.3f" "$(echo "scale=6; $c / $h" | bc)")
  printf "%-4s %-12s %10.2f %10.0f %8s\n" "$opt" header_only "$h" "$(echo "$hm / 1024" | bc)" 1
  printf "%-4s %-12s %10.2f %10.0f %8s\n" "$opt" compiled "$c" "$(echo "$cm / 1024" | bc)" "$ratio"
  h=$(printf "%.2f" "$h"); c=$(printf "%.2f" "$c")
  echo "{\"bench\":\"compile_time\",\"case\":\"consumer_${opt}\",\"runs\":$runs,\"header_only_seconds\":$h,\"compiled_seconds\":$c,\"header_only_peak_kb\":$hm,\"compiled_peak_kb\":$cm,\"ratio\":$ratio,\"target_seconds\":15}"
done
