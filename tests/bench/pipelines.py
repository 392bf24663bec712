"""The reconstruction pipelines the benchmark compares, each run as a child process so that
its wall time and peak memory are its own.

A pipeline turns an unoriented cloud into a mesh and per-point oriented normals (same
points, same order) and reports seconds per stage. `compute` is the sum of the stages
that do the work (normals, orientation, surface), without file I/O or start-up, and is
what the gmpu/peer ratios use; `wall` is the whole child process.

Run as a script, this file is the Open3D child:
    python3 pipelines.py open3d CLOUD.ply MESH.ply POINTS.ply DEPTH
    python3 pipelines.py open3d-oriented ORIENTED.ply MESH.ply POINTS.ply DEPTH TRIM
"""
import json
import os
import re
import resource
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

PYTHON = "/usr/bin/python3"  # Debian's, with numpy and open3d (the first on PATH may lack them)
TIME = "/usr/bin/time"       # GNU time (Debian's `time`), for each child's peak memory
HERE = Path(__file__).resolve().parent

# Open3D: neighbours for PCA normals and for the tangent-plane MST (its docs use 30 / k).
OPEN3D_KNN = 30
# Every run may use at most this much memory (RLIMIT_DATA: heap and anonymous mappings).
# CGAL's pipeline once grew past 17 GB on a 5k-point cloud (fandisk_sparse5k) and would
# have taken the 24 GB machine with it; capped, it fails like any other allocation failure.
MEMORY_CAP_GB = 12


@dataclass
class Run:
    """What one pipeline did on one cloud."""
    ok: bool
    mesh: Path
    points: Path
    wall: float = 0.0           # seconds, the child process from start to exit
    peak_rss_mb: float = 0.0    # the child's maximum resident set
    stages: dict = field(default_factory=dict)  # stage name -> seconds
    info: dict = field(default_factory=dict)    # what else the pipeline reported
    compute: float = 0.0        # sum of the work stages
    error: str = ""


def cap_memory():
    limit = MEMORY_CAP_GB << 30
    resource.setrlimit(resource.RLIMIT_DATA, (limit, limit))


def run_child(cmd, timeout, log_path):
    """Runs cmd; returns (exit code, negative for a signal, or None on timeout; wall seconds;
    peak RSS in MB; stdout). stderr goes to log_path.

    Peak RSS comes from GNU time wrapped around cmd, not from our own wait4: Linux keeps a
    process's peak across exec, so a child forked from this Python process would report at
    least this process's own size (~35 MB). time is small, so its child starts from ~1 MB."""
    out_path, rss_path = Path(f"{log_path}.out"), Path(f"{log_path}.rss")
    start = time.perf_counter()
    with open(out_path, "w") as out, open(log_path, "w") as log:
        proc = subprocess.Popen([TIME, "-f", "%M", "-o", str(rss_path), *cmd], stdout=out,
                                stderr=log, start_new_session=True, preexec_fn=cap_memory)
        try:
            proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)  # time and the pipeline under it
            proc.wait()
            return None, time.perf_counter() - start, 0.0, ""
    wall = time.perf_counter() - start
    report = rss_path.read_text().split() if rss_path.exists() else []
    peak_mb = int(report[-1]) / 1024 if report and report[-1].isdigit() else 0.0
    code = proc.returncode
    if "signal" in report:  # "Command terminated by signal 11"
        code = -int(report[report.index("signal") + 1])
    return code, wall, peak_mb, out_path.read_text(errors="replace")


class Pipeline:
    name = ""
    work_stages = ()  # stage names summed into `compute`

    def command(self, cloud, mesh, points):
        raise NotImplementedError

    def stages(self, stdout, log_text):
        """Seconds per stage (and an "info" dict) from the child's last line of JSON."""
        return json.loads(stdout.strip().splitlines()[-1])

    def available(self):
        """"" when it can run here, else why not."""
        return ""

    def run(self, cloud, workdir, timeout):
        workdir.mkdir(parents=True, exist_ok=True)
        mesh, points = workdir / f"{self.name}_mesh.ply", workdir / f"{self.name}_points.ply"
        log = workdir / f"{self.name}.log"
        for stale in (mesh, points):
            stale.unlink(missing_ok=True)
        code, wall, rss, stdout = run_child(self.command(cloud, mesh, points), timeout, log)
        run = Run(ok=False, mesh=mesh, points=points, wall=wall, peak_rss_mb=rss)
        log_text = log.read_text(errors="replace")
        if code is None:
            run.error = f"timed out after {timeout:.0f} s"
        elif code < 0:
            run.error = f"crashed ({signal.Signals(-code).name}; runs are capped at {MEMORY_CAP_GB} GB)"
        elif code != 0:
            run.error = (log_text.strip().splitlines() or [f"exit {code}"])[-1][:300]
        elif not mesh.exists() or not points.exists():
            run.error = "no output written"
        else:
            try:
                run.stages = self.stages(stdout, log_text)
                run.info = run.stages.pop("info", {})
            except (ValueError, IndexError, KeyError) as e:
                run.error = f"cannot read stage times: {e}"
                return run
            run.compute = sum(run.stages.get(s, 0.0) for s in self.work_stages)
            run.ok = True
        return run


