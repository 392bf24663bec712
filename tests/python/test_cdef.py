"""The cffi cdef and the ABI summary (bindings/abi.txt, read by the Rust and Node tests) are
generated from include/gmpu/gmpu.h: these tests fail when they drift."""
import importlib.util
import re

import pytest
from cffi import FFI

import gmpu
from gmpu import _cdef
from gmpu._library import ffi, lib

from conftest import BINDINGS, REPO

HEADER = REPO / "include" / "gmpu" / "gmpu.h"


def _generator():
    spec = importlib.util.spec_from_file_location("generate_cdef", BINDINGS / "tools" / "generate_cdef.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def header_text():
    return HEADER.read_text(encoding="utf-8")


def test_checked_in_cdef_matches_the_header():
    gen = _generator()
    expected = gen.render_module(gen.generate_cdef(header_text()))
    actual = (BINDINGS / "gmpu" / "_cdef.py").read_text(encoding="utf-8")
    assert actual == expected, (
        "bindings/python/gmpu/_cdef.py is out of date with include/gmpu/gmpu.h: "
        "run /usr/bin/python3 bindings/python/tools/generate_cdef.py")


def test_checked_in_summary_matches_the_header():
    gen = _generator()
    expected = gen.generate_summary(gen.generate_cdef(header_text()))
    actual = (REPO / "bindings" / "abi.txt").read_text(encoding="utf-8")
    assert actual == expected, (
        "bindings/abi.txt is out of date with include/gmpu/gmpu.h: "
        "run /usr/bin/python3 bindings/python/tools/generate_cdef.py")


def test_summary_has_every_declaration():
    gen = _generator()
    summary = gen.generate_summary(_cdef.CDEF)
    kinds = [line.split("\t")[0] for line in summary.splitlines() if not line.startswith("#")]
    names = re.findall(r"GMPU_API\s+[^;(]*?\b(gmpu_\w+)\s*\(", header_text())
    assert kinds.count("fn") == len(names)
    assert kinds.count("opaque") == 3 and kinds.count("callback") == 1 and kinds.count("define") == 5
    assert "fn\tgmpu_surface_set_points_f32\tgmpu_status\tsurface:gmpu_surface *\txyz:const float *\t" \
           "count:size_t\tstride:size_t" in summary
    assert "field\tgmpu_param_info_t\tdoc\tconst char *" in summary
    changed = _cdef.CDEF.replace("double *value);", "float *value);", 1)
    assert gen.generate_summary(changed) != summary


def test_drift_is_detected():
    # The comparison above can fail: any declaration change in the header changes the cdef.
    gen = _generator()
    text = header_text()
    changed = text.replace("gmpu_status gmpu_surface_fit(gmpu_surface *surface);",
                           "gmpu_status gmpu_surface_fit(gmpu_surface *surface, int flags);")
    assert changed != text
    assert gen.generate_cdef(changed) != gen.generate_cdef(text)
    appended = text.replace("GMPU_PARAM_NOISE_SCALE = 11", "GMPU_PARAM_NOISE_SCALE = 11,\n    GMPU_PARAM_NEW = 12")
    assert "GMPU_PARAM_NEW = 12" in gen.generate_cdef(appended)


def test_cdef_is_the_header_without_preprocessor_and_export_macro():
    cdef = _cdef.CDEF
    assert "GMPU_API" not in cdef
    assert "extern" not in cdef and "__cplusplus" not in cdef and "#include" not in cdef
    assert "/*" not in cdef and "//" not in cdef
    # Only integer #defines survive (cffi exposes them as constants).
    for line in cdef.splitlines():
        if line.startswith("#"):
            assert re.fullmatch(r"#define GMPU_\w+ \d+", line), line


def test_generator_refuses_what_it_cannot_translate():
    gen = _generator()
    with pytest.raises(gen.CdefError):
        gen.generate_cdef("#ifdef FOO\n#ifdef BAR\nint x;\n#endif\n#endif\n")
    with pytest.raises(gen.CdefError):
        gen.generate_cdef("#if X\nint x;\n")


def test_every_header_function_is_exported_by_the_library():
    names = re.findall(r"GMPU_API\s+[^;(]*?\b(gmpu_\w+)\s*\(", header_text())
    assert len(names) == len(set(names)) >= 35
    assert set(names) == set(re.findall(r"\b(gmpu_\w+)\s*\(", _cdef.CDEF)) - {"gmpu_progress_fn"}
    for name in names:
        getattr(lib, name)  # AttributeError if the symbol is missing from libgmpu


def test_cdef_parses_standalone_and_matches_enums():
    other = FFI()
    other.cdef(_cdef.CDEF)
    for enum in ("gmpu_status", "gmpu_param", "gmpu_stage", "gmpu_stat"):
        assert other.typeof(enum).relements == ffi.typeof(enum).relements
    header_enums = dict(re.findall(r"\b(GMPU_(?:OK|ERROR_\w+|PARAM_\w+|STAGE_\w+|STAT_\w+))\s*=\s*(\d+)", header_text()))
    assert header_enums
    for name, value in header_enums.items():
        assert getattr(lib, name) == int(value), name


def test_header_and_library_versions_agree():
    m = {k: int(v) for k, v in re.findall(r"#define (GMPU_\w+) (\d+)", header_text())}
    assert lib.GMPU_VERSION_NUMBER == m["GMPU_VERSION_NUMBER"] == lib.gmpu_version_number()
    assert gmpu.abi_version == m["GMPU_ABI_VERSION"] == 1
    assert gmpu.__version__ == f"{m['GMPU_VERSION_MAJOR']}.{m['GMPU_VERSION_MINOR']}.{m['GMPU_VERSION_PATCH']}"


def test_every_status_has_its_exception_class_and_every_stage_its_enum():
    from gmpu._errors import ERROR_CLASSES
    statuses = {k for k in ffi.typeof("gmpu_status").relements if k != "GMPU_OK"}
    assert statuses == set(ERROR_CLASSES)
    stages = {k[len("GMPU_STAGE_"):]: v for k, v in ffi.typeof("gmpu_stage").relements.items()}
    assert stages == {s.name: int(s) for s in gmpu.Stage}


def test_statistic_names_are_the_headers_enumerators():
    """gmpu_stat_name (what the Node binding lists statistics by) names every gmpu_stat key,
    1..gmpu_stat_count() without gaps, as the enumerator's lower-case suffix."""
    enum = {v: k[len("GMPU_STAT_"):].lower() for k, v in ffi.typeof("gmpu_stat").relements.items()}
    count = lib.gmpu_stat_count()
    assert sorted(enum) == list(range(1, count + 1))
    assert {k: ffi.string(lib.gmpu_stat_name(k)).decode() for k in range(1, count + 1)} == enum
    assert lib.gmpu_stat_name(0) == ffi.NULL and lib.gmpu_stat_name(count + 1) == ffi.NULL
