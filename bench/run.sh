#!/usr/bin/env bash
# Runs every benchmark and prints the figures as ratios against baselines measured in the same run.
#   bash bench/run.sh            all benchmarks (several minutes: includes a 10-million-point cloud)
#   BENCH_QUICK=1 bash bench/run.sh   skip the 10-million-point model (conversion and level of detail)
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/release
cli=$bin/pointillist
[ -x "$cli" ] || { echo "bench: build first (make build)" >&2; exit 1; }
models="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

results="$work/results.json"
: > "$results"
for b in io prep features lod format render; do
  if [ -x "$bin/bench/${b}_bench" ]; then
    echo "== ${b}_bench"
    # Human-readable output on the terminal, JSON (one document per program) for the summary.
    # Not CSV: Google Benchmark's CSV writer takes its columns from the first benchmark and aborts
    # when a later one reports another counter (render_bench: quality, QSplat and SPT counters).
    # The filter "-Small" leaves out the CTest smoke sizes (this libbenchmark has POSIX regexes,
    # so no look-ahead).
    "$bin/bench/${b}_bench" --benchmark_filter=-Small --benchmark_min_time=0.5 \
      --benchmark_out="$work/${b}.json" --benchmark_out_format=json 2>&1 | { grep -v '^\*\*\*' || true; }
    cat "$work/${b}.json" >> "$results"
  fi
done

