#!/usr/bin/python3
"""ctest validation.case_files: every validation case file is accepted by `shaker config`
(exit status 0), with every override the runner adds (quick mode, pooled single-shock runs,
the collapse-guard fallback); validation/studies.toml and validation/cases/ list the same
cases; each file's case.name is its file name; and the study's defining values reach the
effective configuration (particle numbers, ceilings, widths, e, protocol). A file with an
unknown key must be rejected (exit status 2), so acceptance means something.

    check_case_files.py --shaker SHAKER
"""
import argparse
import glob
import os
import subprocess
import sys
import tempfile
import tomllib

HERE = os.path.dirname(os.path.abspath(__file__))
VALIDATION = os.path.dirname(HERE)
sys.path.insert(0, VALIDATION)
import run_validation  # noqa: E402

# What each study of issue 6 must set (key path -> value) in the effective configuration.
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


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--shaker", required=True)
    shaker = os.path.abspath(parser.parse_args().shaker)
    problems = []
    studies = run_validation.load_studies(os.path.join(VALIDATION, "studies.toml"))
    files = {os.path.splitext(os.path.basename(p))[0]
             for p in glob.glob(os.path.join(VALIDATION, "cases", "*.toml"))}
    listed = set(studies["by_name"])
    if files != listed:
        problems.append(f"case files {sorted(files - listed)} not in studies.toml; studies "
                        f"without a file: {sorted(listed - files)}")
    if set(EXPECTED) != listed:
        problems.append(f"no expectations for {sorted(listed - set(EXPECTED))}")
    checked = 0
    for name in sorted(files & listed):
        try:
            config = tomllib.loads(run_validation.effective_config(shaker, name, []))
        except ValueError as error:
            problems.append(str(error))
            continue
        checked += 1
        if config["case"]["name"] != name:
            problems.append(f"{name}: case.name is '{config['case']['name']}'")
        for key, value in EXPECTED.get(name, {}).items():
            if lookup(config, key) != value:
                problems.append(f"{name}: {key} = {lookup(config, key)!r}, expected {value!r}")
    # Every run the runner would start, full and quick, with pool and fallback overrides.
    for quick in (False, True):
        names = sorted(listed) if not quick else studies["quick"]["cases"]
        try:
            plan = run_validation.plan_runs(shaker, studies, names, quick)
            for run in plan:
                run_validation.run_key(shaker, run)
                if run["fallback"]:
                    run_validation.run_key(shaker, dict(run, overrides=run["overrides"]
                                                        + run["fallback"]))
                checked += 1
        except ValueError as error:
            problems.append(f"{'quick' if quick else 'full'} plan: {error}")
    # The control: an unknown key must be refused.
    with tempfile.TemporaryDirectory(prefix="validation-case-files-") as tmp:
        bad = os.path.join(tmp, "bad.toml")
        with open(bad, "w") as f:
            f.write("[layer]\nparticle = 3937\n")
        rc = subprocess.run([shaker, "config", bad], capture_output=True).returncode
        if rc != 2:
            problems.append(f"shaker config accepted a file with an unknown key (exit {rc})")
    for p in problems:
        print(f"problem: {p}")
    print(f"{checked} effective configurations checked, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
