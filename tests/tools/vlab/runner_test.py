#!/usr/bin/env python3
"""The virtual lab runner's failure modes (tools/vlab/vlab.py), each reported as such and never a
hang: a test binary that crashes inside the lab, a lab that does not boot within its time-out,
a missing kernel package, no free disk. Example failure: a crash inside the guest reads as a
pass because the runner only looked at qemu's exit status.

Exits 0 when every check passed, 1 otherwise, 77 (skipped) when the lab cannot run here.
"""
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))  # tests/tools/vlab -> the checkout
TOOL = os.path.join(ROOT, "tools", "vlab", "vlab.py")
failures = []


def vlab(*args, env=None, timeout=300):
    merged = dict(os.environ)
    merged.update(env or {})
    started = time.monotonic()
    p = subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True, env=merged, timeout=timeout,
                       check=False)
    return p.returncode, p.stdout + p.stderr, time.monotonic() - started


def check(what, condition, output):
    print(("ok    " if condition else "FAIL  ") + what)
    if not condition:
        failures.append(what)
        print("      output:\n" + "\n".join("      | " + line for line in output.splitlines()[-25:]))


def main():
    if os.environ.get("BASALT_SKIP_VLAB") == "1":
        print("SKIPPED: BASALT_SKIP_VLAB=1 is set")
        return 77
    status, out, _ = vlab("check")
    if status == 77:
        print(out.strip())
        return 77
    with tempfile.TemporaryDirectory(prefix="basalt-vlab-runner-") as tmp:
        # A program that dies of SIGSEGV inside the lab: exit 139, named as a crash, console shown.
        status, out, _ = vlab("run", "--results", os.path.join(tmp, "crash"), "--timeout", "60", "--",
                              "/bin/sh", "-c", "echo before the crash; kill -SEGV $$")
        check("a crash inside the lab exits 128+SIGSEGV", status == 139, out)
        check("a crash inside the lab is named a crash", "crashed inside the lab (SIGSEGV)" in out, out)
        check("the crashing program's own output is shown", "before the crash" in out, out)
        check("the console tail is shown for a crash", "console tail:" in out, out)

        # A program that runs past its limit inside the lab: killed, said so.
        status, out, _ = vlab("run", "--results", os.path.join(tmp, "hang"), "--timeout", "3", "--",
                              "/bin/sleep", "600")
        check("a program past its limit is stopped (status 124)", status == 124, out)
        check("a program past its limit is said to have timed out", "timed out inside the lab" in out, out)
        check("the console tail is shown for a time-out", "console tail:" in out, out)

        # A lab that cannot boot in time: stopped, reported with the console tail.
        status, out, took = vlab("run", "--results", os.path.join(tmp, "boot"), "--boot-timeout", "1", "--",
                                 "/bin/true")
        check("a lab that does not boot in time fails with 125", status == 125, out)
        check("the boot time-out is named", "did not boot within 1 s" in out, out)
        check("the console tail is shown", "---- console" in out, out)
        check("the boot time-out does not hang (under 60 s)", took < 60, out)

        # A kernel package apt cannot get: the lab cannot run here, said so (skip, not a hang).
        empty_cache = os.path.join(tmp, "cache")
        status, out, _ = vlab("build", env={"BASALT_VLAB_CACHE": empty_cache,
                                            "BASALT_VLAB_KERNEL_PACKAGE": "linux-image-0.0.0-basalt-missing-amd64"})
        check("a missing kernel package exits 77", status == 77, out)
        check("a missing kernel package is named", "missing kernel package" in out and
              "linux-image-0.0.0-basalt-missing-amd64" in out, out)

        # No free disk for the kernel: said so, with where and how much.
        status, out, _ = vlab("build", env={"BASALT_VLAB_CACHE": empty_cache, "BASALT_VLAB_MIN_FREE_MB": "999999999"})
        check("no free disk exits 77", status == 77, out)
        check("no free disk is named, with the folder", "no free disk" in out and empty_cache in out, out)
    print(f"{len(failures)} failed" if failures else "all runner checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
