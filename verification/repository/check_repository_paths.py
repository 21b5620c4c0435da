#!/usr/bin/python3
"""Fails if a tracked file refers to something outside the repository: the specification folder
beside the project's checkout on the machine it was developed on, or an absolute path of a
machine (/work/..., /root/..., /home/..., /tmp/..., or this checkout's own absolute path).
A clone has none of them, so such a reference is a dangling link in a document or a report
that tells its reader about one machine only.

    check_repository_paths.py SOURCE_DIR

Reads `git ls-files` (exit 77, skipped, outside a git checkout); binary files are ignored.
Reports name the file, the line and the offending text.
"""
import os
import re
import subprocess
import sys


def patterns(source_dir):
    outside = [r"\.\./shared\b",
               r"(?<![\w.~-])/(?:work|root|home|tmp)/"]  # absolute, not validation/work/
    here = os.path.realpath(source_dir)
    if here != "/":
        outside.append(re.escape(here))
    return re.compile("|".join(outside))


def main():
    source_dir = sys.argv[1] if len(sys.argv) > 1 else "."
    try:
        listed = subprocess.run(["git", "-C", source_dir, "ls-files", "-z"], check=True,
                                capture_output=True).stdout
    except (OSError, subprocess.CalledProcessError) as error:
        print(f"check_repository_paths: not a git checkout ({error}); skipped")
        return 77
    pattern = patterns(source_dir)
    me = os.path.relpath(os.path.realpath(__file__), os.path.realpath(source_dir))
    problems = []
    for name in listed.decode().split("\0"):
        path = os.path.join(source_dir, name)
        if not name or name == me or not os.path.isfile(path):
            continue
        with open(path, "rb") as f:
            data = f.read()
        if b"\0" in data:
            continue
        for number, line in enumerate(data.decode("utf-8", "replace").splitlines(), 1):
            match = pattern.search(line)
            if not match:
                continue
            problems.append(f"{name}:{number}: refers to '{match.group(0)}' outside the "
                            f"repository: {line.strip()[:160]}")
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} reference(s) to files outside the repository; use repository-"
              "relative paths (docs/, reference-data/, reports/) or cite the publication")
        return 1
    count = len([n for n in listed.split(b"\0") if n])
    print(f"{count} tracked files refer only to the repository")
    return 0


if __name__ == "__main__":
    sys.exit(main())
