#!/usr/bin/env python3
"""The 3D continuum decomposed over MPI ranks (docs/parallel.md): checks through the program.

  check_continuum_ranks.py SHAKER explicit P [P ...] [--mpirun CMD]
      An explicit run (no implicit diffusion) writes the same run file and fields file on P
      ranks as without a launcher, bit for bit, every dataset and attribute but the creation
      date; only the energy budget's accumulators, summed over the ranks' shares, may differ,
      within 1e-12 of the budget's scale.
  check_continuum_ranks.py SHAKER wall_stress P [P ...] [--mpirun CMD]
      The explicit check with continuum.wall_stress = "second_order": the wall faces' stress
      reads the next cell above the wall and the tangential divergence of both cells, whose x
      and y neighbours lie in the halo at a block's edge.
  check_continuum_ranks.py SHAKER hybrid [--mpirun CMD]
      The explicit check on a box of 16 x 16 x 40 cells, on 2 ranks of 2 OpenMP threads each
      (blocks large enough to be shared between threads) against the plain run on one thread.
  check_continuum_ranks.py SHAKER implicit P [P ...] [--mpirun CMD]
      The full transport (implicit diffusion) on P ranks, by the distributed CG whose dot
      products are sums over the ranks, against the run without a launcher (Eigen's CG): every
      dataset within 1e-12 of its largest magnitude (a field's velocity components of the
      largest component: the horizontal ones, seeded by the 1e-3 perturbation, are four orders
      below u_z and take its round-off; the budget's accumulators of the budget's scale).
  check_continuum_ranks.py SHAKER implicit_wall_stress P [P ...] [--mpirun CMD]
      The implicit check with continuum.wall_stress = "second_order": the wall rows' lagged
      part (the next cell's momentum at the step's start) in the right-hand side and their
      heating, on every rank's block.
  check_continuum_ranks.py SHAKER restart [--mpirun CMD]
      A checkpoint written on 2 ranks after 1 of 2 cycles, continued on 1 and on 4 ranks: the
      final checkpoint and the time-series rows after the restart equal the straight run's
      (without a launcher) bit for bit; the budget within 1e-12 of its scale.
  check_continuum_ranks.py SHAKER column [--mpirun CMD]
      A 1D column's checkpoint (one cycle) starts the 3D box, which continues it for a second
      cycle: the same run file and fields file on 2 and 4 ranks as without a launcher, bit for
      bit but the budget, and the box stays horizontally uniform (u_x = u_y = 0 in every field).
  check_continuum_ranks.py SHAKER failure [--mpirun CMD]
      A step that fails (unlimited slopes at Courant number 1) on 2 and 4 ranks: exit 1 with the
      plain run's message (the same first failing cell, in box coordinates) and its last good
      state, bit for bit but the budget.
  check_continuum_ranks.py SHAKER signal [--mpirun CMD]
      A stop signal during a run on 2 ranks: sent to the launcher (OpenMPI's mpirun forwards
      SIGTERM to every rank after its odls_base_sigkill_timeout, then waits as long again before
      SIGKILL), and sent to rank 1 alone. Either way every rank stops at the same stored phase,
      the root writes the checkpoint and says so once, no run file is written, and the run
      continued from the checkpoint on 4 ranks ends in the straight run's final checkpoint, bit
      for bit but the budget.
  check_continuum_ranks.py SHAKER signal_repeated N [--mpirun CMD]
      The stop signal to the launcher N times, each once the 2 ranks are in their cycles (the
      first progress line): each time one stop message and the checkpoint at the stored phase
      it names, no run file, no rank killed. (A signal before mpirun has started the ranks ends
      the job before the program runs: nothing to stop, docs/parallel.md.)
  check_continuum_ranks.py SHAKER root_failure [--mpirun CMD]
      A failure of the root alone during a run on 2 ranks (its checkpoint's folder removed
      after the first checkpoint, so that the next one cannot be written): the root says why
      and every rank ends, exit 1 within a minute (no rank left waiting for the others, nor
      the root for them), no run file written.
  check_continuum_ranks.py SHAKER disagree [--mpirun CMD]
      An MPMD launch (`mpirun -np 1 shaker ... : -np 1 shaker ...`) whose ranks get different
      --set values (continuum.box_width 11 and 12; material.e of an MD ensemble; a value
      refused on one rank alone): exit 2 on every rank, the message naming the rank and the key
      that differ with both values, nothing written.
  check_continuum_ranks.py SHAKER refused [--mpirun CMD]
      A 1D column on 2 ranks, an 8 x 8 box on 3 ranks (fewer than 3 cells per rank in x), and a
      box too large for the machine's memory on 2 ranks (their blocks' needs added up, as both
      share the machine), exit 2 with a message naming the sizes and the allowed range,
      writing nothing.

The budget's accumulators are sums, over steps, of the ranks' shares of the energy sources;
on P ranks they are added in another order than on one, so they agree to rounding relative to
the energies summed (frame_energy, the accumulated work and loss), not relative to themselves
(the floor energy and the budget residual are small differences of large sums).

Exit status 0 when every check holds; each failure is printed. Runs in a temporary directory,
removed on success and kept (and printed) on failure.
"""
import argparse
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time

