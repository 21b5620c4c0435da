"""Running the solvers of a planned study: one run per configuration key, reused when it is
finished (its record and run file in WORKDIR/runs), runs side by side as --jobs allows."""
import concurrent.futures
import json
import os
import subprocess
import time
import tomllib

import h5py

from granular_shaker.validation.plan import run_key

COLLAPSE_EXIT_CODE = 3  # an MD run stopped by inelastic collapse (README, exit codes)


def log(message):
    print(f"[validation] {message}", flush=True)


def solver_environment(jobs):
    """The environment of a solver run when `jobs` run at once: the cores are shared out
    (OMP_NUM_THREADS = cores // jobs, at least 1) and idle OpenMP threads sleep instead of
    spinning (OMP_WAIT_POLICY=passive), because spinning threads of one run steal the cores of
    the other (measured: two spinning threads made a 3D cycle slower than one). Values the
    caller set in the environment are kept."""
    env = dict(os.environ)
    env.setdefault("OMP_NUM_THREADS", str(max(1, (os.cpu_count() or 1) // max(1, jobs))))
    env.setdefault("OMP_WAIT_POLICY", "passive")
    return env


def first_kept_cycle(run, config):
    """The first cycle whose output a continued run would lose: the run's first sampled cycle
    and its first stored frame (md.snapshot_cycles, continuum.field_cycles), whichever is
    earlier; a continued run's files hold only the frames and rows it reached itself."""
    values = tomllib.loads(config)
    cycles = values["run"]["transient_cycles"] + values["run"]["sampled_cycles"]
    frames = (values["md"].get("snapshot_cycles", []) if run["solver"] == "md"
              else values.get("continuum", {}).get("field_cycles", []))
    return min([values["run"]["transient_cycles"]]
               + [c if c >= 0 else cycles + c for c in frames])


def usable_checkpoint(path, run, config):
    """Whether a run may continue from the checkpoint at `path`: it exists, reads, and was
    taken before any output the run keeps (first_kept_cycle)."""
    try:
        with h5py.File(path, "r") as f:
            reached = (int(f.attrs["schedule_cycle"]), int(f.attrs["schedule_phase"]))
    except (OSError, KeyError):
        return False
    return reached <= (first_kept_cycle(run, config), 0)


def remove_checkpoints(checkpoint):
    for path in (checkpoint, os.path.splitext(checkpoint)[0] + ".previous.h5"):
        if os.path.exists(path):
            os.remove(path)


def solver_command(shaker, run, output, config, checkpoint, launcher=()):
    """The command of one run. A resumable run (its `checkpoint_every`, in cycles) writes
    periodic checkpoints to `checkpoint` and continues from one an earlier, stopped attempt
    left when that one precedes the output the run keeps (usable_checkpoint; otherwise it is
    removed and the run starts afresh). Neither changes the run's key: a continued run ends
    in the uninterrupted one's state (programs.Checkpoints.RestartIsExact)."""
    cmd = list(launcher) if run["replicas"] > 1 else []
    cmd += [shaker, run["solver"], run["case_file"]]
    cmd += [a for o in run["overrides"] for a in ("--set", o)]
    cmd += ["--set", f"run.output={output}"]
    if run.get("checkpoint_every"):
        if usable_checkpoint(checkpoint, run, config):
            cmd += ["--set", f"run.restart_from={checkpoint}"]
        else:
            remove_checkpoints(checkpoint)
        cmd += ["--set", f"run.checkpoint={checkpoint}",
                "--set", f"run.checkpoint_every={run['checkpoint_every']}"]
    return cmd


def execute(shaker, workdir, run, rerun, reuse_only, env=None, launcher=()):
    """Runs (or reuses) one solver run; returns its record (status, path, seconds, ...). An
    ensemble (replicas > 1) is started through `launcher` (e.g. mpirun -np 8) if one is given."""
    text, key = run_key(shaker, run)
    stem = os.path.join(workdir, "runs", f"{run['solver']}-{key[:20]}")
    record_path, output = stem + ".json", stem + ".h5"
    if not rerun and os.path.exists(record_path):
        with open(record_path) as f:
            record = json.load(f)
        if record["status"] in ("ok", "collapse") and (record["status"] != "ok"
                                                       or os.path.exists(output)):
            # The workdir may have moved since: the run file is where the key puts it.
            record.update(reused=True, path=output if record["status"] == "ok" else None)
            return record
    if reuse_only:
        status = "ok" if os.path.exists(output) else "not run"
        return dict(status=status, path=output if status == "ok" else None, seconds=0.0,
                    key=key, config=text, reused=status == "ok", returncode=None,
                    stderr="--reuse-only: no finished run", command="")
    checkpoint = stem + ".checkpoint.h5"
    if rerun:
        remove_checkpoints(checkpoint)
    cmd = solver_command(shaker, run, output, text, checkpoint, launcher)
    log(f"run {run['solver']} {run['case']}" + (f" [{run['replicas']} replicas]"
                                                if run["replicas"] > 1 else "")
        + f" -> {os.path.basename(output)}")
    start = time.monotonic()
    try:
        result = subprocess.run(cmd, capture_output=True, text=True, timeout=run["timeout"],
                                env=env)
        rc, stdout, stderr = result.returncode, result.stdout, result.stderr
    except subprocess.TimeoutExpired as expired:
        rc, stdout, stderr = None, str(expired.stdout or ""), str(expired.stderr or "")
    seconds = time.monotonic() - start
    if rc == 0 and os.path.exists(output):
        status = "ok"
    elif rc is None:
        status = f"timed out after {run['timeout']:.0f} s"
    elif rc == COLLAPSE_EXIT_CODE:
        status = "collapse"
    else:
        status = "failed"
    record = dict(status=status, path=output if status == "ok" else None, seconds=seconds,
                  key=key, config=text, returncode=rc, command=" ".join(cmd),
                  stdout=stdout[-3000:], stderr=stderr[-3000:], reused=False)
    if status == "ok":
        remove_checkpoints(checkpoint)
    if status in ("ok", "collapse"):
        tmp = record_path + ".partial"
        with open(tmp, "w") as f:
            json.dump(record, f, indent=1)
        os.replace(tmp, record_path)
    return record


def execute_all(shaker, workdir, plan, jobs, rerun, reuse_only, launcher=()):
    env = solver_environment(jobs)

    def one(run):
        record = execute(shaker, workdir, run, rerun, reuse_only, env, launcher)
        if record["status"] == "collapse" and run["fallback"] and not run["expect_failure"]:
            guarded = dict(run, overrides=run["overrides"] + run["fallback"])
            record = execute(shaker, workdir, guarded, rerun, reuse_only, env, launcher)
            record["fallback"] = run["fallback"]
        return record

    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        records = list(pool.map(one, plan))
    for run, record in zip(plan, records):
        run["record"] = record
    return plan
