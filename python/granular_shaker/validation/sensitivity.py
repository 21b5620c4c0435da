"""The continuum sensitivity study: every choice the paper leaves open, one at a time.

    shaker-sensitivity --shaker build/release/solvers/app/shaker [--workdir DIR]
        [--variants validation,plate_inelastic] [--cases base] [--jobs 2]
        [--results DIR/sensitivity.json] [--report reports/continuum-sensitivity.md]
        [--archive reports/continuum-sensitivity/judged.json] [--reuse-only] [--rerun]
        [--repository DIR]

(or `python3 -m granular_shaker.validation.sensitivity ...`). The study's data is read from the
repository (--repository, default: the git top level of the current directory), and its
default outputs go there: validation/work/, reports/continuum-sensitivity.md and the archive.

Each variant of validation/sensitivity.toml appends its `--set` overrides to the continuum
cases of the study; the MD runs of the study's md_cases are run once, as the validation study
runs them (validation/studies.toml: ensembles for single shocks). Runs are keyed by their
effective configuration exactly as the validation study (shaker-validation) keys them, so a
workdir shared with it reuses its runs, and an interrupted study resumes where it stopped.
Every variant is then judged by the claims the continuum fails (evaluated as the validation
study does, with MD's jackknife errors), the 1 % mass bottom above the plate at chosen phases,
the single-shock speed at e = 0.99, and its cost per cycle.
granular_shaker.reports.make_sensitivity_report writes the report.

A work folder lives as long as its machine; the study outlives it through its archive, a JSON
file kept with the report: every variant judged from finished runs is stored with a signature
of what its judgement depends on (the keys of its continuum runs and of the MD runs, the
claims' definitions, the phases of the mass bottoms) and the commit that judged it. A later
call judges an archived variant with an unchanged signature from the archive instead of
running it again. The MD runs and the reference variant's base case are always run (minutes),
since the MD numbers and the Knudsen maps are drawn from their files.

Exit status 0 when the results and report are written; 1 if a run or the report failed; 2 for
bad arguments.
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys
import time

from granular_shaker.reports import make_sensitivity_report
from granular_shaker.repository import (add_repository_option, fill_missing_paths,
                                        repository_argument)
from granular_shaker.validation.claims import evaluate_claims, format_value, measure
from granular_shaker.validation.plan import case_file, load_studies, load_toml, plan_runs, run_key
from granular_shaker.validation.run import execute_all, log
from granular_shaker.validation.summary import git, write_json_atomically
from granular_shaker.validation.views import Comparer, build_view

# Where the archive is kept, in the repository: beside the report's figures.
ARCHIVE = os.path.join("reports", "continuum-sensitivity", "judged.json")
REFERENCE = "validation"  # the variant without overrides: the validation settings


def load_variants(path, studies):
    """The study's settings and variants; ValueError names what is wrong."""
    spec = load_toml(path)
    study, variants = spec["study"], spec["variant"]
    known = set(studies["by_name"])
    names = set()
    for v in variants:
        if v["name"] in names:
            raise ValueError(f"variant {v['name']} appears twice")
        names.add(v["name"])
        unknown = [c for c in v.get("cases", []) if c not in study["cases"]]
        if unknown:
            raise ValueError(f"variant {v['name']}: cases {unknown} are not study cases")
    for c in study["cases"] + study["md_cases"]:
        if c not in known:
            raise ValueError(f"case {c} is not in validation/studies.toml")
    return study, variants


def plan(repository, studies, study, variants, case_filter, archived=()):
    """The solver runs (cases of `repository`): the MD references once, every variant's
    continuum cases except those of `archived` variants (the reference variant's base case is
    always run: the Knudsen maps are drawn from it)."""
    md_cases = [c for c in study["md_cases"] if not case_filter or c in case_filter]
    runs = [dict(r, variant=None) for r in plan_runs(repository, studies, md_cases, False)
            if r["solver"] == "md"]
    for v in variants:
        for case in v.get("cases", study["cases"]):
            if case_filter and case not in case_filter:
                continue
            if v["name"] in archived and not (v["name"] == REFERENCE and case == "base"):
                continue
            runs.append(dict(case=case, case_file=case_file(repository, case),
                             solver="continuum", replicas=1,
                             overrides=list(v["overrides"]), timeout=study["timeout"],
                             fallback=[], expect_failure=False, variant=v["name"]))
    return runs


