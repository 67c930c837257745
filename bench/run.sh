#!/usr/bin/env bash
# Runs every benchmark and prints the figures as ratios against baselines measured in the same run.
#   bash bench/run.sh            all benchmarks (several minutes: includes a 10-million-point cloud)
#   BENCH_QUICK=1 bash bench/run.sh   skip the 10-million-point end-to-end conversion
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/release
cli=$bin/pointillist
[ -x "$cli" ] || { echo "bench: build first (make build)" >&2; exit 1; }
models="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

for b in io prep lod render; do
  if [ -x "$bin/bench/${b}_bench" ]; then
    echo "== ${b}_bench"
    "$bin/bench/${b}_bench" --benchmark_filter='^((?!Small).)*$' --benchmark_min_time=0.5 2>&1 |
      grep -v '^\*\*\*'
  fi
done

seconds() {  # seconds CMD...: wall time of one run
  local t0 t1
  t0=$(date +%s.%N); "$@" >/dev/null; t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.6f", b - a }' 
}

echo
echo "== end-to-end convert (wall time; baseline = reading the same input bytes once)"
printf '%-34s %10s %12s %12s %10s\n' input points "convert s" "baseline s" ratio
row() {  # row NAME POINTS INPUT BASELINE_CMD...
  local name=$1 points=$2 input=$3; shift 3
  local c b
  c=$(seconds "$cli" convert -q "$input" -o "$work/out.ptl")
  b=$(seconds "$@")
  printf '%-34s %10s %12.3f %12.3f %10.1f\n' "$name" "$points" "$c" "$b" "$(awk -v a="$c" -v b="$b" 'BEGIN { printf "%.3f", a / b }')"
}
if [ -f "$models/dragon_vrip.ply.gz" ]; then
  row "dragon_vrip.ply.gz (mesh)" 437645 "$models/dragon_vrip.ply.gz" \
    sh -c "gzip -dc '$models/dragon_vrip.ply.gz' > /dev/null"
fi
if [ -z "${BENCH_QUICK:-}" ]; then
  "$cli" generate -q --points 10000000 -o "$work/cloud10m.ply"
  row "generated cloud (no normals)" 10000000 "$work/cloud10m.ply" \
    sh -c "cat '$work/cloud10m.ply' > /dev/null"
fi
