#!/usr/bin/env bash
# Image quality of the compact files against the mesh: the dragon converted to .ptl version 2
# (leaf trims in sixteenths, and in eighths as the first v2 files), to QSplat's .qs and to
# .ptl version 1 (float nodes, no quantization), each rendered with circle and ellipse splats
# at two views and compared with the mesh's own triangles (render --mode reference).
#   bash bench/quality.sh [WORKDIR]          (VIEWS="AZ,EL ...": other views; default 0,0 135,20)
set -euo pipefail
cd "$(dirname "$0")/.."
cli=build/release/pointillist
[ -x "$cli" ] || { echo "bench: build first (make build)" >&2; exit 1; }
models="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
dragon="$models/dragon_vrip.ply.gz"
[ -f "$dragon" ] || { echo "bench: fetch the models first (bash scripts/fetch-models.sh)" >&2; exit 1; }
work=${1:-$(mktemp -d)}
mkdir -p "$work"

"$cli" convert -q "$dragon" -o "$work/v2.ptl"
"$cli" convert -q "$dragon" -o "$work/v2e.ptl" --leaf-trim eighths
"$cli" convert -q "$dragon" -o "$work/v1.ptl" --ptl-version 1
"$cli" convert -q "$dragon" -o "$work/d.qs"
metric() {  # metric NAME JSON
  sed -n "s/.*\"$1\": \([0-9.e+-]*\).*/\1/p" "$2" | head -1
}
printf '%-9s %-8s %-26s %8s %8s %8s\n' view splat model "PSNR dB" SSIM IoU
for view in ${VIEWS:-0,0 135,20}; do
  "$cli" render -q "$dragon" --mode reference --view "$view" -o "$work/ref.png"
  for splat in circle ellipse; do
    for m in v1.ptl v2.ptl v2e.ptl d.qs; do
      "$cli" render -q "$work/$m" --view "$view" --splat "$splat" -o "$work/t.png"
      "$cli" compare "$work/ref.png" "$work/t.png" --json "$work/c.json" >/dev/null
      case $m in
        v1.ptl) label=".ptl v1 (floats)" ;; v2.ptl) label=".ptl v2 (trim 1/16)" ;;
        v2e.ptl) label=".ptl v2 (trim 1/8)" ;; d.qs) label=".qs (QSplat 1.0)" ;;
      esac
      printf '%-9s %-8s %-26s %8s %8s %8s\n' "$view" "$splat" "$label" \
        "$(metric psnr_db "$work/c.json")" "$(metric ssim "$work/c.json")" \
        "$(metric silhouette_iou "$work/c.json")"
    done
  done
done
