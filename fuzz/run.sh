#!/usr/bin/env bash
# Runs the libFuzzer harnesses of a `fuzz` build (make fuzz; fuzz/README.md).
#   fuzz/run.sh [-s SECONDS] [-j PARALLEL] [-b BUILD_DIR] [-k] [HARNESS...]
# Each harness runs SECONDS (default 60) on its corpus (BUILD_DIR/corpus/<harness>, which keeps
# what it found, seeded from BUILD_DIR/fuzz/seeds/<harness>), PARALLEL harnesses at a time
# (default 2), its output in BUILD_DIR/fuzz-logs/<harness>.log. A harness stops at its first
# finding; the others run to their end. Then one line each (runs, time, corpus), and for each
# harness that failed its libFuzzer report and the reproducer (BUILD_DIR/findings/<harness>/
# crash-*, leak-*, timeout-*, oom-*). Exits 1 when a harness failed.
# -k (keep going, for looking around rather than CI): harnesses run in a child process that is
# restarted after each finding, and the findings are grouped by fuzz/triage.sh at the end.
set -uo pipefail
cd "$(dirname "$0")/.."

seconds=60 parallel=2 build=build/fuzz keep_going=()
while getopts "s:j:b:k" opt; do
  case $opt in
    s) seconds=$OPTARG ;;
    j) parallel=$OPTARG ;;
    b) build=$OPTARG ;;
    k) keep_going=(-fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1) ;;
    *) exit 2 ;;
  esac
done
shift $((OPTIND - 1))
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=(ply las obj xyz qs ptl_v1 ptl_v2 path pfm)

logs=$build/fuzz-logs
mkdir -p "$logs"
# Stacks with file and line; UBSan reports stop the run (the library is built with
# -fno-sanitize-recover, this keeps the harness's own code the same).
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
if [ -z "${ASAN_SYMBOLIZER_PATH:-}" ] && [ -x /usr/lib/llvm-14/bin/llvm-symbolizer ]; then
  export ASAN_SYMBOLIZER_PATH=/usr/lib/llvm-14/bin/llvm-symbolizer
fi

run_one() {
  local h=$1 bin=$build/fuzz/${h}_fuzz
  local corpus=$build/corpus/$h findings=$build/findings/$h
  mkdir -p "$corpus" "$findings"
  local dict=()
  [ -f "fuzz/$h.dict" ] && dict=(-dict="fuzz/$h.dict")
  # -timeout: one input taking 10 s is a hang. -rss_limit_mb: also the largest single malloc
  # (libFuzzer's malloc_limit_mb defaults to it); seeds are a few KiB, so a reader asking for a
  # GiB trusted a count in the file.
  "$bin" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=1024 -print_final_stats=1 \
    -artifact_prefix="$findings/" "${dict[@]+"${dict[@]}"}" "${keep_going[@]+"${keep_going[@]}"}" "$corpus" "$build/fuzz/seeds/$h" \
    >"$logs/$h.log" 2>&1
  echo $? >"$logs/$h.rc"
}

for h in "${harnesses[@]}"; do
  if [ ! -x "$build/fuzz/${h}_fuzz" ]; then
    echo "fuzz: no harness $build/fuzz/${h}_fuzz (build it with make fuzz)" >&2
    exit 2
  fi
done

start=$(date +%s)
for h in "${harnesses[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n; done
  rm -f "$logs/$h.rc"
  run_one "$h" &
done
wait

failed=()
for h in "${harnesses[@]}"; do
  log=$logs/$h.log
  rc=$(cat "$logs/$h.rc" 2>/dev/null || echo 1)
  field() { sed -n "s/^stat::$1: *//p" "$log" | tail -1; }
  runs=$(field number_of_executed_units)
  # -k: the parent's last status line ("#1234: cov: ...") counts the runs of all children.
  [ -n "$runs" ] || runs=$(sed -n 's/^#\([0-9]*\): cov:.*/\1/p' "$log" | tail -1)
  per_s=$(field average_exec_per_sec)
  rss=$(field peak_rss_mb)
  [ -n "$per_s" ] || per_s=$(( ${runs:-0} / seconds ))
  files=$(find "$build/corpus/$h" -type f | wc -l)
  if [ "$rc" = 0 ]; then
    echo "fuzz: $h: ok, ${runs:-?} runs in ${seconds} s (${per_s}/s), corpus $files files${rss:+, peak RSS $rss MB}"
  else
    failed+=("$h")
    echo "fuzz: $h: FAILED (exit $rc) after ${runs:-?} runs; log $log"
  fi
done
for h in "${failed[@]+"${failed[@]}"}"; do
  log=$logs/$h.log
  if [ ${#keep_going[@]} -gt 0 ]; then
    echo
    echo "===== fuzz: $h: findings by kind ====="
    files=("$build/findings/$h"/*)
    if [ -e "${files[0]}" ]; then bash fuzz/triage.sh -b "$build" "$h" "${files[@]}"; else tail -n 20 "$log"; fi
    continue
  fi
  echo
  echo "===== fuzz: $h: libFuzzer report ($log) ====="
  # From the first line of the report (sanitizer, libFuzzer, or the harness's own check) on.
  first=$(grep -n -m1 -E '^==[0-9]+==|ERROR: libFuzzer|runtime error:|pointillist fuzz finding|^ALARM|terminate called' "$log" | cut -d: -f1)
  if [ -n "$first" ]; then tail -n +"$first" "$log" | head -n 200; else tail -n 60 "$log"; fi
  echo "===== reproducer: $(grep -o 'Test unit written to .*' "$log" | sed 's/Test unit written to //' | tr '\n' ' ')"
  echo "      rerun: $build/fuzz/${h}_fuzz <reproducer>"
done
echo "fuzz: ${#harnesses[@]} harnesses, $(( $(date +%s) - start )) s"
[ ${#failed[@]} -eq 0 ]
