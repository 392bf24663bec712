"""The benchmark's corpus section (issue 13): clouds of kinds nobody tuned for — more noise,
thin walls, sparse samples, open scans — generated here from tests/data/corpus/make.sh.

Per cloud it runs gmpu (the CLI), Open3D's screened Poisson on gmpu's own oriented normals
(what a global smooth surface makes of gmpu's orientation), and takes the better of Open3D's
and CGAL's Poisson pipelines either from the committed figures (tests/data/corpus/peers.tsv,
the default: the peers take 5–50 s per cloud) or by running them here (`--corpus-peers live`).
Everything is scored by gmpu-metrics; corpus_report.py turns the rows into tables.

The held-out set (`make bench-heldout`) runs the same on 66 clouds that tests/data/heldout/make.sh
samples from eleven meshes of CGAL's sample data that no setting was tuned on; it has no
committed peer figures, so its peers always run here. So has the sparse noisy set (`make
bench-sparse-noisy`): 51 clouds of the corpus's closed meshes, few points and noisy at once
(tests/data/sparse_noisy/make.sh).
"""
import csv
import json
import os
import subprocess
from pathlib import Path

import pipelines

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT / "tests" / "data" / "corpus"
PEERS_TSV = CORPUS / "peers.tsv"
IPSR_TSV = CORPUS / "ipsr_reference.tsv"
HELDOUT = ROOT / "tests" / "data" / "heldout"
SPARSE_NOISY = ROOT / "tests" / "data" / "sparse_noisy"
# What each set's make.sh writes, and where the meshes the clouds come from are.
SETS = {
    "corpus": {"make": CORPUS / "make.sh", "count": 106, "meshes": lambda out: CORPUS / "meshes"},  # 17 × 6 + 2 × 2
    "heldout": {"make": HELDOUT / "make.sh", "count": 66, "meshes": lambda out: out / "meshes"},  # 11 × 6
    "sparse_noisy": {"make": SPARSE_NOISY / "make.sh", "count": 51, "meshes": lambda out: CORPUS / "meshes"},  # 17 × 3
}

VARIANTS = ("clean", "noise0.5", "noise1.0", "nonuniform", "sparse5k", "sparse1k")
SPARSE_NOISY_VARIANTS = ("sparse1k-noise0.5", "sparse1k-noise1.0", "sparse5k-noise1.0")
OPEN_MESHES = ("elephant-with-holes", "mech-holes-shark")
# peers.tsv's names for the two peers, and the live pipelines that stand for them.
REFERENCE_PEERS = {"cgal_poisson": "cgal", "open3d_poisson_d8": "open3d_d8"}


def variant_of(name):
    """bear_noise0.5 → noise0.5; every cloud of an open mesh → open."""
    mesh, variant = name.rsplit("_", 1)
    return "open" if mesh in OPEN_MESHES else variant


# ---- inputs ----

def generate(out_dir, which="corpus"):
    """The set's clouds, made by its make.sh with fixed seeds (kept between runs)."""
    spec = SETS[which]
    out_dir.mkdir(parents=True, exist_ok=True)
    meshes = spec["meshes"](out_dir)
    if len(list(out_dir.glob("*_meta.json"))) != spec["count"] or not meshes.is_dir():
        print(f"generating the {which} clouds into {out_dir} ({spec['make'].relative_to(ROOT)}: a few minutes)",
              flush=True)
        subprocess.run(["bash", str(spec["make"]), str(out_dir)], check=True)
    clouds = []
    for meta_path in sorted(out_dir.glob("*_meta.json")):
        name = meta_path.name[: -len("_meta.json")]
        meta = json.loads(meta_path.read_text())
        clouds.append({"cloud": name, "variant": variant_of(name), "mesh": meta["mesh"],
                       "points": meta["n"], "noise": meta["noise"],
                       "noise_abs": meta["noise_sigma_abs"],
                       "path": out_dir / f"{name}.ply", "gt_normals": out_dir / f"{name}_gt.ply",
                       "gt_mesh": meshes / meta["mesh"]})
    return clouds


