#!/bin/bash
# The Python package installed the way the README says, from a clone of this repository
# (its committed files), with no network:
#   1. pip install --no-build-isolation .   in a venv made with --system-site-packages
#      (Debian's pip refuses the system interpreter; cffi, numpy and meson-python come
#      from the system);
#   2. python3 -m build --no-isolation      an sdist and a wheel built from it, the wheel
#      then installed with pip into a second venv.
# Each venv then imports gmpu from a directory outside the clone, with no GMPU_LIBRARY,
# PYTHONPATH or LD_LIBRARY_PATH, reconstructs a sphere, and checks that the library it
# loaded is the one inside the installed package.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
source_root=$(cd "$here/../.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/gmpu-wheel.XXXXXX")
trap 'rm -rf "$work"' EXIT
clean_env=(env -u GMPU_LIBRARY -u PYTHONPATH -u LD_LIBRARY_PATH -u PIP_INDEX_URL PIP_NO_INDEX=1
           PIP_DISABLE_PIP_VERSION_CHECK=1)

git clone --quiet "$source_root" "$work/gmpu"

check_venv() {  # VENV: gmpu imports, works, and loads its own copy of libgmpu
    (cd "$work" && "${clean_env[@]}" "$1/bin/python" - "$1" <<'PY'
import os, sys
import numpy as np
import gmpu
venv = os.path.realpath(sys.argv[1])
assert os.path.realpath(gmpu.__file__).startswith(venv + os.sep), gmpu.__file__
assert os.path.realpath(gmpu.library_path).startswith(venv + os.sep), gmpu.library_path
i = np.arange(800)
z = 1 - (2 * i + 1) / 800
r = np.sqrt(1 - z * z)
sphere = np.stack([r * np.cos(2.399963229728653 * i), r * np.sin(2.399963229728653 * i), z], -1)
mesh = gmpu.reconstruct(sphere, resolution=24)
assert mesh.is_watertight and len(mesh.faces) > 0
print(f"{gmpu.__version__} {len(mesh.faces)} triangles, library {os.path.relpath(gmpu.library_path, venv)}")
PY
    )
}

# 1. pip install from the clone.
/usr/bin/python3 -m venv --system-site-packages "$work/venv"
(cd "$work/gmpu" && "${clean_env[@]}" "$work/venv/bin/pip" install --quiet --no-build-isolation .)
out=$(check_venv "$work/venv")
echo "python_wheel: pip install: $out"

# 2. sdist and wheel; the wheel into a fresh venv.
(cd "$work/gmpu" && "${clean_env[@]}" /usr/bin/python3 -m build --no-isolation --outdir "$work/dist" . \
    >"$work/build.log" 2>&1) || { cat "$work/build.log" >&2; exit 1; }
ls "$work"/dist/gmpu-*.tar.gz >/dev/null
wheel=$(ls "$work"/dist/gmpu-*.whl)
/usr/bin/python3 - "$wheel" <<'PY'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
assert "gmpu/libgmpu.so.1" in names, f"{sys.argv[1]} holds no gmpu/libgmpu.so.1: {names}"
PY
/usr/bin/python3 -m venv --system-site-packages "$work/venv2"
"${clean_env[@]}" "$work/venv2/bin/pip" install --quiet "$wheel"
out=$(check_venv "$work/venv2")
echo "python_wheel: python3 -m build: $(basename "$wheel"): $out"
