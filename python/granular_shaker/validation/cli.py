"""Runs the validation study (MD, continuum, the paper's claims) and writes reports/validation.md.

    shaker-validation --shaker build/release/solvers/app/shaker [--quick]
        [--cases base,depth_h4p5] [--workdir DIR] [--report reports/validation.md]
        [--jobs 2] [--launcher "mpirun -np 8"] [--require C1,C4,C10] [--reuse-only] [--rerun]
        [--repository DIR]

(or `python3 -m granular_shaker.validation ...`). The study's data is read from the repository
(--repository, default: the git top level of the current directory), and its default outputs
go there: validation/work/ and reports/validation.md.

Steps (data flows one way: case file -> solver -> run file -> analysis -> claims -> report):
1. every case of validation/studies.toml (or the --cases / --quick subset) is run with each
   solver that the paper used for it. A run is keyed by the SHA-256 of its effective
   configuration (`shaker config CASE --set ...`), so a finished run is reused, never
   re-simulated; --rerun forces new runs. An MD single-shock case is one ensemble of md_pool
   replicas started from consecutive cycles of the periodic state (md.replicas; replica k
   has run.transient_cycles + k), through --launcher (e.g. "mpirun -np 8") if given
   (granular_shaker.validation.plan, .run).
2. every finished run is analysed by `shaker analyze --csv` (the project's one analysis
   implementation), which gives every MD number a jackknife error over the independent
   samples (the replicas of an ensemble, or the sampled cycles of a periodic run) (.views).
3. `shaker compare --csv` gives the agreement metrics of every case run by both solvers.
4. every claim of reference-data/claims.toml is evaluated per solver against its band
   (.claims, .quantities), the diagnoses of validation/diagnoses.toml are measured
   (.diagnoses), and granular_shaker.reports.make_validation_report writes the report.

Exit status: 0 when the report is written and every claim named by --require passes in every
solver it applies to; 1 otherwise (a missing solver makes its claims "not measured", which
fails --require); 2 for bad arguments. Uses /usr/bin/python3 with numpy, matplotlib and h5py
only.
"""
import argparse
import os
import shlex
import sys
import time

from granular_shaker.reports import make_validation_report
from granular_shaker.repository import (add_repository_option, fill_missing_paths,
                                        repository_argument)
from granular_shaker.validation import quantities
from granular_shaker.validation.claims import evaluate_claims, format_value, required_not_passing
from granular_shaker.validation.diagnoses import diagnose, load_diagnoses
from granular_shaker.validation.plan import load_studies, load_toml, plan_runs, resampled_runs
from granular_shaker.validation.run import execute_all, log
from granular_shaker.validation.summary import (phase_sampling_results, study_summary,
                                                write_json_atomically)
from granular_shaker.validation.views import Comparer, build_view


def argument_parser():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--shaker", required=True, help="path of the shaker program")
    parser.add_argument("--quick", action="store_true",
                        help="reduced cycles and resolution, base case only (the ctest subset)")
    parser.add_argument("--cases", help="comma-separated subset of validation/studies.toml")
    parser.add_argument("--workdir",
                        help="where runs, analyses and derived files go (reused across calls; "
                        "default: validation/work of the repository)")
    parser.add_argument("--report", help="default: reports/validation.md of the repository")
    parser.add_argument("--claims", help="default: reference-data/claims.toml of the repository")
    parser.add_argument("--gci", help="GCI table of the base-case grid study (continuum "
                                      "uncertainty; default: the report generator's)")
    parser.add_argument("--studies", help="default: validation/studies.toml of the repository")
    parser.add_argument("--diagnoses",
                        help="default: validation/diagnoses.toml of the repository")
    parser.add_argument("--jobs", type=int, default=2, help="solver runs at once")
    parser.add_argument("--launcher", default="",
                        help="how MD ensembles (md_pool cases) are started, e.g. "
                        "\"mpirun -np 8\" (default: in one process)")
    parser.add_argument("--require", default="",
                        help="comma-separated claim ids that must pass (else exit status 1); "
                        "ID:SOLVER requires only that solver's check (e.g. C1:md)")
    parser.add_argument("--require-not-failing", default="",
                        help="like --require, but 'unresolved' (within 2 standard errors of "
                        "the band) is accepted too: what a study with few samples can show")
    parser.add_argument("--rerun", action="store_true", help="ignore finished runs")
    parser.add_argument("--reuse-only", action="store_true",
                        help="never start a solver; use finished runs in --workdir only")
    add_repository_option(parser)
    return parser


