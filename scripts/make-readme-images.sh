#!/usr/bin/env bash
# Makes the README's pictures again: each example show in configs/shows/, rendered by Basalt
# itself on the headless output, as docs/images/show-NAME.png (640 pixels wide), and the
# diagram docs/images/devices-show-outputs.svg from its Graphviz source beside it.
#   scripts/make-readme-images.sh [BASALT]     (default: build/basalt; `make run` builds it)
# The status page's pictures (docs/images/status-*.png) come from the StatusPage test
# (tests/kiosk/status/status_server_gl_test.cpp).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
basalt=$(realpath "${1:-$top/build/basalt}")
images=$top/docs/images
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Every picture is the frame after a fixed number of frames on the manual clock, from a fixed
# calendar time (a Friday afternoon, inside the opening hours of every example), so a run
# without changes to the renderer or the shows gives the same pictures.
clock=2026-11-27T14:00:00Z

# picture NAME MANIFEST SIZE FRAMES: plays MANIFEST and keeps its last frame as show-NAME.png.
picture() {
  local name=$1 manifest=$2 size=$3 frames=$4
  if ! "$basalt" run "$manifest" --output headless --fast --size "$size" --frames "$frames" \
      --clock-start "$clock" --no-resume --state-dir "$work/state-$name" --status 127.0.0.1:0 \
      --output-dir "$work" --snapshot "$images/show-$name.png" >"$work/$name.log" 2>&1; then
    cat "$work/$name.log" >&2
    echo "make-readme-images: $name did not play (above)" >&2
    exit 1
  fi
  echo "docs/images/show-$name.png: $name, $size, frame $frames"
}

shows=$top/configs/shows
# Each at its manifest's aspect ratio, 640 pixels wide.
picture default "$shows/default/show.toml" 640x480 300
picture cube-cave "$shows/cube-cave/show.toml" 648x288 120
picture video-wall "$shows/video-wall/show.toml" 640x360 90
picture lava-script "$shows/lava-script/show.toml" 640x480 200

# The camera sculpture plays on a projector (KMS) from a V4L2 camera and a PowerMate: here its
# camera and its knob are Basalt's synthetic twins (the camera shows colour bars), as
# configs/shows/README.md describes for every device, and the output is headless.
cp -r "$shows/camera-sculpture" "$work/camera-sculpture"
sed -i -e 's/^kind = "kms"/kind = "headless"/' -e '/^connector = /d' \
    -e 's/^backend = "v4l2"/backend = "synthetic"/' -e '/^match = { path = "\/dev\/video0" }/d' \
    -e 's/^backend = "hid"/backend = "synthetic"/' -e '/^match = { usb = "077d:0410" }/d' \
    "$work/camera-sculpture/show.toml"
if grep -qE 'v4l2|"hid"|"kms"' "$work/camera-sculpture/show.toml"; then
  echo "make-readme-images: camera-sculpture/show.toml changed; update its twins here" >&2
  exit 1
fi
picture camera-sculpture "$work/camera-sculpture/show.toml" 640x480 120

if command -v dot >/dev/null; then
  dot -Tsvg "$images/devices-show-outputs.dot" -o "$images/devices-show-outputs.svg"
  echo "docs/images/devices-show-outputs.svg: from devices-show-outputs.dot"
else
  echo "make-readme-images: no Graphviz (dot; scripts/packages-test.txt): the diagram is left as it is" >&2
fi
