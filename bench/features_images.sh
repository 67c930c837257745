#!/usr/bin/env bash
# The image-variants benchmark of the sharp-features specification (issue 11; spec §4.4, §4.5):
# each test scene in both sampling modes, at an overview (V1) and a close-up of its feature (V2),
# drawn with the variants B0 (no features), B1 (independent clipping), B2 (nearest partner only),
# B3 (the dissertation: its 4.13-4.15 rule and the Linsen test) and B4 (Pointillist's defaults) in
# quality mode, plus B0 and B4 in the fast mode, each measured with `compare --labels` against the
# scene's exact ray-cast label image (`generate --reference`, same camera options).
#
#   bash bench/features_images.sh [--markdown] [--keep DIR] [--tsv FILE]
#
#   POINTILLIST_BIN        the binary (default build/release/pointillist, after `make build`)
#   FEATURES_IMAGES_SIZE   image side in pixels (default 512; the spec's 1024 is slow for a
#                          routine run)
#   FEATURES_IMAGES_SCENES scenes (default "T1 T2 T3 T4 T5 T6 T8 T9 T10 T11 T14-2 T14-5 T15")
#   FEATURES_IMAGES_MODES  sampling modes (default "j r")
#   --markdown             also print the table as markdown
#   --keep DIR             keep the reference and test images (and the JSON) in DIR
#   --tsv FILE             also write the rows tab-separated
#
# One row per (scene, sampling, view, variant): HOLE, SEE (see-through: interior pixels showing
# another face more than 2 mean splat radii behind the reference, from both depth images),
# OVERSHOOT, LER in B_4 and over the covered pixels (%), MIX (interior mixed pixels, and mixed pixels in B_8 per reference boundary pixel),
# edge displacement mean/max (px), transition width mean/max (px) ("-" when no profile has both
# faces in the test; the note counts the profiles that lack one), whole-image PSNR and PSNR in
# B_8 (dB; "inf" also when the band is empty), the normal error in B_8 (mean angle in degrees
# against the exact normals, and the share of pixels over 5°, %; from a second render of the view
# with --normal-colors), the render's wall time and its raster time from --stats (ms). A combination that fails prints its
# error in the row's note and the run goes on. Needs jq, awk and coreutils only.
set -euo pipefail

bin=${POINTILLIST_BIN:-build/release/pointillist}
# A relative binary path is taken from where the script is called, then from the repository.
if [[ $bin == */* && -x $bin ]]; then bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin"); fi
cd "$(dirname "$0")/.."
if [[ $bin != /* ]] && [[ $bin == */* ]]; then bin=$PWD/$bin; fi
command -v "$bin" >/dev/null 2>&1 || [[ -x $bin ]] ||
  { echo "bench: no binary at $bin (make build, or set POINTILLIST_BIN)" >&2; exit 1; }
command -v jq >/dev/null || { echo "bench: needs jq (scripts/setup.sh installs it)" >&2; exit 1; }

markdown=0 keep="" tsv_out=""
while (($#)); do
  case $1 in
    --markdown) markdown=1 ;;
    --keep) keep=${2:?--keep needs a directory}; shift ;;
    --tsv) tsv_out=${2:?--tsv needs a file}; shift ;;
    -h|--help) sed -n '2,25p' "$0"; exit 0 ;;
    *) echo "bench: unknown argument $1" >&2; exit 1 ;;
  esac
  shift
done

size=${FEATURES_IMAGES_SIZE:-512}
scenes=${FEATURES_IMAGES_SCENES:-"T1 T2 T3 T4 T5 T6 T8 T9 T10 T11 T14-2 T14-5 T15"}
modes=${FEATURES_IMAGES_MODES:-"j r"}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[[ -z $keep ]] || mkdir -p "$keep"

# V2: the eye 1.5 from the scene's feature point along DIR (outside the solid), looking at it.
# Prints "--eye X,Y,Z --target X,Y,Z".
closeup() {  # closeup FX FY FZ DX DY DZ
  awk -v fx="$1" -v fy="$2" -v fz="$3" -v dx="$4" -v dy="$5" -v dz="$6" 'BEGIN {
    n = sqrt(dx * dx + dy * dy + dz * dz); s = 1.5 / n
    printf "--eye %.6f,%.6f,%.6f --target %s,%s,%s\n", fx + s * dx, fy + s * dy, fz + s * dz, fx, fy, fz
  }'
}
v2_camera() {
  case $1 in
    T1) closeup 1 1 1 1 1 1 ;;            # the corner (1,1,1), along the diagonal
    T3) closeup 0 0.8 0.8 0 1 1 ;;        # a cap rim point, between the cap's and side's normals
    T4) closeup 0 0.2 0.5 0 1 -1 ;;       # a hole rim point on the top face, from above the hole
    T5|T6|T9) closeup 0 0 0.8 0 0 1 ;;    # a point of the crease / intersection circle x = 0
    T8) closeup 0 0 1 1 1 1 ;;            # the mixed corner: floor, riser and front
    T10) closeup 0.35 0 0.5 1 0 1 ;;      # the crossing curve where the normals are orthogonal
    T11) closeup 1 1 0.01 1 1 1 ;;        # a corner of the slab (front face, two rim faces)
    T2|T14*) closeup 1 1 1 1 1 1 ;;       # the cube's corner, as T1
    T15) closeup 0 0 0.3 0 1 -0.5 ;;      # the open crease where it is still sharp
    *) echo "--view 0,0" ;;
  esac
}
camera() {  # camera SCENE VIEW
  if [[ $2 == V1 ]]; then echo "--view 35,25"; else v2_camera "$1"; fi
}

