"""Python against the C CLI (build/examples/gmpu-reconstruct): same input and parameters give
the same files, and gmpu.reconstruct costs no more than the CLI for the same work.

How the cost is compared (the one timing assertion of the suite): the machine has 2 cores
shared with other engineers' benchmarks, and under that load the wall time of one 35k-point
reconstruction swings by ±30 % from one run to the next, for the CLI and Python alike, so a
5 % bound on wall time would fail at random. CPU time (user + system, all threads) of the same
work barely moves with load (±3 %), and it is what the binding could add: conversions,
copies, callbacks into Python. So the test runs PAIRS CLI/Python pairs interleaved in this
process (alternating which goes first), takes the CPU time of each (the CLI child's from
RUSAGE_CHILDREN, minus the median CPU of starting the CLI and exiting, so that both sides
measure read → reconstruct → write only; Python's from RUSAGE_SELF, which includes the
library's worker threads) and asserts median(Python) ≤ 1.05 × median(CLI). The wall-time
medians and the library's own stage timings are printed for the record, not asserted.
"""
import re
import resource
import statistics
import subprocess
import time

import pytest

import gmpu

PAIRS = 7
TIME_LINE = re.compile(r"gmpu: time (.*)")


def _cpu(usage):
    return usage.ru_utime + usage.ru_stime


def _run_cli(cli, args):
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=300)
    wall = time.perf_counter() - t0
    cpu = _cpu(resource.getrusage(resource.RUSAGE_CHILDREN)) - _cpu(r0)
    assert p.returncode == 0, p.stderr
    return wall, cpu, p.stderr


def _run_python(src, dst):
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    mesh = gmpu.reconstruct(gmpu.read_points(src))
    mesh.write(dst)
    wall = time.perf_counter() - t0
    cpu = _cpu(resource.getrusage(resource.RUSAGE_SELF)) - _cpu(r0)
    return wall, cpu


@pytest.fixture(scope="module")
def paired_runs(cli, clouds, tmp_path_factory):
    """PAIRS interleaved runs of the CLI and of Python on the 35k-point bunny, defaults."""
    src = clouds / "bunny_clean.ply"
    out = tmp_path_factory.mktemp("paired")
    rows = []
    for i in range(PAIRS):
        row = {}
        for who in (("cli", "py") if i % 2 == 0 else ("py", "cli")):
            if who == "cli":
                wall, cpu, err = _run_cli(cli, [src, "-o", out / f"cli{i}.ply"])
                stages = dict((k, float(v)) for k, v in re.findall(r"(\w+) ([\d.]+) s", TIME_LINE.search(err).group(1)))
                row["cli"] = {"wall": wall, "cpu": cpu, "stages": stages, "file": out / f"cli{i}.ply"}
            else:
                wall, cpu = _run_python(src, out / f"py{i}.ply")
                row["py"] = {"wall": wall, "cpu": cpu, "file": out / f"py{i}.ply"}
        _, startup_cpu, _ = _run_cli(cli, ["--help"])  # exec, dynamic loading, exit
        row["startup_cpu"] = startup_cpu
        rows.append(row)
    return rows


def test_python_mesh_is_byte_identical_to_the_cli_mesh(paired_runs):
    ref = paired_runs[0]["cli"]["file"].read_bytes()
    assert len(ref) > 100000
    for row in paired_runs:
        assert row["py"]["file"].read_bytes() == ref
        assert row["cli"]["file"].read_bytes() == ref
    # Same content through the arrays, too.
    mesh_pts = gmpu.read_points(paired_runs[0]["py"]["file"])
    assert mesh_pts.normals is not None and len(mesh_pts) > 10000


def test_reconstruct_costs_within_5_percent_of_the_cli(paired_runs):
    startup = statistics.median(r["startup_cpu"] for r in paired_runs)
    cli_cpu = statistics.median(r["cli"]["cpu"] - startup for r in paired_runs)
    py_cpu = statistics.median(r["py"]["cpu"] for r in paired_runs)
    cli_wall = statistics.median(r["cli"]["wall"] for r in paired_runs)
    py_wall = statistics.median(r["py"]["wall"] for r in paired_runs)
    cli_total = statistics.median(r["cli"]["stages"]["total"] for r in paired_runs)
    report = (f"35k points, {PAIRS} interleaved pairs, medians: CPU python {py_cpu:.3f} s vs CLI {cli_cpu:.3f} s "
              f"(CLI startup {startup:.3f} s removed), ratio {py_cpu / cli_cpu:.3f}; wall python {py_wall:.3f} s vs "
              f"CLI {cli_wall:.3f} s (CLI's own total {cli_total:.3f} s), ratio {py_wall / cli_wall:.3f}")
    print("\n" + report)
    assert py_cpu <= 1.05 * cli_cpu, report


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