def signatures(shaker, runs, variants, study, claims):
    """Each variant's signature: a hash of what its judgement depends on (its continuum runs'
    keys, the MD runs' keys, the definitions of the claims it is judged by, the phases of the
    mass bottoms). Sets each run's "key"."""
    for r in runs:
        r["key"] = run_key(shaker, r)[1]
    md = sorted(r["key"] for r in runs if r["solver"] == "md")
    used = [c for c in claims if c["id"] in study["claims"]]
    out = {}
    for v in variants:
        own = sorted(r["key"] for r in runs if r.get("variant") == v["name"])
        text = json.dumps(dict(continuum=own, md=md, claims=used,
                               phases=study["mass_gap_phases"]), sort_keys=True, default=str)
        out[v["name"]] = hashlib.sha256(text.encode()).hexdigest()
    return out


def load_archive(path):
    """The archive's judged variants by signature ({} without an archive)."""
    if not path or not os.path.exists(path):
        return {}
    with open(path) as f:
        return json.load(f)["judged"]


def write_archive(path, archive, judged, signature, commit):
    """Adds every variant judged here from finished runs (no run failed or missing) under its
    signature, with the commit that judged it; the archive's other entries are kept (a subset
    of the cases has its own signature, so it never stands in for the whole)."""
    entries = dict(archive)
    for v in judged:
        if not v.get("archived_at") and not v["failed"]:
            entries[signature[v["name"]]] = dict(variant=v["name"], commit=commit, judged=v)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    write_json_atomically(path, dict(judged=dict(sorted(entries.items()))))


def cycles_of(config):
    run = config.get("run", {})
    return run.get("transient_cycles", 0) + run.get("sampled_cycles", 0)


def mass_gap(phase, solver, views, comparer):
    """The 1 % mass bottom above the plate at a stored phase of the base case, measured as the
    validation study measures it (with its error over MD's samples): (value, error)."""
    m = measure("mass_gap_at", {"phase": phase}, ["base"], solver, views, comparer, False)
    return m.get("value"), m.get("error")


def judge_variant(variant, md_views, continuum_views, claims, study, comparer):
    """The variant's claims, mass bottoms, single-shock speed and cost."""
    views = dict(md_views)
    views.update({(case, "continuum"): view for case, view in continuum_views.items()})
    cases = set(continuum_views)
    chosen = [c for c in claims if c["id"] in study["claims"]
              and all(case in cases or (case, "md") in md_views for case in c["cases"])]
    results = evaluate_claims(chosen, views, comparer, partial_cases_ok=False)
    verdicts = {}
    for claim in results:
        solver = "md_vs_continuum" if claim["solvers"] == "md_vs_continuum" else "continuum"
        entry = claim["per_solver"].get(solver)
        if entry is None:
            continue
        first = entry["checks"][0]
        verdicts[claim["id"]] = dict(status=entry["status"], value=first.get("value"),
                                     error=first.get("error"), band=claim["band"],
                                     comparison=claim["comparison"],
                                     reason=first.get("reason"))
    base = continuum_views.get("base")
    gaps = {}
    if base is not None and base.status == "ok":
        for phase in study["mass_gap_phases"]:
            gaps[f"{phase:g}"] = mass_gap(phase, "continuum", views, comparer)
    speed = None
    shock = continuum_views.get("single_shock_e0p99")
    if shock is not None and shock.status == "ok":
        speed = shock.shock_speed
    seconds = {case: view.runs[0]["seconds"] for case, view in continuum_views.items() if view.runs}
    per_cycle = {case: seconds[case] / max(cycles_of(view.config), 1)
                 for case, view in continuum_views.items() if case in seconds}
    failed = {case: view.status for case, view in continuum_views.items() if view.status != "ok"}
    return dict(name=variant["name"], choice=variant["choice"], overrides=variant["overrides"],
                note=variant.get("note", ""), claims=verdicts, mass_gap=gaps,
                single_shock_speed=speed, seconds_per_cycle=per_cycle, failed=failed)


