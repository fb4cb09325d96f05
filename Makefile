# The front door. Every target first installs missing Debian packages (silent when all are present),
# then configures and builds out of source.
JOBS      ?= $(shell nproc)
BUILD     ?= build
ASAN      ?= build-asan
FUZZ      ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_SEED ?= 1
DEMO_OUT  ?= runs/demo-heli
NINJA     := $(shell command -v ninja >/dev/null 2>&1 && echo "-G Ninja")
# The generator is chosen only when a build directory is first configured.
gen = $(if $(wildcard $(1)/CMakeCache.txt),,$(NINJA))

.PHONY: all deps configure cli build demo test test-fast test-release test-asan asan-dir install package fuzz bench \
        benchmarks-md figures format format-check tidy docs docs-check clean

all: build

deps:
	@bash scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(call gen,$(BUILD)) >/dev/null

# The `pegasus` CLI (with its libraries and the report bundle) and nothing else: what `make demo` needs.
cli: configure
	@cmake --build $(BUILD) -j $(JOBS) --target pegasus_cli

# Everything: libraries, CLI, tests, benchmarks.
build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# Runs the main job on its shipped small default: the whole helicopter chain (pilot logs, identification, hover
# training, flights on the ground truth against the pilot), printing the headline figures and where the plots are.
# It builds the CLI only, not the test suite.
demo: cli
	@$(BUILD)/pegasus heli pipeline --config experiments/heli-demo.toml --out $(DEMO_OUT) --force
	@echo "demo: results in $(DEMO_OUT) (summary.json; sub-runs pilot-train, pilot-test, pilot-check-1..4, identify, hover, fly)"
	@echo "demo: report: $(DEMO_OUT)/report.html (flights against the pilot and their 3-D replay: $(DEMO_OUT)/fly/report.html)"

# The whole suite in Release (GCC), then again under AddressSanitizer + UndefinedBehaviorSanitizer built by
# clang++ (-O1 with line tables: cheap to compile on 2 cores, and enough for readable reports). Both builds are
# unity builds. Two compilers also keep the code portable; clang compiles this code a quarter faster than GCC
# under the sanitizers, and runs the instrumented tests faster (docs/getting-started/install.md, "Build times").
test: test-release test-asan

test-release: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The inner loop: the unit tests only (label `unit`; the CLI, MPI, browser and install tests are left out).
test-fast: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -L unit

# The Debian package pegasus_<version>_<arch>.deb (cmake/package.cmake says what it holds) in $(BUILD).
package: build
	@cd $(BUILD) && cpack -G DEB >/dev/null && ls $(CURDIR)/$(BUILD)/pegasus_*.deb

# Installs the libraries, headers, CLI, report bundle and CMake package (PREFIX=/usr/local by default).
PREFIX ?= /usr/local
install: build
	@cmake --install $(BUILD) --prefix $(PREFIX)

# A sanitizer build folder configured by another compiler (GCC, before the pass moved to clang) is started
# afresh: CMake drops every other setting of a configured folder whose compiler changes.
asan-dir:
	@if [ -f $(ASAN)/CMakeCache.txt ] && ! grep -q '^CMAKE_CXX_COMPILER:[A-Z]*=.*clang' $(ASAN)/CMakeCache.txt; then \
	  echo "test-asan: $(ASAN) was configured by another compiler; configuring it afresh for clang++"; rm -rf $(ASAN); fi

test-asan: deps asan-dir
	@cmake -S . -B $(ASAN) -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g1" \
	  -DCMAKE_CXX_COMPILER=clang++ -DPEGASUS_SANITIZE=ON -DPEGASUS_BUILD_BENCH=OFF $(call gen,$(ASAN)) >/dev/null
	@cmake --build $(ASAN) -j $(JOBS)
	@cd $(ASAN) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  PEGASUS_SANITIZED=1 ctest --output-on-failure -j $(JOBS)

# Every libFuzzer harness (fuzz/*_fuzz.cpp: the readers of every input) for FUZZ_SECONDS each, built with
# clang++ under -fsanitize=fuzzer,address,undefined in its own build directory (docs/development/fuzzing.md).
fuzz: deps
	@cmake -S . -B $(FUZZ) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
	  -DCMAKE_CXX_COMPILER=clang++ -DPEGASUS_FUZZ=ON \
	  -DPEGASUS_BUILD_TESTS=OFF -DPEGASUS_BUILD_BENCH=OFF -DPEGASUS_MPI=OFF $(call gen,$(FUZZ)) >/dev/null
	@cmake --build $(FUZZ) -j $(JOBS) --target pegasus_fuzzers
	@bash fuzz/run.sh $(FUZZ) $(FUZZ_SECONDS) $(JOBS) $(FUZZ_SEED)