def cloud_diagonal(ply):
    """Bounding-box diagonal of a binary little-endian float32 x y z PLY (make.sh's format):
    gmpu reports its noise estimate relative to the cloud's own diagonal."""
    import numpy as np

    with open(ply, "rb") as f:
        count = 0
        while True:
            line = f.readline()
            if line.startswith(b"element vertex"):
                count = int(line.split()[2])
            if line.strip() == b"end_header" or not line:
                break
        xyz = np.frombuffer(f.read(12 * count), dtype="<f4").reshape(count, 3)
    return float(np.linalg.norm(xyz.max(axis=0) - xyz.min(axis=0)))


def read_tsv(path):
    """Rows of a tab-separated file whose '#' lines are comments."""
    if not path.exists():
        return []
    with open(path) as f:
        return list(csv.DictReader((l for l in f if not l.startswith("#")), delimiter="\t"))


def number(text):
    return float(text) if text not in (None, "") else None


def reference_peers():
    """peers.tsv → {cloud: {peer: figures}}; a failed run (empty fields) is kept as not ok,
    with what the file says of it, so that the report can say why the figure is missing."""
    out = {}
    for r in read_tsv(PEERS_TSV):
        if number(r["f05_exact"]) is None:
            wall = number(r["wall_s"])
            ended = f" (the run ended after {wall:.0f} s)" if wall is not None else ""
            out.setdefault(r["cloud"], {})[REFERENCE_PEERS[r["peer"]]] = {
                "ok": False, "error": f"peers.tsv records no mesh{ended}"}
            continue
        out.setdefault(r["cloud"], {})[REFERENCE_PEERS[r["peer"]]] = {
            "ok": True, "orientation_accuracy": number(r["orient_pct"]) / 100,
            "fscore_0.5": number(r["f05_exact"]), "fscore_1": number(r["f1_exact"]),
            "watertight": r["watertight"] == "True", "components": int(float(r["components"])),
            "seconds": number(r["wall_s"]), "seconds_kind": "wall"}
    return out


def ipsr_reference():
    return {r["cloud"]: {"fscore_0.5": number(r["fscore_0.5"]), "fscore_1": number(r["fscore_1"]),
                         "orientation_accuracy": number(r.get("orientation")),
                         "seconds": number(r["seconds"])} for r in read_tsv(IPSR_TSV)}


# ---- runs ----

def score(metrics_exe, run, cloud, samples, orientation=True):
    cmd = [str(metrics_exe), "--mesh", str(run.mesh), "--gt", str(cloud["gt_mesh"]),
           "--samples", str(samples)]
    if orientation:
        cmd += ["--points-normals", str(run.points), "--gt-normals", str(cloud["gt_normals"])]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        return {"metrics_error": done.stderr.strip()[-300:]}
    return json.loads(done.stdout)


METRIC_KEYS = ("orientation_accuracy", "fscore_0.5", "fscore_1", "chamfer_l1", "watertight",
               "components", "genus", "metrics_error")


def measured(pipeline, run, scores):
    row = {"pipeline": pipeline.name, "ok": run.ok, "error": run.error,
           "seconds": run.compute, "seconds_kind": "compute", "wall": run.wall,
           "peak_rss_mb": run.peak_rss_mb, "stages": run.stages}
    row.update({k: scores[k] for k in METRIC_KEYS if k in scores})
    return row


def estimated_noise(log_path):
    """σ̂ as a fraction of the cloud's diagonal, from the CLI's 'estimated noise' line."""
    import re

    found = re.findall(r"estimated noise ([\d.]+)% of the diagonal", Path(log_path).read_text(errors="replace"))
    return float(found[-1]) / 100 if found else None


def truth_topology(metrics_exe, mesh, cache):
    if mesh not in cache:
        done = subprocess.run([str(metrics_exe), "--mesh", str(mesh)], capture_output=True,
                              text=True, check=True)
        j = json.loads(done.stdout)
        cache[mesh] = {"components": j["components"], "genus": j["genus"], "watertight": j["watertight"]}
    return cache[mesh]


