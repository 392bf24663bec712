"""What the Python binding costs (issue 3's target: `gmpu.reconstruct` on a 35k-point cloud
within 5 % of the C CLI's time for the same work).

The same work on both sides: read the cloud, reconstruct with default parameters, write a
binary PLY mesh. The CLI runs as a child process; Python runs in this process through the
cffi binding (the bench's own interpreter), so both sides are measured by the same script
in the same run. Runs are interleaved in pairs, alternating which side goes first, so that
a change of load on the shared machine hits both alike. The ratio reported is the median of
the pairs' own ratios (Python / CLI of the same pair), which a drift of the machine's speed
over the measurement does not move; the medians of each side are printed beside it.

Wall time decides the target. CPU time (user + system, all threads; the CLI's from
RUSAGE_CHILDREN minus what starting and exiting the CLI costs, Python's from RUSAGE_SELF) is
printed beside it: it moves with how the worker threads happen to wait, by a few percent
from run to run, in both directions. Why this lives here and not in `make test`: a unit test
asserting a 5 % bound on a third of a second failed a CI run at random (CPU ratio 1.085, wall
1.033), with no cost in the binding to find: 19 progress callbacks per reconstruction, the
input read into library memory and viewed (not copied) by numpy, the mesh arrays views of
the library's mesh, and the library's own stage timings the same on both sides within the
run-to-run spread.

Run alone: binding_cost.py [--build build] [--pairs 15] [CLOUD.ply]
"""
import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TARGET_RATIO = 1.05


def _cpu(usage):
    return usage.ru_utime + usage.ru_stime


def _import_gmpu(build):
    os.environ.setdefault("GMPU_LIBRARY", str(Path(build) / "lib" / "libgmpu.so.1"))
    sys.path.insert(0, str(ROOT / "bindings" / "python"))
    import gmpu
    return gmpu


def _run_cli(cli, args):
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True, timeout=600)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{cli} failed: {p.stderr.strip()[-300:]}")
    return wall, _cpu(resource.getrusage(resource.RUSAGE_CHILDREN)) - _cpu(r0), p.stderr


def _run_python(gmpu, src, dst):
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    gmpu.reconstruct(gmpu.read_points(src)).write(dst)
    wall = time.perf_counter() - t0
    return wall, _cpu(resource.getrusage(resource.RUSAGE_SELF)) - _cpu(r0)


def measure(build, cloud, pairs):
    """Medians over `pairs` interleaved CLI/Python runs; a dict the report and README use."""
    gmpu = _import_gmpu(build)
    cli = Path(build) / "examples" / "gmpu-reconstruct"
    rows = []
    with tempfile.TemporaryDirectory(dir=Path(build)) as tmp:
        out = Path(tmp)
        _run_python(gmpu, cloud, out / "warm.ply")  # first call: dlopen, cffi set-up
        for i in range(pairs):
            row = {}
            for side in (("cli", "py") if i % 2 == 0 else ("py", "cli")):
                if side == "cli":
                    wall, cpu, err = _run_cli(cli, [cloud, "-o", out / "cli.ply"])
                    total = re.search(r"gmpu: time .*total ([\d.]+) s", err)
                    row.update(cli_wall=wall, cli_cpu=cpu, cli_total=float(total.group(1)) if total else None)
                else:
                    row["py_wall"], row["py_cpu"] = _run_python(gmpu, cloud, out / "py.ply")
            row["startup_cpu"] = _run_cli(cli, ["--help"])[1]  # exec, dynamic loading, exit
            rows.append(row)
        identical = (out / "cli.ply").read_bytes() == (out / "py.ply").read_bytes()

    def median(key, minus=None):
        return statistics.median(r[key] - (r[minus] if minus else 0) for r in rows)

    result = {"cloud": Path(cloud).name, "points": len(gmpu.read_points(cloud)), "pairs": pairs,
              "cli_wall": median("cli_wall"), "py_wall": median("py_wall"),
              "cli_cpu": median("cli_cpu", "startup_cpu"), "py_cpu": median("py_cpu"),
              "startup_cpu": median("startup_cpu"), "same_mesh_bytes": identical,
              "load": os.getloadavg()[0]}
    totals = [r["cli_total"] for r in rows if r["cli_total"] is not None]
    result["cli_total"] = statistics.median(totals) if totals else None
    result["wall_ratio"] = statistics.median(r["py_wall"] / r["cli_wall"] for r in rows)
    result["cpu_ratio"] = statistics.median(r["py_cpu"] / (r["cli_cpu"] - r["startup_cpu"]) for r in rows)
    return result


def summary(r):
    """One line for the bench output and the README's targets."""
    verdict = "met" if r["wall_ratio"] <= TARGET_RATIO else "missed"
    return (f"Python `gmpu.reconstruct` (read → reconstruct → write) on {r['cloud']} ({r['points'] // 1000}k "
            f"points) within {TARGET_RATIO - 1:.0%} of the CLI: {verdict} (median wall {r['py_wall']:.3f} s vs "
            f"{r['cli_wall']:.3f} s, median ratio of pairs {r['wall_ratio']:.3f}; CPU {r['py_cpu']:.3f} s vs {r['cli_cpu']:.3f} s, "
            f"ratio {r['cpu_ratio']:.3f}; {r['pairs']} interleaved pairs; same mesh bytes: "
            f"{'yes' if r['same_mesh_bytes'] else 'NO'}).")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cloud", nargs="?", type=Path,
                    default=ROOT / "tests" / "data" / "clouds" / "bunny_clean.ply")
    ap.add_argument("--build", type=Path, default=ROOT / "build")
    ap.add_argument("--pairs", type=int, default=21)
    args = ap.parse_args()
    print(summary(measure(args.build, args.cloud, args.pairs)))


if __name__ == "__main__":
    main()
