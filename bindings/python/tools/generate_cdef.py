#!/usr/bin/env python3
"""Generates bindings/python/gmpu/_cdef.py (the cffi cdef) and bindings/abi.txt (the ABI
summary the Rust and Node bindings' tests compare their declarations with) from
include/gmpu/gmpu.h: the one header-sync mechanism of the bindings.

    /usr/bin/python3 bindings/python/tools/generate_cdef.py          # rewrite both
    /usr/bin/python3 bindings/python/tools/generate_cdef.py --check  # exit 1 if either drifted

The header is the single source of truth. The cdef is the header with comments removed,
every preprocessor line dropped (except `#define NAME <integer>`, which cffi understands and
exposes as a constant), the body of `#ifdef __cplusplus` blocks dropped, and the GMPU_API
export macro removed. Anything else conditional is refused, so a header change that this
simple transformation cannot handle fails loudly instead of producing a wrong cdef.
The summary is the cdef parsed by pycparser (cffi's own C parser), one declaration per
line, tab-separated:

    define  NAME  VALUE                 an integer #define
    opaque  NAME                        typedef struct NAME NAME; (no body)
    enum    TYPE  NAME  VALUE           one enumerator
    field   STRUCT  NAME  C-TYPE        one member of a struct with a body
    fn      NAME  C-RETURN  [PARAM:C-TYPE ...]
    callback  NAME  C-RETURN  [PARAM:C-TYPE ...]   a function-pointer typedef

with C types spelled "const double *", "gmpu_surface **". tests/python/test_cdef.py fails
when the checked-in _cdef.py or abi.txt differs from this output.
"""
import argparse
import hashlib
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
HEADER = os.path.join(REPO, "include", "gmpu", "gmpu.h")
TARGET = os.path.join(REPO, "bindings", "python", "gmpu", "_cdef.py")
SUMMARY = os.path.join(REPO, "bindings", "abi.txt")

_TOKENS = re.compile(r'"(?:\\.|[^"\\])*"|\'(?:\\.|[^\'\\])*\'|/\*.*?\*/|//[^\n]*', re.S)
_INT_DEFINE = re.compile(r"#\s*define\s+([A-Za-z_]\w*)\s+(\(?-?(?:0[xX][0-9a-fA-F]+|\d+)[uUlL]*\)?)\s*$")
_GUARD_NAMES = ("__cplusplus",)


class CdefError(ValueError):
    """The header uses a construct this generator does not translate."""


def strip_comments(text: str) -> str:
    """Removes C and C++ comments (keeping line breaks, so line numbers survive)."""

    def repl(m: "re.Match[str]") -> str:
        s = m.group(0)
        if s.startswith("/*"):
            return "\n" * s.count("\n") or " "
        if s.startswith("//"):
            return ""
        return s

    return _TOKENS.sub(repl, text)


def generate_cdef(header: str) -> str:
    """The cffi cdef for the given gmpu.h text."""
    lines = strip_comments(header).splitlines()
    original = header.splitlines()
    out = []
    # One entry per open conditional: True while inside a block whose body is dropped
    # (#ifdef __cplusplus), False for blocks whose directives are dropped but whose
    # declarations are kept (the include guard).
    stack = []
    for number, raw in enumerate(lines, 1):
        line = raw.strip()
        if line.startswith("#"):
            directive = line[1:].strip()
            word = directive.split(None, 1)[0] if directive else ""
            arg = directive[len(word):].strip()
            if word in ("if", "ifdef", "ifndef"):
                stack.append(word == "ifdef" and arg in _GUARD_NAMES)
            elif word in ("elif", "else"):
                if not stack:
                    raise CdefError(f"line {number}: #{word} without #if")
            elif word == "endif":
                if not stack:
                    raise CdefError(f"line {number}: #endif without #if")
                stack.pop()
            elif word == "define":
                m = _INT_DEFINE.match(line)
                if m and not any(stack):
                    out.append(f"#define {m.group(1)} {m.group(2)}")
            elif word not in ("include", "pragma", "undef"):
                raise CdefError(f"line {number}: unsupported directive #{word}")
            continue
        if any(stack):
            continue  # C++-only lines: extern "C" { ... }
        if not line:
            # A line left empty by a removed comment is dropped; a blank line of the header
            # is kept (once), so the cdef reads like the header.
            if original[number - 1].strip() == "" and out and out[-1] != "":
                out.append("")
            continue
        if len(stack) > 1:
            # Declarations inside a conditional other than the include guard would need a
            # real preprocessor to decide whether they exist.
            raise CdefError(f"line {number}: declaration inside a nested conditional: {line!r}")
        line = re.sub(r"\bGMPU_API\b\s*", "", raw.rstrip())
        out.append(line)
    if stack:
        raise CdefError("unterminated conditional")
    while out and out[-1] == "":
        out.pop()
    while out and out[0] == "":
        out.pop(0)
    text = "\n".join(out) + "\n"
    if "GMPU_API" in text:
        raise CdefError("GMPU_API left in the cdef")
    return text


