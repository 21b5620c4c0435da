#!/bin/sh
# Cache misses per pair collision of the MD solver in the elastic gas (nu = 0.3) at
# N = 4,000, 40,000 and 400,000, from valgrind's cache simulation (callgrind): the memory
# traffic behind the large-N loss of collisions per second, independent of the load on the
# machine. A miss of the simulated last-level cache is a line fetched from memory.
#   md-cache-lines.sh [BUILD_DIR]    (default build/release; about 2 minutes)
# Simulated caches: L1 data 48 KiB, last level LL_BYTES (default 8 MiB, the effective
# last-level cache measured on the 2-core development machine).
set -eu
build=${1:-build/release}
tool=$build/verification/benchmarks/md_cache_lines
ll=${LL_BYTES:-8388608}
count=100000
if ! command -v valgrind > /dev/null; then
  echo "md-cache-lines: valgrind is not installed (Debian package valgrind)" >&2
  exit 2
fi
if [ ! -x "$tool" ]; then
  echo "md-cache-lines: $tool is not built (it needs valgrind/callgrind.h when CMake configures)" >&2
  exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| N | pair collisions | cell crossings | stale events | L1 misses | LL read misses | LL write misses |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for n in 4000 40000 400000; do
  valgrind --tool=callgrind --instr-atstart=no --cache-sim=yes --D1=49152,12,64 --LL="$ll",16,64 \
    --callgrind-out-file="$work/out.$n" "$tool" "$n" "$count" > "$work/tally.$n" 2> "$work/log.$n"
  # "==PID== LLd misses: 5,491,093 ( 4,873,039 rd + 618,054 wr)": per pair collision
  awk -v n="$n" '
    FNR == NR { pair = $4; cell = $6; stale = $8; next }
    /D1  misses:/ { gsub(",", ""); d1 = $4 }
    /LLd misses:/ { gsub(",", ""); rd = $6; wr = $9 }
    END { printf "| %d | %d | %.3f | %.3f | %.1f | %.1f | %.1f |\n", n, pair, cell / pair, stale / pair,
                 d1 / pair, rd / pair, wr / pair }' "$work/tally.$n" "$work/log.$n"
done
echo
echo "(counts per pair collision, over $count pair collisions after 5 N to melt the lattice; LL = $ll bytes)"
