"""Prints the site-packages directory that this interpreter reads for an installation prefix.

Used by bindings/python/meson.build at configure time (run with /usr/bin/python3):
meson's python module picks lib/python3/dist-packages on Debian, which Debian's
/usr/bin/python3 does not read for /usr/local; the interpreter's own sys.path is the
authority. Falls back to the sysconfig posix_prefix layout for prefixes it does not read.
"""
import os
import sys
import sysconfig

prefix = os.path.normpath(sys.argv[1])
for entry in sys.path:
    entry = os.path.normpath(entry) if entry else ""
    if os.path.basename(entry) in ("dist-packages", "site-packages") and entry.startswith(prefix + os.sep):
        if os.path.relpath(entry, prefix).split(os.sep)[0] == "lib":
            print(entry)
            break
else:
    print(sysconfig.get_path("purelib", "posix_prefix", vars={"base": prefix, "platbase": prefix}))
