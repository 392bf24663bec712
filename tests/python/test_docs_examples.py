"""The README's Python section and the examples in examples/python actually run."""
import os
import re
import struct
import subprocess

import gmpu

from conftest import REPO, SAMPLE, run_python


def readme_python_code() -> str:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    m = re.search(r"<!-- python:begin -->(.*?)<!-- python:end -->", text, re.S)
    assert m, "README.md has no <!-- python:begin --> ... <!-- python:end --> section"
    blocks = re.findall(r"```python\n(.*?)```", m.group(1), re.S)
    assert len(blocks) == 1, "the README's Python section should hold one ```python block"
    return blocks[0]


def _like_repo_root(tmp_path):
    # The README code reads examples/data/bunny.ply relative to the repository root, as a
    # reader would run it; it runs in a scratch directory laid out the same way.
    (tmp_path / "examples" / "data").mkdir(parents=True)
    (tmp_path / "examples" / "data" / "bunny.ply").symlink_to(SAMPLE)
    return tmp_path


def test_readme_python_section_runs(tmp_path):
    code = readme_python_code()
    assert "gmpu.reconstruct" in code and "gmpu.Surface" in code
    r = run_python(code, cwd=_like_repo_root(tmp_path), timeout=300)
    assert r.returncode == 0, f"README Python code failed:\n{r.stderr}"
    assert "<gmpu.Mesh" in r.stdout and "GMPU_ERROR_DEGENERATE_INPUT" in r.stdout and "fit 100%" in r.stdout
    mesh = gmpu.read_points(tmp_path / "bunny_mesh.ply")
    assert len(mesh) > 1000 and mesh.normals is not None


def test_readme_check_would_catch_a_broken_example(tmp_path):
    # The runner above reports failures: a deliberately broken variant fails.
    broken = readme_python_code().replace("assert f[0] > 0 > f[1]", "assert f[0] < 0 < f[1]")
    r = run_python(broken, cwd=_like_repo_root(tmp_path), timeout=300)
    assert r.returncode != 0 and "AssertionError" in r.stderr


def test_reconstruct_example_matches_the_cli(cli, tmp_path, clouds):
    src = clouds / "kitten_scan.ply"
    script = REPO / "examples" / "python" / "reconstruct.py"
    code = "import runpy, sys; sys.argv = sys.argv[1:]; runpy.run_path(sys.argv[0], run_name='__main__')"
    r = run_python(code, args=[script, src, tmp_path / "py.ply", "--resolution", "40", "--normals-out",
                               tmp_path / "py_pts.ply"])
    assert r.returncode == 0, r.stderr
    assert "gmpu: mesh" in r.stderr and "fit..." in r.stderr
    subprocess.run([str(cli), str(src), "-o", str(tmp_path / "cli.ply"), "--resolution", "40", "--normals-out",
                    str(tmp_path / "cli_pts.ply"), "--quiet"], check=True)
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()
    assert (tmp_path / "py_pts.ply").read_bytes() == (tmp_path / "cli_pts.ply").read_bytes()
    # Errors: a gmpu failure is one line and exit status 1; bad usage is status 2.
    r = run_python(code, args=[script, tmp_path / "missing.ply", tmp_path / "out.ply"])
    assert r.returncode == 1 and "GMPU_ERROR_IO" in r.stderr and "Traceback" not in r.stderr
    r = run_python(code, args=[script, src])
    assert r.returncode == 2


def test_reconstruct_example_runs_as_documented_without_pythonpath(tmp_path, clouds):
    # `/usr/bin/python3 examples/python/reconstruct.py IN OUT` from a checkout works too.
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    r = subprocess.run(["/usr/bin/python3", str(REPO / "examples" / "python" / "reconstruct.py"),
                        str(clouds / "elephant_sparse5k.ply"), str(tmp_path / "e.obj"), "--resolution", "24", "-q"],
                       env=env, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stderr == "" and (tmp_path / "e.obj").read_text().startswith(("#", "v "))


def _png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    return struct.unpack(">II", data[16:24])


def test_slice_field_example_writes_a_png(tmp_path):
    script = REPO / "examples" / "python" / "slice_field.py"
    out = tmp_path / "slice.png"
    code = "import runpy, sys; sys.argv = sys.argv[1:]; runpy.run_path(sys.argv[0], run_name='__main__')"
    r = run_python(code, args=[script, SAMPLE, out, "--size", "120"], env_extra={"MPLBACKEND": "Agg"}, timeout=300)
    assert r.returncode == 0, r.stderr
    w, h = _png_size(out)
    assert w > 300 and h > 300
    m = re.search(r"\((\d+)% of the slice inside\)", r.stdout)
    assert m and 5 < int(m.group(1)) < 80, r.stdout  # the slice cuts through the solid
