"""ctest validation.sensitivity: the continuum sensitivity study's plan and its pipeline.

- The variants of validation/sensitivity.toml cover every choice the study must vary, each is
  accepted by `shaker config` on every case it runs, and each differs from the reference by
  its own overrides only (one choice at a time).
- On synthetic run files (harness/synthetic_runs.py) of two variants, the study
  (granular_shaker.validation.sensitivity) with --reuse-only judges each variant by the claims
  it names, with numbers equal to what `shaker compare` gives for the same files, and writes
  the report with its figure.

    python3 -m pytest python/tests/harness/validation/test_sensitivity.py --shaker SHAKER
"""
import json
import os
import subprocess

from granular_shaker.validation import sensitivity
from granular_shaker.validation.plan import case_file, effective_config, load_studies, run_key
from granular_shaker.validation.summary import git

from .. import REPOSITORY, harness_command, package_environment, synthetic_runs

VALIDATION = os.path.join(REPOSITORY, "validation")
SPEC = os.path.join(VALIDATION, "sensitivity.toml")
# The choices the study must vary (the paper leaves them open, or the project made them).
REQUIRED_CHOICES = (
    "transport variant", "artificial dissipation: form and coefficient",
    "artificial dissipation: density threshold", "temperature floor",
    "thermal wall condition at the plate", "ceiling: condition", "ceiling: height", "cell size",
    "time integrator", "1D column against the 3D 11 x 11 box", "initial state",
    "transient cycles", "reconstruction and limiter")


def load():
    studies = load_studies(os.path.join(VALIDATION, "studies.toml"))
    return (studies,) + sensitivity.load_variants(SPEC, studies)


def test_every_choice_is_varied():
    _, _, variants = load()
    choices = {v["choice"] for v in variants}
    missing = [c for c in REQUIRED_CHOICES if c not in choices]
    assert not missing, f"choices without a variant: {missing}"
    forms = {o.split("=")[1] for v in variants for o in v["overrides"]
             if o.startswith("continuum.artificial_dissipation=")}
    assert {"transport_coefficients", "second_difference", "von_neumann_richtmyer"} <= forms
    coefficients = sorted(float(o.split("=")[1]) for v in variants for o in v["overrides"]
                          if o.startswith("continuum.artificial_viscosity="))
    assert coefficients[-1] / coefficients[0] >= 10.0, "coefficients span at least a decade"
    cells = {o for v in variants for o in v["overrides"] if o.startswith("continuum.cell_size=")}
    assert len(cells | {"continuum.cell_size=0.1"}) >= 3, "three grids"


def test_variants_are_valid_and_one_at_a_time(shaker):
    studies, study, variants = load()
    reference = next(v for v in variants if not v["overrides"])
    assert reference["name"] == "validation"
    for v in variants:
        for case in v.get("cases", study["cases"]):
            # ValueError if refused
            text = effective_config(shaker, case_file(REPOSITORY, case), v["overrides"])
            assert text
        keys = [o.split("=")[0] for o in v["overrides"]]
        assert len(keys) == len(set(keys)), f"{v['name']}: a key set twice"


def test_pipeline_on_synthetic_runs(shaker, work_dir):
    studies, study, variants = load()
    chosen = [v for v in variants if v["name"] in ("validation", "plate_inelastic")]
    workdir = os.path.join(work_dir, "work")
    runs = sensitivity.plan(REPOSITORY, studies, study, chosen, ["base", "depth_h4p5",
                                                                 "depth_h13p5"])
    synthetic_runs.write_plan(shaker, workdir, runs)
    report = os.path.join(work_dir, "continuum-sensitivity.md")
    result = subprocess.run(
        harness_command("validation.sensitivity", "--shaker", shaker,
                        "--workdir", workdir, "--variants", "validation,plate_inelastic",
                        "--cases", "base,depth_h4p5,depth_h13p5", "--reuse-only",
                        "--report", report, "--archive", ""),
        capture_output=True, text=True, env=package_environment())
    assert result.returncode == 0, result.stdout + result.stderr
    results = json.load(open(os.path.join(workdir, "sensitivity.json")))
    assert all(r["reused"] for r in results["runs"]), "every run reused"
    judged = {v["name"]: v for v in results["variants"]}
    assert set(judged) == {"validation", "plate_inelastic"}
    # C10 of a variant is the largest centre-of-mass fractional RMS over the three depths,
    # each as `shaker compare CONTINUUM MD` gives it for the same files.
    by_case = {}
    for r in runs:
        text, key = run_key(shaker, r)
        by_case.setdefault((r["case"], r["solver"], r["variant"]),
                           os.path.join(workdir, "runs", f"{r['solver']}-{key[:20]}.h5"))
    for name in judged:
        expected = 0.0
        for case in ("base", "depth_h4p5", "depth_h13p5"):
            out = os.path.join(work_dir, f"{name}-{case}.csv")
            subprocess.run([shaker, "compare", by_case[(case, "continuum", name)],
                            by_case[(case, "md", None)], "--csv", out], check=True,
                           capture_output=True)
            rows = {line.split(",")[0]: line.split(",")[1] for line in open(out)}
            expected = max(expected, float(rows["center_of_mass_fractional_rms"]))
        got = judged[name]["claims"]["C10"]["value"]
        assert abs(got - expected) < 1e-12, f"{name}: C10 {got} against compare's {expected}"
        assert judged[name]["claims"]["C10"]["error"] is not None, "C10 carries MD's error"
        assert judged[name]["claims"]["C1"]["status"] in ("pass", "fail", "unresolved")
        gap, _ = judged[name]["mass_gap"]["0"]
        assert gap is not None and gap >= 0.0
    text = open(report).read()
    for heading in ("## MD, the reference", "## Decision", "## Every variant"):
        assert heading in text
    assert "plate_inelastic" in text and "`continuum.plate_energy=inelastic`" in text
    png = os.path.join(work_dir, "continuum-sensitivity", "variants.png")
    assert os.path.getsize(png) > 10000


