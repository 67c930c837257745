#!/usr/bin/env bash
# Level of detail at 1280x720: QSplat traversal versus Sequential Point Tree (with and without
# chunk culling), their image difference, the share of the SPT list scanned, and the hit rate of
# the frame-time controller, on the dragon and on a generated 10-million-point model.
#   bash bench/lod.sh [WORKDIR]      (bench/run.sh calls it; BENCH_QUICK=1 skips the 10M model)
# Frame times are medians over an orbit of frames (the machine is shared and noisy); the
# baseline of each model is the QSplat traversal measured in the same run.
set -euo pipefail
cd "$(dirname "$0")/.."
cli=build/release/pointillist
[ -x "$cli" ] || { echo "bench: build first (make build)" >&2; exit 1; }
models="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
work=${1:-$(mktemp -d)}
mkdir -p "$work"
frames=${LOD_FRAMES:-24}

# median FIELD FILE: median over the "path" frames of a stats JSON of one numeric field.
median() {
  jq -r --arg f "$1" '[.frames[] | select(.phase == "path") | .[$f]] | sort |
    if length == 0 then "nan" else .[((length + 1) / 2 | floor) - 1] end' "$2"
}
field() {  # field NAME FILE: a top-level field of a stats JSON
  jq -r --arg f "$1" '.[$f] // "nan"' "$2"
}

model_rows() {  # model_rows NAME MODEL.ptl FRAME_MS
  local name=$1 model=$2 target=$3
  local q="$work/q.json" s="$work/s.json"
  "$cli" render "$model" -o "$work/q.png" --path orbit:$frames --stats "$q" -q
  "$cli" render "$model" -o "$work/s.png" --path orbit:$frames --stats "$s" -q --lod spt
  local u="$work/u.json" c="$work/c.json" cu="$work/cu.json"
  "$cli" render "$model" -o "$work/u.png" --path orbit:$frames --stats "$u" -q --lod spt \
    --no-chunk-culling
  # A close-up orbit (0.4 model radii), where chunks leave the frustum, with and without culling.
  "$cli" render "$model" -o "$work/c.png" --path orbit:$frames --stats "$c" -q --lod spt \
    --distance 0.4
  "$cli" render "$model" -o "$work/c.png" --path orbit:$frames --stats "$cu" -q --lod spt \
    --distance 0.4 --no-chunk-culling
  # The last frame of both orbits is the same view: compare the two images.
  local psnr
  psnr=$("$cli" compare "$work/q.png" "$work/s.png" --json - | sed -n 's/.*"psnr_db": \([0-9.a-z]*\).*/\1/p')
  local qt qs qsel st ss ssel
  qt=$(median ms "$q"); qs=$(median splats "$q"); qsel=$(median ms_select "$q")
  st=$(median ms "$s"); ss=$(median splats "$s"); ssel=$(median ms_select "$s")
  printf '%-12s %-16s %9s %11s %10s %12s %10s\n' "$name" "qsplat traversal" "$qt" "$qsel" "$qs" \
    "$(awk -v n="$qs" -v t="$qsel" 'BEGIN { printf "%.1f", (t > 0 ? n / t / 1e3 : 0) }')" "1.00"
  printf '%-12s %-16s %9s %11s %10s %12s %10s\n' "" "spt (chunked)" "$st" "$ssel" "$ss" \
    "$(awk -v n="$ss" -v t="$ssel" 'BEGIN { printf "%.1f", (t > 0 ? n / t / 1e3 : 0) }')" \
    "$(awk -v a="$qsel" -v b="$ssel" -v n="$qs" -v m="$ss" 'BEGIN { if (b > 0 && n > 0) { printf "%.2f", (a / n) / (b / m) } else { print "nan" } }')"
  printf '%-12s %-16s %9s %11s %10s\n' "" "spt, no culling" "$(median ms "$u")" \
    "$(median ms_select "$u")" "$(median splats "$u")"
  printf '%-12s %-16s %9s %11s %10s\n' "" "close-up spt" "$(median ms "$c")" \
    "$(median ms_select "$c")" "$(median splats "$c")"
  printf '%-12s %-16s %9s %11s %10s\n' "" " no culling" "$(median ms "$cu")" \
    "$(median ms_select "$cu")" "$(median splats "$cu")"
  echo "             PSNR qsplat vs spt (same view): $psnr dB"
  # The share of the list scanned, whole model in view and in a close-up (distance 0.4 model
  # radii, where whole chunks leave the frustum): chunk culling's savings.
  echo "             whole model in view:"
  "$cli" info "$model" --spt --view 0,0 --size 1280x720 | grep -E "list:|scans" | sed 's/^ */               /'
  echo "             close-up (--distance 0.4):"
  "$cli" info "$model" --spt --view 0,0 --size 1280x720 --distance 0.4 | grep -E "scans" | sed 's/^ */               /'
  for lod in qsplat spt; do
    local h="$work/h_$lod.json"
    "$cli" render "$model" -o "$work/h.png" --path orbit:60 --frame-ms "$target" --stats "$h" -q \
      --lod "$lod"
    echo "             frame-time control, $lod, target $target ms, 60-frame orbit: hit rate $(field hit_rate "$h")"
  done
}

echo "== level of detail, 1280x720, medians over a $frames-frame orbit (ms; splats/ms in thousands/s)"
printf '%-12s %-16s %9s %11s %10s %12s %10s\n' model scheme "ms/frame" "ms select" splats \
  "k splats/ms" "per-splat x"
if [ -f "$models/dragon_vrip.ply.gz" ]; then
  "$cli" convert -q "$models/dragon_vrip.ply.gz" -o "$work/dragon.ptl"
  model_rows dragon "$work/dragon.ptl" 6
fi
if [ -z "${BENCH_QUICK:-}" ]; then
  [ -f "$work/cloud10m.ply" ] || "$cli" generate -q --points 10000000 -o "$work/cloud10m.ply"
  "$cli" convert -q "$work/cloud10m.ply" -o "$work/cloud10m.ptl"
  model_rows "10M cloud" "$work/cloud10m.ptl" 25
fi