import h5py
import hdf5_contents
import keep_on_failure
import numpy as np

# 10 x 10 x 20 cells, one fast cycle (f = 0.5: about 100 steps), fields at two phases. On 2
# and 4 ranks a block is 5 cells wide in x: the flux kernels take its rows of pencils two at a
# time and the last alone, the single rank's all in pairs, and the files must still agree.
EXPLICIT_CASE = """
[layer]
particles = 1000
[shaker]
frequency = 0.5
[continuum]
dimension = 3
cell_size = 0.5
box_width = 5.0
ceiling = 10.0
transport = "paper"
diffusion_integrator = "explicit"
field_phases = [0.25, 0.75]
[run]
transient_cycles = 0
sampled_cycles = 1
phases_per_cycle = 4
seed = 3
"""
# 6 x 6 x 10 cells (3 x 3 columns per rank on 4 ranks), full transport with backward-Euler
# diffusion (one implicit step per half step; the default Richardson extrapolation takes three)
# and a fast shaker (f = 2, about 15 steps): every step takes hundreds of CG iterations, each a
# halo exchange and two reductions, which on an oversubscribed machine wait for time slices.
IMPLICIT_CASE = """
[layer]
particles = 1000
[shaker]
frequency = 2.0
[continuum]
dimension = 3
cell_size = 1.0
box_width = 6.0
ceiling = 10.0
transport = "full"
diffusion_integrator = "implicit"
field_phases = [0.5]
[run]
transient_cycles = 0
sampled_cycles = 1
phases_per_cycle = 4
seed = 3
"""
IGNORED_ATTRIBUTES = {"created", "configuration"}
BUDGET = {"timeseries/accumulated_drive_work", "timeseries/accumulated_collisional_loss",
          "timeseries/accumulated_floor_energy", "timeseries/energy_budget_residual",
          "timeseries/energy_budget_relative_residual", "energy_budget"}
BUDGET_SCALE = ("timeseries/frame_energy", "timeseries/accumulated_drive_work",
                "timeseries/accumulated_collisional_loss")
# Time-series columns that count from the start of each run: a continued run starts afresh.
RUN_RELATIVE = {"timeseries/com_z_change_from_previous_cycle", "timeseries/energy_budget_residual",
                "timeseries/energy_budget_relative_residual",
                "timeseries/periodicity_last_two_cycles"}
TOLERANCE = 1e-12


def mpirun_prefix(command, ranks):
    """The launcher's words for P ranks; as root OpenMPI needs its explicit consent. Ranks
    yield the core while they wait (the tests oversubscribe a shared machine) and get the
    launcher's OMP_NUM_THREADS."""
    words = shlex.split(command) + ["-np", str(ranks), "--oversubscribe",
                                    "--mca", "mpi_yield_when_idle", "1", "-x", "OMP_NUM_THREADS"]
    if os.geteuid() == 0:
        words.append("--allow-run-as-root")
    return words


def run(words, cwd, expect=0, threads=1):
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    result = subprocess.run(words, cwd=cwd, capture_output=True, text=True, env=env)
    if result.returncode != expect:
        raise SystemExit(f"{' '.join(words)}: exit {result.returncode}, expected {expect}\n"
                         f"{result.stdout[-2000:]}\n{result.stderr[-2000:]}")
    return result


def shaker_run(shaker, case, output, work, launcher=None, ranks=None, settings=(), threads=1):
    prefix = mpirun_prefix(launcher, ranks) if ranks else []
    words = prefix + [shaker, "continuum", case, "--set", f"run.output={output}", "--quiet"]
    for setting in settings:
        words += ["--set", setting]
    return run(words, work, threads=threads)


