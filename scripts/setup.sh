#!/usr/bin/env bash
# Sets up a fresh machine: Debian packages for headless EGL rendering and open3d (when root),
# then a virtual environment in .venv with sgdata installed in editable mode, on Python 3.11,
# 3.12 or 3.13: whichever `python3` is, or PYTHON=python3.12 (a name or a path).
# Idempotent: a second run only re-installs when pyproject.toml or this script changed.
set -euo pipefail
cd "$(dirname "$0")/.."

# chromium: the labeling tests drive the real `sgdata label` page in headless Chromium
debs=(libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 libusb-1.0-0 chromium)
missing=()
for pkg in "${debs[@]}"; do
  dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if [ "${#missing[@]}" -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "setup: installing Debian packages: ${missing[*]}"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
  else
    echo "setup: please install these Debian packages first: ${missing[*]}" >&2
    exit 1
  fi
fi

# torch 2.14.1, torchvision, open3d 0.20 and usd-core 26.11 publish cp311, cp312 and cp313 wheels.
minor() { "$1" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null || echo none; }
python=$(command -v "${PYTHON:-python3}" || echo "${PYTHON:-python3}")
version=$(minor "$python")
case "$version" in
  3.11 | 3.12 | 3.13) ;;
  *)
    echo "setup: Python 3.11, 3.12 or 3.13 is required; ${PYTHON:-python3} is ${version/none/not a runnable Python} (set PYTHON=python3.12, for example)" >&2
    exit 1
    ;;
esac
if [ -x .venv/bin/python ] && [ "$(minor .venv/bin/python)" != "$version" ]; then
  echo "setup: .venv is Python $(minor .venv/bin/python), not $version; remove it (rm -rf .venv) to switch" >&2
  exit 1
fi
[ -x .venv/bin/python ] || "$python" -m venv .venv

stamp=.venv/.sgdata-installed
pins=constraints/py$version.txt
want=$(cat pyproject.toml scripts/setup.sh $([ -f "$pins" ] && echo "$pins") | sha256sum | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "setup: installing Python dependencies into .venv on Python $version (torch is large: a few minutes)"
  .venv/bin/python -m pip install -q --upgrade pip >/dev/null
  # uv installs the same versions as pip, downloading in parallel and linking from its cache
  # (~/.cache/uv): 35 s from an empty cache where pip took 190 s, and a second clone's .venv
  # costs almost no disk. Where uv cannot be installed, pip does the same work.
  install=(.venv/bin/python -m pip install -q)
  if .venv/bin/python -m pip install -q "uv<1" >/dev/null 2>&1; then
    install=(.venv/bin/uv pip install -q --python .venv/bin/python)
  fi
  # the versions the docs' datasets were made with, where pinned for this Python: the same
  # config and seed then give the docs' bytes (Parquet and PNG bytes follow library versions)
  if [ -f "$pins" ]; then
    "${install[@]}" -c "$pins" -e '.[dev]'
  else
    echo "setup: no pinned versions for Python $version ($pins): installing the newest allowed; datasets may differ in bytes from the docs' (docs/scale.md)"
    "${install[@]}" -e '.[dev]'
  fi
  # pyrender 0.1.45 pins PyOpenGL 3.1.0, whose ctypes array handlers break glGenTextures on
  # Python 3.12+ (textured rendering fails); 3.1.10 works on 3.11-3.13 and renders the same
  # bytes (checked with llvmpipe EGL). Installed over the pin on every Python, so all match
  # (`pip check` names the pin; --no-deps installs without complaint).
  .venv/bin/python -m pip install -q --no-deps 'PyOpenGL==3.1.10'
  echo "$want" > "$stamp"
fi