# summary: one line per figure, each against the baseline measured in the same run.
#   kind "rate": items (or bytes) per second, ratio = value / baseline (higher is better)
#   kind "time": ms, ratio = value / baseline (how many baseline runs one run costs)
summary() {
  # Reads the "benchmarks" arrays of the JSON documents: one "key": value line per field, the
  # name first. Runs that failed (dragon not fetched) are left out.
  awk '
    /^  "context"/ { in_runs = 0; next }
    /^  "benchmarks"/ { in_runs = 1; next }
    in_runs && /^ *"[^"]+": / {
      key = $0; sub(/^ *"/, "", key); sub(/".*/, "", key)
      val = $0; sub(/^ *"[^"]+": */, "", val); sub(/,$/, "", val); gsub(/"/, "", val)
      if (key == "name") { name = val; next }
      if (key == "error_occurred" && val == "true") { failed[name] = 1 }
      if (failed[name]) { delete t[name]; delete items[name]; delete bytes[name]; next }
      if (key == "real_time") t[name] = val
      else if (key == "items_per_second") items[name] = val
      else if (key == "bytes_per_second") bytes[name] = val
      else if (key == "splats") splats[name] = val
      else if (key == "ms_select") sel[name] = val
      else if (key == "ms_raster") ras[name] = val
      else if (key == "psnr_db") psnr[name] = val
      else if (key == "ssim") ssim[name] = val
      else if (key == "holes") holes[name] = val
      else if (key == "bytes_per_point") bpp[name] = val
    }
    function row(what, value, unit, base, base_unit, ratio) {
      printf "%-46s %12s %-10s %12s %-10s %8s\n", what, value, unit, base, base_unit, ratio
    }
    function rate(what, n, b, scale, unit, field,   v, w) {
      v = (field == "bytes") ? bytes[n] : items[n]; w = (field == "bytes") ? bytes[b] : items[b]
      if (v == "" || w == "") return
      row(what, sprintf("%.1f", v / scale), unit, sprintf("%.1f", w / scale), unit,
          sprintf("%.2f", v / w))
    }
    function time(what, n, b,   v, w) {
      if (t[n] == "" || t[b] == "") return
      row(what, sprintf("%.1f", t[n]), "ms", sprintf("%.1f", t[b]), "ms", sprintf("%.2f", t[n] / t[b]))
    }
    END {
      printf "\n== summary (ratio = value / baseline measured in the same run)\n"
      row("figure", "value", "", "baseline", "", "ratio")
      rate("PLY load, binary, 10M points (MB/s)", "BM_PlyLoadBinary/10000000",
           "BM_BaselineBulkReadBinary/10000000", 1e6, "MB/s", "bytes")
      time("PLY load, dragon .ply.gz (vs gunzip alone)", "BM_PlyLoadDragonGz", "BM_BaselineGunzipDragon")
      rate("kNN k=16, 1M points (points/s)", "BM_Knn16/1000000", "BM_BaselineBoundingBox/1000000", 1e6, "M/s", "items")
      rate("PCA normals, 1M points (points/s)", "BM_PcaNormals/1000000", "BM_BaselineBoundingBox/1000000", 1e6, "M/s", "items")
      rate("cloud radii, 1M points (points/s)", "BM_CloudRadii/1000000", "BM_BaselineBoundingBox/1000000", 1e6, "M/s", "items")
      rate("LAS read, lion, 200 tiles (MB/s)", "BM_LasReadLion", "BM_BaselineReadLionBytes", 1e6, "MB/s", "bytes")
      if (items["BM_LasReadLion"] != "")
        row("  points/s", sprintf("%.1f", items["BM_LasReadLion"] / 1e6), "M/s", "", "", "")
      if (bpp["BM_WriteQsDragon"] != "" && bpp["BM_BaselineWritePtlDragon"] != "")
        row(".qs bytes/point, dragon (baseline .ptl v1)", sprintf("%.2f", bpp["BM_WriteQsDragon"]), "B",
            sprintf("%.2f", bpp["BM_BaselineWritePtlDragon"]), "B",
            sprintf("%.3f", bpp["BM_WriteQsDragon"] / bpp["BM_BaselineWritePtlDragon"]))
      time(".qs write dragon (vs writing .ptl v1)", "BM_WriteQsDragon", "BM_BaselineWritePtlDragon")
      time(".qs decode dragon (vs writing .ptl v1)", "BM_ReadQsDragon", "BM_BaselineWritePtlDragon")
      time("prepare dragon mesh (normals+radii)", "BM_PrepareDragonMesh", "BM_BaselineGunzipDragon")
      rate("hierarchy build, 437k points (points/s)", "BM_BuildSphereTree/437645", "BM_BaselineSortFloats/437645", 1e6, "M/s", "items")
      rate("hierarchy build, 10M points (points/s)", "BM_BuildSphereTree/10000000", "BM_BaselineSortFloats/10000000", 1e6, "M/s", "items")
      time("hierarchy build, dragon (vs sorting 437k floats)", "BM_BuildSphereTreeDragon", "BM_BaselineSortFloats/437645")
      time("ptl v2 encode+write, dragon (vs v1 write)", "BM_EncodePtlV2/Dragon", "BM_BaselineWritePtlV1/Dragon")
      time("ptl v2 encode+write, dragon, 2 threads (vs 1)", "BM_EncodePtlV2/Dragon2Threads/real_time", "BM_EncodePtlV2/Dragon")
      time("ptl v2 open+decode_all, dragon (vs v1 read)", "BM_DecodeAllPtlV2/Dragon", "BM_BaselineReadPtlV1/Dragon")
      time("ptl v2 load every page packed (vs decode_all)", "BM_PackAllPagesPtlV2/Dragon", "BM_DecodeAllPtlV2/Dragon")
      b = "BM_BaselineProjectDragonPoints"
      for (th = 1; th <= 4; th *= 2) {
        n = "BM_RenderDragon/" th "/real_time"
        if (t[n] == "" || t[b] == "") continue
        row("render dragon 1280x720, threshold " th " px (ms)", sprintf("%.2f", t[n]), "ms",
            sprintf("%.2f", t[b]), "ms", sprintf("%.2f", t[n] / t[b]))
        row("  splats/s (baseline: leaf points projected/s)", sprintf("%.1f", items[n] / 1e6), "M/s",
            sprintf("%.1f", items[b] / 1e6), "M/s", sprintf("%.2f", items[n] / items[b]))
        row("  splats drawn; ms select + raster", sprintf("%d", splats[n]), "splats",
            sprintf("%.2f+%.2f", sel[n], ras[n]), "ms", "")
      }
      # Quality mode against the fast mode (same view, threshold 1 px, all threads). PSNR and SSIM
      # are against the z-buffered triangles; their "ratio" column is quality − fast.
      f = "BM_DragonFast/1/real_time"
      if (t[f] != "") {
        row("dragon 1280x720 fast circles (ms)", sprintf("%.2f", t[f]), "ms", "", "", "")
        row("  PSNR dB, SSIM vs triangles; holes", sprintf("%.2f", psnr[f]), "dB",
            sprintf("%.4f", ssim[f]), "SSIM", sprintf("%d", holes[f]))
      }
      split("1/0/100:Z-range,1/1/100:Z-threshold,2/0/100:Z-range 2 px,1/0/50:Z-range opacity .5",
            variants, ",")
      for (k = 1; k in variants; ++k) {
        split(variants[k], part, ":")
        n = "BM_DragonQuality/" part[1] "/real_time"
        if (t[n] == "" || t[f] == "") continue
        row("dragon 1280x720 quality, " part[2] " (ms)", sprintf("%.2f", t[n]), "ms",
            sprintf("%.2f", t[f]), "ms", sprintf("%.2f", t[n] / t[f]))
        row("  splats/s (baseline: fast mode)", sprintf("%.1f", items[n] / 1e6), "M/s",
            sprintf("%.1f", items[f] / 1e6), "M/s", sprintf("%.2f", items[n] / items[f]))
        if (psnr[n] != "") {
          row("  PSNR dB vs triangles (baseline: fast)", sprintf("%.2f", psnr[n]), "dB",
              sprintf("%.2f", psnr[f]), "dB", sprintf("%+.2f", psnr[n] - psnr[f]))
          row("  SSIM vs triangles (baseline: fast)", sprintf("%.4f", ssim[n]), "",
              sprintf("%.4f", ssim[f]), "", sprintf("%+.4f", ssim[n] - ssim[f]))
        }
      }
      time("quality Z-range vs clearing its accumulators", "BM_DragonQuality/1/0/100/real_time",
           "BM_BaselineQualityAccumulators/real_time")
    }' "$results"
}

seconds() {  # seconds CMD...: wall time of one run
  local t0 t1
  t0=$(date +%s.%N); "$@" >/dev/null; t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.6f", b - a }' 
}

echo
echo "== end-to-end convert (wall time; baseline = reading the same input bytes once)"
printf '%-34s %10s %12s %12s %12s %10s\n' input points "convert s" "M points/s" "baseline s" ratio
row() {  # row NAME POINTS INPUT BASELINE_CMD...
  local name=$1 points=$2 input=$3; shift 3
  local c b
  c=$(seconds "$cli" convert -q "$input" -o "$work/out.ptl")
  b=$(seconds "$@")
  printf '%-34s %10s %12.3f %12.2f %12.3f %10.1f\n' "$name" "$points" "$c" \
    "$(awk -v a="$c" -v n="$points" 'BEGIN { printf "%.3f", n / a / 1e6 }')" "$b" \
    "$(awk -v a="$c" -v b="$b" 'BEGIN { printf "%.3f", a / b }')"
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

summary

echo
bash bench/lod.sh "$work"
bash bench/paged.sh "$work"
