#!/usr/bin/env python3
"""Checks that includes run one way (DESIGN.md section 1, ARCHITECTURE.md "Folders and rooms").

Every #include "folder/..." in a source file must name its own folder or room, or one the
table below lets it use; and each third-party C library is included in its one folder only.
Prints every include against the graph as `file:line: ...` and exits 1 when there is one.

  scripts/check-includes.py [SOURCE_ROOT]
"""
import os
import re
import sys

# What each folder or room may include besides itself. Longest prefix wins (kiosk/show before kiosk).
LOWER = ["runtime", "devices", "media", "render", "sim"]
ALLOWED = {
    "runtime": [],
    "devices": ["runtime"],
    "media": ["runtime"],
    "render": ["runtime", "embedded"],  # embedded/: shaders made into headers at build time
    "sim": ["devices", "runtime"],
    "kiosk/manifest": LOWER,
    "kiosk/loop": LOWER + ["kiosk/manifest"],
    "kiosk/lock": LOWER + ["kiosk/manifest", "kiosk/loop"],
    "kiosk/policy": LOWER + ["kiosk/manifest", "kiosk/loop"],
    "kiosk/status": LOWER + ["kiosk/manifest", "kiosk/loop", "kiosk/lock", "kiosk/policy"],
    "kiosk/osc": LOWER + ["kiosk/manifest", "kiosk/loop", "kiosk/lock", "kiosk/policy", "kiosk/status"],
    "kiosk/show": LOWER + ["kiosk/manifest", "kiosk/loop", "kiosk/lock", "kiosk/policy", "kiosk/status", "kiosk/osc"],
    "app": LOWER + ["kiosk"],
    "tools/vlab": ["sim", "devices", "runtime"],
}
# Third-party headers and the one folder or room that may include them.
LIBRARIES = [
    (re.compile(r"^(zmq\.h|zmq\.hpp)$"), "ZeroMQ", "kiosk/lock"),
    (re.compile(r"^httplib\.h$"), "cpp-httplib", "kiosk/status"),
    (re.compile(r"^lo/"), "liblo", "kiosk/osc"),
    (re.compile(r"^systemd/"), "libsystemd", "kiosk/policy"),
    (re.compile(r"^toml\+\+/"), "toml++", "kiosk/manifest"),
    (re.compile(r"^cctz/"), "cctz", "kiosk/manifest"),
    (re.compile(r"^(gst|glib|glib-object)/|^glib\.h$"), "GStreamer/GLib", "media"),
    (re.compile(r"^OpenImageIO/"), "OpenImageIO", "media"),
    (re.compile(r"^(EGL|GLES2|GLES3|KHR)/|^(gbm\.h|xf86drm\.h|xf86drmMode\.h)$"), "EGL/GLES/GBM/DRM", "render"),
    (re.compile(r"^(X11)/"), "Xlib", "render"),
    (re.compile(r"^(hidapi|libusb-1\.0)/|^(hidapi\.h|libusb\.h)$"), "hidapi/libusb", "devices/hid"),
    (re.compile(r"^libcamera/"), "libcamera", "devices/libcamera"),
    (re.compile(r"^libudev\.h$"), "libudev", "devices/udev"),
    (re.compile(r"^alsa/"), "ALSA (libasound)", "devices/midi"),
]
SOURCE_DIRS = ["runtime", "devices", "media", "render", "sim", "kiosk", "app", "tools"]
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^">]+)[">]')


def owner(path, table):
    """The longest key of `table` that `path` lies under, or None."""
    best = None
    for key in table:
        if path == key or path.startswith(key + "/"):
            if best is None or len(key) > len(best):
                best = key
    return best


def check(root):
    problems = []
    for top in SOURCE_DIRS:
        for folder, _, files in os.walk(os.path.join(root, top)):
            for name in sorted(files):
                if not name.endswith((".cpp", ".h")):
                    continue
                full = os.path.join(folder, name)
                rel = os.path.relpath(full, root)
                room = owner(rel, ALLOWED)
                if room is None:
                    problems.append(f"{rel}:1: this folder has no place in the include graph (scripts/check-includes.py)")
                    continue
                with open(full, encoding="utf-8", errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        quote, target = m.groups()
                        if quote == '"' and "/" in target:
                            first = target.split("/")[0]
                            if first not in ALLOWED and owner(target, ALLOWED) is None and first != "embedded":
                                continue  # a third-party header written with quotes
                            if target.startswith(room + "/"):
                                continue
                            if not any(target.startswith(a + "/") for a in ALLOWED[room]):
                                problems.append(f"{rel}:{number}: {room} may not include \"{target}\" "
                                                f"(it may include {', '.join(ALLOWED[room]) or 'only itself'})")
                        else:
                            for pattern, library, home in LIBRARIES:
                                if pattern.search(target) and not (rel.startswith(home + "/")):
                                    problems.append(f"{rel}:{number}: {library} belongs to {home} only, "
                                                    f"but this file includes <{target}>")
    return problems


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    problems = check(root)
    for p in problems:
        print(p)
    if problems:
        print(f"check-includes: {len(problems)} include(s) against the graph")
        return 1
    print("check-includes: every include runs one way")
    return 0


if __name__ == "__main__":
    sys.exit(main())
