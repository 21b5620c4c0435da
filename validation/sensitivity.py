#!/usr/bin/python3
"""The continuum sensitivity study: every choice the paper leaves open, one at a time.

    validation/sensitivity.py --shaker build/release/solvers/app/shaker [--workdir DIR]
        [--variants validation,plate_inelastic] [--cases base] [--jobs 2]
        [--results DIR/sensitivity.json] [--report reports/continuum-sensitivity.md]
        [--archive reports/continuum-sensitivity/judged.json] [--reuse-only] [--rerun]

Each variant of validation/sensitivity.toml appends its `--set` overrides to the continuum
cases of the study; the MD runs of the study's md_cases are run once, as the validation study
runs them (validation/studies.toml: ensembles for single shocks). Runs are keyed by their
effective configuration exactly as run_validation.py keys them, so a workdir shared with the
validation study reuses its runs, and an interrupted study resumes where it stopped. Every
variant is then judged by the claims the continuum fails (evaluated as the validation study
does, with MD's jackknife errors), the 1 % mass bottom above the plate at chosen phases, the
single-shock speed at e = 0.99, and its cost per cycle. reports/make_sensitivity_report.py
writes the report.

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

if __package__:
    from . import run_validation as rv
else:  # run as a script: its folder, validation/, is first on sys.path
    import run_validation as rv

HERE = rv.HERE
ROOT = rv.ROOT
ARCHIVE = os.path.join(ROOT, "reports", "continuum-sensitivity", "judged.json")
REFERENCE = "validation"  # the variant without overrides: the validation settings


def load_variants(path, studies):
    """The study's settings and variants; ValueError names what is wrong."""
    spec = rv.load_toml(path)
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


def plan(shaker, studies, study, variants, case_filter, archived=()):
    """The solver runs: the MD references once, every variant's continuum cases except those
    of `archived` variants (the reference variant's base case is always run: the Knudsen maps
    are drawn from it)."""
    md_cases = [c for c in study["md_cases"] if not case_filter or c in case_filter]
    runs = [dict(r, variant=None) for r in rv.plan_runs(shaker, studies, md_cases, False)
            if r["solver"] == "md"]
    for v in variants:
        for case in v.get("cases", study["cases"]):
            if case_filter and case not in case_filter:
                continue
            if v["name"] in archived and not (v["name"] == REFERENCE and case == "base"):
                continue
            runs.append(dict(case=case, solver="continuum", replicas=1,
                             overrides=list(v["overrides"]), timeout=study["timeout"],
                             fallback=[], expect_failure=False, variant=v["name"]))
    return runs


def signatures(shaker, runs, variants, study, claims):
    """Each variant's signature: a hash of what its judgement depends on (its continuum runs'
    keys, the MD runs' keys, the definitions of the claims it is judged by, the phases of the
    mass bottoms). Sets each run's "key"."""
    for r in runs:
        r["key"] = rv.run_key(shaker, r)[1]
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
    with open(path + ".partial", "w") as f:
        json.dump(rv.plain(dict(judged=dict(sorted(entries.items())))), f, indent=1)
    os.replace(path + ".partial", path)


def cycles_of(config):
    run = config.get("run", {})
    return run.get("transient_cycles", 0) + run.get("sampled_cycles", 0)


def mass_gap(phase, solver, views, comparer):
    """The 1 % mass bottom above the plate at a stored phase of the base case, measured as the
    validation study measures it (with its error over MD's samples): (value, error)."""
    m = rv.measure("mass_gap_at", {"phase": phase}, ["base"], solver, views, comparer, False)
    return m.get("value"), m.get("error")


