#!/usr/bin/env python3
"""Unoriented point cloud in, watertight outward-facing mesh out: gmpu-reconstruct in Python.

    PYTHONPATH=bindings/python /usr/bin/python3 examples/python/reconstruct.py IN.ply OUT.ply \
        [--normals-out POINTS.ply] [--error E] [--max-depth D] [--resolution R] [--level L] \
        [--threads T] [--use-normals] [--sharp | --no-sharp] [--quiet]

IN: .ply .xyz .txt .off .obj point cloud (its normals are ignored unless --use-normals).
OUT: .ply .obj .off mesh. Exit status 0 on success, 1 on a gmpu failure, 2 on bad usage.
Ctrl-C stops the reconstruction cleanly (exit status 130).
"""
import argparse
import sys
import time
from pathlib import Path

try:
    import gmpu
except ModuleNotFoundError:  # running from a source checkout without PYTHONPATH
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bindings" / "python"))
    import gmpu


def progress_printer(stream=sys.stderr):
    """A progress callable: a bar on a terminal, one line per stage otherwise."""
    tty = stream.isatty()
    state = {"stage": None, "percent": -1}

    def report(stage: gmpu.Stage, fraction: float) -> None:
        percent = int(fraction * 100 + 0.5)
        if stage != state["stage"]:
            state["stage"], state["percent"] = stage, -1
            if not tty:
                print(f"gmpu: {stage}...", file=stream)
        if tty and percent != state["percent"]:
            filled = percent * 30 // 100
            stream.write(f"\r{str(stage):<11s} [{'#' * filled}{' ' * (30 - filled)}] {percent:3d}%")
            if percent >= 100:
                stream.write("\n")
            stream.flush()
        state["percent"] = percent

    return report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Reconstruct a closed, outward-facing mesh from an unoriented point cloud.")
    ap.add_argument("input", help="point cloud (.ply .xyz .txt .off .obj)")
    ap.add_argument("output", help="mesh to write (.ply .obj .off)")
    ap.add_argument("--normals-out", metavar="POINTS", help="also write the points with their oriented normals")
    ap.add_argument("--error", type=float, help="fit tolerance, fraction of the bounding-box diagonal (0.002)")
    ap.add_argument("--max-depth", type=int, help="deepest octree level (10)")
    ap.add_argument("--resolution", type=int, help="polygonization grid along the longest side (automatic)")
    ap.add_argument("--level", type=int, help="level-of-detail cap (0: all levels)")
    ap.add_argument("--threads", type=int, help="worker threads (0: every core)")
    ap.add_argument("--use-normals", action="store_true", help="orient by the input file's normals")
    sharp = ap.add_mutually_exclusive_group()
    sharp.add_argument("--sharp", dest="sharp", action="store_const", const=True,
                       help="fit piecewise quadrics at sharp edges and corners")
    sharp.add_argument("--no-sharp", dest="sharp", action="store_const", const=False,
                       help="smooth models only (the library's default decides when neither is given)")
    ap.add_argument("-q", "--quiet", action="store_true", help="no progress or summary")
    args = ap.parse_args(argv)

    t0 = time.perf_counter()
    try:
        cloud = gmpu.read_points(args.input)
        if args.use_normals and cloud.normals is None:
            print(f"reconstruct.py: --use-normals given but {args.input} has no normals", file=sys.stderr)
            return 1
        params = dict(error=args.error, max_depth=args.max_depth, resolution=args.resolution, level=args.level,
                      threads=args.threads, sharp_features=args.sharp)
        with gmpu.Surface(cloud, normals=cloud.normals if args.use_normals else None,
                          progress=None if args.quiet else progress_printer(), **params) as surface:
            surface.fit()
            surface.orient()
            mesh = surface.polygonize()
            mesh.write(args.output)
            if args.normals_out:
                gmpu.Points(cloud.positions, surface.normals).write(args.normals_out)
            stats = surface.stats
    except gmpu.Error as e:
        print(f"reconstruct.py: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("\nreconstruct.py: interrupted", file=sys.stderr)
        return 130

    if not args.quiet:
        print(f"gmpu: {len(cloud)} points, {stats['cells']} cells ({stats['leaves']} leaves, depth {stats['depth']}), "
              f"{stats['components']} component{'s' if stats['components'] != 1 else ''}\n"
              f"gmpu: mesh {len(mesh.vertices)} vertices, {len(mesh.faces)} triangles at resolution "
              f"{stats['resolution']} -> {args.output}\n"
              f"gmpu: time fit {stats['fit_seconds']:.3f} s, orient {stats['orient_seconds']:.3f} s, "
              f"polygonize {stats['polygonize_seconds']:.3f} s, total {time.perf_counter() - t0:.3f} s",
              file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
