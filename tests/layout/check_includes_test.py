#!/usr/bin/env python3
"""The include graph's check (scripts/check-includes.py) on the real tree and on small trees
made here. Makes sure an include against the graph fails the check. Example failure caught: a
room including one above it (kiosk/manifest including kiosk/show) passes CI unnoticed."""
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
TOOL = os.path.join(ROOT, "scripts", "check-includes.py")


def run(root):
    r = subprocess.run([sys.executable, TOOL, root], capture_output=True, text=True)
    return r.returncode, r.stdout


def tree(files):
    d = tempfile.mkdtemp(prefix="basalt-includes-")
    for path, text in files.items():
        full = os.path.join(d, path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w") as f:
            f.write(text)
    return d


failures = []


def expect(name, cond, detail=""):
    if not cond:
        failures.append(f"{name}: {detail}")


code, out = run(ROOT)
expect("the real tree", code == 0, out)

ok = tree({"kiosk/show/a.cpp": '#include "kiosk/status/b.h"\n#include "render/c.h"\n',
           "kiosk/status/b.h": '#include "kiosk/policy/d.h"\n', "app/main.cpp": '#include "kiosk/show/a.h"\n'})
code, out = run(ok)
expect("downward includes pass", code == 0, out)

up = tree({"kiosk/manifest/m.cpp": '#include "kiosk/show/show_loader.h"\n'})
code, out = run(up)
expect("a room including one above it fails", code == 1 and "kiosk/manifest/m.cpp:1" in out, out)

sideways = tree({"kiosk/lock/l.cpp": '#include <cstdio>\n#include "kiosk/policy/schedule.h"\n'})
code, out = run(sideways)
expect("sideways between lock and policy fails", code == 1 and "kiosk/lock/l.cpp:2" in out, out)

lower = tree({"render/r.cpp": '#include "media/movie_player.h"\n'})
code, out = run(lower)
expect("render including media fails", code == 1, out)

library = tree({"kiosk/show/s.cpp": "#include <zmq.h>\n", "kiosk/lock/f.cpp": "#include <zmq.h>\n"})
code, out = run(library)
expect("ZeroMQ outside kiosk/lock fails, inside passes",
       code == 1 and "kiosk/show/s.cpp:1" in out and "kiosk/lock/f.cpp" not in out, out)

cctz = tree({"kiosk/policy/p.cpp": "#include <cctz/time_zone.h>\n",
             "kiosk/manifest/t.cpp": "#include <cctz/civil_time.h>\n"})
code, out = run(cctz)
expect("cctz outside kiosk/manifest fails, inside passes",
       code == 1 and "kiosk/policy/p.cpp:1" in out and "kiosk/manifest/t.cpp" not in out, out)

app_up = tree({"devices/d.cpp": '#include "app/options.h"\n'})
code, out = run(app_up)
expect("devices including app fails", code == 1, out)

for f in failures:
    print("FAILED:", f)
print(f"{8 - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