def md_reference(md_views, study, comparer):
    """MD's numbers the variants are judged against, with their errors."""
    base = md_views.get(("base", "md"))
    gaps = {}
    if base is not None and base.status == "ok":
        gaps = {f"{p:g}": mass_gap(p, "md", md_views, comparer)
                for p in study["mass_gap_phases"]}
    shock = md_views.get(("single_shock_e0p99", "md"))
    speed = None
    if shock is not None and shock.status == "ok":
        speed = (shock.shock_speed, shock.per_run_errors.get("shock_speed"))
    formation = exit_phase = None
    if base is not None and base.status == "ok":
        errors = base.per_run_errors
        formation = (base.per_run.get("formation_phase"), errors.get("formation_phase"))
        exit_phase = (base.per_run.get("exit_phase"), errors.get("exit_phase"))
    return dict(mass_gap=gaps, single_shock_speed=speed, formation_phase=formation,
                exit_phase=exit_phase)


def knudsen_inputs(md_base, continuum_base):
    """The base case's profiles with their local Knudsen numbers (`shaker analyze
    --profiles-csv`, written beside each analysed run) and per-phase Knudsen mass fractions,
    MD and the reference variant."""
    out = {}
    for solver, view in (("md", md_base), ("continuum", continuum_base)):
        if view is None or view.status != "ok":
            continue
        out[solver] = dict(profiles_csv=view.path + ".profiles.csv",
                           phase=list(view.analysis["phase"]),
                           fraction=list(view.analysis["knudsen_mass_fraction"]),
                           fraction_error=list(view.errors.get("knudsen_mass_fraction", [])))
    return out


def argument_parser():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--shaker", required=True, help="path of the shaker program")
    parser.add_argument("--workdir",
                        help="runs and derived files (shared with the validation study: "
                        "reused; default: validation/work of the repository)")
    parser.add_argument("--spec", help="default: validation/sensitivity.toml of the repository")
    parser.add_argument("--studies", help="default: validation/studies.toml of the repository")
    parser.add_argument("--claims", help="default: reference-data/claims.toml of the repository")
    parser.add_argument("--variants", help="comma-separated subset of the variants")
    parser.add_argument("--cases", help="comma-separated subset of the study's cases")
    parser.add_argument("--jobs", type=int, default=2, help="solver runs at once")
    parser.add_argument("--results", help="results JSON (default WORKDIR/sensitivity.json)")
    parser.add_argument("--report",
                        help="default: reports/continuum-sensitivity.md of the repository")
    parser.add_argument("--archive",
                        help="judged variants kept across machines ('' for none; default: "
                        f"{ARCHIVE} of the repository)")
    parser.add_argument("--rerun", action="store_true",
                        help="ignore finished runs and the archive")
    parser.add_argument("--reuse-only", action="store_true",
                        help="never start a solver; use finished runs in --workdir only")
    add_repository_option(parser)
    return parser


def with_repository_defaults(args, repository):
    """The arguments with every path left out taken from the repository."""
    validation = os.path.join(repository, "validation")
    defaults = dict(workdir=os.path.join(validation, "work"),
                    spec=os.path.join(validation, "sensitivity.toml"),
                    studies=os.path.join(validation, "studies.toml"),
                    claims=os.path.join(repository, "reference-data", "claims.toml"),
                    report=os.path.join(repository, "reports", "continuum-sensitivity.md"),
                    archive=os.path.join(repository, ARCHIVE))
    return fill_missing_paths(args, defaults)


def chosen_variants_and_cases(parser, args, studies):
    """The study, its variants (--variants, else all) and the case filter (--cases, else
    None); an unknown variant or case is an argument error."""
    try:
        study, variants = load_variants(args.spec, studies)
    except (ValueError, KeyError) as error:
        parser.error(f"{args.spec}: {error}")
    if args.variants:
        wanted = [v.strip() for v in args.variants.split(",") if v.strip()]
        unknown = [w for w in wanted if w not in {v["name"] for v in variants}]
        if unknown:
            parser.error(f"unknown variant(s) {', '.join(unknown)}")
        variants = [v for v in variants if v["name"] in wanted]
    case_filter = None
    if args.cases:
        case_filter = [c.strip() for c in args.cases.split(",") if c.strip()]
        unknown = [c for c in case_filter if c not in study["cases"]]
        if unknown:
            parser.error(f"unknown case(s) {', '.join(unknown)}; study cases: "
                         + ", ".join(study["cases"]))
    return study, variants, case_filter