def with_repository_defaults(args, repository):
    """The arguments with every path left out taken from the repository."""
    validation = os.path.join(repository, "validation")
    defaults = dict(workdir=os.path.join(validation, "work"),
                    report=os.path.join(repository, "reports", "validation.md"),
                    claims=os.path.join(repository, "reference-data", "claims.toml"),
                    studies=os.path.join(validation, "studies.toml"),
                    diagnoses=os.path.join(validation, "diagnoses.toml"))
    return fill_missing_paths(args, defaults)


def chosen_cases(parser, args, studies):
    """The cases to run: --cases, the quick subset, or every case; an unknown one is an
    argument error."""
    if args.cases:
        names = [c.strip() for c in args.cases.split(",") if c.strip()]
    elif args.quick:
        names = list(studies["quick"]["cases"])
    else:
        names = [c["name"] for c in studies["case"]]
    unknown = [n for n in names if n not in studies["by_name"]]
    if unknown:
        parser.error(f"unknown case(s) {', '.join(unknown)}; known: "
                     + ", ".join(studies["by_name"]))
    return names


def run_views(shaker, repository, workdir, studies, names, args):
    """Runs (or reuses) the planned runs; returns the plan, each run with its record, and the
    view of every case in every solver that runs it."""
    plan = plan_runs(repository, studies, names, args.quick)
    if not args.quick:
        plan += resampled_runs(studies, plan)
    plan = execute_all(shaker, workdir, plan, args.jobs,
                       args.rerun, args.reuse_only, shlex.split(args.launcher))
    views = {}
    for name in names:
        for solver in studies["by_name"][name]["solvers"]:
            record = next(r["record"] for r in plan
                          if r["case"] == name and r["solver"] == solver and not r.get("phases"))
            views[(name, solver)] = build_view(shaker, name, solver, record, workdir)
    return plan, views


def agreement_metrics(names, views, comparer):
    """`shaker compare` of every case both solvers ran successfully."""
    metrics = {}
    for name in names:
        md, co = views.get((name, "md")), views.get((name, "continuum"))
        if md and co and md.status == "ok" and co.status == "ok":
            try:
                metrics[name] = comparer(co, md)
            except quantities.NotMeasured as reason:
                metrics[name] = {"error": str(reason)}
    return metrics


def requirements_met(results, args):
    """Logs every claim's verdict; False (after naming them) if a claim of --require or
    --require-not-failing is not met."""
    failing = required_not_passing(results, args.require, {"pass"})
    failing += required_not_passing(results, args.require_not_failing, {"pass", "unresolved"})
    for c in results:
        log(f"{c['id']}: {c['status']}  " + "; ".join(
            f"{s}: {r['status']} {format_value(r['checks'][0].get('value'))}"
            for s, r in c["per_solver"].items()))
    if failing:
        log("required claims not passing: " + ", ".join(failing))
        return False
    return True


def main(argv=None):
    parser = argument_parser()
    args = parser.parse_args(argv)
    repository = repository_argument(parser, args)
    args = with_repository_defaults(args, repository)

    shaker = os.path.abspath(args.shaker)
    workdir = os.path.abspath(args.workdir)
    os.makedirs(os.path.join(workdir, "runs"), exist_ok=True)
    studies = load_studies(args.studies)
    claims = load_toml(args.claims)["claim"]
    try:
        diagnoses = load_diagnoses(args.diagnoses, claims, studies)
    except ValueError as error:
        parser.error(str(error))
    names = chosen_cases(parser, args, studies)

    started = time.monotonic()
    plan, views = run_views(shaker, repository, workdir, studies, names, args)
    comparer = Comparer(shaker, os.path.join(workdir, "derived"))
    metrics = agreement_metrics(names, views, comparer)
    partial = bool(args.cases) or args.quick
    results = evaluate_claims(claims, views, comparer, partial)
    diagnosed, undiagnosed = diagnose(diagnoses, results, views, comparer, partial)
    sampling = phase_sampling_results(shaker, plan, views, workdir)
    summary = study_summary(repository, shaker, plan, views, started,
                            dict(quick=args.quick, cases=names, metrics=metrics, claims=results,
                                 diagnoses=diagnosed, sampling=sampling,
                                 metric_units={name: comparer.units[name]
                                               for m in metrics.values() for name in m},
                                 undiagnosed=undiagnosed))
    results_path = os.path.join(workdir, "results.json")
    write_json_atomically(results_path, summary)

    report = make_validation_report.main(["--results", results_path, "--output", args.report,
                                          "--repository", repository]
                                         + (["--gci", args.gci] if args.gci else []))
    if report != 0:
        log("the report generator failed")
        return 1
    return 0 if requirements_met(results, args) else 1


if __name__ == "__main__":
    sys.exit(main())
