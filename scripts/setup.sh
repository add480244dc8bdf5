#!/usr/bin/env bash
# Set up raysim on a fresh machine: the system library Open3D needs, a virtual environment
# in .venv, and the package (with the test extras when called with "test").
# Idempotent: a second run only checks.
set -euo pipefail
cd "$(dirname "$0")/.."

# Open3D's CPU wheel links libusb-1.0 (Debian/Ubuntu package libusb-1.0-0): `import open3d` fails without it.
if ! ldconfig -p 2>/dev/null | grep -q 'libusb-1\.0\.so\.0'; then
  echo "setup: installing the system library libusb-1.0 (needed by Open3D)" >&2
  if [ "$(id -u)" = 0 ]; then SUDO=""; elif command -v sudo >/dev/null; then SUDO="sudo -n"; else SUDO="none"; fi
  if [ "$SUDO" != "none" ] && command -v apt-get >/dev/null; then
    $SUDO apt-get update -qq && $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libusb-1.0-0 >/dev/null
  elif [ "$SUDO" != "none" ] && command -v dnf >/dev/null; then
    $SUDO dnf install -y -q libusb1
  elif [ "$(uname)" = Darwin ]; then
    : # macOS wheels of Open3D bundle what they need
  else
    echo "setup: cannot install libusb-1.0 here: install it with your package manager (Debian: libusb-1.0-0)" >&2
    exit 1
  fi
fi

PYTHON=${PYTHON:-python3}
"$PYTHON" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' || {
  echo "setup: raysim needs Python >= 3.11 ($PYTHON is $("$PYTHON" --version 2>&1)); set PYTHON=python3.11" >&2; exit 1; }
[ -x .venv/bin/python ] || "$PYTHON" -m venv .venv
EXTRAS=""
[ "${1:-}" = "test" ] && EXTRAS="[test]"
.venv/bin/python -m pip install -q --disable-pip-version-check --upgrade pip >/dev/null
.venv/bin/python -m pip install -q --disable-pip-version-check -e ".${EXTRAS}"
.venv/bin/python -c 'import open3d, embreex, trimesh, pyproj' || { echo "setup: the installed packages do not import" >&2; exit 1; }