def judge_all(shaker, workdir, runs, variants, claims, study, archive, archived, signature):
    """Every variant judged, from its runs or from the archive: (the judged variants, the MD
    views, the reference variant's base-case view, the comparer)."""
    md_views = {(r["case"], "md"): build_view(shaker, r["case"], "md", r["record"], workdir)
                for r in runs if r["solver"] == "md"}
    comparer = Comparer(shaker, os.path.join(workdir, "derived"))
    judged, reference_base = [], None
    for v in variants:
        continuum = {r["case"]: build_view(shaker, r["case"], "continuum", r["record"], workdir)
                     for r in runs if r.get("variant") == v["name"]}
        if v["name"] == REFERENCE:
            reference_base = continuum.get("base")
        if v["name"] in archived:
            entry = archive[signature[v["name"]]]
            judged.append(dict(entry["judged"], archived_at=entry["commit"]))
        else:
            judged.append(judge_variant(v, md_views, continuum, claims, study, comparer))
        verdicts = [f"{k} {c['status']} {format_value(c['value'])}"
                    for k, c in judged[-1]["claims"].items()]
        log(f"{v['name']}: " + ", ".join(verdicts))
    return judged, md_views, reference_base, comparer


def main(argv=None):
    parser = argument_parser()
    args = parser.parse_args(argv)
    repository = repository_argument(parser, args)
    args = with_repository_defaults(args, repository)

    shaker, workdir = os.path.abspath(args.shaker), os.path.abspath(args.workdir)
    studies = load_studies(args.studies)
    study, variants, case_filter = chosen_variants_and_cases(parser, args, studies)
    claims = load_toml(args.claims)["claim"]
    os.makedirs(os.path.join(workdir, "runs"), exist_ok=True)
    archive_path = os.path.abspath(args.archive) if args.archive else None
    archive = load_archive(archive_path)
    signature = signatures(shaker, plan(repository, studies, study, variants, case_filter),
                           variants, study, claims)
    archived = set() if args.rerun else {n for n in signature if signature[n] in archive}
    commit = git(repository, "rev-parse", "HEAD")

    started = time.monotonic()
    runs = execute_all(shaker, workdir, plan(repository, studies, study, variants, case_filter,
                                             archived),
                       args.jobs, args.rerun, args.reuse_only)
    judged, md_views, reference_base, comparer = judge_all(
        shaker, workdir, runs, variants, claims, study, archive, archived, signature)
    if archive_path:
        write_archive(archive_path, archive, judged, signature, commit)
    summary = dict(commit=commit,
                   knudsen=knudsen_inputs(md_views.get(("base", "md")), reference_base),
                   shaker_version=subprocess.run([shaker, "--version"], capture_output=True,
                                                 text=True).stdout.strip(),
                   wall_seconds=time.monotonic() - started,
                   simulated_seconds=sum(r["record"]["seconds"] for r in runs
                                         if not r["record"].get("reused")),
                   study=study, md=md_reference(md_views, study, comparer), variants=judged,
                   runs=[dict(case=r["case"], solver=r["solver"], variant=r.get("variant"),
                              status=r["record"]["status"], seconds=r["record"]["seconds"],
                              reused=r["record"].get("reused", False),
                              stderr=r["record"].get("stderr", "")[-400:]) for r in runs])
    results = os.path.abspath(args.results or os.path.join(workdir, "sensitivity.json"))
    write_json_atomically(results, summary)
    report = make_sensitivity_report.main(["--results", results, "--output", args.report])
    failed = [r for r in runs if r["record"]["status"] not in ("ok",)]
    for r in failed:
        log(f"run failed: {r['case']} {r['solver']} {r.get('variant')}: {r['record']['status']}")
    return 1 if report != 0 or failed else 0


if __name__ == "__main__":
    sys.exit(main())