def better_peer(runs):
    """The better of the peers, column by column (not necessarily the same peer each time)."""
    ok = {name: r for name, r in runs.items() if r.get("ok")}
    if not ok:
        return None
    best = {"peers": sorted(ok)}
    for key in ("orientation_accuracy", "fscore_0.5", "fscore_1"):
        vals = [(r[key], name) for name, r in ok.items() if r.get(key) is not None]
        if vals:
            best[key], best[key + "_by"] = max(vals)
    if "fscore_0.5_by" in best:  # the topology of the peer whose surface is the closer one
        best["components"] = ok[best["fscore_0.5_by"]].get("components")
    times = [r["seconds"] for r in ok.values() if r.get("seconds") is not None]
    best["seconds"] = min(times) if times else None  # the faster peer
    best["seconds_kind"] = next(iter(ok.values())).get("seconds_kind")
    return best


def run_corpus(args, metrics_exe, build):
    """All the rows of a set; `args` carries out, corpus_set, corpus_peers, only, timeout, samples."""
    out = args.out
    which = getattr(args, "corpus_set", "corpus")
    clouds = generate(out / "clouds", which)
    if args.only:
        clouds = [c for c in clouds if any(s in c["cloud"] for s in args.only.split(","))]
    gmpu = pipelines.Gmpu(build)
    gmpu.REPEATS = args.corpus_repeats
    poisson = pipelines.PoissonOnOrientedPoints()
    live = args.corpus_peers == "live" or which != "corpus"  # only the corpus has committed figures
    peers = [pipelines.Open3D(8), pipelines.Cgal(build)] if live else []
    for p in [gmpu, poisson, *peers]:
        why = p.available()
        if why:
            raise SystemExit(f"corpus: {p.name} cannot run: {why}")
    reference = {} if live else reference_peers()
    topology_cache, rows = {}, []
    print(f"{which}: {len(clouds)} clouds; peers {'run live' if live else 'from ' + str(PEERS_TSV.relative_to(ROOT))}",
          flush=True)
    for cloud in clouds:
        workdir = out / "runs" / cloud["cloud"]
        row = {k: (str(v) if isinstance(v, Path) else v) for k, v in cloud.items()}
        row["load_before"] = os.getloadavg()[0]
        row["cloud_diagonal"] = cloud_diagonal(cloud["path"])
        row["truth"] = truth_topology(metrics_exe, cloud["gt_mesh"], topology_cache)
        run = gmpu.run(cloud["path"], workdir, args.timeout)
        row["gmpu"] = measured(gmpu, run, score(metrics_exe, run, cloud, args.samples) if run.ok else {})
        row["gmpu"]["noise_estimate"] = estimated_noise(workdir / "gmpu.log") if run.ok else None
        if run.ok:
            ref = poisson.run(run.points, workdir, args.timeout)
            row["poisson_gmpu"] = measured(
                poisson, ref, score(metrics_exe, ref, cloud, args.samples, orientation=False) if ref.ok else {})
        peer_runs = {}
        for p in peers:
            r = p.run(cloud["path"], workdir, args.timeout)
            peer_runs[p.name] = measured(p, r, score(metrics_exe, r, cloud, args.samples) if r.ok else {})
        row["peer_runs"] = peer_runs if live else reference.get(cloud["cloud"], {})
        row["peer_source"] = "live" if live else "reference"
        row["peer"] = better_peer(row["peer_runs"])
        rows.append(row)
        print(line(row), flush=True)
    return {"rows": rows, "set": which, "peer_source": "live" if live else "reference",
            "ipsr": ipsr_reference() if which == "corpus" else {}}


def line(row):
    g, p, r = row["gmpu"], row.get("peer") or {}, row.get("poisson_gmpu") or {}

    def f(v, spec):
        return "-" if v is None else format(v, spec)
    if not g["ok"]:
        return f"{row['cloud']:<28} gmpu FAILED: {g['error']}"
    return (f"{row['cloud']:<28} orient {f(g.get('orientation_accuracy'), '.4f')}  "
            f"F@0.5% {f(g.get('fscore_0.5'), '.3f')} (peer {f(p.get('fscore_0.5'), '.3f')}, "
            f"poisson {f(r.get('fscore_0.5'), '.3f')})  F@1% {f(g.get('fscore_1'), '.3f')} "
            f"(peer {f(p.get('fscore_1'), '.3f')}, poisson {f(r.get('fscore_1'), '.3f')})  "
            f"comp {g.get('components')}  noise {f(g.get('noise_estimate'), '.5f')}  {g['seconds']:.2f} s")