def contents(path):
    return hdf5_contents.contents(path, IGNORED_ATTRIBUTES)


def budget_scale(*files):
    return max((float(np.nanmax(np.abs(f[name]))) for f in files for name in BUDGET_SCALE
                if name in f), default=0.0)


def same_bits(x, y):
    return x.shape == y.shape and (x.tobytes() == y.tobytes() or (
        x.dtype.kind == "f" and np.array_equal(x, y, equal_nan=True)
        and np.all(np.signbit(x) == np.signbit(y))))


def within(x, y, scale):
    if x.shape != y.shape or x.dtype.kind != "f":
        return same_bits(x, y)
    finite = np.isfinite(x) & np.isfinite(y)
    if not np.array_equal(np.isnan(x), np.isnan(y)):
        return False
    return bool(np.all(np.abs(x[finite] - y[finite]) <= TOLERANCE * scale))


def largest(x):
    return float(np.nanmax(np.abs(x))) if x.size and np.any(np.isfinite(x)) else 0.0


def magnitude(found, name):
    """The scale of dataset `name`: its largest magnitude, or for a velocity component of a
    field snapshot the largest of the three components."""
    group, _, leaf = name.rpartition("/")
    if group.startswith("snapshot_") and leaf in ("ux", "uy", "uz"):
        return max(largest(found[f"{group}/{c}"]) for c in ("ux", "uy", "uz"))
    return largest(found[name])


def differences(a, b, label, exact, scale, skip=()):
    """Names that differ: bit for bit if `exact`, else within TOLERANCE of the dataset's
    largest magnitude; the budget within TOLERANCE of `scale` either way."""
    out = [f"{label}: {n} only in one file" for n in sorted(set(a) ^ set(b))]
    for name in sorted(set(a) & set(b)):
        if name in skip:
            continue
        x, y = a[name], b[name]
        if name in BUDGET:
            same = within(x, y, scale)
        elif exact or x.dtype.kind != "f":
            same = same_bits(x, y)
        else:
            same = within(x, y, magnitude(a, name))
        if not same:
            out.append(f"{label}: {name} differs")
    return out


def compare_rank_counts(shaker, work, launcher, counts, exact, settings=(), threads=1):
    """Runs the case without a launcher on one thread, then on each count of ranks of
    `threads` threads each."""
    failures = []
    reference = "plain"
    shaker_run(shaker, "case.toml", f"{reference}.h5", work, settings=settings)
    files = {kind: contents(os.path.join(work, f"{reference}{kind}.h5"))
             for kind in ("", ".fields")}
    for p in counts:
        result = shaker_run(shaker, "case.toml", f"ranks{p}.h5", work, launcher, p, settings,
                            threads)
        found = []
        for kind, expected in files.items():
            mine = contents(os.path.join(work, f"ranks{p}{kind}.h5"))
            found += differences(mine, expected, f"{p} ranks{kind}", exact,
                                 budget_scale(mine, expected))
        with open(os.path.join(work, f"{reference}.fields.xdmf")) as x, \
                open(os.path.join(work, f"ranks{p}.fields.xdmf")) as y:
            if exact and x.read().replace(reference, f"ranks{p}") != y.read():
                found.append(f"{p} ranks: the XDMF sidecar differs")
        summaries = result.stdout.count("shaker continuum:")
        if summaries != 1:
            found.append(f"{p} ranks: {summaries} summaries printed, expected 1 (the root's)")
        compared = sum(len(f) for f in files.values())
        print(f"{p} rank(s) of {threads} thread(s) against {reference}: {compared} datasets "
              f"and attributes compared ({'bit for bit' if exact else f'within {TOLERANCE}'}); "
              f"{len(found)} differences")
        failures += found
    return failures


def time_series(path):
    """The time-series columns of a run file, keyed timeseries/NAME."""
    with h5py.File(path, "r") as f:
        return {f"timeseries/{k}": np.asarray(v[()]) for k, v in f["timeseries"].items()}


