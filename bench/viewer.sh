#!/usr/bin/env bash
# The interactive viewer (`pointillist view`), run headless under Xvfb with a scripted input file
# and its per-frame log (--log-frames), at 1280x720, on the Stanford dragon and on a generated
# cloud of 20 million points (demo scene):
#
#  1. Orbit: settle, drag left across the window over 150 frames, drag back over 150 frames,
#     settle, quit. Over the "moving" frames after the first 5 of each run: the hit rate (share of
#     frames whose frame_ms is within ±20% of the target 1000/fps ms, or at full detail,
#     detail_px <= 1, and faster than the target), median and p90 of frame_ms, mean detail_px;
#     then the refine frames after the last moving frame and the time from it to the last frame.
#     The dragon, the big model held whole (--whole), and the big model paged (--memory).
#  2. Launch: script `settle` then `quit`. Time from the program's start to the first frame
#     (frame 0's t_ms: opening the model and the window included) and to full detail (the last
#     frame's t_ms), for the big model paged (--memory 2G, pages streamed on the loader thread)
#     and held whole (--whole); frames drawn, pages loaded and peak resident memory.
#  3. Input-to-frame latency: mean and p95 of latency_ms over the moving frames that answered an
#     input event (latency_ms >= 0) of the orbit runs.
#
#   bash bench/viewer.sh [--bin PATH] [--work DIR] [--points N] [--runs N] [--fps F]
#                        [--memory SIZE] [--size WxH]
#
#   --bin PATH     the binary (default $POINTILLIST_BIN, else build/release/pointillist of this repo)
#   --work DIR     work folder, kept between runs so the converted models are reused (default
#                  $VIEWER_BENCH_WORK, else /tmp/pointillist-bench-viewer)
#   --points N     points of the generated model (default $VIEWER_BENCH_POINTS, else 20000000;
#                  2000000 for a quick try). Generating and converting 20 M points takes
#                  minutes and gigabytes of memory, once: big-N.ptl is reused.
#   --runs N       runs of each measurement (default 1): orbit frames are pooled, launch times
#                  are the median of the runs
#   --fps F        frame rate the viewer holds while moving (default 30: target 33.3 ms)
#   --memory SIZE  memory cap of the paged runs (default 2G)
#   --size WxH     window size (default 1280x720)
#   POINTILLIST_MODELS  the model cache holding dragon_vrip.ply.gz (default
#                  ~/.cache/pointillist/models; scripts/fetch-models.sh or make models)
#
# Needs xvfb-run (package xvfb), awk and sort. Progress goes to stderr, the markdown tables to
# stdout. Times are wall-clock on whatever else the machine is doing: run it on a quiet machine.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
bin=${POINTILLIST_BIN:-$repo/build/release/pointillist}
models="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
work=${VIEWER_BENCH_WORK:-/tmp/pointillist-bench-viewer}
points=${VIEWER_BENCH_POINTS:-20000000}
runs=1
fps=30
memory=2G
size=1280x720
while [ $# -gt 0 ]; do
  case $1 in
    --bin) bin=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --points) points=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --fps) fps=$2; shift 2 ;;
    --memory) memory=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench/viewer.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ $points =~ ^[1-9][0-9]*$ ]] || { echo "bench/viewer.sh: --points wants a count" >&2; exit 2; }
[[ $runs =~ ^[1-9][0-9]*$ ]] || { echo "bench/viewer.sh: --runs wants a count" >&2; exit 2; }
[[ $size =~ ^([1-9][0-9]*)x([1-9][0-9]*)$ ]] ||
  { echo "bench/viewer.sh: --size wants WxH" >&2; exit 2; }
width=${BASH_REMATCH[1]}
height=${BASH_REMATCH[2]}
[ -x "$bin" ] || { echo "bench/viewer.sh: $bin is not an executable; build first (make build)" >&2; exit 1; }
command -v xvfb-run >/dev/null ||
  { echo "bench/viewer.sh: xvfb-run missing (apt-get install xvfb)" >&2; exit 1; }
[ -e "$models/dragon_vrip.ply.gz" ] ||
  { echo "bench/viewer.sh: $models/dragon_vrip.ply.gz missing; run make models" >&2; exit 1; }
