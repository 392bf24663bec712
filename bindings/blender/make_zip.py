#!/usr/bin/python3
"""Builds the installable Blender add-on zip: the add-on package (gmpu_reconstruct/) with the
Python binding (bindings/python/gmpu) bundled inside it as gmpu_reconstruct/gmpu.

    /usr/bin/python3 bindings/blender/make_zip.py OUT.zip

The zip is reproducible (sorted entries, fixed timestamps), so an unchanged source gives a
byte-identical file. The shared library is not bundled: it is built for the machine, and
the add-on finds it through its preference or $GMPU_LIBRARY (gmpu_reconstruct/binding.py).
"""
import os
import sys
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
ADDON = "gmpu_reconstruct"
SOURCES = [
    (os.path.join(HERE, ADDON), ADDON),
    (os.path.join(ROOT, "bindings", "python", "gmpu"), ADDON + "/gmpu"),
]
_EPOCH = (1980, 1, 1, 0, 0, 0)


def files():
    for src, prefix in SOURCES:
        for name in sorted(os.listdir(src)):
            if name.endswith(".py") or name == "py.typed":
                yield os.path.join(src, name), f"{prefix}/{name}"


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__)
    out = argv[1]
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    tmp = out + ".tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for path, arcname in files():
            info = zipfile.ZipInfo(arcname, _EPOCH)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            with open(path, "rb") as f:
                z.writestr(info, f.read())
    os.replace(tmp, out)
    print(f"Blender add-on: {out}")


if __name__ == "__main__":
    main(sys.argv)
