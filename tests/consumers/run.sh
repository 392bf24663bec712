#!/bin/bash
# Builds consumer.c against an installed gmpu every way a user would, and runs each program:
#   shared   cc ... $(pkg-config --cflags --libs gmpu) -Wl,-rpath,$(pkg-config --variable=libdir gmpu);
#   static   libgmpu.a with $(pkg-config --static --cflags --libs gmpu): Libs.private complete
#            (the system libraries stay shared: Debian ships meshoptimizer as a .so only);
#   cmake    find_package(gmpu) -> gmpu::gmpu and gmpu::gmpu_static;
#   meson    gmpu as a subproject (subprojects/gmpu -> this source tree), dependency('gmpu').
# The install is `meson install --destdir` of the given build directory into a temporary
# directory. pkg-config there sees only gmpu.pc (PKG_CONFIG_LIBDIR), which proves that
# gmpu.pc needs neither eigen3.pc nor nanoflann.pc.
# Usage: tests/consumers/run.sh BUILD_DIR [shared|static|cmake|meson ...]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
source_root=$(cd "$here/../.." && pwd)
build=$(cd "${1:?usage: run.sh BUILD_DIR [WAY ...]}" && pwd)
shift
ways=("$@")
[ ${#ways[@]} -gt 0 ] || ways=(shared static cmake meson)

work=$(mktemp -d "${TMPDIR:-/tmp}/gmpu-consumers.XXXXXX")
trap 'rm -rf "$work"' EXIT

option() {  # the value of a meson option of the build directory
    /usr/bin/python3 -c 'import json, sys
print(next(o["value"] for o in json.load(open(sys.argv[1])) if o["name"] == sys.argv[2]))' \
        "$build/meson-info/intro-buildoptions.json" "$1"
}
prefix=$(option prefix)
libdir=$(option libdir)
case $libdir in /*) ;; *) libdir=$prefix/$libdir ;; esac
root=$work/dest$prefix
lib=$work/dest$libdir
meson install -C "$build" --no-rebuild --quiet --destdir "$work/dest" >/dev/null

# Every program prints "VERSION TRIANGLES": this tree's version, and a mesh.
version=$(sed -n "s/^  version: '\([^']*\)'.*/\1/p" "$source_root/meson.build")
check_run() {
    local name=$1 out
    shift
    out=$("$@") || { echo "consumers: $name: the program failed" >&2; exit 1; }
    if [[ ! $out =~ ^$version\ [1-9][0-9]*$ ]]; then
        echo "consumers: $name printed '$out', expected '$version <triangles>'" >&2
        exit 1
    fi
    echo "consumers: $name ok ($out)"
}

# The staged install answers for the prefix it was configured with.
pc() { PKG_CONFIG_LIBDIR=$lib/pkgconfig PKG_CONFIG_PATH= pkg-config --define-variable=prefix="$root" "$@" gmpu; }

for way in "${ways[@]}"; do
    case $way in
    shared)
        cflags=$(pc --cflags)
        if [[ $cflags == *eigen* || $cflags == *nanoflann* ]]; then
            echo "consumers: gmpu.pc leaks a private dependency into Cflags: $cflags" >&2
            exit 1
        fi
        cc -o "$work/shared" "$here/consumer.c" $(pc --cflags --libs) -lm -Wl,-rpath,"$(pc --variable=libdir)"
        check_run shared "$work/shared"
        ;;
    static)
        # -l:libgmpu.a: the archive, even where the shared library sits beside it.
        flags=$(pc --static --cflags --libs)
        cc -o "$work/static" "$here/consumer.c" ${flags//-lgmpu/-l:libgmpu.a} -lm
        if [[ $(readelf -d "$work/static") == *NEEDED*libgmpu* ]]; then
            echo "consumers: the static program still needs libgmpu.so" >&2
            exit 1
        fi
        check_run static "$work/static"
        ;;
    cmake)
        mkdir "$work/cmake"
        cp "$here/cmake/CMakeLists.txt" "$here/consumer.c" "$work/cmake/"
        cmake -S "$work/cmake" -B "$work/cmake/build" -DCMAKE_PREFIX_PATH="$root" >/dev/null
        cmake --build "$work/cmake/build" >/dev/null
        check_run cmake-shared "$work/cmake/build/consumer_shared"
        check_run cmake-static "$work/cmake/build/consumer_static"
        if [[ $(readelf -d "$work/cmake/build/consumer_static") == *NEEDED*libgmpu* ]]; then
            echo "consumers: gmpu::gmpu_static linked the shared library" >&2
            exit 1
        fi
        ;;
    meson)
        mkdir -p "$work/meson/subprojects"
        cp "$here/meson/meson.build" "$here/consumer.c" "$work/meson/"
        ln -s "$source_root" "$work/meson/subprojects/gmpu"
        # -O0: this checks the wiring, not the speed, and compiles the library fastest.
        meson setup "$work/meson/build" "$work/meson" --force-fallback-for=gmpu \
            -Doptimization=0 -Ddebug=false >/dev/null
        ninja -C "$work/meson/build" >/dev/null
        check_run meson-subproject "$work/meson/build/consumer"
        ;;
    *)
        echo "consumers: unknown way '$way'" >&2
        exit 2
        ;;
    esac
done
