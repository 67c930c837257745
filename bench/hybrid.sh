#!/usr/bin/env bash
# Hybrid point/polygon rendering, the acceptance of specs/occlusion-simplification-hybrid.md §3.3:
#  1. a 100-frame zoom into the dragon mesh (eye from 5 to 0.3 view-sphere radii from its centre,
#     geometric steps), drawn by the mesh reference, by the pure SPT and by the hybrid mode from
#     the same .ptl: per frame the hole pixels and the PSNR against the reference, the splats,
#     triangles and ms; summary: frames with holes, the smallest PSNR gain of hybrid over points;
#  2. a ground of 200 × 200 units with 16 dragons (scaled to about 1.5 units, "statues") seen
#     from eye height along a 21-frame walk: the ground as 16 M points (0.05 spacing) with
#     --lod spt, against the ground as its 2 triangles with --lod spt --hybrid; mean ms a frame
#     (the first frame, which builds the point trees, left out) and the ratio (target <= 0.5),
#     and both against the all-triangle reference (the ground's 2 triangles and the dragon mesh,
#     --mode reference): mean PSNR and hole pixels.
#   bash bench/hybrid.sh [WORKDIR]        (HYBRID_QUICK=1: 20 zoom frames, no ground scene)
set -euo pipefail
cd "$(dirname "$0")/.."
cli=build/release/pointillist
ground=build/release/bench/ground_plane
[ -x "$cli" ] && [ -x "$ground" ] || { echo "bench: build first (make build)" >&2; exit 1; }
models="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
dragon="$models/dragon_vrip.ply.gz"
[ -f "$dragon" ] || { echo "bench: fetch the models first (bash scripts/fetch-models.sh)" >&2; exit 1; }
work=${1:-$(mktemp -d)}
mkdir -p "$work"
frames=100
[ "${HYBRID_QUICK:-0}" = 1 ] && frames=20

"$cli" convert "$dragon" -o "$work/dragon.ptl" -q
# The zoom path from the view sphere that `info` prints.
read -r cx cy cz r < <("$cli" info "$work/dragon.ptl" |
  sed -n 's/^view sphere: centre (\(.*\), \(.*\), \(.*\)), radius \([0-9.e-]*\).*/\1 \2 \3 \4/p')
awk -v cx="$cx" -v cy="$cy" -v cz="$cz" -v r="$r" -v n="$frames" 'BEGIN {
  for (i = 0; i < n; ++i) {
    d = 5 * exp(log(0.3 / 5) * i / (n - 1))
    printf "%.7g %.7g %.7g %.7g %.7g %.7g\n", cx, cy, cz + d * r, cx, cy, cz
  }
}' > "$work/zoom.path"
rm -rf "$work/ref" "$work/spt" "$work/hyb"
mkdir -p "$work/ref" "$work/spt" "$work/hyb"
"$cli" render "$dragon" --mode reference --path "$work/zoom.path" --frames-out "$work/ref" \
  -o "$work/ref.png" -q
"$cli" render "$work/dragon.ptl" --lod spt --path "$work/zoom.path" --frames-out "$work/spt" \
  -o "$work/spt.png" --stats "$work/spt.json" -q
"$cli" render "$work/dragon.ptl" --lod spt --hybrid --path "$work/zoom.path" \
  --frames-out "$work/hyb" -o "$work/hyb.png" --stats "$work/hyb.json" -q

echo "Dragon zoom, $frames frames, 1280x720 (every 10th frame; ms of the first frame include building the lists)"
echo
echo "| frame | distance (radii) | points: PSNR dB | holes | splats | ms | hybrid: PSNR dB | holes | splats | triangles | ms |"
echo "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
jq -r '.frames[] | "\(.splats) \(.ms)"' "$work/spt.json" > "$work/spt.txt"
jq -r '.frames[] | "\(.splats) \(.triangles) \(.ms)"' "$work/hyb.json" > "$work/hyb.txt"
: > "$work/rows.txt"
for ((i = 0; i < frames; ++i)); do
  f=$(printf frame_%05d.png "$i")
  p=$("$cli" compare --background 0,0,0 --json - "$work/ref/$f" "$work/spt/$f" |
      jq -r '"\(.psnr_db) \(.hole_pixels)"')
  h=$("$cli" compare --background 0,0,0 --json - "$work/ref/$f" "$work/hyb/$f" |
      jq -r '"\(.psnr_db) \(.hole_pixels)"')
  echo "$i $p $h $(sed -n "$((i + 1))p" "$work/spt.txt") $(sed -n "$((i + 1))p" "$work/hyb.txt")" >> "$work/rows.txt"
