#!/usr/bin/env bash
# Installs the Debian packages Basalt needs, idempotently: when all are present it does nothing and
# touches no network. Runs as root, or through sudo when it is available.
#   scripts/setup.sh          what building and running Basalt needs (scripts/packages.txt): make run
#   scripts/setup.sh --test   that and what the tests, benchmarks, lint, fuzzing and the virtual lab
#                             need (scripts/packages-test.txt): make test and the other targets, CI
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lists=("$here/packages.txt")
case "${1:-}" in
  "") ;;
  --test) lists+=("$here/packages-test.txt") ;;
  *) echo "usage: scripts/setup.sh [--test]" >&2; exit 2 ;;
esac
mapfile -t wanted < <(grep -hvE '^\s*(#|$)' "${lists[@]}")
missing=()
for pkg in "${wanted[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$pkg" 2>/dev/null || true)
  [ "$status" = installed ] || missing+=("$pkg")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
as_root=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
  else
    echo "setup: these packages are missing and this user cannot install them: ${missing[*]}" >&2
    echo "setup: run as root, or install sudo, or install them with apt-get yourself." >&2
    exit 1
  fi
fi
echo "setup: installing ${#missing[@]} Debian package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
# An update older than a day may point at package versions the mirror no longer has.
if [ -z "$(find /var/lib/apt/lists -maxdepth 1 -name '*Packages*' -mmin -1440 2>/dev/null | head -1)" ]; then
  "${as_root[@]}" apt-get update -qq
fi
if ! "${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"; then
  echo "setup: apt-get could not install the packages above; check the network and /etc/apt/sources.list, then run again." >&2
  exit 1
fi
