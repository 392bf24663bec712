"""The include layering of lib/ (docs/ARCHITECTURE.md, "Layers"): a module may include its
own headers and those of modules on a lower layer, never one on its own layer or above.
Reads every #include "module/..." line under lib/."""
import re
from pathlib import Path

LIB = Path(__file__).resolve().parents[2] / "lib"

# Lowest first. Modules on one layer are independent of each other.
LAYERS = [
    ["core"],
    ["geometry", "io"],
    ["model"],
    ["fit", "implicit"],
    ["orient"],
    ["mesh"],
    ["pipeline"],
    ["api"],
]
RANK = {module: rank for rank, modules in enumerate(LAYERS) for module in modules}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([a-z_]+)/', re.M)


def violations(lib: Path = LIB):
    found = []
    for source in sorted(lib.glob("*/*.[ch]pp")):
        module = source.parent.name
        for target in INCLUDE.findall(source.read_text()):
            if target == module or target == "gmpu":  # its own files; the public header
                continue
            if module not in RANK or target not in RANK:
                found.append(f"{source.relative_to(lib)}: module {module!r} or {target!r} is not in LAYERS")
            elif RANK[target] >= RANK[module]:
                found.append(f"{source.relative_to(lib)} includes {target}/ (layer {RANK[target]} >= {RANK[module]})")
    return found


def test_no_module_includes_its_own_layer_or_above():
    assert violations() == []


def test_the_check_sees_an_upward_include(tmp_path):
    (tmp_path / "model").mkdir()
    (tmp_path / "model" / "octree.hpp").write_text('#include "fit/local_shape.hpp"\n')
    assert violations(tmp_path) == ["model/octree.hpp includes fit/ (layer 3 >= 2)"]
