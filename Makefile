# Thin wrapper over meson: `make demo` and `make test` work on a fresh Debian 12 machine
# (they apt-get what is missing first). Everything real lives in meson.build and tests/.
SHELL := /bin/bash
PYTHON := /usr/bin/python3
# rustup's cargo lives here on this kind of machine, whatever PATH the caller has.
export PATH := $(HOME)/.cargo/bin:$(PATH)
BUILD := build
SAN_BUILD := build-sanitize
SAMPLE := examples/data/bunny.ply
DEMO_OUT := $(BUILD)/demo/bunny_mesh.ply

# Debian packages each target needs; `deps-*` installs only the missing ones.
CORE_PKGS := g++ pkg-config meson ninja-build libeigen3-dev libnanoflann-dev libcmocka-dev libmeshoptimizer-dev
TEST_PKGS := $(CORE_PKGS) python3-cffi python3-numpy python3-pytest python3-matplotlib python3-scipy python3-distributed \
             valgrind clang libclang-rt-14-dev time python3-open3d \
             cmake python3-venv python3-mesonpy python3-build
# libcgal-demo: CGAL's sample meshes (/usr/share/doc/libcgal-dev/data.tar.gz), the held-out models.
BENCH_PKGS := $(TEST_PKGS) libcgal-dev libcgal-demo libgmp-dev libmpfr-dev

define apt_install
	@missing=""; for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "Installing missing Debian packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" -ne 0 ] && SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing; \
	fi
endef

.PHONY: all deps deps-test deps-bench build demo test test-c test-python test-node test-rust test-consumers \
        test-sanitize bench bench-quick bench-corpus bench-heldout bench-sparse-noisy bench-thinwall fuzz clean plugins deps-plugins test-plugins \
        plugin-screenshots

all: build

deps:
	$(call apt_install,$(CORE_PKGS))

deps-test:
	$(call apt_install,$(TEST_PKGS))
	@# Node.js: the machine's own (NodeSource, with npm) when present; Debian's otherwise.
	@command -v node >/dev/null && command -v npm >/dev/null || $(MAKE) --no-print-directory deps-node

.PHONY: deps-node
deps-node:
	$(call apt_install,nodejs npm)

deps-bench:
	$(call apt_install,$(BENCH_PKGS))

$(BUILD)/build.ninja:
	meson setup $(BUILD) --buildtype=release

build: deps $(BUILD)/build.ninja
	ninja -C $(BUILD)

demo: build
	@mkdir -p $(BUILD)/demo
	$(BUILD)/examples/gmpu-reconstruct $(SAMPLE) -o $(DEMO_OUT) --normals-out $(BUILD)/demo/bunny_oriented_points.ply
	@echo
	@echo "Mesh written to $(abspath $(DEMO_OUT))"
	@echo "Oriented points written to $(abspath $(BUILD)/demo/bunny_oriented_points.ply)"

test: deps-test build
	$(MAKE) --no-print-directory test-c test-load test-python test-node test-rust test-plugins test-consumers \
	  test-sanitize test-tsan test-valgrind fuzz-quick

test-c: build
	meson test -C $(BUILD) --print-errorlogs

test-python: build
	$(PYTHON) -m pytest tests/python -q -p no:cacheprovider --basetemp=$(BUILD)/pytest-python

test-node: build
	cd bindings/node && npm ci --no-audit --no-fund --loglevel=error
	cd examples/node && npm ci --no-audit --no-fund --loglevel=error
	node --test tests/node/

test-rust: build
	@command -v cargo >/dev/null || { echo "test-rust: cargo not found (Rust >= 1.77 is needed)"; exit 1; }
	cd bindings/rust && GMPU_LIBRARY=$(abspath $(BUILD))/lib/libgmpu.so.1 cargo test --offline
	tests/consumers/cargo_user.sh
	$(MAKE) --no-print-directory test-cross

# Programs on an installed gmpu, built the ways the README's install section shows: C through
# pkg-config (shared, static), CMake and a meson subproject; the Python package through pip
# and python3 -m build (from a clone: the committed files) in fresh venvs.
.PHONY: test-consumers
test-consumers: build
	tests/consumers/run.sh $(BUILD)
	tests/consumers/python_wheel.sh

# Same input and parameters -> same mesh in C, Python, Node and Rust (tests/cross/).
.PHONY: test-cross
test-cross: build
	@for d in bindings/node examples/node; do [ -d $$d/node_modules ] || \
	  (cd $$d && npm ci --no-audit --no-fund --loglevel=error) || exit 1; done
	$(PYTHON) tests/cross/cross_language.py --build $(BUILD)

