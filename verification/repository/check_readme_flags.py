#!/usr/bin/python3
"""Fails when the README's table of flags misses a flag of `shaker` or names one it does not
have: every `--flag` that `shaker SUBCOMMAND --help` lists appears in a row of that
subcommand, and every row's flag is one the subcommand's help lists.

    check_readme_flags.py SHAKER SOURCE_DIR
"""
import re
import subprocess
import sys

SUBCOMMANDS = ("md", "continuum", "config", "analyze", "compare")
FLAG = re.compile(r"--[a-z][a-z-]*")


def help_flags(shaker, subcommand):
    run = subprocess.run([shaker, subcommand, "--help"], capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(f"shaker {subcommand} --help exited {run.returncode}: {run.stderr}")
    return set(FLAG.findall(run.stdout)) - {"--help"}


def readme_flags(readme):
    """{subcommand: flags} from the rows `| \\`sub\\`, ... | \\`--flag ...\\`, ... | meaning |`."""
    rows = {s: set() for s in SUBCOMMANDS}
    for line in readme.splitlines():
        cells = [c.strip() for c in line.split("|")[1:-1]]
        if len(cells) != 3 or not cells[1].startswith("`--"):
            continue
        for subcommand in re.findall(r"`([a-z]+)`", cells[0]):
            rows.setdefault(subcommand, set()).update(FLAG.findall(cells[1]))
    return rows


def main():
    shaker, source_dir = sys.argv[1], sys.argv[2]
    with open(f"{source_dir}/README.md") as f:
        documented = readme_flags(f.read())
    problems = []
    for subcommand in SUBCOMMANDS:
        actual = help_flags(shaker, subcommand)
        for flag in sorted(actual - documented[subcommand]):
            problems.append(f"shaker {subcommand} {flag} is not in the README's table of flags")
        for flag in sorted(documented[subcommand] - actual):
            problems.append(f"the README lists {flag} for shaker {subcommand}, "
                            "which has no such flag")
        print(f"shaker {subcommand}: {len(actual)} flags, "
              f"{len(documented[subcommand])} in the README")
    for p in problems:
        print("PROBLEM: " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
