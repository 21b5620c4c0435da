#!/usr/bin/python3
"""Fails when a line of a status.txt (verification/README.md) selects no test: a pattern left
behind by a renamed or removed test would otherwise go on saying nothing, silently. Reads the
tests the build directory declares (`ctest --show-only=json-v1`) and checks that every pattern
of every status.txt under the source tree matches at least one of them, and that the first
matching line's labels are the labels the test carries.

    PYTHONPATH=SOURCE_DIR/python check_status_files.py CTEST SOURCE_DIR BUILD_DIR

(ctest sets PYTHONPATH: it reads the status files with the reader of
granular_shaker.reports.report_common.)
"""
import fnmatch
import json
import os
import subprocess
import sys

from granular_shaker.reports.report_common import status_lines


def main():
    ctest, source_dir, build_dir = sys.argv[1], sys.argv[2], sys.argv[3]
    listed = subprocess.run([ctest, "--test-dir", build_dir, "--show-only=json-v1"],
                            capture_output=True, text=True)
    if listed.returncode != 0:
        print(f"ctest --show-only failed ({listed.returncode}):\n{listed.stderr}")
        return 1
    labels_of = {}
    for test in json.loads(listed.stdout)["tests"]:
        properties = {p["name"]: p["value"] for p in test.get("properties", [])}
        labels_of[test["name"]] = sorted(properties.get("LABELS", []))
    lines = status_lines(source_dir)
    problems = []
    decided = set()
    for path, number, pattern, labels, _ in lines:
        where = f"{os.path.relpath(path, source_dir)}:{number}"
        if pattern is None:
            problems.append(f"{where}: not PATTERN LABELS TIMEOUT ENVIRONMENT REASON")
            continue
        matched = [name for name in labels_of if fnmatch.fnmatchcase(name, pattern)]
        if not matched:
            problems.append(f"{where}: '{pattern}' matches no test")
        for name in matched:
            if name in decided:
                continue
            decided.add(name)
            if labels_of[name] != labels:
                problems.append(f"{where}: {name} carries labels {labels_of[name]}, "
                                f"the line says {labels}")
    for problem in problems:
        print("PROBLEM:", problem)
    if problems:
        return 1
    print(f"{len(lines)} status lines, each matching a test with its labels; "
          f"{len(decided)} of {len(labels_of)} tests decided by them")
    return 0


if __name__ == "__main__":
    sys.exit(main())