# name | render mode | flags
variants=(
  "B0|quality|--no-features"
  "B1|quality|--features --clip-rule independent"
  "B2|quality|--features --clip-rule nearest"
  "B3|quality|--features --clip-rule dissertation --edge-test linsen"
  "B4|quality|--features"
  "B0-fast|fast|--no-features"
  "B4-fast|fast|--features"
)

now_ms() { echo $(( $(date +%s%N) / 1000000 )); }
oneline() { tr '\n\t' '  ' <"$1" | sed 's/  */ /g; s/^ //; s/ $//' | cut -c1-160; }

rows=$work/rows.tsv
header="scene\tsamp\tview\tvariant\tHOLE\tSEE\tOVERSHOOT\tLER_B4%\tLER_cov%\tMIX\tMIX/bpx\tdisp_mean\tdisp_max\ttw_mean\ttw_max\tPSNR\tPSNR_B8\tNERR_B8\tN>5deg%\twall_ms\traster_ms\tnote"
printf '%b\n' "$header" >"$rows"
blank="\t\t\t\t\t\t\t\t\t\t\t\t\t\t\t"  # the 15 metric columns, empty
total=0
for scene in $scenes; do
  for mode in $modes; do
    for view in V1 V2; do
      read -r -a cam <<<"$(camera "$scene" "$view")"
      tag=${scene}_${mode}_${view}
      ply=$work/${scene}_${mode}.ply
      ref=$work/${tag}_ref.png
      ref_depth=$work/${tag}_ref.pfm
      ref_normals=$work/${tag}_ref_n.png
      if ! "$bin" generate -q --scene "$scene" --sampling "$mode" -o "$ply" --reference "$ref" \
          --reference-depth "$ref_depth" --reference-normals "$ref_normals" --size "${size}x${size}" "${cam[@]}" 2>"$work/err"; then
        printf '%s\t%s\t%s\t%s%b\t\t\tgenerate failed: %s\n' "$scene" "$mode" "$view" "-" "$blank" \
          "$(oneline "$work/err")" >>"$rows"
        continue
      fi
      [[ -z $keep ]] || cp "$ref" "$keep/"
      # SEE-THROUGH's gap: 2 mean splat radii (spec §4.5), as info reports them for the samples.
      gap=$("$bin" info "$ply" | awk '/^splat radii:/ { gsub(",", "", $4); print 2 * $4 }')
      for v in "${variants[@]}"; do
        IFS='|' read -r name rmode flags <<<"$v"
        read -r -a fl <<<"$flags"
        img=$work/${tag}_${name}.png
        t0=$(now_ms)
        if ! "$bin" render -q "$ply" -o "$img" --depth "$work/test.pfm" --size "${size}x${size}" \
            "${cam[@]}" --mode "$rmode" --unlit "${fl[@]}" --stats "$work/stats.json" \
            2>"$work/err"; then
          printf '%s\t%s\t%s\t%s%b\t\t\trender failed: %s\n' "$scene" "$mode" "$view" "$name" "$blank" \
            "$(oneline "$work/err")" >>"$rows"
          continue
        fi
        wall=$(( $(now_ms) - t0 ))
        total=$((total + 1))
        raster=$(jq -r '.ms.raster // empty' "$work/stats.json" 2>/dev/null || true)
        note=""
        [[ -s $work/err ]] && note="stderr: $(oneline "$work/err")"
        # The same view again as a normal map, for the NORMAL ERROR (not timed).
        if ! "$bin" render -q "$ply" -o "$work/test_n.png" --size "${size}x${size}" "${cam[@]}" \
            --mode "$rmode" --normal-colors "${fl[@]}" 2>"$work/err"; then
          printf '%s\t%s\t%s\t%s%b\t%s\t%s\tnormal render failed: %s\n' "$scene" "$mode" "$view" \
            "$name" "$blank" "$wall" "$raster" "$(oneline "$work/err")" >>"$rows"
          continue
        fi
        if ! "$bin" compare "$ref" "$img" --labels --json "$work/cmp.json" --depth "$ref_depth" \
            "$work/test.pfm" --see-through-gap "$gap" --normals "$ref_normals" "$work/test_n.png" \
            >/dev/null 2>"$work/err"; then
          printf '%s\t%s\t%s\t%s%b\t%s\t%s\tcompare failed: %s\n' "$scene" "$mode" "$view" "$name" \
            "$blank" "$wall" "$raster" "$(oneline "$work/err")" >>"$rows"
          continue
        fi
        [[ -z $keep ]] || { cp "$img" "$keep/"; cp "$work/cmp.json" "$keep/${tag}_${name}.json"; }
        jq -r --arg s "$scene" --arg m "$mode" --arg v "$view" --arg n "$name" \
          --arg wall "$wall" --arg raster "$raster" --arg note "$note" '
          def n: if . == null then "-" else tostring end;
          .labels as $l |
          [$s, $m, $v, $n,
           ($l.hole_pixels | n), ($l.see_through_pixels | n), ($l.overshoot_pixels | n),
           ($l.ler_band | if . == null then null else . * 100 end | n),
           ($l.ler_covered | if . == null then null else . * 100 end | n),
           ($l.mixed_pixels | n), ($l.mixed_per_boundary_pixel | n),
           (if ($l.profiles // 0) == 0 then "-", "-", "-", "-" else
             ($l.edge_displacement_mean_px | n), ($l.edge_displacement_max_px | n),
             ($l.transition_width_mean_px | n), ($l.transition_width_max_px | n) end),
           (if .psnr_db == null then "inf" else (.psnr_db | n) end),
           (if $l.psnr_band_db == null then "inf" else ($l.psnr_band_db | n) end),
           (if ($l.normal_error.band_pixels // 0) == 0 then "-", "-" else
             ($l.normal_error.band_mean_deg | n), ($l.normal_error.band_over_5deg * 100 | n) end),
           $wall, $raster,
           ([(if ($l.unmatched_profiles // 0) > 0 then "\($l.unmatched_profiles) of \($l.profiles + $l.unmatched_profiles) profiles lack a face in the test" else empty end),
             (if $note != "" then $note else empty end)] | join("; "))
          ] | @tsv' "$work/cmp.json" >>"$rows"
      done
    done
  done
done

# Fixed decimals per column (numbers only; "-", "inf" and errors pass through).
awk -F'\t' -v OFS='\t' '
  NR > 1 {
    for (i = 5; i < NF; i++) {
      if ($i !~ /^-?[0-9.]+(e[-+]?[0-9]+)?$/) continue
      if (i == 8 || i == 9 || i == 11) $i = sprintf("%.3f", $i)
      else if (i == 12 || i == 14 || i == 16 || i == 17 || i == 18 || i == 19) $i = sprintf("%.2f", $i)
      else if (i == 13 || i == 21) $i = sprintf("%.1f", $i)
    }
  }
  { print }' "$rows" >"$rows.fmt" && mv "$rows.fmt" "$rows"

# Aligned text: text columns left, numbers right; the note last, unpadded.
awk -F'\t' '
  { n = NR; nf[NR] = NF; for (i = 1; i <= NF; i++) { c[NR, i] = $i; if (i < NF && length($i) > w[i]) w[i] = length($i) } }
  END {
    for (r = 1; r <= n; r++) {
      line = ""
      for (i = 1; i <= nf[r]; i++) {
        if (i == nf[r]) { line = line c[r, i]; break }
        if (i <= 4) line = line sprintf("%-" w[i] "s  ", c[r, i])
        else line = line sprintf("%" w[i] "s  ", c[r, i])
      }
      sub(/ +$/, "", line); print line
    }
  }' "$rows"

if ((markdown)); then
  echo
  awk -F'\t' '
    { line = "|"; for (i = 1; i <= NF; i++) line = line " " $i " |"; print line
      if (NR == 1) { sep = "|"; for (i = 1; i <= NF; i++) sep = sep (i <= 4 || i == NF ? " --- |" : " ---: |"); print sep } }' "$rows"
fi
[[ -z $tsv_out ]] || cp "$rows" "$tsv_out"
echo
case " $scenes " in *" T8 "*)
  echo "T8: generate labels each box's faces, so the L-shaped front, back and left faces are two labels" \
    "each (a seam on one plane, which the renderer rightly blends) and 12 labels share 8 colours:" \
    "its LER, MIX and transition width count the seam too." ;;
esac
echo "size ${size}x${size}, $total renders; V1 --view 35,25, V2 eye 1.5 from the feature point;" \
  "$(nproc) cores; binary $bin"
