"""Turns the benchmark's rows into results.md, summary.md (the README section), PNG plots
and side-by-side renders. Everything here reads results.json's structure only."""
import math
import os
import statistics
from pathlib import Path

import binding_cost
import render

PIPELINE_LABELS = {"gmpu": "gmpu", "open3d_d8": "Open3D (Poisson d8)",
                   "open3d_d9": "Open3D (Poisson d9)", "cgal": "CGAL"}
PEERS = ("open3d_d8", "open3d_d9", "cgal")
# Camera per ground-truth model (azimuth, elevation in degrees; world +y up).
VIEWS = {"bunny00": (35, 20), "fandisk": (60, 20), "knot2": (60, 20), "elephant": (180, 20)}
BYTES_PER_POINT_TARGET = 150


def label(name):
    return PIPELINE_LABELS.get(name, name)


def fmt(value, spec):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    return format(value, spec)


STAGE_NAMES = ("read", "normals", "fit", "orient", "reconstruct", "polygonize", "write")


def stages(row):
    """'normals 0.21 · orient 3.44 · ...': every timed stage, in pipeline order."""
    timed = row.get("stages", {})
    return " · ".join(f"{k} {timed[k]:.2f}" for k in STAGE_NAMES if k in timed)


def by_cloud(rows):
    out = {}
    for r in rows:
        out.setdefault(r["cloud"], {})[r["pipeline"]] = r
    return out


def pipelines_in(rows):
    seen = []
    for r in rows:
        if r["pipeline"] not in seen:
            seen.append(r["pipeline"])
    return seen


# ---- tables ----

def results_table(rows):
    head = ("| cloud | pipeline | orientation | Chamfer-L1 | F@0.5% | F@1% | normal cons. | "
            "watertight | comp. | time (s) | wall (s) | peak MB | stages (s) |\n"
            "|---|---|---:|---:|---:|---:|---:|:---:|---:|---:|---:|---:|---|\n")
    lines = []
    for r in rows:
        if not r["ok"]:
            lines.append(f"| {r['cloud']} | {label(r['pipeline'])} | failed: {r['error'][:80]} "
                         "| | | | | | | | | | |")
            continue
        lines.append(
            f"| {r['cloud']} | {label(r['pipeline'])} | {fmt(r.get('orientation_accuracy'), '.2%')} "
            f"| {fmt(r.get('chamfer_l1'), '.3%')} | {fmt(r.get('fscore_0.5'), '.3f')} "
            f"| {fmt(r.get('fscore_1'), '.3f')} | {fmt(r.get('normal_consistency'), '.3f')} "
            f"| {'yes' if r.get('watertight') else 'no'} | {r.get('components', '–')} "
            f"| {r['compute']:.2f} | {r['wall']:.2f} | {r['peak_rss_mb']:.0f} | {stages(r)} |")
    return head + "\n".join(lines) + "\n"


def ratio_rows(rows):
    """Per cloud and peer: peer time / gmpu time (× faster) and gmpu − peer quality."""
    out = []
    for cloud, runs in by_cloud(rows).items():
        g = runs.get("gmpu")
        for peer in PEERS:
            p = runs.get(peer)
            if not (g and p and g["ok"] and p["ok"] and g["compute"] > 0):
                continue
            out.append({"cloud": cloud, "peer": peer, "speedup": p["compute"] / g["compute"],
                        "memory": g["peak_rss_mb"] / p["peak_rss_mb"],
                        "d_orient": g.get("orientation_accuracy", 0) - p.get("orientation_accuracy", 0),
                        "d_f05": (g.get("fscore_0.5") - p.get("fscore_0.5"))
                        if g.get("fscore_0.5") is not None and p.get("fscore_0.5") is not None else None})
    return out


def ratio_table(rows):
    ratios = ratio_rows(rows)
    if not ratios:
        return "_No cloud has both a gmpu run and a peer run: no ratios._\n"
    head = ("| cloud | peer | peer time / gmpu time | gmpu memory / peer memory | "
            "orientation gmpu − peer | F@0.5% gmpu − peer |\n|---|---|---:|---:|---:|---:|\n")
    lines = [f"| {r['cloud']} | {label(r['peer'])} | {r['speedup']:.1f}× | {r['memory']:.2f} "
             f"| {r['d_orient'] * 100:+.2f} pt | {fmt(r['d_f05'], '+.3f')} |" for r in ratios]
    return head + "\n".join(lines) + "\n"


