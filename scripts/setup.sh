#!/usr/bin/env bash
# Installs what building gaze-lidar needs on a fresh Debian machine, only
# when missing: cmake and libclang (HiGHS is compiled from source by
# the `highs` crate (highs-sys); its bindgen step loads libclang.so, which only
# the libclang-dev package provides: the image's libclang-cpp.so is a
# different library and does not count) and a C++ compiler.
# Idempotent and quiet when everything is there.
set -euo pipefail
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q 'install ok installed'; }
need=()
command -v cmake >/dev/null 2>&1 || need+=(cmake)
# What bindgen (clang-sys) actually loads: libclang.so or libclang-<ver>.so(.N),
# never libclang-cpp. Ask dpkg for the package that ships it.
if ! installed libclang-dev; then
  need+=(libclang-dev)
fi
command -v c++ >/dev/null 2>&1 || need+=(g++)
# The Python package (`pip install ./python`) needs CPython 3.9+ with venv
# and pip (maturin and numpy come from PyPI at install time). Debian's own
# python3 ships venv separately.
if ! command -v python3 >/dev/null 2>&1; then
  need+=(python3 python3-venv python3-pip)
elif ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
  need+=(python3-venv)
fi
if [ ${#need[@]} -gt 0 ]; then
  echo "setup: installing ${need[*]}" >&2
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}" >/dev/null
fi
