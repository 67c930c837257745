#!/usr/bin/env bash
# Pointillist's conversion against PotreeConverter 2 on the same LAS input, in one sitting: wall
# time, CPU time, CPU/wall, points/s and peak resident memory (whole processes, /usr/bin/time),
# Pointillist's as ratios over PotreeConverter's. PotreeConverter is built outside this
# repository from its public source (nothing of it is committed), e.g.
#   git clone https://github.com/potree/PotreeConverter && cmake -S PotreeConverter -B pc-build \
#     -DCMAKE_BUILD_TYPE=Release && cmake --build pc-build -j2     (needs libtbb-dev)
# PotreeConverter computes no normals or radii; Pointillist computes both, orients the normals
# and writes a .ptl v2 file.
#
#   bash bench/potree.sh --potree PATH [--bin PATH] [--work DIR] [--points N] [--memory SIZE]
#
#   --points N     points of the generated cloud with colours (default 20000000; LAS 1.2 at
#                  26 bytes a point)
#   --memory SIZE  Pointillist's budget (default: its own, half the physical memory)
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${POINTILLIST_BIN:-build/release/pointillist}"
to_las="${PLY_TO_LAS:-build/release/bench/ply_to_las}"
work="${POTREE_BENCH_WORK:-/tmp/pointillist-bench-potree}"
points=20000000
memory=""
potree=""
while [ $# -gt 0 ]; do
  case "$1" in
    --potree) potree="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --points) points="$2"; shift 2 ;;
    --memory) memory="$2"; shift 2 ;;
    *) echo "potree.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -x "$potree" ] || { echo "potree.sh: give --potree PATH to a PotreeConverter 2 binary" >&2; exit 1; }
[ -x "$bin" ] || { echo "potree.sh: no binary at $bin (make build)" >&2; exit 1; }
[ -x "$to_las" ] || { echo "potree.sh: no ply_to_las at $to_las (build the bench targets)" >&2; exit 1; }
mkdir -p "$work"
las="$work/cloud-$points.las"
if [ ! -f "$las" ]; then
  "$bin" generate -o "$work/cloud.ply" --points "$points" --colors -q
  "$to_las" "$work/cloud.ply" "$las"
  rm -f "$work/cloud.ply"
fi

# measure NAME CMD...: prints "NAME wall cpu peak_kb".
measure() {
  local name="$1"; shift
  /usr/bin/time -f "%e %U %S %M" -o "$work/$name.time" "$@" > "$work/$name.log" 2>&1
  read -r wall user sys peak < "$work/$name.time"
  echo "$name $wall $(echo "$user + $sys" | bc) $peak"
}

rm -rf "$work/potree-out" "$work/pointillist.ptl"
results=("$(measure potree "$potree" "$las" -o "$work/potree-out")")
results+=("$(measure pointillist "$bin" convert "$las" -o "$work/pointillist.ptl" ${memory:+--memory "$memory"})")

echo "input: $points points, $las ($(du -h "$las" | cut -f1))"
printf '%-12s %8s %8s %8s %10s %10s %8s %8s\n' run wall_s cpu_s cpu/wall Mpoints/s peak_MB \
  wall/PC peak/PC
base_wall="" base_peak=""
for r in "${results[@]}"; do
  read -r name wall cpu peak <<< "$r"
  if [ "$name" = potree ]; then base_wall=$wall; base_peak=$peak; fi
  awk -v n="$name" -v w="$wall" -v c="$cpu" -v p="$peak" -v pts="$points" -v bw="$base_wall" \
      -v bp="$base_peak" 'BEGIN {
    printf "%-12s %8.1f %8.1f %8.2f %10.3f %10.0f %8.2f %8.2f\n", n, w, c, c / w,
           pts / w / 1e6, p / 1024, w / bw, p / bp }'
done
grep -h "chunks\|one piece" "$work/pointillist.log" || true
