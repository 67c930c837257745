#!/usr/bin/env bash
# Groups reproducers by what they break: runs the harness on each file and prints, per distinct
# report (its first line and the first stack frame in src/), how many files give it and the
# smallest of them.
#   fuzz/triage.sh [-b BUILD_DIR] HARNESS FILE...
set -uo pipefail
cd "$(dirname "$0")/.."

build=build/fuzz
while getopts "b:" opt; do
  case $opt in
    b) build=$OPTARG ;;
    *) exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -ge 2 ] || { echo "usage: fuzz/triage.sh [-b BUILD_DIR] HARNESS FILE..." >&2; exit 2; }
harness=$1
shift
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
[ -x /usr/lib/llvm-14/bin/llvm-symbolizer ] &&
  export ASAN_SYMBOLIZER_PATH=${ASAN_SYMBOLIZER_PATH:-/usr/lib/llvm-14/bin/llvm-symbolizer}

declare -A count smallest size
for f in "$@"; do
  [ -f "$f" ] || continue
  out=$("$build/fuzz/${harness}_fuzz" -timeout=10 -rss_limit_mb=1024 "$f" 2>&1)
  if [ $? -eq 0 ]; then
    what="no failure (fixed, or needs the state of a longer run)"
  else
    what=$(grep -m1 -E 'pointillist fuzz finding|runtime error:|ERROR: AddressSanitizer|ERROR: LeakSanitizer|ERROR: libFuzzer: (timeout|out-of-memory|malloc)|terminate called|what\(\)' <<<"$out" |
      sed -E 's/==[0-9]+==//; s/0x[0-9a-f]+/0x…/g; s/(position|normal|radius) [0-9]+/\1 N/')
    where=$(grep -m1 -E '^ +#[0-9]+ .* /.*/src/' <<<"$out" | sed -E 's/^ +#[0-9]+ 0x[0-9a-f]+ in //')
    what="$what | ${where:-?}"
  fi
  bytes=$(stat -c %s "$f")
  count[$what]=$(( ${count[$what]:-0} + 1 ))
  if [ -z "${size[$what]:-}" ] || [ "$bytes" -lt "${size[$what]}" ]; then
    size[$what]=$bytes
    smallest[$what]=$f
  fi
done
for what in "${!count[@]}"; do
  echo "${count[$what]} x ${what}"
  echo "    smallest: ${smallest[$what]} (${size[$what]} bytes)"
done