def summary_table(rows):
    """One line per pipeline over the non-scale clouds: the means, and the worst case."""
    head = ("| pipeline | clouds | mean orientation | worst orientation | mean Chamfer-L1 | "
            "mean F@0.5% | mean F@1% | watertight | median time (s) | median peak MB |\n"
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n")
    lines = []
    for name in pipelines_in(rows):
        mine = [r for r in rows if r["pipeline"] == name]
        ok = [r for r in mine if r["ok"]]
        if not ok:
            lines.append(f"| {label(name)} | 0/{len(mine)} | | | | | | | | |")
            continue
        orient = [r["orientation_accuracy"] for r in ok if r.get("orientation_accuracy") is not None]
        with_gt = [r for r in ok if r.get("chamfer_l1") is not None]

        def mean(key):
            vals = [r[key] for r in with_gt if r.get(key) is not None]
            return statistics.fmean(vals) if vals else None
        lines.append(
            f"| {label(name)} | {len(ok)}/{len(mine)} | {fmt(statistics.fmean(orient), '.2%')} "
            f"| {fmt(min(orient), '.2%')} | {fmt(mean('chamfer_l1'), '.3%')} "
            f"| {fmt(mean('fscore_0.5'), '.3f')} | {fmt(mean('fscore_1'), '.3f')} "
            f"| {sum(bool(r.get('watertight')) for r in ok)}/{len(ok)} "
            f"| {statistics.median(r['compute'] for r in ok):.2f} "
            f"| {statistics.median(r['peak_rss_mb'] for r in ok):.0f} |")
    return head + "\n".join(lines) + "\n"


def per_cloud_table(rows):
    """Per cloud: gmpu's figures beside the best any peer reached on each (not necessarily
    the same peer for every column), and gmpu's mesh topology."""
    head = ("| cloud | points | orientation (best peer) | Chamfer-L1 (best peer) | F@0.5% (best peer) "
            "| watertight | components | genus | time s (fastest peer) |\n"
            "|---|---:|---:|---:|---:|:---:|---:|---:|---:|\n")
    lines = []
    for cloud, runs in by_cloud(rows).items():
        g = runs.get("gmpu")
        if not g:
            continue
        peers = [runs[p] for p in PEERS if p in runs and runs[p]["ok"]]

        def best(key, spec, pick=max):
            vals = [r[key] for r in peers if r.get(key) is not None]
            return f"{fmt(g.get(key), spec)} ({fmt(pick(vals), spec) if vals else '–'})"
        if not g["ok"]:
            lines.append(f"| {cloud} | {g['points']} | failed: {g['error'][:80]} | | | | | | |")
            continue
        fastest = min((r["compute"] for r in peers), default=None)
        lines.append(
            f"| {cloud} | {g['points']:,} | {best('orientation_accuracy', '.3%')} "
            f"| {best('chamfer_l1', '.3%', min)} | {best('fscore_0.5', '.4f')} "
            f"| {'yes' if g.get('watertight') else 'no'} | {g.get('components', '–')} "
            f"| {','.join(map(str, g.get('genus') or [])) or '–'} "
            f"| {g['compute']:.2f} ({fmt(fastest, '.2f')}) |")
    return head + "\n".join(lines) + "\n"


def scale_table(scale):
    if not scale:
        return "_No scale series in this run._\n"
    head = ("| points | pipeline | time (s) | wall (s) | peak MB | bytes / point | orientation | F@0.5% |\n"
            "|---:|---|---:|---:|---:|---:|---:|---:|\n")
    lines = []
    for r in sorted(scale, key=lambda r: (r["points"], r["pipeline"])):
        if not r["ok"]:
            lines.append(f"| {r['points']:,} | {label(r['pipeline'])} | failed: {r['error'][:60]} | | | | | |")
            continue
        lines.append(f"| {r['points']:,} | {label(r['pipeline'])} | {r['compute']:.2f} | {r['wall']:.2f} "
                     f"| {r['peak_rss_mb']:.0f} | {r['peak_rss_mb'] * 2**20 / r['points']:.0f} "
                     f"| {fmt(r.get('orientation_accuracy'), '.2%')} | {fmt(r.get('fscore_0.5'), '.3f')} |")
    return head + "\n".join(lines) + "\n"


def targets(results):
    """The issue's targets, each with the figure that meets or misses it."""
    rows, scale = results["rows"], results.get("scale", [])
    out = []
    at35k = [r for r in rows if r["points"] == 35000]
    clouds = by_cloud(at35k)
    speedups = []
    for runs in clouds.values():
        g = runs.get("gmpu")
        peers = [runs[p]["compute"] for p in PEERS if p in runs and runs[p]["ok"]]
        if g and g["ok"] and peers and g["compute"] > 0:
            speedups.append(min(peers) / g["compute"])
    if speedups:
        worst = min(speedups)
        out.append(f"- 35k points, ≥ 10× faster than the faster peer on every cloud: "
                   f"{'met' if worst >= 10 else 'missed'} (worst {worst:.1f}×, median "
                   f"{statistics.median(speedups):.1f}×).")
    behind = []
    for cloud, runs in by_cloud(rows).items():
        g = runs.get("gmpu")
        if not (g and g["ok"]):
            behind.append(f"{cloud} (gmpu failed)")
            continue
        # Orientation as a percentage to 3 decimals: 0.99986 against 0.99990 must not read
        # as "0.9999 < 0.9999".
        for key, name, spec in (("orientation_accuracy", "orientation", ".3%"), ("fscore_0.5", "F@0.5%", ".4f")):
            best = max((runs[p].get(key) for p in PEERS if p in runs and runs[p]["ok"]
                        and runs[p].get(key) is not None), default=None)
            if best is not None and (g.get(key) is None or g[key] < best):
                behind.append(f"{cloud} {name} {fmt(g.get(key), spec)} < {best:{spec}}")
    if any(r["pipeline"] == "gmpu" for r in rows):
        out.append("- Orientation accuracy and F@0.5% at least the peers' on every cloud: "
                   + ("met." if not behind else "missed on " + "; ".join(behind) + "."))
    big = [r for r in scale if r["points"] >= 1_000_000]
    g = next((r for r in big if r["pipeline"] == "gmpu"), None)
    if g and g["ok"]:
        peers = [r for r in big if r["pipeline"] != "gmpu" and r["ok"]]
        if peers:
            fastest = min(peers, key=lambda r: r["compute"])
            s = fastest["compute"] / g["compute"]
            out.append(f"- 1M points, ≥ 10× faster than the faster peer: {'met' if s >= 10 else 'missed'} "
                       f"({s:.1f}× against {label(fastest['pipeline'])}).")
        bpp = g["peak_rss_mb"] * 2**20 / g["points"]
        out.append(f"- 1M points, peak memory ≤ {BYTES_PER_POINT_TARGET} bytes per point: "
                   f"{'met' if bpp <= BYTES_PER_POINT_TARGET else 'missed'} ({bpp:.0f} B/point).")
    if results.get("binding"):
        out.append("- " + binding_cost.summary(results["binding"]))
    return "\n".join(out) + "\n" if out else "_No gmpu runs: targets not assessed._\n"


# ---- plots ----

def plot_scale(scale, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    for key, ylabel, name in (("compute", "time (s)", "time_vs_points.png"),
                              ("peak_rss_mb", "peak memory (MB)", "memory_vs_points.png")):
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        for p in pipelines_in(scale):
            pts = sorted((r["points"], r[key]) for r in scale if r["pipeline"] == p and r["ok"])
            if pts:
                ax.plot(*zip(*pts), marker="o", label=label(p))
        if key == "peak_rss_mb" and scale:
            ns = sorted({r["points"] for r in scale})
            ax.plot(ns, [n * BYTES_PER_POINT_TARGET / 2**20 for n in ns], "k:",
                    label=f"{BYTES_PER_POINT_TARGET} bytes/point (gmpu target)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("input points")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        ax.set_title(f"{ylabel.split(' (')[0].capitalize()} vs points (bunny, sampled)")
        fig.tight_layout()
        fig.savefig(out_dir / name, dpi=110)
        plt.close(fig)


def plot_accuracy(rows, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    clouds = list(by_cloud(rows))
    names = pipelines_in(rows)
    fig, axes = plt.subplots(2, 1, figsize=(max(8, 0.7 * len(clouds) + 3), 7.5), sharex=True)
    width = 0.8 / max(1, len(names))
    for ax, key, title in ((axes[0], "orientation_accuracy", "orientation accuracy"),
                           (axes[1], "fscore_0.5", "F-score at 0.5 % of the diagonal")):
        runs = by_cloud(rows)
        for i, p in enumerate(names):
            vals = [runs[c].get(p, {}).get(key) if runs[c].get(p, {}).get("ok") else 0 for c in clouds]
            vals = [v if v is not None else np.nan for v in vals]
            ax.bar(np.arange(len(clouds)) + (i - (len(names) - 1) / 2) * width, vals, width, label=label(p))
        ax.set_ylim(0, 1.02)
        ax.set_title(title)
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].legend(ncol=len(names), fontsize=8, loc="lower left")
    axes[1].set_xticks(np.arange(len(clouds)))
    axes[1].set_xticklabels(clouds, rotation=40, ha="right", fontsize=8)
    fig.tight_layout()
    fig.savefig(out_dir / "accuracy_per_model.png", dpi=110)
    plt.close(fig)


def render_models(rows, out_dir):
    """One PNG per cloud: the ground truth, then every pipeline, same camera."""
    import numpy as np
    import open3d as o3d

    folder = out_dir / "renders"
    folder.mkdir(exist_ok=True)
    written = []
    for cloud, runs in by_cloud(rows).items():
        any_row = next(iter(runs.values()))
        gt = any_row.get("gt_mesh")
        stem = Path(gt).stem if gt else cloud.split("_")[0]
        azimuth, elevation = VIEWS.get(stem, (35, 20))
        panels = [("ground truth", gt)] if gt else []
        for p, r in runs.items():
            text = label(p)
            if r["ok"]:
                text += (f"\norient {fmt(r.get('orientation_accuracy'), '.1%')}  "
                         f"F@0.5% {fmt(r.get('fscore_0.5'), '.3f')}")
            panels.append((text, r["mesh"] if r["ok"] else None))
        # Frame on the input points, so that a wild output cannot move the camera.
        pts = np.asarray(o3d.io.read_point_cloud(any_row["cloud_path"]).points)
        frame = None
        if len(pts):
            lo, hi = pts.min(axis=0), pts.max(axis=0)
            frame = ((lo + hi) / 2, 0.55 * np.linalg.norm(hi - lo))
        path = folder / f"{cloud}.png"
        render.side_by_side(panels, path, cloud, azimuth, elevation, frame)
        written.append(path)
    return written


def load_note(rows):
    """Times are only comparable on a quiet machine: say so when this one was not. The
    bench's own runs (two threads, and the peers after them) leave a 1-minute load of up to
    the core count; above it, other work was competing."""
    loads = [r["load_before"] for r in rows if "load_before" in r]
    cores = os.cpu_count() or 1
    if not loads:
        return ""
    figures = (f"1-minute load average before each run: mean {statistics.fmean(loads):.1f}, "
               f"max {max(loads):.1f}, on {cores} cores")
    if statistics.fmean(loads) <= cores:
        return f" The load stayed within what the bench's own runs make ({figures})."
    return (f" **The machine was shared with other work during this run** ({figures}): times are "
            "longer and noisier than on an idle machine.")


# ---- everything ----

def write_all(results, out_dir, renders=True):
    out_dir = Path(out_dir)
    rows, scale = results["rows"], results.get("scale", [])
    if rows:
        plot_accuracy(rows, out_dir)
    if scale:
        plot_scale(scale, out_dir)
    pictures = render_models(rows, out_dir) if renders and rows else []
    m = results["machine"]
    machine = (f"{m['cpu']}, {m['cores']} cores, {m['memory_gb']} GB, {m['os']}; run {m['date']}")
    summary = (
        f"Measured on {machine}. Every number below comes from one run of `make bench`, gmpu "
        "and the peers side by side; distances are exact point-to-triangle, relative to the "
        "ground truth's bounding-box diagonal, 100k samples per surface; orientation is the "
        "share of input points whose output normal points outward (no global flip allowed). "
        "Time is normals + orientation + surface (no file I/O, no interpreter start-up); wall "
        "and peak memory are the whole child process. gmpu's figures are those of the median "
        "of 3 runs where a run takes under 10 s (one run of a third of a second varies by "
        "±30 % on a shared machine); the peers, at seconds to minutes, run once." + load_note(rows + scale) + "\n\n"
        "### Targets (issues 3 and 5)\n\n" + targets(results) + "\n"
        "### Over all clouds\n\n" + summary_table(rows) + "\n"
        "### Per cloud: gmpu (the best peer)\n\n" + per_cloud_table(rows) + "\n"
        "### Scale series\n\n" + scale_table(scale) + "\n"
        + ("![time vs points](time_vs_points.png) ![memory vs points](memory_vs_points.png)\n\n"
           if scale else "")
        + ("![accuracy per model](accuracy_per_model.png)\n\n" if rows else "")
        + "### Pictures (red: a surface seen from inside, i.e. inside-out)\n\n"
        + "".join(f"[{p.stem}](renders/{p.name}) " for p in pictures) + "\n")
    (out_dir / "summary.md").write_text(summary)
    full = ("# gmpu beside Open3D and CGAL: benchmark results\n\n" + summary +
            "\n## Every run\n\n" + results_table(rows) +
            "\n## Ratios gmpu / peer, same run\n\n" + ratio_table(rows))
    (out_dir / "results.md").write_text(full)
    print("\n" + ratio_table(rows))


if __name__ == "__main__":
    # Rebuild the report of an earlier run: report.py RESULTS_DIR [--no-renders]
    import json
    import sys

    folder = Path(sys.argv[1])
    write_all(json.loads((folder / "results.json").read_text()), folder,
              renders="--no-renders" not in sys.argv)