# The progress cadence and cancel latency are promised in CPU time, so they must hold on a
# busy machine: the cancel suite and the Python progress tests beside two busy loops. (The
# Ctrl-C tests are left out: they time a signal in wall time, which the busy loops delay.)
# Half test-c's cloud (200k points; test-c runs the suite on 400k unloaded) keeps it near a
# minute and a half on 2 cores.
.PHONY: test-load
test-load: build
	GMPU_CANCEL_POINTS=200000 tests/load/with_busy_cores.sh meson test -C $(BUILD) --no-rebuild --print-errorlogs cancel
	tests/load/with_busy_cores.sh $(PYTHON) -m pytest tests/python/test_progress.py -q -p no:cacheprovider \
	  --basetemp=$(BUILD)/pytest-load -k "not ctrl_c"

# ---- plugins (issue 16): the Blender add-on and the ParaView plugin ------------------------
# build/plugins holds the add-on zip (the binding bundled inside), the ParaView plugin file and
# the binding beside it (which the plugin imports when gmpu is not installed).
PLUGIN_DIR := $(BUILD)/plugins
PLUGIN_PKGS := blender paraview python3-cffi python3-numpy xvfb
# Throwaway Blender user directories: the test installs the add-on, never into ~/.config.
BLENDER_SANDBOX = BLENDER_USER_SCRIPTS=$$sandbox/scripts BLENDER_USER_CONFIG=$$sandbox/config

plugins:
	$(PYTHON) bindings/blender/make_zip.py $(PLUGIN_DIR)/gmpu_reconstruct.zip
	rm -rf $(PLUGIN_DIR)/gmpu && mkdir -p $(PLUGIN_DIR)/gmpu
	cp bindings/python/gmpu/*.py bindings/python/gmpu/py.typed $(PLUGIN_DIR)/gmpu/
	cp bindings/paraview/gmpu_paraview.py $(PLUGIN_DIR)/
	@echo "ParaView plugin: $(PLUGIN_DIR)/gmpu_paraview.py"

deps-plugins:
	$(call apt_install,$(PLUGIN_PKGS))

# Headless (tests/plugins/): blender -b; the add-on's modal path and Esc in a Blender window
# on Xvfb; pvpython.
test-plugins: deps-plugins build plugins
	sandbox=$$(mktemp -d) && trap 'rm -rf "$$sandbox"' EXIT && \
	  env -u GMPU_LIBRARY GMPU_BUILD=$(abspath $(BUILD)) $(BLENDER_SANDBOX) \
	  blender -b --factory-startup --python-exit-code 1 --python tests/plugins/blender_test.py
	sandbox=$$(mktemp -d) && trap 'rm -rf "$$sandbox"' EXIT && \
	  env -u GMPU_LIBRARY GMPU_BUILD=$(abspath $(BUILD)) $(BLENDER_SANDBOX) \
	  xvfb-run -a -s "-screen 0 1280x1024x24" \
	  blender --factory-startup --enable-event-simulate --python tests/plugins/blender_ui_test.py
	GMPU_BUILD=$(abspath $(BUILD)) GMPU_LIBRARY=$(abspath $(BUILD))/lib/libgmpu.so.1 \
	  pvpython --force-offscreen-rendering tests/plugins/paraview_test.py

# The README's pictures (docs/plugins/): Cycles on the CPU under blender -b, and ParaView's
# SaveScreenshot, whose OpenGL context Debian's X11 build of ParaView takes from Xvfb.
plugin-screenshots: deps-plugins build plugins
	@mkdir -p docs/plugins
	sandbox=$$(mktemp -d) && trap 'rm -rf "$$sandbox"' EXIT && \
	  GMPU_BUILD=$(abspath $(BUILD)) $(BLENDER_SANDBOX) blender -b --factory-startup --python-exit-code 1 \
	  --python bindings/blender/screenshot.py -- docs/plugins/blender.png
	GMPU_BUILD=$(abspath $(BUILD)) GMPU_LIBRARY=$(abspath $(BUILD))/lib/libgmpu.so.1 \
	  xvfb-run -a -s "-screen 0 1280x1024x24" pvpython --force-offscreen-rendering \
	  bindings/paraview/screenshot.py docs/plugins/paraview.png

# ---- robustness (issue 6): sanitizers, valgrind, fuzzing, the hostile corpus -------------
# build-sanitize: clang, ASan + UBSan (any report aborts), for the C suites and the CLI on
# the hostile corpus. The fuzz targets build apart (build-fuzz, tests/fuzz/run.sh): the suites
# would run several times slower under libFuzzer's coverage instrumentation.
TSAN_BUILD := build-tsan
FUZZ_BUILD := build-fuzz
SAN_SETUP := -Db_sanitize=address,undefined -Db_lundef=false \
             -Doptimization=2 -Ddebug=true \
             -Dcpp_args=-fno-sanitize-recover=all -Dc_args=-fno-sanitize-recover=all
SAN_ENV := ASAN_OPTIONS=halt_on_error=1:abort_on_error=1:detect_leaks=1 \
           UBSAN_OPTIONS=halt_on_error=1:abort_on_error=1:print_stacktrace=1
# Every C suite registered in tests/c/meson.build (the lines "  'name': files(...)"), less
# shapes (the longest under ASan; the pipeline it drives runs here through the other suites,
# the fuzzers and the hostile corpus) and metrics (a timing assertion).
# `make test-sanitize SAN_SKIP=` runs them all.
C_SUITES = $(shell sed -n "s/^  '\([a-z0-9_]*\)': files.*/\1/p" tests/c/meson.build)
SAN_SKIP ?= shapes metrics
SAN_SUITES = $(filter-out $(SAN_SKIP),$(C_SUITES))
# Under valgrind (~30x slower): the robustness suites and the C ABI ones, small inputs.
VALGRIND_SUITES := abi_errors limits cancel concurrency cli io io_abi
FUZZ_SECONDS ?= 300
FUZZ_QUICK_SECONDS ?= 15

