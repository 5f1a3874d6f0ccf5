#!/usr/bin/env python3
"""The slowest tests of a CTest run, with their labels, and the time per label.

    ctest --test-dir build -j2 -LE "slow|scenario-full" --output-junit junit.xml
    python3 scripts/slowest_tests.py build build/junit.xml [--top 25]

CTest writes the JUnit file relative to the build folder; the labels come
from the build folder's test list (ctest --show-only=json-v1).  Times are
each test's wall time as CTest measured it; with -j2 two tests share the
machine, so the sum over tests is about twice the run's wall time.
"""
import argparse
import collections
import json
import subprocess
import sys
import xml.etree.ElementTree as ET


def read_labels(build_dir):
    """Test name -> its labels, from CTest's own list of the build's tests."""
    listing = subprocess.run(["ctest", "--test-dir", build_dir, "--show-only=json-v1"],
                             capture_output=True, text=True, check=True).stdout
    labels = {}
    for test in json.loads(listing)["tests"]:
        for prop in test.get("properties", []):
            if prop["name"] == "LABELS":
                labels[test["name"]] = prop["value"]
    return labels


def read_junit(path, labels_of):
    """(name, seconds, status, labels) for every test case of a CTest JUnit file."""
    tests = []
    for case in ET.parse(path).getroot().iter("testcase"):
        labels = labels_of.get(case.get("name"), [])
        status = case.get("status", "run")
        if case.find("failure") is not None:
            status = "failed"
        elif case.find("skipped") is not None:
            status = "skipped"
        tests.append((case.get("name"), float(case.get("time", "0")), status, labels))
    return tests


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build", help="the build folder the tests ran in")
    parser.add_argument("junit", help="the file ctest --output-junit wrote")
    parser.add_argument("--top", type=int, default=25, help="how many of the slowest to list")
    args = parser.parse_args()
    try:
        tests = read_junit(args.junit, read_labels(args.build))
    except (OSError, ET.ParseError, subprocess.CalledProcessError, ValueError) as e:
        print(f"slowest_tests: {e}", file=sys.stderr)
        return 1
    per_label = collections.defaultdict(lambda: [0, 0.0])
    for _, seconds, _, labels in tests:
        for label in labels or ["(none)"]:
            per_label[label][0] += 1
            per_label[label][1] += seconds
    print(f"{len(tests)} tests, {sum(t[1] for t in tests):.1f} s summed")
    for label, (count, seconds) in sorted(per_label.items()):
        print(f"  {label:14s} {count:4d} tests {seconds:8.1f} s")
    print(f"the {args.top} slowest:")
    for name, seconds, status, labels in sorted(tests, key=lambda t: -t[1])[: args.top]:
        print(f"  {seconds:7.1f} s  {name}  [{','.join(labels)}]{'' if status == 'run' else '  ' + status}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
