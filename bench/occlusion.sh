#!/usr/bin/env bash
# Occlusion culling on the scenes of spec §1.8 (issue 12): the wall hiding 100 dragons, the city
# of 1,024 scanned models among façades (street walk, static view, fly-over, turn), the open
# field (nothing hidden: the cost of culling) and a row of dragons. Each camera path is rendered
# with --occlusion none and with each method (and CHC++ with each rule switched off on the city
# walk), in the same run; every frame's PNG is compared with none's (identical bits expected).
# The wall, row, field and street walk are also rendered in --mode quality, with and without
# culling ("quality:none", "quality:chc++", compared with each other).
#
#   bash bench/occlusion.sh [--stride N] [--size WxH] [--markdown]
#
#   --stride N   render every Nth frame of each path (default 3; 1 = the spec's full paths)
#   --no-economy skip the query economy on the full paths (spec §1.8 checks 4 and 5: the city
#                walk, static view and turn at every frame, CHC against CHC++ and its own rules;
#                about 4 minutes)
#   --size WxH   image size (default 1280x720)
#   POINTILLIST_BIN   the binary (default build/release/pointillist)
#   POINTILLIST_MODELS  the model cache (default ~/.cache/pointillist/models; make models)
#
# One row per (scene, path, method): frames, median and standard deviation of the frame time
# (ms), its ratio to none's median, median splats and their ratio, queries per frame (single +
# multi + v, median), the largest number of v-queries in a frame, flushes per frame, stalls,
# culled leaves per frame, and "same" = frames bit-identical to none's. Needs python3.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${POINTILLIST_BIN:-build/release/pointillist}
models="${POINTILLIST_MODELS:-${XDG_CACHE_HOME:-$HOME/.cache}/pointillist/models}"
stride=3
size=1280x720
markdown=0
economy=1
while [ $# -gt 0 ]; do
  case $1 in
    --stride) stride=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --markdown) markdown=1; shift ;;
    --no-economy) economy=0; shift ;;
    *) echo "bench/occlusion.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "bench/occlusion.sh: build first (make build)" >&2; exit 1; }
