#!/usr/bin/python3
"""Fails when docs/configuration.md is not the output of `shaker config --describe --markdown`
(the schema in solvers/*/parameters.cpp changed and the document was not regenerated).

    check_configuration_doc.py SHAKER SOURCE_DIR
"""
import difflib
import os
import subprocess
import sys


def main():
    shaker, source_dir = sys.argv[1], sys.argv[2]
    document = os.path.join(source_dir, "docs", "configuration.md")
    run = subprocess.run([shaker, "config", "--describe", "--markdown"], capture_output=True,
                         text=True)
    if run.returncode != 0:  # e.g. a key declared without units
        print(f"shaker config --describe --markdown failed ({run.returncode}):\n{run.stderr}")
        return 1
    generated = run.stdout
    try:
        with open(document) as f:
            stored = f.read()
    except OSError as error:
        stored = ""
        print(f"cannot read {document}: {error}")
    if stored == generated:
        print("docs/configuration.md matches `shaker config --describe --markdown`")
        return 0
    sys.stdout.writelines(difflib.unified_diff(stored.splitlines(True), generated.splitlines(True),
                                               "docs/configuration.md", "shaker config --describe"))
    print("\ndocs/configuration.md is out of date; regenerate it from the source directory with\n"
          "    build/release/solvers/app/shaker config --describe --markdown"
          " > docs/configuration.md")
    return 1


if __name__ == "__main__":
    sys.exit(main())
