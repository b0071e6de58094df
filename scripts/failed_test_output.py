#!/usr/bin/env python3
"""Prints the end of each failed test's output from ctest's LastTest.log, after the summary.

CI shows only the tail of a run's output; ctest prints a failed test's output when the test ends,
long before that tail. Called by the Makefile when a ctest run fails.

    failed_test_output.py BUILD_DIR [--lines N]
"""
import argparse
import os
import re
import sys


def failed_tests(log_text):
    """(name, output lines) of each test whose record ends in anything but "Test Passed."."""
    records = re.split(r"^-{20,}\n(?=\d+/\d+ Testing: )", log_text, flags=re.MULTILINE)
    for record in records:
        name = re.match(r"\d+/\d+ Testing: (.+)", record)
        if not name or "\nTest Passed." in record:
            continue
        output = re.search(r"^Output:\n-+\n(.*?)<end of output>", record, re.MULTILINE | re.DOTALL)
        yield name.group(1).strip(), (output.group(1) if output else record).splitlines()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build_dir")
    parser.add_argument("--lines", type=int, default=60)
    args = parser.parse_args()
    log = os.path.join(args.build_dir, "Testing", "Temporary", "LastTest.log")
    if not os.path.exists(log):
        print(f"failed_test_output: no {log}", file=sys.stderr)
        return
    with open(log, errors="replace") as f:
        text = f.read()
    for name, lines in failed_tests(text):
        print(f"==== {name}: the last {min(len(lines), args.lines)} lines of its output ====")
        print("\n".join(lines[-args.lines:]))


if __name__ == "__main__":
    main()
