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
CORE_PKGS := g++ pkg-config meson ninja-build libeigen3-dev libnanoflann-dev libcmocka-dev
TEST_PKGS := $(CORE_PKGS) python3-cffi python3-numpy python3-pytest python3-matplotlib \
             valgrind clang libclang-rt-14-dev
BENCH_PKGS := $(TEST_PKGS) python3-open3d libcgal-dev libgmp-dev libmpfr-dev

define apt_install
	@missing=""; for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "Installing missing Debian packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" -ne 0 ] && SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing; \
	fi
endef

.PHONY: all deps deps-test deps-bench build demo test test-c test-python test-node test-rust \
        test-sanitize bench bench-quick fuzz clean

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
	$(MAKE) --no-print-directory test-c test-python test-node test-rust test-sanitize

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
	cd bindings/rust && GMPU_LIB_DIR=$(abspath $(BUILD))/lib cargo test --offline
	$(MAKE) --no-print-directory test-cross

# Same input and parameters -> same mesh in C, Python, Node and Rust (tests/cross/).
.PHONY: test-cross
test-cross: build
	@for d in bindings/node examples/node; do [ -d $$d/node_modules ] || \
	  (cd $$d && npm ci --no-audit --no-fund --loglevel=error) || exit 1; done
	$(PYTHON) tests/cross/cross_language.py --build $(BUILD)

test-sanitize: deps-test

bench: deps-bench build
	$(PYTHON) tests/bench/run_bench.py --build $(BUILD) --out bench-results
	$(PYTHON) tests/bench/update_readme.py bench-results

bench-quick: deps-bench build
	$(PYTHON) tests/bench/run_bench.py --quick --build $(BUILD) --out bench-results/quick

fuzz: deps-test

clean:
	rm -rf $(BUILD) $(SAN_BUILD) build-fuzz