def check_restart(shaker, work, launcher):
    failures = []
    two = ["run.sampled_cycles=2"]
    shaker_run(shaker, "case.toml", "straight.h5", work,
               settings=two + ["run.checkpoint=straight.ckpt.h5"])
    shaker_run(shaker, "case.toml", "first.h5", work, launcher, 2,
               settings=["run.checkpoint=first.ckpt.h5"])
    straight = contents(os.path.join(work, "straight.ckpt.h5"))
    straight_series = time_series(os.path.join(work, "straight.h5"))
    for p in (1, 4):
        shaker_run(shaker, "case.toml", f"rest{p}.h5", work, launcher, p,
                   settings=two + ["run.restart_from=first.ckpt.h5",
                                   f"run.checkpoint=rest{p}.ckpt.h5"])
        rest = contents(os.path.join(work, f"rest{p}.ckpt.h5"))
        scale = budget_scale(straight_series)
        found = differences(rest, straight, f"continued on {p} ranks: final checkpoint", True,
                            scale)
        series = time_series(os.path.join(work, f"rest{p}.h5"))
        rows = len(series["timeseries/t"])
        tail = {k: v[-rows:] for k, v in straight_series.items()}
        if rows == 0 or rows >= len(straight_series["timeseries/t"]):
            found.append(f"continued on {p} ranks: {rows} rows, not the straight run's last ones")
        found += differences(series, tail, f"continued on {p} ranks: time series", True, scale,
                             skip=RUN_RELATIVE)
        print(f"checkpoint of 2 ranks continued on {p}: {len(rest)} checkpoint datasets and "
              f"attributes and {rows} rows x {len(series)} columns compared with the straight "
              f"run; {len(found)} differences")
        failures += found
    return failures


def check_column_start(shaker, work, launcher):
    shaker_run(shaker, "case.toml", "column.h5", work,
               settings=["continuum.dimension=1", "continuum.field_phases=[]",
                         "run.checkpoint=column.ckpt.h5"])
    continued = ["run.restart_from=column.ckpt.h5", "run.sampled_cycles=2"]
    failures = compare_rank_counts(shaker, work, launcher, [2, 4], True, continued)
    with h5py.File(os.path.join(work, "plain.fields.h5"), "r") as f:
        snapshots = [name for name in f if name.startswith("snapshot_")]
        horizontal = max(largest(np.asarray(f[f"{s}/{c}"][()])) for s in snapshots
                         for c in ("ux", "uy"))
    print(f"box from the column: {len(snapshots)} field snapshots, largest |u_x|, |u_y| "
          f"{horizontal:.3e}")
    if not snapshots or horizontal != 0.0:
        failures.append(f"box from the column: {len(snapshots)} snapshots, largest horizontal "
                        f"velocity {horizontal} (expected 0: a horizontally uniform start)")
    return failures


def check_failure(shaker, work, launcher):
    failures = []
    unstable = ["continuum.limiter=none", "continuum.cfl=1.0"]

    def failed(output, ranks=None):
        words = (mpirun_prefix(launcher, ranks) if ranks else []) + [
            shaker, "continuum", "case.toml", "--set", f"run.output={output}.h5", "--quiet"]
        result = run(words + [w for s in unstable for w in ("--set", s)], work, expect=1)
        return result.stderr.split("\n")[0]

    message = failed("plain")
    expected = contents(os.path.join(work, "plain.last_good.h5"))
    for p in (2, 4):
        found = []
        mine = failed(f"ranks{p}", p)
        if mine != message:
            found.append(f"{p} ranks: message '{mine}' instead of '{message}'")
        last_good = contents(os.path.join(work, f"ranks{p}.last_good.h5"))
        found += differences(last_good, expected, f"{p} ranks: last good state", True,
                             float(np.max(np.abs(expected["energy_budget"]))))
        print(f"step failure on {p} ranks: exit 1; {len(found)} differences from the plain run")
        failures += found
    return failures


# Seconds between OpenMPI's mpirun forwarding SIGTERM and its SIGKILL (odls_base_sigkill_timeout;
# the default, 1, leaves a decomposed run too little time to reach a stored phase).
SIGNAL_GRACE = 3


def rank_process(launcher_pid, rank):
    """The pid of `rank` among the launcher's child processes (OMPI_COMM_WORLD_RANK)."""
    for entry in os.listdir("/proc"):
        try:
            with open(f"/proc/{entry}/stat") as stat:
                parent = int(stat.read().rsplit(")", 1)[1].split()[1])
            with open(f"/proc/{entry}/environ", "rb") as environ:
                variables = environ.read().split(b"\0")
        except (OSError, ValueError, IndexError):
            continue
        if parent == launcher_pid and f"OMPI_COMM_WORLD_RANK={rank}".encode() in variables:
            return int(entry)
    return None


