#!/usr/bin/python3
"""Sparse thin-walled shapes the corpus does not have (tests/data/thinwall): gmpu's default
surface on each cloud, scored by gmpu-metrics against the true mesh, optionally beside another
gmpu-reconstruct (an older build) on the same clouds. Prints a Markdown table.

  thinwall.py --build BUILD [--clouds DIR] [--baseline OTHER/gmpu-reconstruct]

The clouds are generated into DIR (default bench-results/thinwall/clouds) when missing.
Times are one wall-clock run each, CLI end to end.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))


def metrics(build, args):
    out = subprocess.run([os.path.join(build, "tests", "bench", "gmpu-metrics")] + args, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)


def run(cli, build, cloud, clouds, work):
    mesh, normals = os.path.join(work, "mesh.ply"), os.path.join(work, "normals.ply")
    start = time.perf_counter()
    subprocess.run([cli, os.path.join(clouds, cloud + ".ply"), "-o", mesh, "--normals-out", normals, "--quiet"],
                   check=True)
    seconds = time.perf_counter() - start
    truth = os.path.join(clouds, "meshes", json.load(open(os.path.join(clouds, cloud + "_meta.json")))["mesh"])
    m = metrics(build, ["--mesh", mesh, "--gt", truth, "--points-normals", normals,
                        "--gt-normals", os.path.join(clouds, cloud + "_gt.ply")])
    return dict(f5=m["fscore_0.5"], f1=m["fscore_1"], orientation=m["orientation_accuracy"],
                components=m["components"], genus=m["genus"], seconds=seconds)


def topology(genus):
    return ",".join(str(g) for g in genus)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True)
    ap.add_argument("--clouds", default=os.path.join(ROOT, "bench-results", "thinwall", "clouds"))
    ap.add_argument("--baseline", help="another gmpu-reconstruct to run beside this build's")
    a = ap.parse_args()
    if not os.path.isdir(a.clouds) or not any(f.endswith("_meta.json") for f in os.listdir(a.clouds)):
        subprocess.run(["bash", os.path.join(ROOT, "tests", "data", "thinwall", "make.sh"), a.clouds], check=True)
    cli = os.path.join(a.build, "examples", "gmpu-reconstruct")
    clouds = sorted(f[:-len("_meta.json")] for f in os.listdir(a.clouds) if f.endswith("_meta.json"))
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for cloud in clouds:
            mesh = json.load(open(os.path.join(a.clouds, cloud + "_meta.json")))["mesh"]
            truth_path = os.path.join(a.clouds, "meshes", mesh)
            t = metrics(a.build, ["--mesh", truth_path, "--gt", truth_path, "--samples", "1000"])
            now = run(cli, a.build, cloud, a.clouds, work)
            before = run(a.baseline, a.build, cloud, a.clouds, work) if a.baseline else None
            rows.append((cloud, t, before, now))
            print(cloud, "done", file=sys.stderr)

    def cell(key, fmt, before, now):
        return f"{fmt % before[key]} → {fmt % now[key]}" if before else fmt % now[key]

    print("| cloud | F@0.5% | F@1% | orientation | components (truth) | genus (truth) | s |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    sums = [0.0, 0.0, 0.0]
    for cloud, t, before, now in rows:
        comps = f"{before['components']} → {now['components']}" if before else str(now["components"])
        genus = f"{topology(before['genus'])} → {topology(now['genus'])}" if before else topology(now["genus"])
        print(f"| {cloud} | {cell('f5', '%.3f', before, now)} | {cell('f1', '%.3f', before, now)} | "
              f"{cell('orientation', '%.1f%%', dict(before, orientation=100 * before['orientation']) if before else None, dict(now, orientation=100 * now['orientation']))} | "
              f"{comps} ({t['components']}) | {genus} ({topology(t['genus'])}) | {cell('seconds', '%.2f', before, now)} |")
        if before:
            sums = [s + now[k] - before[k] for s, k in zip(sums, ("f5", "f1", "orientation"))]
    if any(r[2] for r in rows):
        print(f"\nSummed change: F@0.5% {sums[0]:+.3f}, F@1% {sums[1]:+.3f}, orientation {100 * sums[2]:+.1f} points.")


if __name__ == "__main__":
    main()
