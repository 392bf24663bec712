"""The corpus section's report (issue 13): every target checked per cloud, a summary per
variant, and the per-cloud table, as corpus.md (the README's corpus section) — read from
the corpus rows of results.json only.

Targets (issue 13; closed meshes only: the open scans are shown, not judged):
  orientation ≥ ORIENTATION_TARGET[variant] (the issue sets none for the sparse noisy set);
  F@0.5 % and F@1 % ≥ the better peer's, and ≥ Poisson-on-gmpu-normals − POISSON_SLACK;
  σ̂ within ±30 % of the true σ on noisy clouds, ≤ 0.05 % of the diagonal on noise-free ones;
  thin walls at 35k clean/nonuniform: the ground truth's components and genus;
  at 1k points, F@1 % within 0.05 of iPSR's, at ≥ 100× its speed.
"""
import statistics

ORIENTATION_TARGET = {"clean": 0.999, "nonuniform": 0.999, "noise0.5": 0.995,
                      "noise1.0": 0.99, "sparse5k": 0.99, "sparse1k": 0.97}
VARIANT_ORDER = ("clean", "noise0.5", "noise1.0", "nonuniform", "sparse5k", "sparse1k", "open",
                 "sparse1k-noise0.5", "sparse1k-noise1.0", "sparse5k-noise1.0")
POISSON_SLACK = 0.005
NOISE_TOLERANCE = 0.30          # relative, on noisy clouds
CLEAN_NOISE_CEILING = 0.0005    # fraction of the diagonal, on noise-free clouds
THIN_WALLS = ("hollow_sphere", "pipe", "thin_plate")
THIN_WALL_VARIANTS = ("clean", "nonuniform")
IPSR_F1_SLACK = 0.05
IPSR_SPEEDUP = 100
FSCORES = (("fscore_0.5", "F@0.5%"), ("fscore_1", "F@1%"))


def fmt(v, spec):
    return "–" if v is None else format(v, spec)


def mark(ok):
    return "" if ok is None else (" ✓" if ok else " ✗")


def mesh_name(row):
    return row["mesh"].rsplit(".", 1)[0]


def peer_figures_rounded(v, row):
    """peers.tsv keeps 4 decimals: against its figures, compare gmpu at the same precision
    (live peers' figures are exact, and so is the comparison)."""
    return None if v is None else round(v, 4) if row.get("peer_source") != "live" else v


# ---- the targets, per cloud: None = not judged on this cloud ----

def checks(row):
    g, peer, poisson = row["gmpu"], row.get("peer") or {}, row.get("poisson_gmpu") or {}
    judged = row["variant"] != "open"
    out = {}
    if not g.get("ok"):
        return {"gmpu": False} if judged else {}
    if not judged:
        return out
    o, target = g.get("orientation_accuracy"), ORIENTATION_TARGET.get(row["variant"])
    if target is not None:
        out["orientation"] = o is not None and o >= target
    for key, _ in FSCORES:
        v = g.get(key)
        if peer.get(key) is not None:
            out[key + "_peer"] = v is not None and peer_figures_rounded(v, row) >= peer[key]
        if poisson.get(key) is not None:
            out[key + "_poisson"] = v is not None and v >= poisson[key] - POISSON_SLACK
    est = noise_fraction_of_truth(row)
    if row["noise"] > 0:
        out["noise"] = est is not None and abs(est / row["noise"] - 1) <= NOISE_TOLERANCE
    elif g.get("noise_estimate") is not None:
        out["noise"] = g["noise_estimate"] <= CLEAN_NOISE_CEILING
    if mesh_name(row) in THIN_WALLS and row["variant"] in THIN_WALL_VARIANTS:
        out["topology"] = right_topology(row)
    return out


def noise_fraction_of_truth(row):
    """σ̂ re-expressed as a fraction of the ground truth's diagonal, like the true σ (gmpu
    reports it relative to the cloud's own diagonal, which noise widens)."""
    est = row["gmpu"].get("noise_estimate")
    if est is None or not row.get("noise_abs"):
        return None
    return est * row["cloud_diagonal"] / (row["noise_abs"] / row["noise"])


def right_topology(row):
    g, t = row["gmpu"], row["truth"]
    return g.get("components") == t["components"] and sorted(g.get("genus") or []) == sorted(t["genus"])