def stopped_run(shaker, work, launcher, output, to_rank):
    """Starts 40 cycles on 2 ranks, waits for the first progress line (the ranks are in the run
    loop), sends SIGTERM to the launcher or to rank `to_rank`, returns (stderr, problems)."""
    words = mpirun_prefix(launcher, 2) + [
        "--mca", "odls_base_sigkill_timeout", str(SIGNAL_GRACE), shaker, "continuum",
        "case.toml", "--set", f"run.output={output}.h5", "--set", "run.sampled_cycles=40",
        "--progress-interval", "0"]
    process = subprocess.Popen(words, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, env=dict(os.environ, OMP_NUM_THREADS="1"))
    first = process.stderr.readline()
    target = process.pid if to_rank is None else rank_process(process.pid, to_rank)
    if target is not None:
        os.kill(target, signal.SIGTERM)
    _, rest = process.communicate(timeout=120)
    problems = [] if target is not None else [f"{output}: no process of rank {to_rank} found"]
    if "cycle" not in first:
        problems.append(f"{output}: no progress line before the signal: {first!r}")
    if process.returncode == 0:
        problems.append(f"{output}: exit 0, the run ended before the signal reached the ranks")
    return first + rest, problems


def check_signal(shaker, work, launcher):
    failures = []
    for output, to_rank in (("launcher", None), ("rank1", 1)):
        stderr, found = stopped_run(shaker, work, launcher, output, to_rank)
        stops = re.findall(r"stopped by signal 15 \(SIGTERM\).*in cycle (\d+)", stderr)
        if len(stops) != 1:
            found.append(f"{output}: {len(stops)} stop messages, expected 1 (the root's): "
                         f"{stderr[-600:]}")
        checkpoint = os.path.join(work, f"{output}.checkpoint.h5")
        if not os.path.exists(checkpoint) or os.path.exists(os.path.join(work, f"{output}.h5")):
            found.append(f"{output}: expected the checkpoint and no run file: {os.listdir(work)}")
        if found:
            failures += found
            continue
        end = [f"run.sampled_cycles={int(stops[0]) + 2}"]
        shaker_run(shaker, "case.toml", f"{output}-straight.h5", work,
                   settings=end + [f"run.checkpoint={output}-straight.ckpt.h5"])
        shaker_run(shaker, "case.toml", f"{output}-rest.h5", work, launcher, 4,
                   settings=end + [f"run.restart_from={checkpoint}",
                                   f"run.checkpoint={output}-rest.ckpt.h5"])
        straight = contents(os.path.join(work, f"{output}-straight.ckpt.h5"))
        found += differences(contents(os.path.join(work, f"{output}-rest.ckpt.h5")), straight,
                             f"{output}: continued on 4 ranks", True,
                             budget_scale(time_series(os.path.join(work,
                                                                   f"{output}-straight.h5"))))
        print(f"SIGTERM to the {output}: stopped in cycle {stops[0]}, one checkpoint; continued "
              f"on 4 ranks to cycle {int(stops[0]) + 2}: {len(straight)} datasets and "
              f"attributes compared with the straight run; {len(found)} differences")
        failures += found
    return failures


def check_signal_repeated(shaker, work, launcher, repeats):
    """SIGTERM to the launcher `repeats` times, each once the ranks are in their cycles: every
    time one stop message (the root's, exit 143), the checkpoint at the phase it names, no run
    file, no rank killed (SIGKILL) and no other failure."""
    failures = []
    for attempt in range(repeats):
        output = f"repeat{attempt}"
        stderr, found = stopped_run(shaker, work, launcher, output, None)
        stops = re.findall(r"stopped by signal 15 \(SIGTERM\).*stored phase (\d+) of \d+ in cycle "
                           r"(\d+)", stderr)
        checkpoint = os.path.join(work, f"{output}.checkpoint.h5")
        if len(stops) != 1:
            found.append(f"{output}: {len(stops)} stop messages, expected 1: {stderr[-600:]}")
        elif not os.path.exists(checkpoint):
            found.append(f"{output}: no checkpoint: {os.listdir(work)}")
        else:
            with h5py.File(checkpoint, "r") as f:
                position = (int(f.attrs["schedule_phase"]), int(f.attrs["schedule_cycle"]))
            if position != tuple(int(x) for x in stops[0]):
                found.append(f"{output}: checkpoint at {position}, the message says {stops[0]}")
        for needle in ("shaker: failed", "signal 9", "Killed", "shaker: error"):
            if needle in stderr:
                found.append(f"{output}: '{needle}' in the output: {stderr[-600:]}")
        if os.path.exists(os.path.join(work, f"{output}.h5")):
            found.append(f"{output}: a run file was written")
        print(f"SIGTERM {attempt + 1} of {repeats} to the launcher: "
              f"{'stopped at ' + str(stops[0]) if len(stops) == 1 else 'no single stop'}, "
              f"{len(found)} problems")
        failures += found
    return failures


