#!/usr/bin/python3
"""Regenerates the README's benchmark sections from a `make bench` run.

    update_readme.py [RESULTS_DIR] [--readme README.md] [--assets docs/bench]
                     [--sections bench,corpus]

Each section replaces what lies between its two marker lines in the README:
  bench   RESULTS_DIR/summary.md         between `<!-- bench:begin -->` and `<!-- bench:end -->`
          (or, failing those, `<!-- results:begin -->` / `<!-- results:end -->`)
  corpus  RESULTS_DIR/corpus/corpus.md   between `<!-- corpus:begin -->` and `<!-- corpus:end -->`
  heldout RESULTS_DIR/heldout/corpus.md  between `<!-- heldout:begin -->` and `<!-- heldout:end -->`
  sparse_noisy RESULTS_DIR/sparse_noisy/corpus.md  between `<!-- sparse_noisy:begin -->` and
          `<!-- sparse_noisy:end -->`
A section whose file is missing is skipped (said on stdout) unless it was asked for by
--sections; the plots and renders a section links to are copied into the assets folder
(bench-results/ itself is not committed). Exits 1 when the README lacks a section's markers,
so that a section is never silently left stale.
"""
import argparse
import re
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SECTIONS = {
    "bench": ("summary.md", [("<!-- bench:begin -->", "<!-- bench:end -->"),
                             ("<!-- results:begin -->", "<!-- results:end -->")]),
    "corpus": ("corpus/corpus.md", [("<!-- corpus:begin -->", "<!-- corpus:end -->")]),
    "heldout": ("heldout/corpus.md", [("<!-- heldout:begin -->", "<!-- heldout:end -->")]),
    "sparse_noisy": ("sparse_noisy/corpus.md", [("<!-- sparse_noisy:begin -->", "<!-- sparse_noisy:end -->")]),
}


def replace_section(readme, markers, text):
    pair = next(((b, e) for b, e in markers if readme.count(b) == 1 and readme.count(e) == 1
                 and readme.index(b) < readme.index(e)), None)
    if pair is None:
        return None
    begin, end = pair
    head, rest = readme.split(begin, 1)
    _, tail = rest.split(end, 1)
    return f"{head}{begin}\n{text.rstrip()}\n{end}{tail}"


def relinked(summary, results, readme_path, assets):
    """Copies every linked PNG and points the link at the copy, relative to the README."""
    prefix = Path(*assets.resolve().relative_to(readme_path.resolve().parent).parts)

    def relink(match):
        target = match.group(2)
        source = results / target
        if not source.exists():
            return match.group(0)
        dest = assets / target
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, dest)
        return f"{match.group(1)}({(prefix / target).as_posix()})"

    return re.sub(r"(\]\s*)\(([^)\s]+\.png)\)", relink, summary)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="?", type=Path, default=ROOT / "bench-results")
    ap.add_argument("--readme", type=Path, default=ROOT / "README.md")
    ap.add_argument("--assets", type=Path, default=ROOT / "docs" / "bench",
                    help="where the linked PNGs are copied (committed with the README)")
    ap.add_argument("--sections", default="", help="comma-separated: bench, corpus, heldout, sparse_noisy (default: "
                    "every section whose file the results folder has)")
    args = ap.parse_args()

    if not args.readme.exists():
        sys.exit(f"update_readme: {args.readme} does not exist")
    asked = [s for s in args.sections.split(",") if s]
    for name in asked:
        if name not in SECTIONS:
            sys.exit(f"update_readme: unknown section {name} (known: {', '.join(SECTIONS)})")
    readme = args.readme.read_text()
    done = []
    for name, (file, markers) in SECTIONS.items():
        if asked and name not in asked:
            continue
        path = args.results / file
        if not path.exists():
            if asked:
                sys.exit(f"update_readme: {path} is missing: run the benchmark first")
            print(f"update_readme: no {path}: the {name} section is left as it is")
            continue
        updated = replace_section(readme, markers, relinked(path.read_text(), path.parent,
                                                             args.readme, args.assets))
        if updated is None:
            sys.exit(f"update_readme: {args.readme} needs one '{markers[0][0]}' line and, after it, "
                     f"one '{markers[0][1]}' line around the {name} section")
        readme = updated
        done.append(f"{name} (from {path})")
    if not done:
        sys.exit(f"update_readme: nothing in {args.results}: run `make bench` first")
    args.readme.write_text(readme)
    print(f"update_readme: {args.readme}: regenerated " + ", ".join(done))


if __name__ == "__main__":
    main()
