#!/usr/bin/env bash
# Conversion of a generated cloud (demo scene, positions only: normals and radii are computed)
# in one piece against the chunked conversion under memory budgets, in the same sitting: wall
# time, CPU time, CPU/wall, points/s and peak resident memory (whole process, /usr/bin/time),
# each as a ratio against the one-piece conversion; and whether each chunked file renders the
# one-piece file's image byte for byte (their page layouts differ by design, the hierarchies
# should not).
#
#   bash bench/chunked.sh [--bin PATH] [--work DIR] [--points N] [--memory SIZE[,SIZE...]]
#                         [--no-whole] [--colors] [--mpi] [--features]
#
#   --points N     points of the generated cloud (default 10000000). 100000000 takes about
#                  25 s to generate (1.2 GB), minutes to convert, and 17 GB in one piece.
#   --memory LIST  budgets for the chunked runs (default 1G,512M; a budget the cloud fits in one
#                  piece runs in one piece)
#   --no-whole     skip the one-piece run (inputs too large for this machine's memory); ratios
#                  are then left out
#   --colors       the cloud has colours (generate --colors): 15 bytes a point
#   --mpi          also run each budget under `mpirun -n 2 --oversubscribe` (one thread a rank)
#                  and check that it writes the single process's file byte for byte
#   --features     every conversion finds the sharp features too (convert --features; in chunks
#                  part by part), and the renders that compare them draw them (--mode quality)
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${POINTILLIST_BIN:-build/release/pointillist}"
work="${CHUNKED_BENCH_WORK:-/tmp/pointillist-bench-chunked}"
points=10000000
memory="1G,512M"
whole=1
colors=""
mpi=0
features=()
render_mode=()
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --points) points="$2"; shift 2 ;;
    --memory) memory="$2"; shift 2 ;;
    --no-whole) whole=0; shift ;;
    --colors) colors="--colors"; shift ;;
    --mpi) mpi=1; shift ;;
    --features) features=(--features); render_mode=(--mode quality); shift ;;
    *) echo "chunked.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "chunked.sh: no binary at $bin (make build)" >&2; exit 1; }
mkdir -p "$work"
cloud="$work/cloud-$points${colors:+-rgb}.ply"
if [ ! -f "$cloud" ]; then
  need=$(( points * 12 + 1000000 ))
  free=$(df --output=avail -B1 "$work" | tail -1)
  [ "$free" -gt $(( need * 4 )) ] || { echo "chunked.sh: $work needs about $(( need * 4 / 1000000000 )) GB free" >&2; exit 1; }
  "$bin" generate -o "$cloud" --points "$points" $colors -q
fi

# run NAME ARGS...: one conversion; prints "NAME wall cpu peak_kb chunks". Under mpirun the
# peak is the largest rank's.
run() {
  local name="$1"; shift
  local out="$work/$name.ptl" log="$work/$name.log" launcher=()
  case "$name" in
    mpi-*) launcher=(env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
                     mpirun -n 2 --oversubscribe) ;;
  esac
  /usr/bin/time -f "%e %U %S %M" -o "$work/$name.time" "${launcher[@]}" "$bin" convert "$cloud" \
    -o "$out" "${features[@]}" "$@" > "$log"
  read -r wall user sys peak < "$work/$name.time"
  local chunks
  chunks=$(sed -n 's/^in \([0-9]*\) chunks.*/\1/p' "$log")
  echo "$name $wall $(echo "$user + $sys" | bc) $peak ${chunks:-0}"
}

echo "cloud: $points points ($cloud)${features:+, with --features}"
results=()
if [ "$whole" = 1 ]; then results+=("$(run whole)"); fi
IFS=',' read -ra budgets <<< "$memory"
for m in "${budgets[@]}"; do
  results+=("$(run "chunked-$m" --memory "$m")")
  if [ "$mpi" = 1 ]; then
    results+=("$(run "mpi-$m" --memory "$m" --threads 1)")
    cmp -s "$work/chunked-$m.ptl" "$work/mpi-$m.ptl" \
      && echo "mpi-$m: the same file, byte for byte, as one process" >&2 \
      || echo "mpi-$m: a different file from one process" >&2
  fi
done

printf '%-14s %8s %8s %8s %10s %10s %7s %8s %8s\n' run wall_s cpu_s cpu/wall Mpoints/s peak_MB chunks wall/1 peak/1
base_wall="" base_peak=""
for r in "${results[@]}"; do
  read -r name wall cpu peak chunks <<< "$r"
  if [ "$name" = whole ]; then base_wall=$wall; base_peak=$peak; fi
  awk -v n="$name" -v w="$wall" -v c="$cpu" -v p="$peak" -v k="$chunks" -v pts="$points" \
      -v bw="$base_wall" -v bp="$base_peak" 'BEGIN {
    rw = bw == "" ? "-" : sprintf("%.2f", w / bw); rp = bp == "" ? "-" : sprintf("%.2f", p / bp);
    printf "%-14s %8.1f %8.1f %8.2f %10.3f %10.0f %7d %8s %8s\n", n, w, c, c / w, pts / w / 1e6,
           p / 1024, k, rw, rp }'
done
if [ "$whole" = 1 ]; then
  # Same model: the renders at one view are compared byte for byte (the files' page layouts
  # differ by design, the decoded hierarchies should not).
  "$bin" render "$work/whole.ptl" -o "$work/whole.png" --view 30,20 "${render_mode[@]}" -q
  for r in "${results[@]:1}"; do
    read -r name _ <<< "$r"
    case "$name" in mpi-*) continue ;; esac
    "$bin" render "$work/$name.ptl" -o "$work/$name.png" --view 30,20 "${render_mode[@]}" -q
    cmp -s "$work/whole.png" "$work/$name.png" \
      && echo "$name: renders the same image, byte for byte, as the one-piece file" \
      || echo "$name: renders a different image from the one-piece file"
  done
fi
