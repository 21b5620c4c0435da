#!/usr/bin/env bash
# Runs each fuzz target for a fixed time and writes a markdown summary (executions, exec/s,
# coverage) of the run. Fails (exit 1) if any target finds a crash, a sanitizer report, a leak,
# a timeout (-timeout per input) or runs out of memory; the input that did it is kept in
# ARTIFACTS/<target>/ and named in the summary.
#
#   verification/fuzz/run_fuzzers.sh [--seconds S] [--build-dir DIR] [--seeds DIR]
#                                    [--corpus DIR] [--artifacts DIR] [--report FILE]
#                                    [--targets "fuzz_config fuzz_run_file ..."]
#
#   --seconds S      time per target (default 600, the nightly's)
#   --build-dir DIR  the fuzz preset's build (default build/fuzz)
#   --seeds DIR      seeds from make_corpus.sh (default build/fuzz/seeds)
#   --corpus DIR     the growing corpus, kept between runs (default build/fuzz/corpus)
#   --artifacts DIR  crashing inputs (default build/fuzz/artifacts)
#   --report FILE    the summary (default build/fuzz/fuzz-summary.md)
# One process per target (-jobs is not used), -rss_limit_mb=2048, -timeout=25 s per input.
set -uo pipefail
cd "$(dirname "$0")/../.."
seconds=600
build_dir=build/fuzz
seeds=
corpus=
artifacts=
report=
targets="fuzz_config fuzz_run_file fuzz_md_checkpoint fuzz_continuum_checkpoint"
while [[ $# -gt 0 ]]; do
  case $1 in
    --seconds) seconds=${2:?--seconds needs a number}; shift 2 ;;
    --build-dir) build_dir=${2:?--build-dir needs a directory}; shift 2 ;;
    --seeds) seeds=${2:?--seeds needs a directory}; shift 2 ;;
    --corpus) corpus=${2:?--corpus needs a directory}; shift 2 ;;
    --artifacts) artifacts=${2:?--artifacts needs a directory}; shift 2 ;;
    --report) report=${2:?--report needs a file}; shift 2 ;;
    --targets) targets=${2:?--targets needs names}; shift 2 ;;
    -h|--help) sed -n '2,/^set -uo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "run_fuzzers.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ $seconds =~ ^[0-9]+$ && $seconds -gt 0 ]] || { echo "run_fuzzers.sh: --seconds must be a whole number > 0" >&2; exit 2; }
seeds=${seeds:-$build_dir/seeds}
corpus=${corpus:-$build_dir/corpus}
artifacts=${artifacts:-$build_dir/artifacts}
report=${report:-$build_dir/fuzz-summary.md}
mkdir -p "$(dirname "$report")"
# The targets' per-process input files: in the build tree, so that a target stopped by a
# finding (no exit handlers run) leaves nothing in /tmp.
export TMPDIR=$(realpath -m "$build_dir/tmp")
rm -rf "$TMPDIR" && mkdir -p "$TMPDIR"

rows=()
failed=()
for target in $targets; do
  program=$build_dir/verification/fuzz/$target
  log=$build_dir/$target.log
  if [[ ! -x $program ]]; then
    echo "run_fuzzers.sh: $program is not built (cmake --build --preset fuzz)" >&2
    failed+=("$target")
    rows+=("| $target | not built | | | | | | |")
    continue
  fi
  mkdir -p "$corpus/$target" "$artifacts/$target"
  options=(-max_total_time="$seconds" -rss_limit_mb=2048 -timeout=25 -print_final_stats=1
           -artifact_prefix="$artifacts/$target/")
  [[ $target = fuzz_config && -f $seeds/config.dict ]] && options+=(-dict="$seeds/config.dict")
  echo "-- $target, $seconds s"
  # The seeds as a second corpus directory: read, never written.
  started=$(date +%s)
  timeout $(( seconds + 300 )) "$program" "${options[@]}" "$corpus/$target" "$seeds/$target" > "$log" 2>&1
  status=$?
  ran=$(( $(date +%s) - started ))
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+.*cov: [0-9]+' "$log" | tail -1)
  cov=$(sed -n 's/.*cov: \([0-9]*\).*/\1/p' <<< "$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<< "$last")
  outcome=clean
  if [[ $status -ne 0 ]]; then
    finding=$(grep -m1 -E 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error:|deadly signal|uncaught exception|terminate called' "$log")
    outcome="FAILED (exit $status): ${finding:-see $log}; input in $artifacts/$target/"
    failed+=("$target")
    tail -60 "$log" >&2
  fi
  rows+=("| $target | $ran | ${executions:-?} | ${rate:-?} | ${cov:-?} | ${ft:-?} | ${rss:-?} | $outcome |")
done

rm -rf "$TMPDIR"

{
  echo "# Fuzzing summary"
  echo
  echo "Commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown), $(date -u +%Y-%m-%dT%H:%M:%SZ)."
  echo "Each target ran alone for $seconds s (less if it found something; seconds: wall time, start-up"
  echo "and the seed corpus included), from the corpus kept in $corpus and the seeds of"
  echo "make_corpus.sh (cov: coverage points of the instrumented code reached; ft: features)."
  echo
  # Units in the headers (docs/units.md): seconds are wall-clock seconds; counts are numbers.
  echo "| target | seconds [s] | executions [1] | exec/s [1/s] | cov [1] | ft [1] | peak RSS [MB] | outcome |"
  echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |"
  printf '%s\n' "${rows[@]}"
} > "$report"
cat "$report"
if [[ ${#failed[@]} -gt 0 ]]; then
  echo "run_fuzzers.sh: FAILED: ${failed[*]}" >&2
  exit 1
fi