class Gmpu(Pipeline):
    """build/examples/gmpu-reconstruct; stage times from its closing 'gmpu: time' line."""
    name = "gmpu"
    work_stages = ("fit", "orient", "polygonize")
    TIME_LINE = re.compile(r"gmpu: time (.*)")

    def __init__(self, build_dir, extra_args=()):
        self.exe = Path(build_dir) / "examples" / "gmpu-reconstruct"
        self.extra_args = list(extra_args)

    def available(self):
        return "" if self.exe.exists() else f"{self.exe} not built"

    def command(self, cloud, mesh, points):
        return [str(self.exe), str(cloud), "-o", str(mesh), "--normals-out", str(points),
                *self.extra_args]

    def stages(self, stdout, log_text):
        found = self.TIME_LINE.findall(log_text)
        if not found:
            return {}  # an older CLI without stage times: only wall time is known
        return {name: float(sec) for name, sec in re.findall(r"(\w+) ([\d.]+) s", found[-1])}

    # gmpu takes a fraction of a second on most clouds, where one run on a shared machine
    # varies by ±30 %: the median of REPEATS runs is reported (the peers take seconds and
    # run once; repeating them would double the benchmark's length).
    REPEATS = 3
    REPEAT_BELOW_SECONDS = 10.0

    def run(self, cloud, workdir, timeout):
        runs = [self.run_once(cloud, workdir, timeout)]
        while (len(runs) < self.REPEATS and runs[-1].ok and runs[-1].compute < self.REPEAT_BELOW_SECONDS):
            runs.append(self.run_once(cloud, workdir, timeout))
        if not all(r.ok for r in runs):
            return next(r for r in runs if not r.ok)
        median = sorted(runs, key=lambda r: r.compute)[len(runs) // 2]
        median.info["repeats"] = len(runs)  # every run wrote the same mesh: the last one is on disk
        return median

    def run_once(self, cloud, workdir, timeout):
        run = super().run(cloud, workdir, timeout)
        if run.ok and not run.stages:
            run.compute = run.wall
        return run


class Open3D(Pipeline):
    """Open3D: PCA normals, orient_normals_consistent_tangent_plane, screened Poisson."""
    work_stages = ("normals", "orient", "reconstruct")

    def __init__(self, depth):
        self.depth = depth
        self.name = f"open3d_d{depth}"

    def available(self):
        probe = subprocess.run([PYTHON, "-c", "import open3d"], capture_output=True)
        return "" if probe.returncode == 0 else "python3-open3d is not installed"

    def command(self, cloud, mesh, points):
        return [PYTHON, str(HERE / "pipelines.py"), "open3d", str(cloud), str(mesh), str(points),
                str(self.depth)]


class Cgal(Pipeline):
    """CGAL: jet normals, mst_orient_normals, Poisson (tests/bench/cgal_peer.cpp), compiled
    here with g++ on first use; never linked into gmpu."""
    name = "cgal"
    work_stages = ("normals", "orient", "reconstruct")
    SOURCE = HERE / "cgal_peer.cpp"
    FLAGS = ["-O2", "-DNDEBUG", "-std=c++17", "-DCGAL_EIGEN3_ENABLED", "-I/usr/include/eigen3"]

    def __init__(self, build_dir):
        self.exe = Path(build_dir) / "bench" / "cgal_peer"

    def available(self):
        if not Path("/usr/include/CGAL/poisson_surface_reconstruction.h").exists():
            return "libcgal-dev is not installed"
        if self.exe.exists() and self.exe.stat().st_mtime >= self.SOURCE.stat().st_mtime:
            return ""
        self.exe.parent.mkdir(parents=True, exist_ok=True)
        print(f"compiling {self.exe} (CGAL is header-only: about a minute)", flush=True)
        # g++'s temporary files go beside the output: a shared /tmp may be emptied meanwhile.
        built = subprocess.run(["g++", *self.FLAGS, str(self.SOURCE), "-o", str(self.exe),
                                "-lgmp", "-lmpfr"], capture_output=True, text=True,
                               env={**os.environ, "TMPDIR": str(self.exe.parent)})
        return "" if built.returncode == 0 else "cgal_peer does not compile:\n" + built.stderr[-2000:]

    def command(self, cloud, mesh, points):
        return [str(self.exe), str(cloud), str(mesh), str(points)]


class PoissonOnOrientedPoints(Pipeline):
    """Open3D's screened Poisson on points that already carry oriented normals (gmpu's own,
    from --normals-out): what a global smooth surface makes of gmpu's orientation, the
    reference its surface stage is measured against. Low-density vertices are trimmed the
    way the corpus's committed Open3D figures were made (tests/data/corpus/README.md)."""
    work_stages = ("reconstruct",)

    def __init__(self, depth=8, trim_quantile=0.01, name="poisson_gmpu"):
        self.depth, self.trim_quantile, self.name = depth, trim_quantile, name

    available = Open3D.available

    def command(self, oriented, mesh, points):
        return [PYTHON, str(HERE / "pipelines.py"), "open3d-oriented", str(oriented), str(mesh),
                str(points), str(self.depth), str(self.trim_quantile)]


def open3d_child(cloud, mesh_path, points_path, depth):
    """The Open3D pipeline itself (runs in the child). Prints seconds per stage as JSON."""
    import open3d as o3d

    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    t = {}
    start = time.perf_counter()
    pcd = o3d.io.read_point_cloud(str(cloud))
    if len(pcd.points) == 0:
        sys.exit(f"open3d: cannot read {cloud}")
    t["read"] = time.perf_counter() - start

    start = time.perf_counter()
    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(knn=OPEN3D_KNN))
    t["normals"] = time.perf_counter() - start

    start = time.perf_counter()
    pcd.orient_normals_consistent_tangent_plane(OPEN3D_KNN)
    t["orient"] = time.perf_counter() - start

    start = time.perf_counter()
    mesh, _densities = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=depth)
    t["reconstruct"] = time.perf_counter() - start

    start = time.perf_counter()
    # Density trimming is left out on purpose: it opens the surface, and a closed mesh is
    # what is compared.
    ok = o3d.io.write_triangle_mesh(str(mesh_path), mesh, write_vertex_normals=False,
                                    write_vertex_colors=False)
    ok = ok and o3d.io.write_point_cloud(str(points_path), pcd)
    t["write"] = time.perf_counter() - start
    if not ok:
        sys.exit("open3d: cannot write the outputs")
    print(json.dumps(t))