$(SAN_BUILD)/build.ninja:
	CC=clang CXX=clang++ meson setup $(SAN_BUILD) $(SAN_SETUP)

.PHONY: test-tsan test-valgrind fuzz-quick
test-sanitize: deps-test $(SAN_BUILD)/build.ninja
	ninja -C $(SAN_BUILD) examples/gmpu-reconstruct $(addprefix tests/c/test_,$(SAN_SUITES))
	$(SAN_ENV) meson test -C $(SAN_BUILD) --no-rebuild --print-errorlogs --timeout-multiplier 3 $(SAN_SUITES)
	rm -rf $(SAN_BUILD)/hostile
	$(PYTHON) tests/cli/hostile_corpus.py generate $(SAN_BUILD)/hostile
	$(SAN_ENV) $(PYTHON) tests/cli/hostile_corpus.py run $(SAN_BUILD)/examples/gmpu-reconstruct $(SAN_BUILD)/hostile

# ThreadSanitizer: concurrent evaluate from 8 threads on one surface, separate surfaces in
# separate threads (tests/c/test_concurrency.c), against a TSan build of the library. That
# build leaves the precompiled header out (b_pch=false), so every source is also compiled
# with only the includes it names (lib/pch/gmpu_pch.hpp).
test-tsan: deps-test
	@[ -f $(TSAN_BUILD)/build.ninja ] || meson setup $(TSAN_BUILD) -Db_sanitize=thread -Db_lundef=false \
	  -Dtests=false -Doptimization=2 -Ddebug=true -Db_pch=false
	ninja -C $(TSAN_BUILD) lib/libgmpu.so.1.0.0
	cc -std=c11 -O1 -g -fsanitize=thread -Iinclude tests/c/test_concurrency.c tests/c/abort_on_failure.c \
	  -o $(TSAN_BUILD)/test_concurrency -L$(TSAN_BUILD)/lib -lgmpu -lcmocka -lm -pthread \
	  -Wl,-rpath,$(abspath $(TSAN_BUILD))/lib
	TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 $(TSAN_BUILD)/test_concurrency

# valgrind memcheck on the release build: any error or definite leak fails.
test-valgrind: deps-test build
	GMPU_TEST_QUICK=1 meson test -C $(BUILD) --no-rebuild --print-errorlogs --timeout-multiplier 4 \
	  --wrapper 'valgrind -q --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,indirect' \
	  $(VALGRIND_SUITES)

# The corpus section's peers: `reference` takes the committed figures
# (tests/data/corpus/peers.tsv), `live` runs Open3D and CGAL on all 106 clouds (hours).
CORPUS_PEERS ?= reference