# Every benchmark in Release, one JSON file.
bench: build
	@mkdir -p $(BUILD)/bench-results
	@$(BUILD)/bench/pegasus_bench --benchmark_out=$(BUILD)/bench-results/bench.json --benchmark_out_format=json
	@echo "bench: results in $(BUILD)/bench-results/bench.json"
	@bash bench/mpi_scaling.sh $(BUILD)

# BENCHMARKS.md from the JSON of the last `make bench` (python3 standard library only).
benchmarks-md:
	@python3 scripts/benchmarks_md.py $(BUILD)/bench-results/bench.json --out BENCHMARKS.md

# The images of the README and the manual (docs/images/*.png): runs the shipped experiment configs into
# runs/figures, writes their reports and photographs the key charts in headless chromium (web/figures.mjs).
figures: build
	@node web/figures.mjs --cli $(BUILD)/pegasus --node-modules $(BUILD)/web/node_modules --out docs/images

# The manual (docs/, Sphinx with MyST Markdown, furo, breathe over Doxygen XML of include/pegasus, autodoc from the
# Python stubs) into $(DOCS_BUILD)/html, offline, with Debian's own Python. Any Sphinx warning fails the build,
# a broken internal link or a missing anchor included (-W --keep-going: every warning is listed before it fails;
# -E rereads every page, so that no warning hides behind an earlier build). docs-check also checks the README's
# length and the toctrees (docs/check.sh).
DOCS_BUILD ?= build-docs
SPHINX_PYTHON ?= /usr/bin/python3
docs: deps
	@PEGASUS_DOXYGEN_OUT=$(CURDIR)/$(DOCS_BUILD)/doxygen $(SPHINX_PYTHON) -m sphinx -b html -W --keep-going -q -E \
	  -d $(DOCS_BUILD)/doctrees docs $(DOCS_BUILD)/html
	@echo "docs: $(DOCS_BUILD)/html/index.html"

docs-check: deps
	@bash docs/check.sh $(DOCS_BUILD)

# Every C++ file git tracks, formatted by the repo's .clang-format (`format` rewrites, `format-check` fails on a
# difference; CI runs the check).
CXX_FILES = $(shell git ls-files '*.cpp' '*.hpp' '*.h' '*.inc')
format:
	@clang-format -i $(CXX_FILES)

format-check:
	@clang-format --dry-run -Werror $(CXX_FILES)

# clang-tidy over the library's, the CLI's and the Python bindings' sources (src/, apps/, python/src/, with the
# public headers they include) by the repo's .clang-tidy (python/.clang-tidy lets pybind11's handles pass by
# value): any finding fails. Uses the compile_commands.json of a folder configured (not built) without unity
# builds, whose entries are the source files themselves (a unity build's are its generated units, which the
# file filters below would not match); the bindings' -fno-fat-lto-objects is GCC's, which clang-tidy's clang
# would report.
TIDY ?= build-tidy
tidy: deps
	@cmake -S . -B $(TIDY) -DCMAKE_BUILD_TYPE=Release -DPEGASUS_UNITY_BUILD=OFF -DPEGASUS_UNITY_TESTS=OFF \
	  $(call gen,$(TIDY)) >/dev/null
	@run-clang-tidy -p $(TIDY) -j $(JOBS) -quiet -extra-arg=-Wno-unknown-warning-option \
	  -extra-arg=-Wno-ignored-optimization-argument "$(CURDIR)/src/" "$(CURDIR)/apps/" "$(CURDIR)/python/src/" \
	  > $(TIDY)/tidy.log 2>&1 || { sed 's/\x1b\[[0-9;]*m//g' $(TIDY)/tidy.log | grep -E "(error|warning): " | sort -u; \
	  echo "tidy: findings above (whole output: $(TIDY)/tidy.log)"; exit 1; }
	@echo "tidy: no findings"

clean:
	rm -rf $(BUILD) $(ASAN) $(FUZZ) $(TIDY) $(DOCS_BUILD)