mkdir -p "$work/logs"
target=$(awk -v f="$fps" 'BEGIN { printf "%.4f", 1000 / f }')
millions=$(awk -v n="$points" 'BEGIN { printf "%g M", n / 1e6 }')
say() { echo "== $*" >&2; }

# Models: converted once, reused from the work folder (written under a temporary name first, so
# an interrupted run leaves no half-written model behind).
dragon=$work/dragon.ptl
if [ ! -s "$dragon" ]; then
  say "converting the dragon to $dragon"
  "$bin" convert "$models/dragon_vrip.ply.gz" -o "$work/dragon.tmp.ptl" --quiet
  mv "$work/dragon.tmp.ptl" "$dragon"
fi
big=$work/big-$points.ptl
if [ ! -s "$big" ]; then
  say "generating $points points (demo scene) and converting them to $big"
  "$bin" generate --scene demo --points "$points" -o "$work/big-$points.ply" --quiet
  "$bin" convert "$work/big-$points.ply" -o "$work/big-$points.tmp.ptl" --quiet
  mv "$work/big-$points.tmp.ptl" "$big"
  rm -f "$work/big-$points.ply"
else
  say "reusing $big"
fi

# Input scripts: an orbit across the window and back at mid-height, 150 frames each way.
x0=100
x1=$((width - 100))
y=$((height / 2))
printf '%s\n' "settle" "drag left $x0 $y $x1 $y 150" "drag left $x1 $y $x0 $y 150" "settle" \
  "quit" > "$work/orbit.events"
printf '%s\n' "settle" "quit" > "$work/launch.events"

# view NAME EVENTS MODEL [OPTIONS...]: one headless run per --runs; its logs are
# $work/logs/NAME-R.csv.
view() {
  local name=$1 events=$2 model=$3 r
  shift 3
  for ((r = 1; r <= runs; r++)); do
    say "view $name (run $r of $runs)"
    rm -f "$work/logs/$name-$r.csv"
    xvfb-run -a -s "-screen 0 ${width}x${height}x24" \
      "$bin" view "$model" --size "$size" --fps "$fps" --events "$work/$events" \
      --log-frames "$work/logs/$name-$r.csv" -q "$@"
    [ -s "$work/logs/$name-$r.csv" ] ||
      { echo "bench/viewer.sh: view $name wrote no frame log" >&2; exit 1; }
  done
}
logs() { for ((r = 1; r <= runs; r++)); do echo "$work/logs/$1-$r.csv"; done; }

# pct P: the P-th percentile (nearest rank) of the numbers on stdin, "-" when there are none.
pct() {
  sort -g | awk -v p="$1" '{ v[NR] = $1 }
    END { if (NR == 0) { print "-"; exit }
          k = int(p / 100 * NR); if (k < p / 100 * NR) k++; if (k < 1) k = 1
          printf "%.1f", v[k] }'
}