def render_module(cdef: str) -> str:
    """The text of gmpu/_cdef.py holding the cdef."""
    if "'''" in cdef or "\\" in cdef:
        raise CdefError("the cdef contains ''' or a backslash")
    digest = hashlib.sha256(cdef.encode()).hexdigest()
    return (
        "# Generated by bindings/python/tools/generate_cdef.py from include/gmpu/gmpu.h.\n"
        "# Do not edit: rerun the generator (tests/python/test_cdef.py fails on drift).\n"
        f"CDEF_SHA256 = {digest!r}\n"
        f"CDEF = '''\n{cdef}'''\n"
    )


def _c_type(node) -> str:
    from pycparser import c_ast
    if isinstance(node, c_ast.PtrDecl):
        inner = _c_type(node.type)
        return inner + ("*" if inner.endswith("*") else " *") + (" const" if node.quals else "")
    if isinstance(node, c_ast.TypeDecl):
        t = node.type
        name = " ".join(t.names) if isinstance(t, c_ast.IdentifierType) else t.name
        return " ".join(node.quals + [name])
    raise CdefError(f"unsupported type {node!r}")


def _params(func) -> list:
    from pycparser import c_ast
    out = []
    for p in (func.args.params if func.args else []):
        if isinstance(p, c_ast.Typename):  # (void)
            continue
        out.append(f"{p.name}:{_c_type(p.type)}")
    return out


def generate_summary(cdef: str) -> str:
    """The ABI summary (see the module's doc) of a cdef."""
    from pycparser import CParser, c_ast
    prelude_types = ("unsigned long size_t", "unsigned int uint32_t", "long int64_t", "unsigned long uint64_t",
                     "unsigned char uint8_t")
    prelude = "".join(f"typedef {t}; " for t in prelude_types) + "\n"
    lines, body = [], []
    for line in cdef.splitlines():
        m = re.match(r"#define (\w+) (\d+)$", line)
        if m:
            lines.append(f"define\t{m.group(1)}\t{m.group(2)}")
        else:
            body.append(line)
    ast = CParser().parse(prelude + "\n".join(body), "gmpu.h")
    for node in ast.ext[len(prelude_types):]:
        t = node.type
        if isinstance(node, c_ast.Typedef) and isinstance(t, c_ast.TypeDecl) and isinstance(t.type, c_ast.Enum):
            value = 0
            for e in t.type.values.enumerators:
                value = int(e.value.value) if e.value is not None else value
                lines.append(f"enum\t{node.name}\t{e.name}\t{value}")
                value += 1
        elif isinstance(node, c_ast.Typedef) and isinstance(t, c_ast.TypeDecl) and isinstance(t.type, c_ast.Struct):
            if t.type.decls is None:
                lines.append(f"opaque\t{node.name}")
            for d in t.type.decls or []:
                lines.append(f"field\t{node.name}\t{d.name}\t{_c_type(d.type)}")
        elif isinstance(node, c_ast.Typedef) and isinstance(t, c_ast.PtrDecl) and isinstance(t.type, c_ast.FuncDecl):
            lines.append("\t".join(["callback", node.name, _c_type(t.type.type)] + _params(t.type)))
        elif isinstance(node, c_ast.Decl) and isinstance(t, c_ast.FuncDecl):
            lines.append("\t".join(["fn", node.name, _c_type(t.type)] + _params(t)))
        else:
            raise CdefError(f"no summary line for {node.coord}: {type(node).__name__}")
    return ("# The C ABI of include/gmpu/gmpu.h, one declaration per line (tab-separated), generated\n"
            "# by bindings/python/tools/generate_cdef.py: do not edit. The Rust and Node tests\n"
            "# compare their declarations with it.\n" + "\n".join(lines) + "\n")


def _sync(path: str, text: str, check: bool) -> bool:
    """Writes text to path (or, with check, only compares); True when it was up to date."""
    try:
        with open(path, encoding="utf-8") as f:
            current = f.read()
    except FileNotFoundError:
        current = None
    if current == text:
        print(f"{path} is up to date")
        return True
    if check:
        print(f"{path} is out of date with {HEADER}; run {sys.argv[0]}", file=sys.stderr)
        return False
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    print(f"wrote {path}")
    return True


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="only compare; exit 1 on drift")
    ap.add_argument("--header", default=HEADER)
    ap.add_argument("--output", default=TARGET)
    ap.add_argument("--summary", default=SUMMARY)
    args = ap.parse_args()
    with open(args.header, encoding="utf-8") as f:
        cdef = generate_cdef(f.read())
    fresh = [_sync(args.output, render_module(cdef), args.check),
             _sync(args.summary, generate_summary(cdef), args.check)]
    return 0 if all(fresh) else 1


if __name__ == "__main__":
    sys.exit(main())