for m in dragon_vrip.ply.gz stanford_bunny_reduced.ply lion_takanawa_las; do
  [ -e "$models/$m" ] || { echo "bench/occlusion.sh: $models/$m missing; run make models" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "== models and scenes (in $work)"
"$bin" convert "$models/dragon_vrip.ply.gz" -o "$work/dragon.ptl" --quiet
"$bin" convert "$models/stanford_bunny_reduced.ply" -o "$work/bunny.ptl" --quiet
"$bin" convert "$models"/lion_takanawa_las/*.las -o "$work/lion.ptl" --quiet
"$bin" generate --scene wall -o "$work/wall/wall.json" --models "$work/dragon.ptl"
"$bin" generate --scene row -o "$work/row/row.json" --models "$work/dragon.ptl"
"$bin" generate --scene field -o "$work/field/field.json" \
  --models "$work/dragon.ptl,$work/bunny.ptl,$work/lion.ptl"
"$bin" generate --scene city -o "$work/city/city.json" \
  --models "$work/dragon.ptl,$work/bunny.ptl,$work/lion.ptl"

# A path file thinned to every `stride`th frame (header lines kept).
thin() {
  awk -v s="$stride" '/^[ \t]*(#|fov|$)/ { print; next } { if (n++ % s == 0) print }' "$1" > "$2"
}

runs="$work/runs.tsv"
: > "$runs"
# run SCENE PATHNAME LABEL ARGS...
run() {
  local scene=$1 path=$2 label=$3
  shift 3
  local dir="$work/out/$path/${label/:/-}"
  mkdir -p "$dir"
  thin "$work/$scene/$path.path" "$work/$path.thin.path"
  echo "-- $path $label"
  "$bin" render "$work/$scene/$scene.json" --path "$work/$path.thin.path" --size "$size" \
    -o "$dir/last.png" --frames-out "$dir" --stats "$dir/stats.json" --quiet "$@"
  printf '%s\t%s\t%s\n' "$path" "$label" "$dir" >> "$runs"
}

for p in wall:wall row:row field:field city:city-walk city:city-static city:city-fly city:city-turn; do
  scene=${p%%:*}
  path=${p#*:}
  run "$scene" "$path" none
  run "$scene" "$path" chc++ --occlusion chc++
  if [ "$path" = city-walk ]; then
    run "$scene" "$path" chc --occlusion chc
    run "$scene" "$path" stop-and-wait --occlusion stop-and-wait
    for rule in batching multiqueries split random tight; do
      run "$scene" "$path" "chc++-no-$rule" --occlusion chc++ --chc-off "$rule"
    done
    run "$scene" "$path" chc++-fixed-requery --occlusion chc++ --chc-doublings 0
  fi
  if [ "$path" = city-turn ]; then
    run "$scene" "$path" chc++-no-random --occlusion chc++ --chc-off random
  fi
  # The quality mode (an occluder pass, then the visible leaves drawn in the order of no
  # culling), against its own run without culling.
  case $path in
    wall|row|field|city-walk)
      run "$scene" "$path" quality:none --mode quality
      run "$scene" "$path" quality:chc++ --mode quality --occlusion chc++ ;;
  esac
done

python3 - "$runs" "$markdown" <<'EOF'
import filecmp, json, os, statistics as st, sys
runs = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
markdown = sys.argv[2] == "1"
base = {}
rows = []
for path, label, d in runs:
    frames = json.load(open(os.path.join(d, "stats.json")))["frames"]
    # The first frame builds the hierarchies and sizes buffers: medians over the others.
    body = frames[1:] if len(frames) > 1 else frames
    ms = [f["ms"] for f in body]
    splats = [f["splats"] for f in body]
    occ = [f.get("occlusion") for f in body]
    # Quality runs ("quality:...") compare with the quality run without culling.
    group = (path, label.split(":")[0] if ":" in label else "")
    if label.split(":")[-1] == "none":
        base[group] = (st.median(ms), st.median(splats), d, len(frames))
    b = base[group]
    pngs = sorted(x for x in os.listdir(d) if x.startswith("frame_"))
    same = sum(filecmp.cmp(os.path.join(d, x), os.path.join(b[2], x), shallow=False)
               for x in pngs)
    q = [o["queries_single"] + o["queries_multi"] + o["v_queries"] for o in occ] if occ[0] else [0]
    row = [path, label, len(frames), f"{st.median(ms):.1f}",
           f"{st.pstdev(ms):.1f}", f"{st.median(ms) / b[0]:.3f}", f"{st.median(splats):.0f}",
           f"{st.median(splats) / b[1]:.3f}", f"{st.median(q):.0f}",
           f"{max(o['v_queries'] for o in occ):.0f}" if occ[0] else "-",
           f"{st.median(o['flushes'] for o in occ):.0f}" if occ[0] else "-",
           f"{sum(o['stalls'] for o in occ)}" if occ[0] else "-",
           f"{st.median(o['leaves_culled'] for o in occ):.0f}" if occ[0] else "-",
           f"{same}/{len(pngs)}"]
    rows.append(row)
head = ["path", "method", "frames", "ms", "sd", "ms/none", "splats", "splats/none",
        "queries", "max v-q", "flushes", "stalls", "culled", "same"]
if markdown:
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for r in rows:
        print("| " + " | ".join(str(x) for x in r) + " |")
else:
    print("\t".join(head))
    for r in rows:
        print("\t".join(str(x) for x in r))
EOF

[ "$economy" = 1 ] || exit 0
# Query economy on the full paths (every frame; only the statistics are kept).
echo "== query economy (full paths)"
econ="$work/economy.tsv"
: > "$econ"
for spec in "city-walk|chc|--occlusion chc" "city-walk|chc++|--occlusion chc++" \
            "city-walk|chc++ without split|--occlusion chc++ --chc-off split" \
            "city-walk|chc++ fixed re-query|--occlusion chc++ --chc-doublings 0" \
            "city-static|chc|--occlusion chc" "city-static|chc++|--occlusion chc++" \
            "city-turn|chc++|--occlusion chc++" \
            "city-turn|chc++ without R5|--occlusion chc++ --chc-off random"; do
  IFS='|' read -r path label args <<< "$spec"
  out="$work/econ-$path-${label// /_}.json"
  # shellcheck disable=SC2086
  "$bin" render "$work/city/city.json" --path "$work/city/$path.path" --size "$size" \
    -o "$work/econ.png" --stats "$out" --quiet $args
  printf '%s\t%s\t%s\n' "$path" "$label" "$out" >> "$econ"
done
python3 - "$econ" <<'EOF2'
import json, statistics as st, sys
print("| path | method | frames | queries / frame (median) | single | multi | v | failed multi | culling nodes visited | queries / nodes visited | max v-queries | sd of ms |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for line in open(sys.argv[1]):
    path, label, f = line.rstrip("\n").split("\t")
    frames = json.load(open(f))["frames"]
    # Check 4 counts the static view after frame 10; the others skip the first frame.
    body = frames[10:] if path == "city-static" else frames[1:]
    o = [x["occlusion"] for x in body]
    q = [x["queries_single"] + x["queries_multi"] + x["v_queries"] for x in o]
    visited = st.median(x["culling_nodes_visited"] for x in o)
    print(f"| {path} | {label} | {len(frames)} | {st.median(q):.0f} | "
          f"{st.median(x['queries_single'] for x in o):.0f} | "
          f"{st.median(x['queries_multi'] for x in o):.0f} | "
          f"{st.median(x['v_queries'] for x in o):.0f} | "
          f"{st.median(x['multiquery_failed'] for x in o):.0f} | {visited:.0f} | "
          f"{st.median(q) / visited:.3f} | {max(x['v_queries'] for x in o)} | "
          f"{st.pstdev(x['ms'] for x in body):.1f} |")
EOF2
