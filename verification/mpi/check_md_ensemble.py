#!/usr/bin/env python3
"""MD ensembles (md.replicas, docs/parallel.md): checks of the pooled run file.

  check_md_ensemble.py SHAKER pooling
      md.replicas = K in one process equals K separate runs (seeds run.seed + r; for the
      single shock, run.transient_cycles + r) pooled by `shaker analyze --pooled`, bit for bit.
  check_md_ensemble.py SHAKER ranks P [P ...] [--mpirun CMD]
      `mpirun -np P shaker md` writes the same file as the plain run for every P (more ranks
      than replicas included), every dataset and attribute but the creation date, for both
      protocols; the files hold every replica's time series (replica 0's in /timeseries, the
      others' in /replica_timeseries, docs/output-schema.md), the single shock's of different
      lengths.

Exit status 0 when every check holds; each failure is printed. Runs in a temporary directory,
removed on success.
"""
import argparse
import os
import shlex
import subprocess
import sys

import hdf5_contents
import keep_on_failure
import numpy as np

CASE = """
[layer]
particles = 40
[md]
box_width = 4.0
ceiling = 60.0
[run]
transient_cycles = 1
sampled_cycles = 2
phases_per_cycle = 5
seed = 7
"""
REPLICAS = 3
# What differs between an ensemble's file and its pooled separate runs by construction: the
# creation date, the configuration (md.replicas, the seed) and the variant's wording.
IGNORED_ATTRIBUTES = {"created", "configuration", "model_variant"}


def mpirun_prefix(command, ranks):
    """The launcher's words for P ranks; as root OpenMPI needs its explicit consent."""
    words = shlex.split(command) + ["-np", str(ranks), "--oversubscribe"]
    if os.geteuid() == 0:
        words.append("--allow-run-as-root")
    return words


def run(words, cwd, expect=0):
    result = subprocess.run(words, cwd=cwd, capture_output=True, text=True)
    if result.returncode != expect:
        raise SystemExit(f"{' '.join(words)}: exit {result.returncode}, expected {expect}\n"
                         f"{result.stdout[-2000:]}\n{result.stderr[-2000:]}")
    return result


def contents(path, groups=None):
    return hdf5_contents.contents(path, IGNORED_ATTRIBUTES, groups)


def differences(a, b, label):
    """The names whose values differ bit for bit (NaN equal to NaN), or exist in only one."""
    out = [f"{label}: {n} only in one file" for n in sorted(set(a) ^ set(b))]
    for name in sorted(set(a) & set(b)):
        x, y = a[name], b[name]
        same = x.shape == y.shape and (x.tobytes() == y.tobytes() or
                                       (x.dtype.kind == "f" and np.array_equal(x, y, equal_nan=True)
                                        and np.all(np.signbit(x) == np.signbit(y))))
        if not same:
            out.append(f"{label}: {name} differs")
    return out


def check_pooling(shaker, work):
    failures = []
    for protocol, varied in (("periodic", "run.seed"), ("single_shock", "run.transient_cycles")):
        protocol_set = ["--set", f"run.protocol={protocol}"]
        run([shaker, "md", "case.toml", *protocol_set, "--set", f"md.replicas={REPLICAS}",
             "--set", "run.output=ensemble.h5", "--quiet"], work)
        first = 7 if varied == "run.seed" else 1
        singles = []
        for r in range(REPLICAS):
            singles.append(f"single{r}.h5")
            run([shaker, "md", "case.toml", *protocol_set, "--set", f"{varied}={first + r}",
                 "--set", f"run.output={singles[-1]}", "--quiet"], work)
        run([shaker, "analyze", *singles, "--pooled", "pooled.h5", "--quiet", "--json",
             "pooled.json"], work)
        pooled = contents(os.path.join(work, "pooled.h5"), {"profiles", "cycle_samples"})
        ensemble = contents(os.path.join(work, "ensemble.h5"), {"profiles", "cycle_samples"})
        failures += differences(ensemble, pooled, f"{protocol}: ensemble vs pooled runs")
        samples = ensemble.get("cycle_samples/cycles")
        print(f"{protocol}: {len(pooled)} datasets and attributes compared; "
              f"{'no' if not failures else len(failures)} differences")
        if samples is None:
            failures.append(f"{protocol}: the ensemble file has no cycle_samples/cycles")
    return failures


def replica_series_missing(found, protocol):
    """What the file lacks of every replica's time series: replica r >= 1 in
    replica_timeseries/replica_RRRRR with /timeseries's columns, rows as the protocol runs."""
    out = []
    if found.get("replica_timeseries@replicas") != REPLICAS:
        out.append(f"{protocol}: replica_timeseries@replicas is "
                   f"{found.get('replica_timeseries@replicas')}, expected {REPLICAS}")
    columns = str(found["timeseries@columns"]).split(",")
    rows = len(found["timeseries/t"])
    for r in range(1, REPLICAS):
        group = f"replica_timeseries/replica_{r:05d}"
        # The single shock's replica r runs r more cycles of 5 stored phases.
        expected = rows + (5 * r if protocol == "single_shock" else 0)
        for column in columns:
            if found.get(f"{group}/{column}", np.empty(0)).shape != (expected,):
                out.append(f"{protocol}: {group}/{column} missing or not {expected} rows")
    return out


def check_ranks(shaker, work, launcher, counts):
    failures = []
    for protocol in ("periodic", "single_shock"):
        ensemble = [shaker, "md", "case.toml", "--set", f"run.protocol={protocol}", "--set",
                    f"md.replicas={REPLICAS}", "--quiet"]
        run(ensemble + ["--set", f"run.output={protocol}-plain.h5"], work)
        plain = contents(os.path.join(work, f"{protocol}-plain.h5"))
        failures += replica_series_missing(plain, protocol)
        for p in counts:
            out = f"{protocol}-ranks{p}.h5"
            result = run(mpirun_prefix(launcher, p) + ensemble + ["--set", f"run.output={out}"],
                         work)
            found = differences(contents(os.path.join(work, out)), plain,
                                f"{protocol}, {p} ranks vs plain")
            summaries = result.stdout.count("shaker md:")
            if summaries != 1:
                found.append(f"{protocol}, {p} ranks: {summaries} summaries printed, expected 1 "
                             "(the root's)")
            print(f"{protocol}, {p} rank(s): {len(plain)} datasets and attributes compared "
                  f"({sum(n.startswith('replica_timeseries/') for n in plain)} of replicas 1 .. "
                  f"{REPLICAS - 1}'s time series); {len(found)} differences")
            failures += found
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("shaker")
    parser.add_argument("check", choices=["pooling", "ranks"])
    parser.add_argument("ranks", nargs="*", type=int, default=[1, 2, 4])
    parser.add_argument("--mpirun", default="mpirun", help="the launcher (default: mpirun)")
    args = parser.parse_args()
    work = keep_on_failure.work_folder(f"md-ensemble-{args.check}-")
    with open(os.path.join(work, "case.toml"), "w") as f:
        f.write(CASE)
    if args.check == "pooling":
        failures = check_pooling(args.shaker, work)
    else:
        failures = check_ranks(args.shaker, work, args.mpirun, args.ranks)
    for failure in failures:
        print("FAIL:", failure)
    return keep_on_failure.finish(work, failures)


if __name__ == "__main__":
    sys.exit(main())
