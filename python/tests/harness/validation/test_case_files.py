"""ctest validation.case_files: every validation case file is accepted by `shaker config`
(exit status 0), with every override the runner adds (quick mode, pooled single-shock runs,
the collapse-guard fallback); validation/studies.toml and validation/cases/ list the same
cases; each file's case.name is its file name; and the study's defining values reach the
effective configuration (particle numbers, ceilings, widths, e, protocol). A file with an
unknown key must be rejected (exit status 2), so acceptance means something.

    python3 -m pytest python/tests/harness/validation/test_case_files.py --shaker SHAKER
"""
import glob
import os
import subprocess
import tomllib

from granular_shaker.validation.plan import (case_file, effective_config, load_studies,
                                             plan_runs, resampled_runs, run_key)

from .. import REPOSITORY

VALIDATION = os.path.join(REPOSITORY, "validation")

# What each study of the validation must set (key path -> value) in the effective configuration.
EXPECTED = {
    "base": {"layer.particles": 3937, "material.e": 0.9, "continuum.ceiling": 80.0,
             "md.box_width": 20.0, "run.protocol": "periodic"},
    "base_seed2": {"layer.particles": 3937, "material.e": 0.9, "md.box_width": 20.0,
                   "run.protocol": "periodic", "run.seed": 2, "run.sampled_cycles": 10},
    "depth_h4p5": {"layer.particles": 1969, "continuum.ceiling": 200.0},
    "depth_h13p5": {"layer.particles": 5906, "continuum.ceiling": 80.0},
    "continuum_ceiling200": {"continuum.ceiling": 200.0, "layer.particles": 3937},
    "continuum_3d_w11": {"continuum.dimension": 3, "continuum.box_width": 11.0},
    "continuum_3d_w20": {"continuum.dimension": 3, "continuum.box_width": 20.0},
    "collapse_e0p70": {"material.e": 0.7, "material.restitution": "constant",
                       "md.collapse_guard": "off"},
    "velocity_dependent": {"run.protocol": "single_shock", "material.e": 0.9,
                           "run.switch_restitution": "velocity_dependent",
                           "run.switch_phase": -0.33},
}
for tag, bin_height in (("1", 1.0), ("0p5", 0.5), ("0p25", 0.25)):
    EXPECTED[f"base_bin{tag}"] = {"layer.particles": 3937, "material.e": 0.9,
                                  "md.box_width": 20.0, "md.bin_height": bin_height,
                                  "run.sampled_cycles": 40}
for tag, e in (("0p80", 0.80), ("0p85", 0.85), ("0p90", 0.90), ("0p95", 0.95), ("0p99", 0.99),
               ("1p00", 1.0)):
    EXPECTED[f"single_shock_e{tag}"] = {"run.protocol": "single_shock", "material.e": 0.9,
                                        "run.switch_e": e, "run.switch_phase": -0.33,
                                        "run.switch_restitution": "constant"}


def lookup(config, dotted):
    section, key = dotted.split(".")
    return config[section][key]


STUDIES = load_studies(os.path.join(VALIDATION, "studies.toml"))
ALL_FILES = {os.path.splitext(os.path.basename(p))[0]
             for p in glob.glob(os.path.join(VALIDATION, "cases", "*.toml"))}
# The onset study's cases (docs/patterns.md) are run by its Gamma sweep, not by the
# validation runner, so studies.toml does not list them.
PATTERN_FILES = {name for name in ALL_FILES if name.startswith("pattern_")}
FILES = ALL_FILES - PATTERN_FILES
LISTED = set(STUDIES["by_name"])

# What every onset-study case must set: the rectangular box of both solvers, the layer depth.
PATTERN_EXPECTED = {"md.box_width": 128.0, "md.box_depth": 8.0, "layer.particles": 5600,
                    "run.protocol": "periodic", "material.e": 0.7}
PATTERN_SOLVER_EXPECTED = {"md": {"md.initial_perturbation": 0.5, "md.collapse_guard": "tc"},
                           "continuum": {"continuum.dimension": 3, "continuum.box_width": 128.0,
                                         "continuum.box_depth": 4.0}}


def test_case_files_are_the_studies():
    assert FILES == LISTED, (f"case files {sorted(FILES - LISTED)} not in studies.toml; studies "
                             f"without a file: {sorted(LISTED - FILES)}")
    assert set(EXPECTED) == LISTED, f"no expectations for {sorted(LISTED - set(EXPECTED))}"


def test_effective_configurations(shaker):
    problems = []
    for name in sorted(FILES & LISTED):
        try:
            config = tomllib.loads(effective_config(shaker, case_file(REPOSITORY, name), []))
        except ValueError as error:
            problems.append(str(error))
            continue
        if config["case"]["name"] != name:
            problems.append(f"{name}: case.name is '{config['case']['name']}'")
        for key, value in EXPECTED.get(name, {}).items():
            if lookup(config, key) != value:
                problems.append(f"{name}: {key} = {lookup(config, key)!r}, expected {value!r}")
    assert problems == []


