#!/usr/bin/env python3
"""The README shows what it tells: every picture it links is there, is a real PNG, JPEG or SVG
and stays small (at most 512 KB, 1280 pixels wide), and every example show in configs/shows/ has
its picture (docs/images/show-NAME.png, made by scripts/make-readme-images.sh, which must name
the show too). Example failures caught: a sixth example show added without a picture, an image
renamed and its link left behind, a full-size screenshot committed, an empty or truncated file."""
import os
import re
import struct
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MAX_BYTES = 512 * 1024
MAX_WIDTH = 1280
failures = []

with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
    readme = f.read()
# Markdown images, and HTML <img src="..."> where a size had to be set.
images = re.findall(r"!\[([^\]]*)\]\(([^)\s]+)\)", readme)
images += [("html", src) for src in re.findall(r"<img\s[^>]*src=\"([^\"]+)\"", readme)]
if not images:
    failures.append("README.md links no picture at all")


def png_width(data):
    if data[:8] != b"\x89PNG\r\n\x1a\n" or data[12:16] != b"IHDR":
        return None
    return struct.unpack(">I", data[16:20])[0]


linked = set()
for alt, target in images:
    if re.match(r"^[a-z]+:", target):
        failures.append(f"README.md: the picture '{target}' is not in the repository; keep pictures under docs/")
        continue
    if not alt.strip():
        failures.append(f"README.md: the picture '{target}' has no alternative text")
    path = os.path.normpath(os.path.join(ROOT, target))
    linked.add(os.path.relpath(path, ROOT))
    if not os.path.isfile(path):
        failures.append(f"README.md: the picture '{target}' leads nowhere")
        continue
    size = os.path.getsize(path)
    if size > MAX_BYTES:
        failures.append(f"README.md: '{target}' is {size} bytes; pictures stay within {MAX_BYTES}")
    with open(path, "rb") as f:
        data = f.read()
    if target.endswith(".png"):
        width = png_width(data)
        if width is None:
            failures.append(f"README.md: '{target}' is not a PNG")
        elif width > MAX_WIDTH:
            failures.append(f"README.md: '{target}' is {width} pixels wide; pictures stay within {MAX_WIDTH}")
    elif target.endswith(".svg"):
        if b"<svg" not in data[:4096] or not data.rstrip().endswith(b"</svg>"):
            failures.append(f"README.md: '{target}' is not a whole SVG file")
    elif target.endswith((".jpg", ".jpeg")):
        if data[:3] != b"\xff\xd8\xff":
            failures.append(f"README.md: '{target}' is not a JPEG")
    else:
        failures.append(f"README.md: '{target}': pictures are PNG, JPEG or SVG")

shows_dir = os.path.join(ROOT, "configs", "shows")
shows = sorted(d for d in os.listdir(shows_dir) if os.path.isfile(os.path.join(shows_dir, d, "show.toml")))
if not shows:
    failures.append("configs/shows/ holds no example show")
with open(os.path.join(ROOT, "scripts", "make-readme-images.sh"), encoding="utf-8") as f:
    script = f.read()
for show in shows:
    picture = os.path.join("docs", "images", f"show-{show}.png")
    if picture not in linked:
        failures.append(f"README.md: the example show '{show}' has no picture ({picture})")
    if not re.search(rf"^picture {re.escape(show)} ", script, re.MULTILINE):
        failures.append(f"scripts/make-readme-images.sh does not make the picture of '{show}'")

for f in failures:
    print("FAILED:", f)
print(f"{len(images)} pictures and {len(shows)} example shows checked: "
      f"{1 if not failures else 0} passed, {1 if failures else 0} failed ({len(failures)} problem(s))")
sys.exit(1 if failures else 0)
