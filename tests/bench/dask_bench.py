#!/usr/bin/env python3
"""Tiled reconstruction on Dask against the one-process C path (issue 17), on a bunny cloud
of --points points sampled by this script (area-uniform on tests/data/meshes/bunny00.off,
seed 17, float32 binary PLY so that the tiles memory-map it):

- untiled: the CLI (build/examples/gmpu-reconstruct) under /usr/bin/time: wall, peak RSS;
- tiled: gmpu.dask.reconstruct on a LocalCluster of 2 worker processes (1 thread each) at
  the untiled run's grid resolution: wall, peak RSS of each worker and of the driver;
- seams: boundary and non-manifold edges of the tiled mesh; Chamfer (mean nearest-vertex
  distance, both ways) to the untiled mesh as a share of the diagonal; orientation: the
  share of tiled vertices whose normal agrees with the nearest untiled vertex's;
- with --kill-check, the tiled run again with one worker killed part way: the mesh must be
  identical.

    /usr/bin/python3 tests/bench/dask_bench.py --build build --out bench-results/dask [--points 10000000]

Prints one table row per run and writes OUT/dask.json.
"""
import argparse
import contextlib
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "bindings" / "python"))


def read_off(path):
    words = Path(path).read_text().split()
    nv, nf = int(words[1]), int(words[2])
    v = np.array(words[4:4 + 3 * nv], float).reshape(nv, 3)
    f = np.array(words[4 + 3 * nv:4 + 3 * nv + 4 * nf], np.int64).reshape(nf, 4)[:, 1:]
    return v, f


