#!/usr/bin/env python3
"""Prints a summary of a ctest run: totals per tier (ctest label), every skipped test with the
reason it gave, and every failure. Exits 1 when a test failed.

usage: test_summary.py BUILD_DIR   (reads BUILD_DIR/ctest-junit.xml and asks ctest for labels)
"""
import collections
import json
import re
import subprocess
import sys
import xml.etree.ElementTree as ET


def labels_by_test(build):
    out = subprocess.run(["ctest", "--test-dir", build, "--show-only=json-v1"],
                         capture_output=True, text=True, check=False).stdout
    labels = {}
    try:
        for test in json.loads(out).get("tests", []):
            names = []
            for prop in test.get("properties", []):
                if prop.get("name") == "LABELS":
                    names = prop.get("value", [])
            labels[test["name"]] = names or ["(no label)"]
    except (json.JSONDecodeError, KeyError):
        pass
    return labels


def skip_reason(output):
    """The text GoogleTest prints after 'file:line: Skipped', up to the [  SKIPPED ] line."""
    m = re.search(r":\d+: Skipped\n(.*?)\n\[  SKIPPED \]", output, re.S)
    if m and m.group(1).strip():
        return " ".join(m.group(1).split())
    m = re.search(r"SKIP(?:PED)?:? *(.+)", output)
    return m.group(1).strip() if m else "(no reason given)"


def failure_excerpt(out, limit=12):
    """The lines of a test's output that say why it failed: GoogleTest's 'Failure' blocks, a
    crash or a time-out, else its last lines."""
    lines = [l.rstrip()[:300] for l in out.splitlines() if l.strip()]
    keys = ("Failure", "Expected", "Value of", "Actual", "Which is", "Segmentation", "Timeout", "Aborted",
            "Exception", "ERROR:", "AddressSanitizer", "runtime error")
    chosen = []
    for i, line in enumerate(lines):
        if any(k in line for k in keys):
            for j in (i, i + 1):
                if j < len(lines) and j not in chosen and not lines[j].startswith("["):
                    chosen.append(j)
        if len(chosen) >= limit:
            break
    picked = [lines[j] for j in chosen]
    return picked[:limit] if picked else lines[-limit:]


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    try:
        suite = ET.parse(f"{build}/ctest-junit.xml").getroot()
    except (OSError, ET.ParseError) as e:
        print(f"test summary: cannot read {build}/ctest-junit.xml: {e}")
        return 1
    labels = labels_by_test(build)
    per_label = collections.defaultdict(lambda: collections.Counter())
    skipped = collections.defaultdict(list)
    failed = []
    excerpts = {}
    for case in suite.iter("testcase"):
        name = case.get("name")
        status = case.get("status")
        out = case.findtext("system-out") or ""
        if case.find("skipped") is not None or status == "notrun":
            kind = "skipped"
            skipped[skip_reason(out)].append(name)
        elif case.find("failure") is not None or status == "fail":
            kind = "failed"
            failed.append(name)
            excerpts[name] = failure_excerpt(out)
        else:
            kind = "passed"
        for label in labels.get(name, ["(no label)"]):
            per_label[label][kind] += 1

    print("\n==== Basalt test summary ====")
    total = collections.Counter()
    for label in sorted(per_label):
        c = per_label[label]
        total.update(c)
        print(f"  {label:10s} {c['passed']:5d} passed  {c['skipped']:4d} skipped  {c['failed']:4d} failed")
    if skipped:
        print("\nSkipped, with the reason each gave:")
        for reason, names in sorted(skipped.items(), key=lambda kv: -len(kv[1])):
            shown = ", ".join(names[:4]) + (f", and {len(names) - 4} more" if len(names) > 4 else "")
            print(f"  - {reason}\n      ({len(names)}: {shown})")
    if failed:
        print("\nFailed:")
        for name in failed:
            print(f"  - {name}")
        # Why, in a few lines each, so that the end of a CI log says what went wrong.
        print("\nWhy each failed (the first lines of its failure; the whole output is above):")
        for name in failed:
            print(f"  - {name}:")
            for line in excerpts[name]:
                print(f"      {line}")
    skip_count = sum(len(names) for names in skipped.values())
    case_count = sum(1 for _ in suite.iter("testcase"))
    print(f"\n{'FAILED' if failed else 'OK'}: {len(failed)} failed, {skip_count} skipped, of {case_count} tests")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