# orbit_row LABEL NAME: one row of the orbit table from the logs of NAME.
orbit_row() {
  local label=$1 name=$2 files
  mapfile -t files < <(logs "$name")
  # The moving frames after the first 5 of each run: frame_ms, detail_px.
  local moving
  moving=$(awk -F, 'FNR == 1 { n = 0; next } $3 == "moving" && ++n > 5 { print $6, $4 }' \
    "${files[@]}")
  local counted hits mean_detail med p90
  read -r counted hits mean_detail < <(echo "$moving" | awk -v t="$target" '
    NF == 2 { n++; d += $2
              if (($1 >= 0.8 * t && $1 <= 1.2 * t) || ($2 <= 1 && $1 < t)) h++ }
    END { printf "%d %d %.2f\n", n, h, n ? d / n : 0 }')
  med=$(echo "$moving" | awk 'NF == 2 { print $1 }' | pct 50)
  p90=$(echo "$moving" | awk 'NF == 2 { print $1 }' | pct 90)
  # After the last moving frame of each run: refine frames, and ms until the last frame (mean
  # over the runs).
  local refine settle
  read -r refine settle < <(awk -F, '
    function flush() { if (file != "") { runs++; rf += refine; st += last - moved } }
    FNR == 1 { flush(); file = FILENAME; refine = 0; moved = 0; next }
    { last = $2 }
    $3 == "moving" { moved = $2; refine = 0 }
    $3 == "refine" { refine++ }
    END { flush(); printf "%.1f %.0f\n", rf / runs, st / runs }' "${files[@]}")
  # Latency: moving frames that answered an input event.
  local lat lat_n lat_mean lat_p95
  lat=$(awk -F, 'FNR > 1 && $3 == "moving" && $7 >= 0 { print $7 }' "${files[@]}")
  read -r lat_n lat_mean < <(echo "$lat" | awk 'NF { n++; s += $1 }
    END { printf "%d %.1f\n", n, n ? s / n : 0 }')
  lat_p95=$(echo "$lat" | awk 'NF' | pct 95)
  local rate
  rate=$(awk -v h="$hits" -v n="$counted" 'BEGIN { if (n) printf "%.1f%%", 100 * h / n; else print "-" }')
  printf '| %s | %d | %s | %s | %s | %s | %s | %s | %s | %s |\n' "$label" "$counted" "$rate" \
    "$med" "$p90" "$mean_detail" "$refine" "$settle" "$lat_mean" "$lat_p95"
}

# launch_row LABEL NAME: one row of the launch table (times: medians over the runs; frames, pages
# and memory: the last run).
launch_row() {
  local label=$1 name=$2 files
  mapfile -t files < <(logs "$name")
  local per_run
  per_run=$(awk -F, '
    function flush() { if (file != "") print first, last, frames, splats, pages, peak }
    FNR == 1 { flush(); file = FILENAME; frames = 0; pages = 0; peak = 0; next }
    { if (++frames == 1) { first = $2; splats = $8 }
      last = $2; pages = $10; if ($9 > peak) peak = $9 }
    END { flush() }' "${files[@]}")
  local first full frames splats pages peak
  first=$(echo "$per_run" | awk '{ print $1 / 1000 }' | sort -g |
    awk '{ v[NR] = $1 } END { printf "%.2f", v[int((NR + 1) / 2)] }')
  full=$(echo "$per_run" | awk '{ print $2 / 1000 }' | sort -g |
    awk '{ v[NR] = $1 } END { printf "%.2f", v[int((NR + 1) / 2)] }')
  read -r _ _ frames splats pages peak < <(echo "$per_run" | tail -n 1)
  printf '| %s | %s | %s | %s | %s | %s | %.0f |\n' "$label" "$first" "$splats" "$full" "$frames" \
    "$pages" "$(awk -v b="$peak" 'BEGIN { print b / 1e6 }')"
}

view orbit-dragon orbit.events "$dragon"
view orbit-big orbit.events "$big" --whole
view orbit-big-paged orbit.events "$big" --memory "$memory"
view launch-big-paged launch.events "$big" --memory "$memory"
view launch-big-whole launch.events "$big" --whole

echo "## pointillist view at $size, target $(awk -v t="$target" 'BEGIN { printf "%.1f", t }') ms per frame (--fps $fps)"
echo
echo "Orbit: settle, drag across the window and back (150 + 150 frames), settle, quit; $runs run(s)."
echo "Hit: a moving frame (after the first 5 of a run) within ±20% of the target, or at full detail"
echo "(detail_px <= 1) and faster than it. Latency: input event to the frame on screen, moving frames"
echo "that answered one."
echo
echo "| model | moving frames | hit rate | median ms | p90 ms | mean detail px | refine frames after | to full detail after, ms | latency mean ms | latency p95 ms |"
echo "|---|---|---|---|---|---|---|---|---|---|"
orbit_row "dragon" orbit-dragon
orbit_row "$millions points, held whole" orbit-big
orbit_row "$millions points, paged --memory $memory" orbit-big-paged
echo
echo "Launch: settle, quit; seconds from the program's start (median of $runs run(s); frames, pages"
echo "and memory of the last run)."
echo
echo "| model | first frame, s | its splats | full detail, s | frames | pages loaded | peak resident MB |"
echo "|---|---|---|---|---|---|---|"
launch_row "$millions points, paged --memory $memory" launch-big-paged
launch_row "$millions points, held whole" launch-big-whole
echo
echo "Reference (from the issue): Open3D's legacy viewer on Mesa llvmpipe (software OpenGL) on this machine: 92 ms per frame for the dragon at 1280×720, 2.9 s per frame for 10 M points"
echo
echo "Frame logs: $work/logs"
