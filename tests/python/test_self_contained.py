"""The repository carries its own test and benchmark data: no tracked file outside
tests/data may reach for a folder beside the checkout (the steering repository's shared/
exists only next to CI, never next to a user's clone)."""
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
FORBIDDEN = ("../shared", "shared/data", "shared/corpus", "shared/tools", '"shared" /', "'shared',")


def tracked_files():
    out = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True, check=True).stdout
    return [REPO / p for p in out.splitlines() if not p.startswith("tests/data/")]


def test_no_tracked_file_reads_a_folder_beside_the_checkout():
    offenders = []
    for path in tracked_files():
        if path.name == Path(__file__).name or not path.is_file():
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        for n, line in enumerate(text.splitlines(), 1):
            if any(f in line for f in FORBIDDEN):
                offenders.append(f"{path.relative_to(REPO)}:{n}: {line.strip()[:100]}")
    assert not offenders, "paths outside the repository:\n" + "\n".join(offenders)


def test_the_data_the_suites_name_is_in_the_repository():
    data = REPO / "tests" / "data"
    for rel in ("clouds/bunny_clean.ply", "clouds/bunny_clean_gt.ply", "meshes/bunny00.off",
                "scans/kitten.xyz", "corpus/make.sh", "tools/sample.py"):
        assert (data / rel).is_file(), rel
    assert len(list((data / "clouds").glob("*_meta.json"))) >= 8
    assert len(list((data / "corpus" / "meshes").glob("*.off"))) == 19
