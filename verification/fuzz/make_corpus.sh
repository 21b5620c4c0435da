#!/usr/bin/env bash
# Seed corpora of the fuzz targets, made from real files: a short MD and a short 1D continuum
# run of small_case.toml (run files and checkpoints, as recipes: hdf5_recipe.hpp) and the case
# files of validation/cases as configuration seeds, plus a dictionary of the schema's keys.
#
#   verification/fuzz/make_corpus.sh [--shaker PROGRAM] [--output DIR]
#
#   --shaker PROGRAM   the `shaker` that writes the files (default build/release/solvers/app/shaker)
#   --output DIR       where the seeds go (default build/fuzz/seeds): DIR/<target>/ for each
#                      target, and DIR/config.dict
# Deterministic: the runs use small_case.toml's seed.
set -euo pipefail
cd "$(dirname "$0")/../.."
shaker=build/release/solvers/app/shaker
output=build/fuzz/seeds
while [[ $# -gt 0 ]]; do
  case $1 in
    --shaker) shaker=${2:?--shaker needs a program}; shift 2 ;;
    --output) output=${2:?--output needs a directory}; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "make_corpus.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ -x $shaker ]] || { echo "make_corpus.sh: no shaker program at '$shaker' (build the release preset or give --shaker)" >&2; exit 2; }
python=/usr/bin/python3  # h5py
case_file=verification/fuzz/small_case.toml
work=$(mktemp -d "${TMPDIR:-/tmp}/shaker-fuzz-corpus.XXXXXX")
trap 'rm -rf "$work"' EXIT

"$shaker" md "$case_file" --set run.output="$work/md.h5" \
    --set run.checkpoint="$work/md-checkpoint.h5" > "$work/md.log"
"$shaker" continuum "$case_file" --set run.output="$work/continuum.h5" \
    --set run.checkpoint="$work/continuum-checkpoint.h5" > "$work/continuum.log"
# Checkpoints whose schedule and sums the restart path checks: two sampled cycles (the sums of
# both), and single shocks after their switch (check_switch against the stored protocol).
"$shaker" md "$case_file" --set run.output="$work/md2.h5" --set run.sampled_cycles=2 \
    --set run.checkpoint="$work/md-checkpoint-sampled.h5" > "$work/md2.log"
for solver in md continuum; do
  "$shaker" "$solver" "$case_file" --set run.output="$work/$solver-shock.h5" \
      --set run.protocol=single_shock --set run.transient_cycles=1 \
      --set run.checkpoint="$work/$solver-checkpoint-single-shock.h5" > "$work/$solver-shock.log"
done

rm -rf "$output"
mkdir -p "$output"/{fuzz_config,fuzz_run_file,fuzz_md_checkpoint,fuzz_continuum_checkpoint}
recipe() { "$python" verification/fuzz/h5_to_recipe.py "$1" "$2"; }
recipe "$work/md.h5" "$output/fuzz_run_file/md-run"
recipe "$work/continuum.h5" "$output/fuzz_run_file/continuum-run"
recipe "$work/md-checkpoint.h5" "$output/fuzz_md_checkpoint/md-checkpoint"
recipe "$work/continuum-checkpoint.h5" "$output/fuzz_continuum_checkpoint/continuum-checkpoint"
recipe "$work/md-checkpoint-sampled.h5" "$output/fuzz_md_checkpoint/md-checkpoint-sampled"
recipe "$work/md-checkpoint-single-shock.h5" "$output/fuzz_md_checkpoint/md-checkpoint-single-shock"
recipe "$work/continuum-checkpoint-single-shock.h5" \
    "$output/fuzz_continuum_checkpoint/continuum-checkpoint-single-shock"

for file in validation/cases/*.toml "$case_file"; do
  cp "$file" "$output/fuzz_config/$(basename "$file" .toml)"
done
# Overrides after a document (fuzz_config.cpp: lines "--set KEY=VALUE" after the document).
{ cat "$case_file"; printf '%s\n' '--set material.e=0.5' '--set md.crossing_heights=[10, 20.5]' \
    '--set run.protocol=single_shock' '--set continuum.dimension=3'; } > "$output/fuzz_config/with-overrides"
# The effective configuration as `shaker config` prints it: every key, in schema order.
"$shaker" config "$case_file" > "$output/fuzz_config/effective"

# Dictionary for fuzz_config: every section and key of the schema, and the text choices.
"$shaker" config "$case_file" | "$python" -c '
import re, sys
words = set()
for line in sys.stdin:
    if m := re.match(r"\[(\w+)\]", line):
        words.add("[" + m.group(1) + "]")
        section = m.group(1)
    elif m := re.match(r"(\w+)\s*=", line):
        words.add(m.group(1) + " = ")
        words.add("--set " + section + "." + m.group(1) + "=")
for w in ["constant", "velocity_dependent", "periodic", "single_shock", "flat_layer", "gas",
          "checkpoint", "calendar", "heap", "tc", "off", "full", "paper", "true", "false",
          "nan", "inf", "-inf", "1e308", "[[", "]]", "\"\"\""]:
    words.add(w)
for w in sorted(words):
    print("\"" + w.replace("\\", "\\\\").replace("\"", "\\\"") + "\"")
' > "$output/config.dict"

for target in "$output"/fuzz_*; do
  echo "$(basename "$target"): $(ls "$target" | wc -l) seeds, $(cat "$target"/* | wc -c) bytes"
done
