#!/usr/bin/env bash
# Sets up tg_drake on a fresh Debian 12 machine: the one system library open3d needs (libusb-1.0),
# a virtual environment in .venv, and the package with its test extras. Idempotent and quick when
# nothing changed (a stamp file records the pyproject.toml and setup.py it installed).
set -euo pipefail
cd "$(dirname "$0")/.."

# open3d's pybind module links libusb-1.0; Debian ships it as libusb-1.0-0.
if ! ldconfig -p 2>/dev/null | grep -q 'libusb-1.0.so.0'; then
  echo "[setup] installing libusb-1.0-0 (needed by open3d)"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libusb-1.0-0 >/dev/null
fi

PYTHON="${PYTHON:-python3.11}"
if [ ! -x .venv/bin/python ]; then
  echo "[setup] creating .venv with $PYTHON"
  "$PYTHON" -m venv .venv
fi

# pip and the build backend write to a log, shown only when the installation fails.
stamp=.venv/.tg_drake_installed
log=.venv/setup.log
if [ ! -f "$stamp" ] || ! cat pyproject.toml setup.py | cmp -s - "$stamp"; then
  echo "[setup] installing tg_drake and its dependencies into .venv (log: $log)"
  if ! { .venv/bin/python -m pip install -q --upgrade pip &&
         .venv/bin/python -m pip install -q -e '.[test]'; } >"$log" 2>&1; then
    cat "$log" >&2
    echo "[setup] the installation failed: the log is above and in $log" >&2
    exit 1
  fi
  cat pyproject.toml setup.py >"$stamp"
fi
