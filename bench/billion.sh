#!/usr/bin/env bash
# The billion-point run of the README ("A billion points"): a generated cloud with colours (15
# bytes a point in binary PLY) converted under a memory budget, then rendered paged: the first
# frame of a progressive render, and the full-detail frame under a render budget. Prints each
# step's whole-process wall time, CPU time and peak memory, the conversion's phase times, and the
# renders' statistics (bytes read, pages, splats), then removes the input and the model unless
# --keep.
#
#   bash bench/billion.sh [--bin PATH] [--work DIR] [--points N] [--memory SIZE]
#                         [--render-memory SIZE] [--keep]
#
#   --points N            default 1000000000 (a 15 GB input; the chunk folder peaks near 40 GB
#                         beside it and the model is about 8 GB: about 65 GB of free disk)
#   --memory SIZE         the conversion's budget (default 16G)
#   --render-memory SIZE  the paged render's budget (default 2G)
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${POINTILLIST_BIN:-build/release/pointillist}"
work="${BILLION_BENCH_WORK:-/tmp/pointillist-bench-billion}"
points=1000000000
memory=16G
render_memory=2G
keep=0
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --points) points="$2"; shift 2 ;;
    --memory) memory="$2"; shift 2 ;;
    --render-memory) render_memory="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    *) echo "billion.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "billion.sh: no binary at $bin (make build)" >&2; exit 1; }
mkdir -p "$work"
need=$(( points * 65 ))
free=$(df --output=avail -B1 "$work" | tail -1)
[ "$free" -gt "$need" ] || { echo "billion.sh: $work needs about $(( need / 1000000000 )) GB free, has $(( free / 1000000000 ))" >&2; exit 1; }
cloud="$work/cloud-$points.ply" model="$work/cloud-$points.ptl"

# step NAME COMMAND...: runs it, prints "NAME: wall s, cpu s, peak MB".
step() {
  local name="$1"; shift
  /usr/bin/time -f "%e %U %S %M" -o "$work/$name.time" "$@" > "$work/$name.log" 2>&1 \
    || { cat "$work/$name.log" >&2; exit 1; }
  read -r wall user sys peak < "$work/$name.time"
  awk -v n="$name" -v w="$wall" -v u="$user" -v s="$sys" -v p="$peak" \
    'BEGIN { printf "%s: %.1f s wall, %.1f s CPU (%.2f x wall), peak %.0f MB\n", n, w, u + s, (u + s) / w, p / 1024 }'
}

[ -f "$cloud" ] || step generate "$bin" generate -o "$cloud" --points "$points" --colors -q
step convert "$bin" convert "$cloud" -o "$model" --memory "$memory"
grep -E "^(converted|in |phases)" "$work/convert.log"
step first-frame "$bin" render "$model" -o "$work/first.png" --progressive 1 --stats "$work/first.json" -q
step full-frame "$bin" render "$model" -o "$work/full.png" --memory "$render_memory" \
  --stats "$work/full.json" -q
for f in first full; do
  echo "$f frame:"
  grep -oE '"(bytes_read|pages|pages_loaded|pages_evicted|complete|splats|resident_bytes_peak|select|raster|total)": *[0-9a-z.]+' \
    "$work/$f.json" | sort -u | tr '\n' ' '
  echo
done
if [ "$keep" = 0 ]; then rm -f "$cloud" "$model"; fi