def set_value(text):
    """The value of `--set key=text` as shaker reads it: TOML, or else a bare string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def test_every_planned_run_is_accepted(shaker):
    """Every run the runner would start, full and quick, with pool and fallback overrides."""
    for quick in (False, True):
        names = sorted(LISTED) if not quick else STUDIES["quick"]["cases"]
        plan = plan_runs(REPOSITORY, STUDIES, names, quick)
        if not quick:
            plan += resampled_runs(STUDIES, plan)
        assert plan
        for run in plan:
            runs = [run] + ([dict(run, overrides=run["overrides"] + run["fallback"])]
                            if run["fallback"] else [])
            for r in runs:
                text, key = run_key(shaker, r)
                assert len(key) == 64, key
                # Every override is in the effective configuration, with its value.
                config = tomllib.loads(text)
                for override in r["overrides"]:
                    name, value = override.split("=", 1)
                    section, field = name.split(".", 1)
                    assert config[section][field] == set_value(value), (r["case"], override)


def test_unknown_key_is_refused(shaker, work_dir):
    """The control: an unknown key must be refused."""
    bad = os.path.join(work_dir, "bad.toml")
    with open(bad, "w") as f:
        f.write("[layer]\nparticle = 3937\n")
    rc = subprocess.run([shaker, "config", bad], capture_output=True).returncode
    assert rc == 2, f"shaker config accepted a file with an unknown key (exit {rc})"


# The keys that make up the continuum model and its numerics near vacuum: one setting for the
# program's default and every validation case (docs/models.md).
CONTINUUM_SETTING = ("transport", "artificial_dissipation", "artificial_viscosity",
                     "artificial_conductivity", "artificial_volume_fraction", "temperature_floor",
                     "plate_energy", "ceiling_energy", "limiter", "riemann", "wall_stress",
                     "background_volume_fraction", "initial_temperature",
                     "initial_volume_fraction")


def test_an_empty_case_file_is_the_base_case(shaker, work_dir):
    empty = os.path.join(work_dir, "empty.toml")
    open(empty, "w").close()
    result = subprocess.run([shaker, "config", empty], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    defaults = tomllib.loads(result.stdout)
    base = tomllib.loads(effective_config(shaker, case_file(REPOSITORY, "base"), []))
    differences = sorted(f"{section}.{key}: default {defaults[section].get(key)!r}, base "
                         f"{value!r}" for section, values in base.items()
                         for key, value in values.items()
                         if defaults[section].get(key) != value)
    assert differences == []


# The only departures from that setting: the onset study reproduces the 2005 paper, whose
# continuum is taken to be the 2002 paper's (`paper` transport); its case with the default
# transport stands beside them (docs/patterns.md, "The continuum's onset").
SETTING_DEPARTURES = {"pattern_continuum_f0p18": {"transport": "paper"},
                      "pattern_continuum_f0p14": {"transport": "paper"}}


def test_every_case_uses_the_default_continuum_setting(shaker, work_dir):
    empty = os.path.join(work_dir, "empty.toml")
    open(empty, "w").close()
    defaults = tomllib.loads(subprocess.run([shaker, "config", empty], capture_output=True,
                                            text=True, check=True).stdout)["continuum"]
    assert "pattern_continuum_full_f0p18" in ALL_FILES
    assert set(SETTING_DEPARTURES) <= ALL_FILES
    differences = []
    for name in sorted(ALL_FILES):
        text = effective_config(shaker, case_file(REPOSITORY, name), [])
        continuum = tomllib.loads(text)["continuum"]
        expected = dict(defaults, **SETTING_DEPARTURES.get(name, {}))
        differences += [f"{name}: continuum.{key} = {continuum[key]!r}, expected "
                        f"{expected[key]!r}" for key in CONTINUUM_SETTING
                        if continuum[key] != expected[key]]
    assert differences == []


def test_pattern_cases_are_accepted_at_every_gamma_of_the_sweep(shaker):
    """Each onset-study case is accepted with the sweep's lowest and highest Gamma and sets the
    rectangular box (the continuum's model: test_every_case_uses_the_default_continuum_setting)."""
    assert {"pattern_md_f0p18", "pattern_md_f0p14", "pattern_continuum_f0p18",
            "pattern_continuum_f0p14"} <= PATTERN_FILES
    problems = []
    for name in sorted(PATTERN_FILES):
        solver = "md" if name.startswith("pattern_md_") else "continuum"
        for gamma in ("2.0", "3.2"):
            try:
                config = tomllib.loads(effective_config(
                    shaker, case_file(REPOSITORY, name), [f"shaker.gamma={gamma}"]))
            except ValueError as error:
                problems.append(str(error))
                continue
            expected = dict(PATTERN_EXPECTED, **PATTERN_SOLVER_EXPECTED[solver])
            expected["case.name"] = name
            for key, value in expected.items():
                if lookup(config, key) != value:
                    problems.append(f"{name}: {key} = {lookup(config, key)!r}, expected {value!r}")
    assert problems == []
