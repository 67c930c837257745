#!/usr/bin/env bash
# Opening and streaming models: bytes per point, time to the first frame and to full detail,
# and the cost of rendering page by page (records decoded during the traversal) against the
# whole decoded hierarchy in memory, on the dragon and on a generated 20-million-point cloud.
#   bash bench/paged.sh [WORKDIR]      (BENCH_QUICK=1: the dragon only)
# Wall times of whole `pointillist` runs (process start to PNG written), so they include opening
# the file; the baseline of each row is stated in it.
set -euo pipefail
cd "$(dirname "$0")/.."
cli=build/release/pointillist
[ -x "$cli" ] || { echo "bench: build first (make build)" >&2; exit 1; }
models="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
work=${1:-$(mktemp -d)}
mkdir -p "$work"

seconds() {  # seconds CMD...: wall time of one run
  local t0 t1
  t0=$(date +%s.%N); "$@" >/dev/null; t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }'
}
median_ms() {  # median of the frames' "ms" from the 10th frame on
  jq -r '[.frames[9:][] | .ms] | sort |
    if length == 0 then "nan" else .[((length + 1) / 2 | floor) - 1] end' "$1"
}

rows() {  # rows NAME MODEL.ptl POINTS
  local name=$1 model=$2 points=$3 size
  size=$(stat -c %s "$model")
  printf '%-10s %-42s %12s\n' "$name" "file size, bytes per point" \
    "$(awk -v s="$size" -v n="$points" 'BEGIN { printf "%.1f MB, %.2f", s / 1e6, s / n }')"
  local first full whole
  first=$(seconds "$cli" render "$model" -o "$work/p.png" --progressive 1 -q)
  "$cli" render "$model" -o "$work/p.png" --progressive 1 -q --stats "$work/first.json"
  full=$(seconds "$cli" render "$model" -o "$work/p.png" --memory 1000G -q)
  whole=$(seconds "$cli" render "$model" -o "$work/p.png" -q)
  printf '%-10s %-42s %12s\n' "" "first frame, s (bytes read for it)" \
    "$first ($(jq -r '.frames[0].bytes_read' "$work/first.json"))"
  printf '%-10s %-42s %12s\n' "" "full detail page by page, s" "$full"
  printf '%-10s %-42s %12s\n' "" "baseline: decode whole + render, s" "$whole"
  # Steady-state frames: the same view 40 times, paged (everything resident after a few frames)
  # against the whole hierarchy in memory.
  "$cli" render "$model" -o "$work/p.png" --progressive 40 --read-per-frame 1000G -q \
    --stats "$work/paged.json"
  "$cli" render "$model" -o "$work/p.png" --refine 40 -q --stats "$work/mem.json"
  local pm mm
  pm=$(median_ms "$work/paged.json"); mm=$(median_ms "$work/mem.json")
  printf '%-10s %-42s %12s\n' "" "frame ms: paged / in memory (ratio)" \
    "$pm / $mm ($(awk -v a="$pm" -v b="$mm" 'BEGIN { printf "%.2f", a / b }'))"
  # Coarse views (a billion points at 1280x720 have about a thousand points a pixel): pages are
  # read a level at a time; the baseline is the same pages read whole (resident_page_bytes).
  local size
  for size in 320x180 160x90; do
    "$cli" render "$model" -o "$work/p.png" --size "$size" --memory 1000G -q \
      --stats "$work/coarse.json"
    printf '%-10s %-42s %12s\n' "" "$size: MB read / pages whole (ratio)" \
      "$(jq -r '"\(.bytes_read / 1e6 * 10 | round / 10) / \(.resident_page_bytes / 1e6 * 10 | round / 10) (\(.bytes_read / .resident_page_bytes * 100 | round / 100))"' "$work/coarse.json")"
  done
}

echo "== opening and streaming models (1280x720, 1 px threshold)"
if [ -f "$models/dragon_vrip.ply.gz" ]; then
  "$cli" convert -q "$models/dragon_vrip.ply.gz" -o "$work/dragon.ptl"
  rows dragon "$work/dragon.ptl" 437645
fi
if [ -z "${BENCH_QUICK:-}" ]; then
  [ -f "$work/cloud20m.ply" ] || "$cli" generate -q --points 20000000 --with-normals \
    -o "$work/cloud20m.ply"
  "$cli" convert -q "$work/cloud20m.ply" -o "$work/cloud20m.ptl"
  rm -f "$work/cloud20m.ply"
  rows "20M cloud" "$work/cloud20m.ptl" 20000000
fi