def test_archive_stands_in_for_runs_lost_with_their_machine(shaker, work_dir):
    """A variant judged from finished runs is archived under its signature; once its runs are
    gone, the study judges it from the archive, with the same numbers and the commit that
    judged it. A changed claim definition changes the signature: the archive no longer
    stands in, and the lost runs show as not run."""
    studies, study, variants = load()
    chosen = [v for v in variants if v["name"] in ("validation", "plate_inelastic")]
    workdir = os.path.join(work_dir, "work")
    cases = ["base", "depth_h4p5", "depth_h13p5"]
    runs = sensitivity.plan(REPOSITORY, studies, study, chosen, cases)
    synthetic_runs.write_plan(shaker, workdir, runs)
    archive = os.path.join(work_dir, "judged.json")

    def study_call(claims_file=None, status=0):
        command = harness_command("validation.sensitivity", "--shaker", shaker,
                                  "--workdir", workdir, "--variants", "validation,plate_inelastic",
                                  "--cases", ",".join(cases), "--reuse-only", "--archive", archive,
                                  "--report", os.path.join(work_dir, "continuum-sensitivity.md"))
        if claims_file:
            command += ["--claims", claims_file]
        result = subprocess.run(command, capture_output=True, text=True,
                                env=package_environment())
        assert result.returncode == status, result.stdout + result.stderr
        return {v["name"]: v for v in
                json.load(open(os.path.join(workdir, "sensitivity.json")))["variants"]}

    first = study_call()
    entries = json.load(open(archive))["judged"]
    assert sorted(e["variant"] for e in entries.values()) == ["plate_inelastic", "validation"]
    for r in runs:
        if r["variant"] == "plate_inelastic":
            os.remove(os.path.join(workdir, "runs",
                                   f"continuum-{run_key(shaker, r)[1][:20]}.h5"))
    second = study_call()
    assert second["plate_inelastic"]["claims"] == first["plate_inelastic"]["claims"]
    assert second["plate_inelastic"]["mass_gap"] == first["plate_inelastic"]["mass_gap"]
    assert second["plate_inelastic"]["archived_at"] == git(REPOSITORY, "rev-parse", "HEAD")
    assert second["validation"]["claims"] == first["validation"]["claims"]
    assert second["validation"]["archived_at"], "an unchanged signature is never judged twice"
    assert "from the study's archive" in open(os.path.join(work_dir,
                                                           "continuum-sensitivity.md")).read()

    claims = open(os.path.join(REPOSITORY, "reference-data", "claims.toml")).read()
    changed = os.path.join(work_dir, "claims.toml")
    at = claims.index('id = "C10"')
    band = claims.index("band = [0.03]", at)
    open(changed, "w").write(claims[:band] + "band = [0.031]" + claims[band + 13:])
    third = study_call(changed, status=1)  # 1: runs are missing
    assert "archived_at" not in third["plate_inelastic"]
    assert set(third["plate_inelastic"]["failed"]) == set(cases), "its lost runs: not run"


def test_a_key_at_its_neutral_value_leaves_the_run_key_unchanged(shaker):
    """A key added with a value that reproduces the program before it (NEUTRAL_VALUES) does
    not change a run's key when it has that value, and does when it has another."""
    from granular_shaker.validation import plan as study_plan
    base = dict(case="base", case_file=study_plan.case_file(REPOSITORY, "base"), overrides=[])
    for solver in ("md", "continuum"):
        plain = study_plan.run_key(shaker, dict(base, solver=solver))[1]
        for (section, key), neutral in study_plan.NEUTRAL_VALUES.items():
            if section == "continuum" and solver == "md":
                continue
            at_neutral = dict(base, solver=solver, overrides=[f"{section}.{key}={neutral}"])
            assert study_plan.run_key(shaker, at_neutral)[1] == plain, (solver, key)
        deeper = dict(base, solver=solver, overrides=["md.box_depth=25"])
        assert study_plan.run_key(shaker, deeper)[1] != plain, solver