def judge_variant(variant, md_views, continuum_views, claims, study, comparer):
    """The variant's claims, mass bottoms, single-shock speed and cost."""
    views = dict(md_views)
    views.update({(case, "continuum"): view for case, view in continuum_views.items()})
    cases = set(continuum_views)
    chosen = [c for c in claims if c["id"] in study["claims"]
              and all(case in cases or (case, "md") in md_views for case in c["cases"])]
    results = rv.evaluate_claims(chosen, views, comparer, partial_cases_ok=False)
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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--shaker", required=True, help="path of the shaker program")
    parser.add_argument("--workdir", default=os.path.join(HERE, "work"),
                        help="runs and derived files (shared with run_validation.py: reused)")
    parser.add_argument("--spec", default=os.path.join(HERE, "sensitivity.toml"))
    parser.add_argument("--studies", default=os.path.join(HERE, "studies.toml"))
    parser.add_argument("--claims", default=os.path.join(ROOT, "reference-data", "claims.toml"))
    parser.add_argument("--variants", help="comma-separated subset of the variants")
    parser.add_argument("--cases", help="comma-separated subset of the study's cases")
    parser.add_argument("--jobs", type=int, default=2, help="solver runs at once")
    parser.add_argument("--results", help="results JSON (default WORKDIR/sensitivity.json)")
    parser.add_argument("--report", default=os.path.join(ROOT, "reports",
                                                         "continuum-sensitivity.md"))
    parser.add_argument("--archive", default=ARCHIVE,
                        help="judged variants kept across machines ('' for none)")
    parser.add_argument("--rerun", action="store_true",
                        help="ignore finished runs and the archive")
    parser.add_argument("--reuse-only", action="store_true",
                        help="never start a solver; use finished runs in --workdir only")
    args = parser.parse_args(argv)

    shaker, workdir = os.path.abspath(args.shaker), os.path.abspath(args.workdir)
    studies = rv.load_studies(args.studies)
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
    claims = rv.load_toml(args.claims)["claim"]
    os.makedirs(os.path.join(workdir, "runs"), exist_ok=True)
    archive_path = os.path.abspath(args.archive) if args.archive else None
    archive = load_archive(archive_path)
    signature = signatures(shaker, plan(shaker, studies, study, variants, case_filter),
                           variants, study, claims)
    archived = set() if args.rerun else {n for n in signature if signature[n] in archive}
    commit = rv.git("rev-parse", "HEAD")

    started = time.monotonic()
    runs = rv.execute_all(shaker, workdir, plan(shaker, studies, study, variants, case_filter,
                                                archived),
                          args.jobs, args.rerun, args.reuse_only)
    md_views = {(r["case"], "md"): rv.build_view(shaker, r["case"], "md", r["record"], workdir)
                for r in runs if r["solver"] == "md"}
    comparer = rv.Comparer(shaker, os.path.join(workdir, "derived"))
    judged, reference_base = [], None
    for v in variants:
        continuum = {r["case"]: rv.build_view(shaker, r["case"], "continuum", r["record"], workdir)
                     for r in runs if r.get("variant") == v["name"]}
        if v["name"] == REFERENCE:
            reference_base = continuum.get("base")
        if v["name"] in archived:
            entry = archive[signature[v["name"]]]
            judged.append(dict(entry["judged"], archived_at=entry["commit"]))
        else:
            judged.append(judge_variant(v, md_views, continuum, claims, study, comparer))
        verdicts = [f"{k} {c['status']} {rv._format_value(c['value'])}"
                    for k, c in judged[-1]["claims"].items()]
        rv.log(f"{v['name']}: " + ", ".join(verdicts))
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
    with open(results + ".partial", "w") as f:
        json.dump(rv.plain(summary), f, indent=1)
    os.replace(results + ".partial", results)
    report = subprocess.run([sys.executable, os.path.join(ROOT, "reports",
                                                          "make_sensitivity_report.py"),
                             "--results", results, "--output", args.report])
    failed = [r for r in runs if r["record"]["status"] not in ("ok",)]
    for r in failed:
        rv.log(f"run failed: {r['case']} {r['solver']} {r.get('variant')}: {r['record']['status']}")
    return 1 if report.returncode != 0 or failed else 0


if __name__ == "__main__":
    sys.exit(main())
