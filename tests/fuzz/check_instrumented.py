#!/usr/bin/env python3
"""Checks that every object of the given static libraries carries libFuzzer's coverage
instrumentation (-fsanitize=fuzzer-no-link): an object that defines code must refer to
__sanitizer_cov_* (the counters' and PC tables' initialisers its module constructor calls).

An object compiled without it still links into the fuzzer, and the fuzzer still runs, but its
feedback is blind inside that object: this is the check that the fuzz build instruments the
libraries under test and not only the fuzz target's own file.

  check_instrumented.py [--nm NM] LIBRARY.a...

Prints one line per library (objects with code, objects instrumented) and each object that is
not; exits 1 when any is not, or when a library holds no code at all.
"""

import argparse
import re
import subprocess
import sys
from collections import defaultdict

# "archive.a:member.o:0000000000000000 T name" or "archive.a:member.o:                 U name"
LINE = re.compile(r"^(?P<member>[^:]+\.a:[^:]+):\s*(?:[0-9a-fA-F]+\s+)?(?P<type>\S)\s+(?P<name>\S+)")


def is_coverage_symbol(name: str) -> bool:
    return "__sanitizer_cov" in name or name.startswith("sancov.")


def is_sanitizer_code(name: str) -> bool:
    """Functions a sanitizer adds to every object (AddressSanitizer's module constructor in a file
    of data only): not code of the library's own."""
    return name.startswith(("asan.", "__asan", "ubsan.", "__ubsan", "sancov.", "__sanitizer"))


def check(nm: str, library: str) -> list[str]:
    """Returns the members of `library` that define code without the instrumentation."""
    out = subprocess.run([nm, "-A", library], check=True, capture_output=True, text=True).stdout
    code: dict[str, bool] = defaultdict(bool)
    covered: dict[str, bool] = defaultdict(bool)
    for line in out.splitlines():
        match = LINE.match(line)
        if not match:
            continue
        member = match["member"].split(":", 1)[1]
        if match["type"] in "TtW" and not is_sanitizer_code(match["name"]):
            code[member] = True
        if is_coverage_symbol(match["name"]):
            covered[member] = True
    with_code = sorted(m for m, has in code.items() if has)
    missing = [m for m in with_code if not covered[m]]
    print(f"{library}: {len(with_code) - len(missing)} of {len(with_code)} objects with code instrumented")
    if not with_code:
        missing.append("(no object with code)")
    return missing


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--nm", default="nm")
    parser.add_argument("libraries", nargs="+")
    args = parser.parse_args()
    failed = False
    for library in args.libraries:
        for member in check(args.nm, library):
            print(f"  not instrumented: {member}")
            failed = True
    if failed:
        print("FAIL: compile every Basalt library of the fuzz build with -fsanitize=fuzzer-no-link")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
