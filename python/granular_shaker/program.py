"""Running the `shaker` program from Python (the example notebooks do)."""
import os
import shutil
import subprocess


def find_shaker():
    """The `shaker` program: the environment variable SHAKER, else `shaker` on PATH."""
    program = os.environ.get("SHAKER") or shutil.which("shaker")
    if not program:
        raise FileNotFoundError("no shaker program: set the environment variable SHAKER to it "
                                "(e.g. build/release/solvers/app/shaker) or put shaker on PATH")
    if not os.access(program, os.X_OK):
        raise FileNotFoundError(f"SHAKER = {program}: not an executable file")
    return os.path.abspath(program)


def run_shaker(*arguments):
    """Run `shaker ARGUMENTS...`; its standard output, or RuntimeError with its messages."""
    command = [find_shaker(), *map(str, arguments)]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} exited {result.returncode}:\n"
                           f"{result.stdout}{result.stderr}")
    return result.stdout
