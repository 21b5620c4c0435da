#!/usr/bin/env bash
# The README's main job: the paper's base case (validation/cases/base.toml) in every solver
# that is available, analysed by `shaker analyze`, and a markdown report with plots at
# out/base-case/base-case.md (out/ is not tracked; BASE_CASE_DIR chooses another folder).
# Installs missing dependencies and builds as needed.
# Quick default resolution: the continuum column at cell 0.25 (the case file says 0.1, several
# times the cost per cycle: docs/reproducing-the-paper.md gives run times); the MD run is the
# full case. Extra arguments are passed to both solvers after these, e.g.
# --set run.sampled_cycles=4 or --set continuum.cell_size=0.1.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
cmake --preset release > /dev/null
cmake --build --preset release
shaker=build/release/solvers/app/shaker
runs=${BASE_CASE_DIR:-out/base-case}
mkdir -p "$runs"
status=()
for solver in md continuum; do
  echo "== shaker $solver validation/cases/base.toml $*"
  start=$(date +%s%N)
  set +e
  # The run writes its log, $runs/$solver.log, itself (run.log).
  "$shaker" "$solver" validation/cases/base.toml --set "run.output=$runs/$solver.h5" \
    --set continuum.cell_size=0.25 "$@"
  rc=$?
  set -e
  milliseconds=$(( ($(date +%s%N) - start) / 1000000 ))
  case $rc in
    0) "$shaker" analyze "$runs/$solver.h5" --csv "$runs/$solver-analysis.csv" > /dev/null
       status+=("$solver=ok:$milliseconds") ;;
    *) echo "shaker $solver failed with exit code $rc" >&2; exit "$rc" ;;
  esac
done
PYTHONPATH=python /usr/bin/python3 -m granular_shaker.reports.make_base_case_report \
  --runs "$runs" --output "$runs/base-case.md" --status "${status[@]}"
echo "report: $runs/base-case.md"