TARGET_NAMES = {
    "gmpu": "gmpu runs",
    "orientation": "orientation ≥ 99.9 % clean/nonuniform, 99.5 % noise0.5, 99 % noise1.0/sparse5k, 97 % sparse1k",
    "fscore_0.5_peer": "F@0.5% ≥ the better peer",
    "fscore_1_peer": "F@1% ≥ the better peer",
    "fscore_0.5_poisson": f"F@0.5% ≥ Poisson on gmpu's normals − {POISSON_SLACK}",
    "fscore_1_poisson": f"F@1% ≥ Poisson on gmpu's normals − {POISSON_SLACK}",
    "noise": "noise estimate within ±30 % of σ (noisy), ≤ 0.05 % of the diagonal (noise-free)",
    "topology": "thin walls (hollow_sphere, pipe, thin_plate; clean, nonuniform): truth's components and genus",
}


LIST_MISSED_UP_TO = 12


def verdict(text, judged, missed, variant):
    """'- TEXT: met (n/n clouds).' or '- TEXT: missed (met on k/n; missed: …).'"""
    if not missed:
        return f"- {text}: met ({len(judged)}/{len(judged)} clouds)."
    if len(missed) <= LIST_MISSED_UP_TO:
        which = ", ".join(missed)
    else:  # a long list says less than where the misses are
        counts = {}
        for c in missed:
            counts[variant[c]] = counts.get(variant[c], 0) + 1
        which = ", ".join(f"{counts[v]} {v}" for v in VARIANT_ORDER if v in counts)
    return f"- {text}: **missed** (met on {len(judged) - len(missed)}/{len(judged)}; missed: {which})."


def targets(rows, ipsr_rows):
    per_cloud = [(r["cloud"], checks(r)) for r in rows]
    variant = {r["cloud"]: r["variant"] for r in rows}
    lines = []
    for key, text in TARGET_NAMES.items():
        judged = [(c, ch[key]) for c, ch in per_cloud if key in ch]
        if judged:
            lines.append(verdict(text, judged, [c for c, ok in judged if not ok], variant))
    if ipsr_rows:
        missed = [r["cloud"] for r in ipsr_rows if not (r["f1_ok"] and r["speed_ok"])]
        lines.append(verdict(f"at 1k points, F@1% within {IPSR_F1_SLACK} of iPSR's (depth 8) at ≥ "
                             f"{IPSR_SPEEDUP}× its speed", ipsr_rows, missed, variant))
    return "\n".join(lines) + "\n"


# ---- tables ----

def mean(vals):
    vals = [v for v in vals if v is not None]
    return statistics.fmean(vals) if vals else None


def median(vals):
    vals = [v for v in vals if v is not None]
    return statistics.median(vals) if vals else None


def met_count(rows, key):
    judged = [checks(r)[key] for r in rows if key in checks(r)]
    return f"{sum(judged)}/{len(judged)}" if judged else "–"