done
awk -v n="$frames" '{
  d = 5 * exp(log(0.3 / 5) * $1 / (n - 1))
  if ($1 % 10 == 0 || $1 == n - 1)
    printf "| %d | %.2f | %.2f | %d | %d | %.1f | %.2f | %d | %d | %d | %.1f |\n", $1, d, $2, $3, $6, $7, $4, $5, $8, $9, $10
}' "$work/rows.txt"
echo
awk 'BEGIN { min = 1e9 } {
  gain = $4 - $2; if (gain < min) min = gain
  if ($3 > 0) ph++; if ($5 > 0) hh++
  if (NR > 1) { ps += $7; hs += $10 }
} END {
  printf "frames with holes: points %d, hybrid %d; smallest PSNR gain of hybrid over points %.3f dB; mean ms a frame after the first: points %.1f, hybrid %.1f\n", ph, hh, min, ps / (NR - 1), hs / (NR - 1)
}' "$work/rows.txt"

[ "${HYBRID_QUICK:-0}" = 1 ] && exit 0

# The ground and the statues.
"$ground" "$work/ground_points.ply" 200 0.05
"$ground" "$work/ground_mesh.ply" 200 0 --mesh
"$cli" convert "$work/ground_points.ply" -o "$work/ground_points.ptl" -q
"$cli" convert "$work/ground_mesh.ply" -o "$work/ground_mesh.ptl" -q
rm -f "$work/ground_points.ply"
scene() {  # scene GROUND OUT.json: the ground and a 4 × 4 grid of dragons 4 units apart
  {
    printf '{"instances": [{"model": "%s"}' "$1"
    for x in -6 -2 2 6; do
      for z in -6 -2 2 6; do
        printf ', {"model": "dragon.ptl", "translate": [%s, 0.527, %s], "rotate_deg": [0, %s, 0], "scale": 10}' \
          "$x" "$z" "$(( (x + z + 12) * 15 ))"
      done
    done
    printf ']}\n'
  } > "$2"
}
scene ground_points.ptl "$work/points.json"
scene ground_mesh.ptl "$work/hybrid.json"
cp "$dragon" "$work/dragon_mesh.ply.gz"
scene ground_mesh.ply "$work/reference.json"
sed -i 's/"dragon.ptl"/"dragon_mesh.ply.gz"/g' "$work/reference.json"
awk 'BEGIN { for (k = 0; k <= 20; ++k) printf "0.5 1.7 %g 0 1.2 %g\n", 14 - 0.4 * k, -0.4 * k }' > "$work/walk.path"
rm -rf "$work/walk_ref" "$work/walk_pts" "$work/walk_hyb"
mkdir -p "$work/walk_ref" "$work/walk_pts" "$work/walk_hyb"
"$cli" render "$work/reference.json" --mode reference --path "$work/walk.path" \
  --frames-out "$work/walk_ref" -o "$work/walk_ref.png" -q
"$cli" render "$work/points.json" --lod spt --path "$work/walk.path" -o "$work/walk_points.png" \
  --frames-out "$work/walk_pts" --stats "$work/walk_points.json" -q
"$cli" render "$work/hybrid.json" --lod spt --hybrid --path "$work/walk.path" \
  --frames-out "$work/walk_hyb" -o "$work/walk_hybrid.png" --stats "$work/walk_hybrid.json" -q
echo
echo "Ground (200 × 200) and 16 statues from eye height, 21 frames, 1280x720 (mean of frames 2-21)"
echo
psnr() {  # mean PSNR and total hole pixels of a frame folder against the reference's
  for ((i = 0; i <= 20; ++i)); do
    f=$(printf frame_%05d.png "$i")
    "$cli" compare --background 0,0,0 --json - "$work/walk_ref/$f" "$1/$f" |
      jq -r '"\(.psnr_db) \(.hole_pixels)"'
  done | awk '{ s += $1; h += $2 } END { printf "%.2f %d\n", s / NR, h }'
}
read -r pts_psnr pts_holes < <(psnr "$work/walk_pts")
read -r hyb_psnr hyb_holes < <(psnr "$work/walk_hyb")
echo "| ground as | splats | triangles | ms a frame | PSNR against the all-triangle reference (mean) | hole pixels (all frames) |"
echo "| --- | ---: | ---: | ---: | ---: | ---: |"
jq -r '[.frames[1:][] | .splats] | add / length | floor' "$work/walk_points.json" > "$work/a"
jq -r '[.frames[1:][] | .ms] | add / length' "$work/walk_points.json" > "$work/b"
jq -r '[.frames[1:][] | .splats] | add / length | floor' "$work/walk_hybrid.json" > "$work/c"
jq -r '[.frames[1:][] | .triangles] | add / length | floor' "$work/walk_hybrid.json" > "$work/d"
jq -r '[.frames[1:][] | .ms] | add / length' "$work/walk_hybrid.json" > "$work/e"
printf "| 16 M points (--lod spt) | %d | 0 | %.1f | %s dB | %s |\n" "$(cat "$work/a")" "$(cat "$work/b")" "$pts_psnr" "$pts_holes"
printf "| 2 triangles (--lod spt --hybrid) | %d | %d | %.1f | %s dB | %s |\n" "$(cat "$work/c")" "$(cat "$work/d")" "$(cat "$work/e")" "$hyb_psnr" "$hyb_holes"
awk -v a="$(cat "$work/b")" -v b="$(cat "$work/e")" 'BEGIN { printf "\nhybrid / points: %.2f (target <= 0.5)\n", b / a }'