def write_surface_samples(out, rng, vertices, faces, n):
    """n points area-uniform on a triangle mesh, appended to `out` as float32 xyz in chunks
    (a 100M-point cloud never sits in memory whole)."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    for start in range(0, n, 1 << 21):
        m = min(1 << 21, n - start)
        tri = rng.choice(len(faces), m, p=area / area.sum())
        s, t = rng.random(m), rng.random(m)
        flip = s + t > 1
        s[flip], t[flip] = 1 - s[flip], 1 - t[flip]
        p = a[tri] + s[:, None] * (b[tri] - a[tri]) + t[:, None] * (c[tri] - a[tri])
        out.write(p.astype("<f4").tobytes())


def write_ply_header(out, n):
    out.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\nproperty float x\n"
              f"property float y\nproperty float z\nend_header\n".encode())


def write_cloud(path, n, seed=17):
    v, f = read_off(REPO / "tests" / "data" / "meshes" / "bunny00.off")
    rng = np.random.default_rng(seed)
    with open(path, "wb") as out:
        write_ply_header(out, n)
        write_surface_samples(out, rng, v, f, n)


def write_mosaic(path, n, side, seed=17):
    """A scale cloud: `side`×`side` bunnies on a ground grid (each turned about the vertical
    and scaled at random, a bunny's width apart), n points in all, area-uniform on each,
    written in chunks to a float32 binary PLY (the tiles memory-map it). One closed piece
    per bunny."""
    v, f = read_off(REPO / "tests" / "data" / "meshes" / "bunny00.off")
    v = v - v.mean(0)
    width = float(np.ptp(v, axis=0).max())
    rng = np.random.default_rng(seed)
    copies = side * side
    per = np.full(copies, n // copies)
    per[: n - per.sum()] += 1
    with open(path, "wb") as out:
        write_ply_header(out, n)
        for c in range(copies):
            angle, scale = rng.uniform(0, 2 * np.pi), rng.uniform(0.8, 1.0)
            rot = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
            # bunny00's up axis is y: the turn is about y
            rot = rot[[0, 2, 1]][:, [0, 2, 1]]
            place = np.array([c % side, 0.0, c // side]) * 2 * width
            write_surface_samples(out, rng, v @ rot.T * scale + place, f, int(per[c]))


def read_mesh_ply(path):
    """Vertices and triangles of a binary little-endian PLY the CLI wrote."""
    with open(path, "rb") as f:
        props, nv, nf, element = [], 0, 0, None
        while True:
            words = f.readline().decode().split()
            if words[0] == "element":
                element = words[1]
                if element == "vertex":
                    nv = int(words[2])
                else:
                    nf = int(words[2])
            elif words[0] == "property" and element == "vertex":
                props.append((words[2], {"float": "<f4", "double": "<f8"}[words[1]]))
            elif words[0] == "end_header":
                break
        vert = np.frombuffer(f.read(nv * np.dtype(props).itemsize), np.dtype(props), nv)
        faces = np.frombuffer(f.read(nf * 13), np.dtype([("n", "u1"), ("i", "<i4", 3)]), nf)
    xyz = np.stack([vert["x"], vert["y"], vert["z"]], axis=1).astype(np.float64)
    normals = np.stack([vert["nx"], vert["ny"], vert["nz"]], axis=1) if "nx" in vert.dtype.names else None
    return xyz, faces["i"].astype(np.int64), normals


def edge_problems(faces):
    f = faces.astype(np.int64)
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    key = e[:, 0] * (int(f.max()) + 1) + e[:, 1]
    _, counts = np.unique(key, return_counts=True)
    return int((counts == 1).sum()), int((counts > 2).sum())


def compare(tiled_v, tiled_n, untiled_v, untiled_n, samples=300_000, seed=1):
    from scipy.spatial import cKDTree
    rng = np.random.default_rng(seed)
    a = rng.choice(len(tiled_v), min(samples, len(tiled_v)), replace=False)
    b = rng.choice(len(untiled_v), min(samples, len(untiled_v)), replace=False)
    da, ia = cKDTree(untiled_v).query(tiled_v[a])
    db, _ = cKDTree(tiled_v).query(untiled_v[b])
    agree = np.einsum("ij,ij->i", tiled_n[a], untiled_n[ia]) > 0
    return 0.5 * (da.mean() + db.mean()), float(agree.mean())


def untiled_run(build, cloud, out):
    cli = Path(build) / "examples" / "gmpu-reconstruct"
    t = time.perf_counter()
    r = subprocess.run(["/usr/bin/time", "-f", "PEAK_KB %M", str(cli), str(cloud), "-o", str(out)],
                       capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t
    peak = int(next(line.split()[1] for line in r.stderr.splitlines() if line.startswith("PEAK_KB")))
    resolution = int(r.stderr.split("at resolution ")[1].split()[0])
    return wall, peak * 1024, resolution


@contextlib.contextmanager
def local_client(workers):
    """A client of a LocalCluster of `workers` single-threaded worker processes, closed after."""
    from distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                           memory_limit=0)
    client = Client(cluster)
    try:
        yield client
    finally:
        client.close()
        cluster.close()


def tiled_run(cloud, resolution, tile_points, workers, kill=False):
    """The tiled run on a fresh LocalCluster: wall, peak RSS per worker and of the driver.
    With `kill`, the fault-tolerance check on the same cloud: the run again with one worker
    process killed (SIGKILL) half-way through the first run's first phase; the nanny restarts
    it, Dask recomputes what it held, and the mesh must be identical to the first run's."""
    import signal
    import threading
    import gmpu.dask as gd
    killed = None
    with local_client(workers) as client:
        stats = {}
        t = time.perf_counter()
        mesh = gd.reconstruct(str(cloud), client, tile_points=tile_points, resolution=resolution, stats=stats,
                              threads=1)
        wall = time.perf_counter() - t
        peaks = client.run(lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
        if kill:
            pid = sorted(client.run(os.getpid).values())[0]
            killer = threading.Timer(0.5 * stats["phase1_seconds"], lambda: os.kill(pid, signal.SIGKILL))
            killer.start()
            disturbed = gd.reconstruct(str(cloud), client, tile_points=tile_points, resolution=resolution,
                                       threads=1)
            killer.join()
            restarted = pid not in client.run(os.getpid).values()
            same = (np.array_equal(np.asarray(mesh.vertices), np.asarray(disturbed.vertices)) and
                    np.array_equal(np.asarray(mesh.faces), np.asarray(disturbed.faces)))
            killed = (same, restarted)
            del disturbed
    driver = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    return mesh, wall, sorted(peaks.values()), driver, stats, killed


def mesh_topology(faces, vertex_count):
    """(components, genus of a closed mesh) by Euler's formula per the whole."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    f = faces.astype(np.int64)
    graph = coo_matrix((np.ones(2 * len(f)), (np.concatenate([f[:, 0], f[:, 1]]), np.concatenate([f[:, 1], f[:, 2]]))),
                       shape=(vertex_count, vertex_count))
    _, label = connected_components(graph, directed=False)
    pieces = len(np.unique(label[np.unique(f)]))
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    edges = len(np.unique(e[:, 0] * vertex_count + e[:, 1]))
    chi = vertex_count - edges + len(f)
    return pieces, (2 * pieces - chi) // 2


def scale_run(out, points, side, resolution, tile_points, workers):
    """The scale point: a mosaic of side² bunnies, tiled only (one process could not hold
    it), the mesh streamed to a PLY by the driver; then the seams and topology of that file."""
    import gmpu.dask as gd
    cloud = out / f"mosaic_{points}.ply"
    if not cloud.exists():
        subprocess.run([sys.executable, "-c", f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); "
                        f"import dask_bench; dask_bench.write_mosaic({str(cloud)!r}, {points}, {side})"], check=True)
    mesh_path = out / f"mosaic_{points}_mesh.ply"
    with local_client(workers) as client:
        stats = {}
        t = time.perf_counter()
        counts = gd.reconstruct(str(cloud), client, tile_points=tile_points, resolution=resolution, stats=stats,
                                threads=1, output=str(mesh_path))
        wall = time.perf_counter() - t
        peaks = sorted(client.run(lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024).values())
    driver = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    v, f, _ = read_mesh_ply(mesh_path)
    boundary, nonmanifold = edge_problems(f)
    pieces, genus = mesh_topology(f, len(v))
    row = {"scale_points": points, "scale_bunnies": side * side, "scale_tiles": stats["tiles"],
           "scale_seconds": round(wall, 2), "scale_worker_peak_bytes": peaks, "scale_driver_peak_bytes": driver,
           "scale_triangles": counts["faces"], "scale_boundary_edges": boundary, "scale_nonmanifold_edges": nonmanifold,
           "scale_components": pieces, "scale_genus_total": genus, "scale_tile_seconds": stats["tile_seconds"]}
    print(f"scale:   {points} points ({side * side} bunnies), {stats['tiles']} tiles: {wall:.1f} s wall, workers "
          f"{[round(p / 1e9, 2) for p in peaks]} GB peak, driver {driver / 1e9:.2f} GB (streamed); "
          f"{counts['faces']} triangles; boundary {boundary}, non-manifold {nonmanifold}, components {pieces} "
          f"(bunnies {side * side}), genus sum {genus}", flush=True)
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default="bench-results/dask")
    ap.add_argument("--points", type=int, default=10_000_000)
    ap.add_argument("--tile-points", type=int, default=1_000_000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--kill-check", action="store_true",
                    help="run the tiled point twice, killing a worker in the second run: the meshes must be identical")
    ap.add_argument("--scale-points", type=int, default=0,
                    help="points of the scale point (a mosaic of bunnies, tiled only; 0: none)")
    ap.add_argument("--scale-side", type=int, default=10, help="the mosaic is side × side bunnies")
    ap.add_argument("--scale-resolution", type=int, default=0,
                    help="grid cubes along the mosaic's longest side (0: 107 per bunny, the untiled default)")
    ap.add_argument("--scale-only", action="store_true", help="run the scale point alone")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.scale_only:
        row = scale_run(out, args.scale_points, args.scale_side, args.scale_resolution or 107 * 2 * args.scale_side,
                        args.tile_points, args.workers)
        (out / "dask_scale.json").write_text(json.dumps(row, indent=1))
        return 0
    cloud = out / f"bunny_{args.points}.ply"
    if not cloud.exists():
        # In a child process, so that this one's peak memory is the driver's alone.
        subprocess.run([sys.executable, "-c", f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); "
                        f"import dask_bench; dask_bench.write_cloud({str(cloud)!r}, {args.points})"], check=True)
    untiled_mesh = out / "untiled.ply"
    u_wall, u_peak, resolution = untiled_run(args.build, cloud, untiled_mesh)
    print(f"untiled: {u_wall:.1f} s wall, {u_peak / 1e9:.2f} GB peak, resolution {resolution}", flush=True)
    load = os.getloadavg()
    mesh, t_wall, peaks, driver, stats, killed = tiled_run(cloud, resolution, args.tile_points, args.workers,
                                                           args.kill_check)
    boundary, nonmanifold = edge_problems(np.asarray(mesh.faces))
    components, genus = mesh_topology(np.asarray(mesh.faces), len(mesh.vertices))
    uv, uf, un = read_mesh_ply(untiled_mesh)
    diagonal = float(np.linalg.norm(uv.max(0) - uv.min(0)))
    cham, agree = compare(np.asarray(mesh.vertices), np.asarray(mesh.normals), uv, un)
    row = {
        "points": args.points, "tiles": stats["tiles"], "tile_points": args.tile_points, "workers": args.workers,
        "untiled_seconds": round(u_wall, 2), "untiled_peak_bytes": u_peak,
        "tiled_seconds": round(t_wall, 2), "worker_peak_bytes": peaks, "driver_peak_bytes": driver,
        "boundary_edges": boundary, "nonmanifold_edges": nonmanifold, "components": components,
        "genus": genus, "chamfer_share_of_diagonal": cham / diagonal, "orientation_agreement": agree,
        "tiled_volume_positive": bool(mesh.volume > 0), "resolution": resolution,
        "phase1_seconds": round(stats["phase1_seconds"], 2), "tile_seconds": stats["tile_seconds"],
        "tile_points_with_margin": stats["tile_points"], "tile_resident_bytes": stats["tile_resident_bytes"],
        "load_average": [round(x, 1) for x in load],
    }
    print(f"tiled:   {t_wall:.1f} s wall, workers {[round(p / 1e9, 2) for p in peaks]} GB peak, driver "
          f"{driver / 1e9:.2f} GB; {stats['tiles']} tiles; boundary {boundary}, non-manifold {nonmanifold}, "
          f"components {components}, genus {genus}; Chamfer {100 * cham / diagonal:.4f} % of the diagonal; "
          f"orientation agreement {100 * agree:.3f} %; load average {load[0]:.1f}", flush=True)
    print(f"tiles:   points with margin {min(stats['tile_points'])}..{max(stats['tile_points'])}; resident MB after "
          + ", ".join(f"{k} {v / 1e6:.0f}" for k, v in stats["tile_resident_bytes"].items()), flush=True)
    if killed is not None:
        row.update(kill_check_identical=killed[0], kill_check_worker_restarted=killed[1])
        print(f"killed a worker mid-run on {args.points} points: worker restarted {killed[1]}, mesh identical "
              f"{killed[0]}", flush=True)
    if args.scale_points:
        row.update(scale_run(out, args.scale_points, args.scale_side,
                             args.scale_resolution or 107 * 2 * args.scale_side, args.tile_points, args.workers))
    (out / "dask.json").write_text(json.dumps(row, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