def check_root_failure(shaker, work, launcher):
    folder = os.path.join(work, "checkpoints")
    os.mkdir(folder)
    checkpoint = os.path.join(folder, "box.ckpt.h5")
    words = mpirun_prefix(launcher, 2) + [
        shaker, "continuum", "case.toml", "--set", "run.output=root_failure.h5",
        "--set", "run.sampled_cycles=40", "--set", f"run.checkpoint={checkpoint}",
        "--set", "run.checkpoint_every=1", "--quiet"]
    process = subprocess.Popen(words, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, env=dict(os.environ, OMP_NUM_THREADS="1"),
                               start_new_session=True)
    failures = []
    waited = time.monotonic()
    while not os.path.exists(checkpoint) and process.poll() is None:
        if time.monotonic() - waited > 120:
            failures.append("no checkpoint after 120 s")
            break
        time.sleep(0.05)
    shutil.rmtree(folder)
    removed = time.monotonic()
    try:
        _, stderr = process.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        _, stderr = process.communicate()
        return failures + [f"still running 60 s after the root's failure (a rank left waiting): "
                           f"{stderr[-600:]}"]
    if process.returncode != 1:
        failures.append(f"exit {process.returncode}, expected 1: {stderr[-600:]}")
    for needle in ("shaker: failed", "cannot write", "box.ckpt.h5"):
        if needle not in stderr:
            failures.append(f"the message lacks '{needle}': {stderr[-600:]}")
    if os.path.exists(os.path.join(work, "root_failure.h5")):
        failures.append("a run file was written")
    print(f"root's checkpoint folder removed after the first checkpoint: exit "
          f"{process.returncode} {time.monotonic() - removed:.1f} s later")
    return failures


def width_filling(share):
    """A box width (cell 0.5, ceiling 10: 20 cells high) whose solver working set, 600 bytes
    a cell, is `share` of this machine's MemAvailable: at 1.5 each of 2 ranks' halves fits,
    their sum does not."""
    with open("/proc/meminfo") as meminfo:
        available = next(int(line.split()[1]) * 1024 for line in meminfo
                         if line.startswith("MemAvailable:"))
    return int((share * available / (600 * 20 * 4)) ** 0.5)


def check_refused(shaker, work, launcher):
    failures = []
    for label, ranks, settings, needles in (
            ("1D column on 2 ranks", 2, ["continuum.dimension=1", "continuum.field_phases=[]"],
             ["continuum.dimension = 1", "one rank"]),
            ("8 x 8 box on 3 ranks", 3, ["continuum.box_width=4.0"],
             ["8 x 8 cells", "1 x 3 ranks", "at least 3 cells per rank",
              "at most 2 ranks in x and 2 in y"]),
            ("box too large for this machine on 2 ranks", 2,
             [f"continuum.box_width={width_filling(1.5)}", "continuum.field_phases=[]"],
             ["over 2 ranks, 2 of them on this machine", "MemAvailable",
              "fewer ranks per machine"])):
        result = run(mpirun_prefix(launcher, ranks) + [shaker, "continuum", "case.toml", "--set",
                                                       "run.output=refused.h5", "--quiet"]
                     + [w for s in settings for w in ("--set", s)], work, expect=2)
        failures += refusal_problems(label, result.stderr, needles, work, "refused")
        print(f"{label}: exit 2, {len(failures)} problems so far")
    return failures


