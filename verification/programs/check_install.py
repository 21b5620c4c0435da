#!/usr/bin/python3
"""`cmake --install` into a temporary prefix: bin/shaker runs (--help, --version) and the
documentation is in share/doc/granular-shaker. The prefix is removed when the check passes
and kept (its path printed) when it fails.

    check_install.py CMAKE BUILD_DIR
"""
import os
import subprocess
import sys

import keep_on_failure

DOCS = ["README.md", "LICENSE", "CITATION.cff", "docs/models.md", "docs/units.md",
        "docs/configuration.md", "docs/output-schema.md", "docs/reproducing-the-paper.md"]


def main():
    cmake, build_dir = sys.argv[1], sys.argv[2]
    prefix = keep_on_failure.work_folder("shaker-install-")
    problems = []
    done = subprocess.run([cmake, "--install", build_dir, "--prefix", prefix],
                          capture_output=True, text=True)
    if done.returncode != 0:
        problems.append(f"cmake --install failed ({done.returncode}):\n{done.stdout}{done.stderr}")
    else:
        shaker = os.path.join(prefix, "bin", "shaker")
        for flag in ("--help", "--version"):
            run = subprocess.run([shaker, flag], capture_output=True, text=True)
            if run.returncode != 0 or "shaker" not in run.stdout:
                problems.append(f"{shaker} {flag}: exit {run.returncode}\n{run.stdout}{run.stderr}")
        doc_dir = os.path.join(prefix, "share", "doc", "granular-shaker")
        problems += [f"missing {os.path.join(doc_dir, d)}" for d in DOCS
                     if not os.path.isfile(os.path.join(doc_dir, d))]
    for problem in problems:
        print("PROBLEM:", problem)
    return keep_on_failure.finish(
        prefix, problems, f"installed bin/shaker and {len(DOCS)} documents; prefix removed")


if __name__ == "__main__":
    sys.exit(main())
