"""Python against the C CLI (build/examples/gmpu-reconstruct): same input and parameters give
the same files, byte for byte.

What Python costs against the CLI (issue 3: within 5 % for the same work) is a speed target,
so it is measured by the benchmark (tests/bench/binding_cost.py, in `make bench` and printed
by `make bench-quick`), not asserted here: a 5 % bound on a third of a second on a shared
2-core machine failed a CI run at random.
"""
import subprocess

import gmpu


def _run_cli(cli, args):
    p = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr


def test_python_mesh_is_byte_identical_to_the_cli_mesh(cli, clouds, tmp_path):
    src = clouds / "bunny_clean.ply"
    _run_cli(cli, [src, "-o", tmp_path / "cli.ply"])
    gmpu.reconstruct(gmpu.read_points(src)).write(tmp_path / "py.ply")
    ref = (tmp_path / "cli.ply").read_bytes()
    assert len(ref) > 100000
    assert (tmp_path / "py.ply").read_bytes() == ref
    # Same content through the arrays, too.
    mesh_pts = gmpu.read_points(tmp_path / "py.ply")
    assert mesh_pts.normals is not None and len(mesh_pts) > 10000


def test_same_parameters_same_files_as_the_cli(cli, clouds, tmp_path):
    # Non-default parameters and the oriented-points output, on a smaller cloud.
    src = clouds / "kitten_scan.ply"
    _run_cli(cli, [src, "-o", tmp_path / "cli.off", "--normals-out", tmp_path / "cli_points.ply", "--error", "0.004",
                   "--max-depth", "8", "--resolution", "40", "--level", "6", "--threads", "1"])
    cloud = gmpu.read_points(src)
    with gmpu.Surface(cloud, error=0.004, max_depth=8, resolution=40, level=6, threads=1) as s:
        s.fit().orient()
        s.polygonize().write(tmp_path / "py.off")
        gmpu.Points(cloud.positions, s.normals).write(tmp_path / "py_points.ply")
    assert (tmp_path / "py.off").read_bytes() == (tmp_path / "cli.off").read_bytes()
    assert (tmp_path / "py_points.ply").read_bytes() == (tmp_path / "cli_points.ply").read_bytes()
    # And with given normals (--use-normals).
    gt = clouds / "kitten_scan_gt.ply"
    _run_cli(cli, [gt, "-o", tmp_path / "cli_n.ply", "--use-normals", "--resolution", "32"])
    p = gmpu.read_points(gt)
    gmpu.reconstruct(p, normals=p.normals, resolution=32).write(tmp_path / "py_n.ply")
    assert (tmp_path / "py_n.ply").read_bytes() == (tmp_path / "cli_n.ply").read_bytes()
