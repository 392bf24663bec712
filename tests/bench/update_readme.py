#!/usr/bin/python3
"""Regenerates the README's benchmark section from a `make bench` run.

    update_readme.py [RESULTS_DIR] [--readme README.md] [--assets docs/bench]

Replaces what lies between the `<!-- bench:begin -->` and `<!-- bench:end -->` lines of
the README (or, failing those, `<!-- results:begin -->` / `<!-- results:end -->`) with
RESULTS_DIR/summary.md, and copies the plots and renders it links to into the assets
folder (bench-results/ itself is not committed). Exits 1 when the README has no such
markers, so that a section is never silently left stale.
"""
import argparse
import re
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MARKERS = [("<!-- bench:begin -->", "<!-- bench:end -->"),
           ("<!-- results:begin -->", "<!-- results:end -->")]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="?", type=Path, default=ROOT / "bench-results")
    ap.add_argument("--readme", type=Path, default=ROOT / "README.md")
    ap.add_argument("--assets", type=Path, default=ROOT / "docs" / "bench",
                    help="where the linked PNGs are copied (committed with the README)")
    args = ap.parse_args()

    summary_path = args.results / "summary.md"
    if not summary_path.exists():
        sys.exit(f"update_readme: {summary_path} is missing: run `make bench` first")
    if not args.readme.exists():
        sys.exit(f"update_readme: {args.readme} does not exist")
    readme = args.readme.read_text()
    pair = next(((b, e) for b, e in MARKERS if readme.count(b) == 1 and readme.count(e) == 1
                 and readme.index(b) < readme.index(e)), None)
    if pair is None:
        sys.exit(f"update_readme: {args.readme} needs one '{MARKERS[0][0]}' line and, after it, "
                 f"one '{MARKERS[0][1]}' line around the benchmark section")
    begin, end = pair

    summary = summary_path.read_text()
    # Copy every linked PNG and point the link at the copy, relative to the README.
    prefix = Path(*args.assets.resolve().relative_to(args.readme.resolve().parent).parts)

    def relink(match):
        target = match.group(2)
        source = args.results / target
        if not source.exists():
            return match.group(0)
        dest = args.assets / target
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, dest)
        return f"{match.group(1)}({(prefix / target).as_posix()})"

    summary = re.sub(r"(\]\s*)\(([^)\s]+\.png)\)", relink, summary)
    head, rest = readme.split(begin, 1)
    _, tail = rest.split(end, 1)
    args.readme.write_text(f"{head}{begin}\n{summary.rstrip()}\n{end}{tail}")
    print(f"update_readme: {args.readme} benchmark section regenerated from {summary_path}")


if __name__ == "__main__":
    main()