def open3d_oriented_child(oriented, mesh_path, points_path, depth, trim_quantile):
    """Poisson on given oriented normals (runs in the child). Prints seconds per stage."""
    import numpy as np
    import open3d as o3d

    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    t = {}
    start = time.perf_counter()
    pcd = o3d.io.read_point_cloud(str(oriented))
    if len(pcd.points) == 0 or not pcd.has_normals():
        sys.exit(f"open3d: {oriented} has no points with normals")
    t["read"] = time.perf_counter() - start

    start = time.perf_counter()
    mesh, densities = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=depth)
    if trim_quantile > 0:
        densities = np.asarray(densities)
        mesh.remove_vertices_by_mask(densities < np.quantile(densities, trim_quantile))
    t["reconstruct"] = time.perf_counter() - start

    start = time.perf_counter()
    ok = o3d.io.write_triangle_mesh(str(mesh_path), mesh, write_vertex_normals=False,
                                    write_vertex_colors=False)
    ok = ok and o3d.io.write_point_cloud(str(points_path), pcd)  # the normals it was given
    t["write"] = time.perf_counter() - start
    if not ok:
        sys.exit("open3d: cannot write the outputs")
    print(json.dumps(t))


if __name__ == "__main__":
    if len(sys.argv) == 6 and sys.argv[1] == "open3d":
        open3d_child(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]))
    elif len(sys.argv) == 7 and sys.argv[1] == "open3d-oriented":
        open3d_oriented_child(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]),
                              float(sys.argv[6]))
    else:
        sys.exit("usage: pipelines.py open3d CLOUD.ply MESH.ply POINTS.ply DEPTH\n"
                 "       pipelines.py open3d-oriented ORIENTED.ply MESH.ply POINTS.ply DEPTH TRIM")