def variant_table(rows):
    head = ("| variant | clouds | orientation gmpu mean (worst) · peer mean | F@0.5% gmpu · peer · Poisson(gmpu) "
            "| F@1% gmpu · peer · Poisson(gmpu) | orientation target | F ≥ peer (0.5 · 1) "
            "| F ≥ Poisson(gmpu) − 0.005 (0.5 · 1) | noise target | truth's components gmpu · peer · "
            "Poisson(gmpu) | truth's components and genus (gmpu) | watertight (gmpu) "
            "| median s gmpu · Poisson(gmpu) · peer |\n"
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n")
    lines = []
    for variant in VARIANT_ORDER:
        mine = [r for r in rows if r["variant"] == variant]
        if not mine:
            continue
        g = [r["gmpu"] for r in mine if r["gmpu"].get("ok")]
        p = [r.get("peer") or {} for r in mine]
        q = [r.get("poisson_gmpu") or {} for r in mine]
        orient = [x.get("orientation_accuracy") for x in g if x.get("orientation_accuracy") is not None]
        cells = []
        for key, _ in FSCORES:
            cells.append(" · ".join(fmt(mean(x.get(key) for x in xs), ".3f") for xs in (g, p, q)))
        topo = [right_topology(r) for r in mine if r["gmpu"].get("ok")]
        components = " · ".join(components_right(mine, who) for who in ("gmpu", "peer", "poisson_gmpu"))
        lines.append(
            f"| {variant} | {len(mine)} | {fmt(mean(orient), '.2%')} ({fmt(min(orient, default=None), '.2%')})"
            f" · {fmt(mean(x.get('orientation_accuracy') for x in p), '.2%')} "
            f"| {cells[0]} | {cells[1]} | {met_count(mine, 'orientation')} "
            f"| {met_count(mine, 'fscore_0.5_peer')} · {met_count(mine, 'fscore_1_peer')} "
            f"| {met_count(mine, 'fscore_0.5_poisson')} · {met_count(mine, 'fscore_1_poisson')} "
            f"| {met_count(mine, 'noise')} | {components} | {sum(topo)}/{len(topo)} "
            f"| {sum(bool(x.get('watertight')) for x in g)}/{len(g)} "
            f"| {fmt(median(x.get('seconds') for x in g), '.2f')} · {fmt(median(x.get('seconds') for x in q), '.2f')}"
            f" · {fmt(median(x.get('seconds') for x in p), '.2f')} |")
    return head + "\n".join(lines) + "\n"


def components_right(rows, who):
    """'k/n': how many of who's meshes have the truth's component count."""
    have = [r for r in rows if (r.get(who) or {}).get("components") is not None]
    return f"{sum(r[who]['components'] == r['truth']['components'] for r in have)}/{len(have)}" if have else "–"


def polygonize_share(run):
    """The polygonize stage's share of fit + orient + polygonize (issue 14's target: 25 %)."""
    stages, total = run.get("stages") or {}, run.get("seconds")
    return stages["polygonize"] / total if "polygonize" in stages and total else None


def cloud_table(rows):
    head = ("| cloud | orientation | F@0.5% (peer · Poisson(gmpu)) | F@1% (peer · Poisson(gmpu)) "
            "| components (truth) | genus (truth) | watertight | σ̂ / σ (% of diag.) "
            "| s gmpu (polygonize share) · Poisson(gmpu) · peer |\n"
            "|---|---:|---:|---:|---:|---:|:---:|---:|---:|\n")
    lines = []
    for r in rows:
        g, peer, q, ch = r["gmpu"], r.get("peer") or {}, r.get("poisson_gmpu") or {}, checks(r)
        if not g.get("ok"):
            lines.append(f"| {r['cloud']} | failed: {g.get('error', '')[:80]} | | | | | | | |")
            continue
        fs = []
        for key, _ in FSCORES:
            fs.append(f"{fmt(g.get(key), '.3f')} ({fmt(peer.get(key), '.3f')}{mark(ch.get(key + '_peer'))} · "
                      f"{fmt(q.get(key), '.3f')}{mark(ch.get(key + '_poisson'))})")
        t = r["truth"]
        genus = ",".join(map(str, g.get("genus") or [])) or "–"
        if r["noise"] > 0:
            noise = f"{fmt(noise_fraction_of_truth(r), '.3%')} / {r['noise']:.2%}"
        else:
            noise = f"{fmt(g.get('noise_estimate'), '.3%')} / 0"
        lines.append(
            f"| {r['cloud']} | {fmt(g.get('orientation_accuracy'), '.2%')}{mark(ch.get('orientation'))} "
            f"| {fs[0]} | {fs[1]} | {g.get('components', '–')} ({t['components']}){mark(ch.get('topology'))} "
            f"| {genus} ({','.join(map(str, t['genus']))}) | {'yes' if g.get('watertight') else 'no'} "
            f"| {noise}{mark(ch.get('noise'))} "
            f"| {g['seconds']:.2f} ({fmt(polygonize_share(g), '.0%')}) · {fmt(q.get('seconds'), '.2f')} "
            f"· {fmt(peer.get('seconds'), '.1f')} |")
    return head + "\n".join(lines) + "\n"


def missing_figures(rows):
    """Why a figure of a cloud gmpu reconstructed is shown as –: one line per missing column
    group (Poisson on gmpu's normals, the peer, gmpu's own scores). A failed gmpu run says why
    in its own row."""
    def why(run):
        text = (run or {}).get("error") or (run or {}).get("metrics_error") or "not run"
        return " ".join(str(text).split())[:200]

    out = []
    for r in rows:
        g = r["gmpu"]
        if not g.get("ok"):
            continue
        if g.get("metrics_error"):
            out.append(f"{r['cloud']}, gmpu's scores: {why(g)}")
        q = r.get("poisson_gmpu") or {}
        if not q.get("ok") or q.get("fscore_0.5") is None:
            out.append(f"{r['cloud']}, Poisson(gmpu): {why(q)}")
        if (r.get("peer") or {}).get("fscore_0.5") is None:
            runs = r.get("peer_runs") or {}
            reasons = "; ".join(f"{name}: {why(run)}" for name, run in sorted(runs.items())
                                if not run.get("ok") or run.get("fscore_0.5") is None)
            out.append(f"{r['cloud']}, peer: {reasons or 'no figure recorded'}")
    return out


def missing_note(rows):
    lines = missing_figures(rows)
    if not lines:
        return ""
    return "\nFigures shown as –, and why:\n\n" + "\n".join(f"- {l}" for l in lines) + "\n"


def ipsr_comparison(rows, ipsr):
    """gmpu beside the committed iPSR figures, on the clouds iPSR was run on."""
    out = []
    by_name = {r["cloud"]: r for r in rows}
    for cloud, ref in sorted(ipsr.items()):
        r = by_name.get(cloud)
        if not r or not r["gmpu"].get("ok") or ref.get("fscore_1") is None:
            continue
        g = r["gmpu"]
        speed = ref["seconds"] / g["wall"] if g.get("wall") else None
        out.append({"cloud": cloud, "ipsr": ref, "gmpu": g, "speed": speed,
                    "f1_ok": g.get("fscore_1") is not None and g["fscore_1"] >= ref["fscore_1"] - IPSR_F1_SLACK,
                    "speed_ok": speed is not None and speed >= IPSR_SPEEDUP})
    return out


def ipsr_table(comparison):
    if not comparison:
        return "_No committed iPSR figure for a cloud of this run._\n"
    head = ("| cloud | iPSR F@0.5% | iPSR F@1% | iPSR s | gmpu F@0.5% | gmpu F@1% | gmpu s (wall) "
            "| iPSR s / gmpu s |\n|---|---:|---:|---:|---:|---:|---:|---:|\n")
    lines = [f"| {c['cloud']} | {fmt(c['ipsr']['fscore_0.5'], '.3f')} | {fmt(c['ipsr']['fscore_1'], '.3f')} "
             f"| {c['ipsr']['seconds']:.0f} | {fmt(c['gmpu'].get('fscore_0.5'), '.3f')} "
             f"| {fmt(c['gmpu'].get('fscore_1'), '.3f')}{mark(c['f1_ok'])} | {c['gmpu']['wall']:.2f} "
             f"| {fmt(c['speed'], '.0f')}×{mark(c['speed_ok'])} |" for c in comparison]
    return head + "\n".join(lines) + "\n"


HELDOUT_INTRO = (
    "66 clouds generated by `tests/data/heldout/make.sh` from eleven closed meshes of CGAL's "
    "sample data (Debian's libcgal-demo) that no setting of gmpu was tuned on: armadillo, homer "
    "(organic), turbine (genus 11), anchor_dense (genus 4) (CAD parts), cheese (a block with 133 "
    "holes), and, added later, elk (thin antlers and legs, genus 1), bull, diplodocus (organic), "
    "dragknob, joint (genus 2), part (low-polygon CAD parts) × the corpus's six variants (clean, "
    "noise σ 0.5 % and 1 % of the diagonal, ten-fold nonuniform density, 5k and 1k points)")


def live_peers_section(intro, targets_heading, corpus, machine, load_note=""):
    """A README section of a set whose peers run in the benchmark (no committed figures, no
    iPSR): `intro` describes the clouds, `targets_heading` titles the targets' list."""
    rows = corpus["rows"]
    return (
        f"Measured on {machine}. {intro}. Peer: the "
        "better of Open3D's (Poisson depth 8) and CGAL's Poisson pipelines, **run in this benchmark** "
        "(time: normals + orientation + surface), column by column. Poisson(gmpu): Open3D's screened "
        "Poisson (depth 8, trimmed at the 1 % density quantile) on gmpu's own oriented normals. ✓/✗: "
        "the issue-13 target met/missed on that cloud." + load_note + "\n\n"
        f"#### {targets_heading}\n\n" + targets(rows, []) + "\n"
        "#### Per variant\n\n" + variant_table(rows) + "\n"
        "#### Per cloud\n\n<details><summary>" + f"{len(rows)} clouds</summary>\n\n"
        + cloud_table(rows) + "\n</details>\n" + missing_note(rows))


SPARSE_NOISY_INTRO = (
    "51 clouds generated by `tests/data/sparse_noisy/make.sh` from the corpus's 17 closed meshes, "
    "few points and noisy at once, as a hand-held or long-range scan sees a part: 1k points with "
    "noise σ 0.5 % and 1 % of the diagonal, 5k points with 1 % (the corpus has each condition "
    "alone). The screening's knee was set on these clouds (How it works, 3, *Noise finer than the "
    "grid*), so they are not held out")


def section(corpus, machine, load_note=""):
    """The README's corpus section (markdown)."""
    if corpus.get("set") == "heldout":  # the corpus's targets on models never tuned on
        return live_peers_section(HELDOUT_INTRO + ", scored by gmpu-metrics like the corpus",
                                  "Targets (issue 13, on models not tuned on)", corpus, machine, load_note)
    if corpus.get("set") == "sparse_noisy":  # issue 13 sets no orientation target for these
        return live_peers_section(SPARSE_NOISY_INTRO + "; scored by gmpu-metrics like the corpus",
                                  "Targets (issue 13's, where they apply)", corpus, machine, load_note)
    rows = corpus["rows"]
    comparison = ipsr_comparison(rows, corpus.get("ipsr", {}))
    live = corpus["peer_source"] == "live"
    peers = ("the better of Open3D's (Poisson depth 8) and CGAL's Poisson pipelines, **run in this "
             "benchmark** (pipelines.py; time: normals + orientation + surface)" if live else
             "the better of Open3D's and CGAL's Poisson pipelines **from the committed reference "
             "figures** `tests/data/corpus/peers.tsv` (not re-run here; `make bench-corpus "
             "CORPUS_PEERS=live` runs them; time: whole process)")
    return (
        f"Measured on {machine}. {len(rows)} clouds generated by `tests/data/corpus/make.sh` "
        "(17 closed meshes × clean, noise σ 0.5 % and 1 % of the diagonal, ten-fold nonuniform "
        "density, 5k and 1k points; 2 open scans × clean, noise 0.5 %), scored by gmpu-metrics "
        "(exact distances, 100k samples, F at 0.5 % and 1 % of the diagonal; orientation strict, "
        f"no global flip). Peer: {peers}, column by column. Poisson(gmpu): Open3D's screened "
        "Poisson (depth 8, vertices under the 1 % density quantile trimmed) on gmpu's own "
        "oriented normals. gmpu time: fit + orient + polygonize, one run. "
        "✓/✗: the issue-13 target met/missed on that cloud (open scans are not judged)."
        + load_note + "\n\n"
        "#### Targets (issue 13)\n\n" + targets(rows, comparison) + "\n"
        "#### Per variant\n\n" + variant_table(rows) + "\n"
        "#### iPSR at 1k points (committed figures, `tests/data/corpus/ipsr_reference.tsv`)\n\n"
        + ipsr_table(comparison) + "\n"
        "#### Per cloud\n\n<details><summary>" + f"{len(rows)} clouds</summary>\n\n"
        + cloud_table(rows) + "\n</details>\n" + missing_note(rows))


def write(results, folder):
    """folder/corpus.md from the corpus results."""
    import report

    m = results["machine"]
    text = section(results, f"{m['cpu']}, {m['cores']} cores, {m['memory_gb']} GB; run {m['date']}",
                   report.load_note(results["rows"]))
    (folder / "corpus.md").write_text(text)


if __name__ == "__main__":
    # Rebuild the section of an earlier run: corpus_report.py RESULTS_DIR/corpus
    import json
    import sys
    from pathlib import Path

    import corpus as corpus_run

    folder = Path(sys.argv[1])
    results = json.loads((folder / "corpus.json").read_text())
    for r in results["rows"]:
        r["peer"] = corpus_run.better_peer(r.get("peer_runs", {}))
    results["ipsr"] = corpus_run.ipsr_reference() if results.get("set", "corpus") == "corpus" else {}
    write(results, folder)
    print(f"{folder / 'corpus.md'} rewritten")
