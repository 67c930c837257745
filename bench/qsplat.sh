#!/usr/bin/env bash
# Pointillist's mesh conversion against QSplat 1.0's qsplat_make (Stanford, 2000) on the same
# binary big-endian PLY meshes, in one sitting: the Stanford dragon (437,645 vertices) and the
# same dragon subdivided twice (6,979,655 vertices, made by bench tool subdivide_mesh). Whole
# processes under /usr/bin/time, the two programs in turn, RUNS times each; medians of wall time,
# CPU time and peak resident memory, and Pointillist's as ratios over qsplat_make's. qsplat_make
# is built outside this repository from its public source (nothing of it is committed), with its
# own makefile's flags on x86-64 (its endianness test only knows i386):
#   g++ -O3 -ffast-math -funroll-loops -fpermissive -w -Di386 -include cstring \
#     -include cstdlib qsplat_make_main.cpp qsplat_make_from_mesh.cpp \
#     qsplat_make_qtree_v11.cpp qsplat_colorquant.cpp qsplat_normquant.cpp \
#     qsplat_spherequant.cpp -o qsplat_make
# (its output on dragon_vrip_res4 equals ../shared/testdata/qsplat/dragon_vrip_res4.qs byte for
# byte). qsplat_make runs on one thread; Pointillist on all.
#
#   bash bench/qsplat.sh --qsplat-make PATH [--bin PATH] [--work DIR] [--runs N]
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${POINTILLIST_BIN:-build/release/pointillist}"
subdivide="${SUBDIVIDE_MESH:-build/release/bench/subdivide_mesh}"
work="${QSPLAT_BENCH_WORK:-/tmp/pointillist-bench-qsplat}"
dragon="../shared/testdata/qsplat/dragon_vrip.bbe.ply"
runs=3
qsplat_make=""
while [ $# -gt 0 ]; do
  case "$1" in
    --qsplat-make) qsplat_make="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    *) echo "qsplat.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -x "$qsplat_make" ] || { echo "qsplat.sh: give --qsplat-make PATH to a qsplat_make binary" >&2; exit 1; }
[ -x "$bin" ] || { echo "qsplat.sh: no binary at $bin (make build)" >&2; exit 1; }
[ -x "$subdivide" ] || { echo "qsplat.sh: no subdivide_mesh at $subdivide (build the bench targets)" >&2; exit 1; }
[ -f "$dragon" ] || { echo "qsplat.sh: $dragon missing (../shared/testdata)" >&2; exit 1; }
mkdir -p "$work"
cp "$dragon" "$work/dragon.ply"
[ -f "$work/dragon7m.ply" ] || "$subdivide" "$work/dragon.ply" "$work/dragon7m.ply" 2

# measure CMD...: prints "wall cpu peak_kb" of one run.
measure() {
  /usr/bin/time -f "%e %U %S %M" -o "$work/run.time" "$@" > "$work/run.log" 2>&1
  read -r wall user sys peak < "$work/run.time"
  echo "$wall $(echo "$user + $sys" | bc) $peak"
}
# median of the values on stdin
median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

printf '%-10s %-22s %6s %8s %8s %8s %9s %8s %8s\n' mesh program vertices wall_s cpu_s cpu/wall \
  peak_MB wall/QM peak/QM
for mesh in dragon dragon7m; do
  in="$work/$mesh.ply"
  vertices=$(grep -a -m1 "^element vertex" "$in" | awk '{print $3}')
  declare -A w c p
  for k in qm ptl qs; do w[$k]=""; c[$k]=""; p[$k]=""; done
  for ((i = 0; i < runs; i++)); do
    for k in qm ptl qs; do
      case $k in
        qm) r=$(measure "$qsplat_make" "$in" "$work/qm.qs") ;;
        ptl) r=$(measure "$bin" convert "$in" -o "$work/p.ptl" -q) ;;
        qs) r=$(measure "$bin" convert "$in" -o "$work/p.qs" -q) ;;
      esac
      read -r wall cpu peak <<< "$r"
      w[$k]+="$wall"$'\n'; c[$k]+="$cpu"$'\n'; p[$k]+="$peak"$'\n'
    done
  done
  qm_wall=$(printf '%s' "${w[qm]}" | median); qm_peak=$(printf '%s' "${p[qm]}" | median)
  for k in qm ptl qs; do
    name=$([ $k = qm ] && echo "qsplat_make -> .qs" || echo "pointillist -> .$k")
    wall=$(printf '%s' "${w[$k]}" | median); cpu=$(printf '%s' "${c[$k]}" | median)
    peak=$(printf '%s' "${p[$k]}" | median)
    awk -v m="$mesh" -v n="$name" -v v="$vertices" -v w="$wall" -v c="$cpu" -v p="$peak" \
        -v bw="$qm_wall" -v bp="$qm_peak" 'BEGIN {
      printf "%-10s %-22s %6.2fM %8.2f %8.2f %8.2f %9.0f %8.2f %8.2f\n", m, n, v / 1e6, w, c,
             c / w, p / 1024, w / bw, p / bp }'
  done
  unset w c p
done