bench: deps-bench build
	$(PYTHON) tests/bench/run_bench.py --build $(BUILD) --out bench-results
	$(PYTHON) tests/bench/run_bench.py --corpus-only --corpus-peers $(CORPUS_PEERS) --build $(BUILD) --out bench-results
	$(PYTHON) tests/bench/run_bench.py --heldout-only --build $(BUILD) --out bench-results
	$(PYTHON) tests/bench/run_bench.py --sparse-noisy-only --build $(BUILD) --out bench-results
	$(PYTHON) tests/bench/update_readme.py bench-results
	$(MAKE) --no-print-directory bench-meshes
	$(MAKE) --no-print-directory bench-dask
	$(MAKE) --no-print-directory bench-thinwall

# Sparse thin-walled shapes the corpus does not have (tests/data/thinwall, generated into
# bench-results/thinwall/clouds): gmpu alone against the true meshes, a Markdown table on
# stdout (~1 min). BASELINE=path/to/other/gmpu-reconstruct adds an older build's columns.
.PHONY: bench-thinwall
bench-thinwall: deps-bench build
	$(PYTHON) tests/bench/thinwall.py --build $(BUILD) $(if $(BASELINE),--baseline $(BASELINE))

# Decimation, level-of-detail topology, trimmed open scans, mesh size and polygonize share,
# the bunny at 35k and 1M points, sharp-edge normal error (tests/bench/mesh_ops.py;
# the trim, size and sharp rows on corpus clouds need the clouds the corpus section generates).
.PHONY: bench-meshes
bench-meshes: deps-bench build
	$(PYTHON) tests/bench/mesh_ops.py --build $(BUILD) --out bench-results/mesh_ops

# Tiled reconstruction on a 2-worker Dask LocalCluster against the one-process path, 10M points,
# and the scale point: a mosaic of 10×10 bunnies, 100M points, tiled only, the mesh streamed
# (tests/bench/dask_bench.py; DASK_POINTS, DASK_SCALE_POINTS override the sizes).
DASK_POINTS ?= 10000000
DASK_SCALE_POINTS ?= 100000000
.PHONY: bench-dask
bench-dask: deps-bench build
	$(PYTHON) tests/bench/dask_bench.py --build $(BUILD) --out bench-results/dask --points $(DASK_POINTS) --kill-check \
		--scale-points $(DASK_SCALE_POINTS)

# The corpus section alone (issue 13's targets on 106 generated clouds).
bench-corpus: deps-bench build
	$(PYTHON) tests/bench/run_bench.py --corpus-only --corpus-peers $(CORPUS_PEERS) --build $(BUILD) --out bench-results
	$(PYTHON) tests/bench/update_readme.py bench-results --sections corpus

# The held-out section alone: the corpus's targets on 66 clouds of eleven models no setting was
# tuned on (tests/data/heldout/make.sh, from CGAL's sample data in Debian's libcgal-demo;
# peers run live, ~35 min).
.PHONY: bench-heldout
bench-heldout: deps-bench build
	$(PYTHON) tests/bench/run_bench.py --heldout-only --build $(BUILD) --out bench-results
	$(PYTHON) tests/bench/update_readme.py bench-results --sections heldout

# The sparse noisy section alone: the corpus's meshes at 1k and 5k points with noise
# (tests/data/sparse_noisy/make.sh; peers run live, ~3 min).
.PHONY: bench-sparse-noisy
bench-sparse-noisy: deps-bench build
	$(PYTHON) tests/bench/run_bench.py --sparse-noisy-only --build $(BUILD) --out bench-results
	$(PYTHON) tests/bench/update_readme.py bench-results --sections sparse_noisy

# gmpu alone, against quality floors: needs no peer, so CI runs it after `make test`.
bench-quick: deps-test build
	$(PYTHON) tests/bench/run_bench.py --quick --build $(BUILD) --out bench-results/quick

# Every fuzz target for FUZZ_SECONDS each (`make fuzz FUZZ_SECONDS=3600`); fuzz-quick is
# the bounded run `make test` does.
fuzz: deps-test
	GMPU_FUZZ_BUILD=$(FUZZ_BUILD) tests/fuzz/run.sh $(FUZZ_SECONDS)

fuzz-quick: deps-test
	GMPU_FUZZ_BUILD=$(FUZZ_BUILD) tests/fuzz/run.sh $(FUZZ_QUICK_SECONDS)

clean:
	rm -rf $(BUILD) $(SAN_BUILD) $(FUZZ_BUILD)
