"""Finding libgmpu: $GMPU_LIBRARY, then next to the installed package, then the build dir;
and `meson install` puts a package there that imports with no environment."""
import json
import os
import shutil
import subprocess

import gmpu
from gmpu import _library

from conftest import BINDINGS, PYTHON, REPO, run_python

BUILD_LIB = REPO / "build" / "lib" / "libgmpu.so.1"
PRINT_PATH = "import gmpu; print(gmpu.library_path)"


def test_find_library_order_in_a_checkout():
    cands, pinned = _library.find_library(environ={})
    assert not pinned
    names = [what for what, _ in cands]
    assert names[0] == "$GMPU_LIBRARY"
    assert names.index("inside the package directory") < names.index("meson build directory") \
        < names.index("system library search path") == len(names) - 1
    assert dict(cands)["meson build directory"] == str(BUILD_LIB)


def test_find_library_honours_the_environment_only(tmp_path):
    cands, pinned = _library.find_library(environ={"GMPU_LIBRARY": "/some/libgmpu.so.1"})
    assert pinned and cands == [("$GMPU_LIBRARY", "/some/libgmpu.so.1")]
    cands, _ = _library.find_library(environ={"GMPU_LIBRARY": str(tmp_path)})
    assert cands == [("$GMPU_LIBRARY", str(tmp_path / "libgmpu.so.1"))]


def test_checkout_uses_the_build_directory():
    assert gmpu.library_path == str(BUILD_LIB) or os.environ.get("GMPU_LIBRARY")
    r = run_python(PRINT_PATH, env_extra={"GMPU_LIBRARY": ""})
    assert r.returncode == 0 and r.stdout.strip() == str(BUILD_LIB), r.stderr


def test_gmpu_library_wins_over_the_build_directory(tmp_path):
    copy = tmp_path / "elsewhere" / "libgmpu.so.1"
    copy.parent.mkdir()
    shutil.copy(BUILD_LIB, copy)
    r = run_python(PRINT_PATH, env_extra={"GMPU_LIBRARY": str(copy)})
    assert r.returncode == 0 and r.stdout.strip() == str(copy), r.stderr
    r = run_python(PRINT_PATH, env_extra={"GMPU_LIBRARY": str(copy.parent)})  # a directory works too
    assert r.returncode == 0 and r.stdout.strip() == str(copy), r.stderr


def test_bad_gmpu_library_fails_loudly_without_falling_back(tmp_path):
    r = run_python("import gmpu", env_extra={"GMPU_LIBRARY": str(tmp_path / "nope.so")})
    assert r.returncode != 0
    assert "LibraryNotFoundError" in r.stderr and "cannot load libgmpu.so.1; looked in:" in r.stderr
    assert f"$GMPU_LIBRARY: {tmp_path / 'nope.so'}: no such file" in r.stderr
    assert "meson build directory" not in r.stderr  # no silent fallback to another copy
    (tmp_path / "junk.so").write_bytes(b"not a library")
    r = run_python("import gmpu", env_extra={"GMPU_LIBRARY": str(tmp_path / "junk.so")})
    assert r.returncode != 0 and "junk.so" in r.stderr


def test_error_lists_every_place_it_looked(tmp_path):
    # A copy of the package far from any build directory or installed library, laid out
    # like a checkout (bindings/python/gmpu) whose build directory is missing.
    root = tmp_path / "checkout"
    shutil.copytree(BINDINGS / "gmpu", root / "bindings" / "python" / "gmpu", ignore=shutil.ignore_patterns("__pycache__"))
    (root / "include" / "gmpu").mkdir(parents=True)
    (root / "include" / "gmpu" / "gmpu.h").touch()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "GMPU_LIBRARY")}
    env["PYTHONPATH"] = str(root / "bindings" / "python")
    r = subprocess.run([PYTHON, "-c", "import gmpu; print(gmpu.library_path)"], cwd=tmp_path, capture_output=True,
                       text=True, env=env)
    if r.returncode == 0:  # libgmpu is installed system-wide on this machine: the last resort found it
        assert r.stdout.strip() == "libgmpu.so.1"
        return
    err = r.stderr
    assert "$GMPU_LIBRARY: not set" in err
    pkg = root / "bindings" / "python" / "gmpu"
    assert f"inside the package directory: {pkg / 'libgmpu.so.1'}: no such file" in err
    assert f"meson build directory: {root / 'build' / 'lib' / 'libgmpu.so.1'}: no such file" in err
    assert "system library search path: libgmpu.so.1:" in err
    assert err.index("$GMPU_LIBRARY") < err.index("inside the package") < err.index("meson build") \
        < err.index("system library")
    assert "make build" in err
    # Outside a checkout, the build directory is not guessed at.
    shutil.rmtree(root / "include")
    r = subprocess.run([PYTHON, "-c", "import gmpu"], cwd=tmp_path, capture_output=True, text=True, env=env)
    assert r.returncode != 0 and "meson build directory: not in a source checkout" in r.stderr


def _build_options():
    with open(REPO / "build" / "meson-info" / "intro-buildoptions.json") as f:
        return {o["name"]: o["value"] for o in json.load(f)}


def test_meson_install_puts_an_importable_package_next_to_the_library(tmp_path):
    dest = tmp_path / "dest"
    r = subprocess.run(["meson", "install", "-C", str(REPO / "build"), "--no-rebuild", "--quiet", "--destdir",
                        str(dest)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    opts = _build_options()
    prefix, libdir = opts["prefix"], opts["libdir"]
    site = subprocess.run([PYTHON, str(BINDINGS / "tools" / "site_dir.py"), prefix], capture_output=True,
                          text=True, check=True).stdout.strip()
    if prefix == "/usr/local":  # Debian's /usr/bin/python3 reads this without any PYTHONPATH
        assert site in subprocess.run([PYTHON, "-c", "import sys; print(sys.path)"], capture_output=True,
                                      text=True, check=True).stdout
    staged_site = dest / site.lstrip("/")
    lib = dest / prefix.lstrip("/") / libdir / "libgmpu.so.1"
    assert (staged_site / "gmpu" / "__init__.py").is_file() and (staged_site / "gmpu" / "_install.py").is_file()
    assert lib.exists()
    # Imported from the staged site directory, from elsewhere, with no GMPU_LIBRARY: it finds
    # the staged library beside it (the recorded prefix-relative path), and works.
    code = ("import gmpu, numpy as np; m = gmpu.reconstruct(gmpu.read_points(%r), resolution=16); "
            "print(gmpu.__file__); print(gmpu.library_path); print(len(m.faces))" % str(REPO / "examples/data/bunny.ply"))
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "GMPU_LIBRARY")}
    env["PYTHONPATH"] = str(staged_site)
    r = subprocess.run([PYTHON, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    file_, path, faces = r.stdout.split()
    assert file_.startswith(str(staged_site)) and path == str(lib) and int(faces) > 0