def refusal_problems(label, stderr, needles, work, output):
    """What a refusal lacks: fragments of its message, or an empty folder of outputs named
    `output`*."""
    problems = [f"{label}: message lacks '{needle}': {stderr[-600:]}"
                for needle in needles if needle not in stderr]
    written = [n for n in os.listdir(work) if n.startswith(output)]
    return problems + ([f"{label}: wrote {written}"] if written else [])


def check_disagreeing_ranks(shaker, work, launcher):
    """An MPMD launch whose two ranks get different settings: exit 2 on every rank, naming the
    rank and the key that differ (or the rank whose configuration did not load)."""
    failures = []
    words = shlex.split(launcher) + ["--oversubscribe", "--mca", "mpi_yield_when_idle", "1"]
    if os.geteuid() == 0:
        words.append("--allow-run-as-root")
    for label, solver, ours, theirs, needles in (
            ("continuum box widths 11 and 12", "continuum", "continuum.box_width=11",
             "continuum.box_width=12",
             ["rank 1 has continuum.box_width = 12.0 where rank 0 has continuum.box_width = 11.0"]),
            ("MD ensemble with e 0.9 and 0.8", "md", "material.e=0.9", "material.e=0.8",
             ["rank 1 has material.e = 0.8 where rank 0 has material.e = 0.9"]),
            ("a setting refused on rank 1 alone", "continuum", "material.e=0.9", "material.e=1.5",
             ["rank 1 has 'error: ", "material.e"])):
        contexts = []
        for setting in (ours, theirs):
            contexts += ["-np", "1", shaker, solver, "case.toml", "--quiet", "--set",
                         "run.output=disagree.h5", "--set", "md.replicas=2", "--set", setting, ":"]
        result = run(words + contexts[:-1], work, expect=2)
        failures += refusal_problems(
            label, result.stderr,
            needles + ["the 2 ranks of this launch disagree on the effective configuration",
                       "allowed: the same case file and --set values on every rank"],
            work, "disagree")
        print(f"{label}: exit 2, {len(failures)} problems so far")
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("shaker")
    parser.add_argument("check", choices=["explicit", "wall_stress", "hybrid", "implicit",
                                          "implicit_wall_stress", "restart", "column", "failure",
                                          "signal", "signal_repeated", "root_failure", "refused",
                                          "disagree"])
    parser.add_argument("ranks", nargs="*", type=int, default=[1, 2, 4])
    parser.add_argument("--mpirun", default="mpirun", help="the launcher (default: mpirun)")
    args = parser.parse_args()
    work = keep_on_failure.work_folder(f"continuum-ranks-{args.check}-")
    with open(os.path.join(work, "case.toml"), "w") as f:
        f.write(IMPLICIT_CASE if args.check.startswith("implicit") else EXPLICIT_CASE)
    if args.check in ("explicit", "implicit"):
        failures = compare_rank_counts(args.shaker, work, args.mpirun, args.ranks,
                                       args.check == "explicit")
    elif args.check == "wall_stress":
        failures = compare_rank_counts(args.shaker, work, args.mpirun, args.ranks, True,
                                       ["continuum.wall_stress=second_order"])
    elif args.check == "implicit_wall_stress":
        failures = compare_rank_counts(args.shaker, work, args.mpirun, args.ranks, False,
                                       ["continuum.wall_stress=second_order"])
    elif args.check == "hybrid":
        failures = compare_rank_counts(args.shaker, work, args.mpirun, [2], True,
                                       ["continuum.box_width=8", "continuum.ceiling=20"], 2)
    elif args.check == "restart":
        failures = check_restart(args.shaker, work, args.mpirun)
    elif args.check == "column":
        failures = check_column_start(args.shaker, work, args.mpirun)
    elif args.check == "failure":
        failures = check_failure(args.shaker, work, args.mpirun)
    elif args.check == "signal":
        failures = check_signal(args.shaker, work, args.mpirun)
    elif args.check == "signal_repeated":
        failures = check_signal_repeated(args.shaker, work, args.mpirun, args.ranks[0])
    elif args.check == "root_failure":
        failures = check_root_failure(args.shaker, work, args.mpirun)
    elif args.check == "disagree":
        failures = check_disagreeing_ranks(args.shaker, work, args.mpirun)
    else:
        failures = check_refused(args.shaker, work, args.mpirun)
    for failure in failures:
        print("FAIL:", failure)
    return keep_on_failure.finish(work, failures)


if __name__ == "__main__":
    sys.exit(main())
