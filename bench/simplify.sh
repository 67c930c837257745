#!/usr/bin/env bash
# Point-set simplification, the table of specs/occlusion-simplification-hybrid.md §2.7: every
# method on the analytic sphere, torus and cube (1 M samples to 100 k, 20 k and 5 k; exact
# distances), the dragon at 10, 5 and 1 % (against its own triangles) and the lion scan (against
# its points' local planes), with the time and peak memory of each `simplify` process; and the
# cut of our own QSplat hierarchy at one node size (qsplat-cut), what it draws above the leaves.
#   bash bench/simplify.sh [WORKDIR]      (SIMPLIFY_QUICK=1: the torus at 20 k and the dragon at 5 % only)
# Distances are in 1e-3 of the reference's bounding-box diagonal; rms is the symmetric one,
# sqrt((forward^2 + backward^2) / 2); "×voxel" is the backward RMS (the spec's bars) against the
# voxel grid's, the baseline of each row group.
set -euo pipefail
cd "$(dirname "$0")/.."
cli=build/release/pointillist
[ -x "$cli" ] || { echo "bench: build first (make build)" >&2; exit 1; }
models="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
work=${1:-$(mktemp -d)}
mkdir -p "$work"
methods="voxel voxel-nearest random hierarchical incremental quadric qsplat-cut"

echo "| input | points | method | forward rms | backward rms | rms | ×voxel | Hausdorff | holes % | normal° mean / p95 | s | peak MB |"
echo "| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"

# row NAME INPUT TARGET REFERENCE-ARGS...
row_group() {
  local name=$1 input=$2 target=$3
  shift 3
  local voxel_rms=""
  for m in $methods; do
    local t
    t=$( { /usr/bin/time -f "%e %M" "$cli" simplify $input -o "$work/s.ply" --points "$target" \
           --method "$m" -q; } 2>&1 | tail -1)
    "$cli" compare-surface "$work/s.ply" "$@" --json "$work/e.json" > /dev/null
    local rms
    rms=$(jq -r '((.forward.rms * .forward.rms + .backward.rms * .backward.rms) / 2 | sqrt)' "$work/e.json")
    [ "$m" = voxel ] && voxel_rms=$(jq -r '.backward.rms' "$work/e.json")
    jq -r --arg name "$name" --arg m "$m" --arg rms "$rms" --arg base "$voxel_rms" --arg t "$t" '
      ($t | split(" ")) as $tm |
      "| \($name) | \(.splats) | \($m) | \(.forward.rms * 1e4 | round / 1e4) | \(.backward.rms * 1e4 | round / 1e4) | \($rms | tonumber * 1e4 | round / 1e4) | \(if ($base | tonumber) > 0 then (.backward.rms / ($base | tonumber) * 100 | round / 100) else "-" end) | \(.hausdorff * 1e3 | round / 1e3) | \(.hole_fraction * 1e5 | round / 1e3) | \(.normal_mean_deg * 100 | round / 100) / \(.normal_p95_deg * 100 | round / 100) | \($tm[0]) | \($tm[1] | tonumber / 1024 | round) |"' \
      "$work/e.json"
  done
}

if [ -n "${SIMPLIFY_QUICK:-}" ]; then
  "$cli" generate --scene torus --points 1000000 --seed 1 --with-normals -o "$work/torus.ply" -q
  row_group "torus" "$work/torus.ply" 20000 --reference-scene torus
else
  for shape in sphere torus cube; do
    "$cli" generate --scene $shape --points 1000000 --seed 1 --with-normals -o "$work/$shape.ply" -q
    for target in 100000 20000 5000; do
      row_group "$shape" "$work/$shape.ply" $target --reference-scene $shape
    done
  done
fi

dragon="$models/dragon_vrip.ply.gz"
if [ -f "$dragon" ]; then
  targets="43765 21882 4376"
  [ -n "${SIMPLIFY_QUICK:-}" ] && targets=21882
  for target in $targets; do
    row_group "dragon" "$dragon" $target --reference "$dragon"
  done
else
  echo "(dragon not fetched: bash scripts/fetch-models.sh)"
fi

lion="$models/lion_takanawa_las"
if [ -d "$lion" ] && [ -z "${SIMPLIFY_QUICK:-}" ]; then
  # The lion's 200 tiles as one cloud (its reference: the same points' local planes).
  "$cli" convert "$lion"/*.las -o "$work/lion.ply" -q
  n=$(head -c 4096 "$work/lion.ply" | grep -a "element vertex" | awk '{print $3}')
  for pct in 10 5 1; do
    row_group "lion" "$work/lion.ply" $(( n * pct / 100 )) --reference "$work/lion.ply"
  done
fi

# Images (spec §2.7): each method's 5 % of the dragon rendered at the README's four views with
# circle and ellipse splats, against the mesh drawn by `render --mode reference`, all with the
# mesh's camera (its view sphere, as `info` prints it; the default orbit distance of fov 30°).
if [ -f "$dragon" ]; then
  read -r cx cy cz r < <("$cli" info "$dragon" | awk '/^view sphere:/ {
    gsub(/[(),]/, " "); print $4, $5, $6, $8 }')
  views="0,0 135,20 270,-10 60,45"
  cam() {  # cam AZ EL: the --eye/--target of orbit_camera for up = +y
    awk -v az="$1" -v el="$2" -v cx="$cx" -v cy="$cy" -v cz="$cz" -v r="$r" 'BEGIN {
      pi = atan2(0, -1); a = az * pi / 180; e = el * pi / 180; d = 1.05 / sin(15 * pi / 180) * r
      printf "--eye %.7g,%.7g,%.7g --target %.7g,%.7g,%.7g\n", cx + d * cos(e) * sin(a),
        cy + d * sin(e), cz + d * cos(e) * cos(a), cx, cy, cz }'
  }
  for v in $views; do
    "$cli" render "$dragon" --mode reference -o "$work/ref_${v}.png" --size 640x480 $(cam ${v%,*} ${v#*,}) -q
  done
  echo
  echo "| dragon 5 % | splat | PSNR dB | SSIM | silhouette IoU | hole px |"
  echo "| --- | --- | ---: | ---: | ---: | ---: |"
  for m in voxel hierarchical incremental quadric qsplat-cut; do
    "$cli" simplify "$dragon" -o "$work/img.ptl" --points 21882 --method "$m" -q
    for k in circle ellipse; do
      : > "$work/img.jsonl"
      for v in $views; do
        "$cli" render "$work/img.ptl" -o "$work/img.png" --size 640x480 --splat $k $(cam ${v%,*} ${v#*,}) -q
        "$cli" compare "$work/ref_${v}.png" "$work/img.png" --json - >> "$work/img.jsonl"
      done
      jq -s -r --arg m "$m" --arg k "$k" '"| \($m) | \($k) | \(map(.psnr_db) | add / length * 100 | round / 100) | \(map(.ssim) | add / length * 1000 | round / 1000) | \(map(.silhouette_iou) | add / length * 1000 | round / 1000) | \(map(.hole_pixels) | add) |"' "$work/img.jsonl"
    done
  done
fi
