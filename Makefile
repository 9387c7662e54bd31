# proxima: the two commands of the README.
#   make run   builds in release and runs the main job, the paper's experiments
#              (bench/paper_experiments; PAPER_ARGS=--quick for the reduced run)
#   make test  installs what is missing, builds, runs every test (unit tests under the
#              sanitizers; peers, Python, packaging and the browser in release)
JOBS ?= $(shell nproc)

.PHONY: all run test test-release setup release asan dev bench fuzz clean results results-quick compare

all: release

setup:
	@bash scripts/setup

release: setup
	cmake --preset release >/dev/null
	cmake --build --preset release -j $(JOBS)

# The sanitizer build (ASan + UBSan) compiles at -O1 with line tables only
# (-g1), enough for the sanitizers' stack traces. UBSan's alignment, null,
# object-size and pointer-overflow checks are off: they made each file
# slower to compile (the first two about twice as slow, figures in
# CHANGELOG.md), and ASan reports every null, wild or out-of-bounds
# dereference itself (x86-64 has no alignment faults for what they check). The test files' own code is
# compiled with ASan's heap checks only (tests/CMakeLists.txt,
# PROXIMA_TEST_FILE_FLAGS): the code under test keeps every check. It builds
# and runs every unit test, the random sweeps with fewer cases
# (tests/support/sanitizers.h); the tests that link the peers (FCL, Bullet:
# PROXIMA_PEER_TESTS) run in the release build only.
asan: setup
	cmake --preset asan >/dev/null
	cmake --build --preset asan -j $(JOBS)

dev: setup
	cmake --preset dev >/dev/null
	cmake --build --preset dev -j $(JOBS)

PAPER_ARGS ?=
run: release
	./build/release/bench/paper_experiments $(PAPER_ARGS)

# The tests need no micro-benchmark (bench/*_bench), and the unit tests run
# in the sanitizer build: make test builds the release tree without either
# (PROXIMA_UNIT_TESTS=OFF keeps only the peers' tests;
# a command-line -D overrides the preset's ON; `make release` and every
# `cmake --preset release` turn them on again).
test-release: setup
	cmake --preset release -DPROXIMA_BUILD_BENCH=OFF -DPROXIMA_UNIT_TESTS=OFF >/dev/null
	cmake --build --preset release -j $(JOBS)

test: test-release asan
	@echo "== release build: peer tests, examples, Python, packaging, docs =="
	ctest --preset release -j $(JOBS)
	@echo "== unit tests, ASan + UBSan build (and the fuzz corpus replayed) =="
	ctest --preset asan -j $(JOBS)

# ThreadSanitizer: builds batch_test alone (the batch queries' threads) and runs it.
tsan: setup
	cmake --preset tsan >/dev/null
	cmake --build --preset tsan -j $(JOBS)
	ctest --preset tsan

# The Python module alone; the build prints the PYTHONPATH that imports it.
python: setup
	cmake --preset release >/dev/null
	cmake --build --preset release --target proxima_python -j $(JOBS)

# Every measured figure from one command, on HEAD: the paper's experiments,
# the scene benchmark and the micro-benchmarks, tables in
# bench/results/latest/RESULTS.md with the commit, date, machine and load
# (about 20 minutes on 2 cores; results-quick checks the chain in about 1.5).
results: setup
	/usr/bin/python3 scripts/results

results-quick: setup
	/usr/bin/python3 scripts/results --quick

# HEAD (this working tree) against REF, benchmarks interleaved in one run:
# tracked and cold queries, Scene::step, callgrind instruction counts.
#   make compare REF=<commit>   (ROUNDS=5 by default)
ROUNDS ?= 5
compare:
	@test -n "$(REF)" || { echo "usage: make compare REF=<commit> [ROUNDS=5]"; exit 2; }
	python3 scripts/compare_builds $(REF) --rounds $(ROUNDS)

bench: release
	@for b in build/release/bench/*_bench; do echo "== $$b =="; $$b; done

clean:
	rm -rf build out

# Fuzzes the mesh readers for 30 s (clang, libFuzzer + ASan + UBSan).
# Fuzzing the mesh readers (libFuzzer, its own clang build): a random
# search, so it is not part of `make test`, which replays the corpus
# (fuzz/corpus) under the sanitizers; CI (.ci/run) fuzzes 20 s after it.
FUZZ_SECONDS ?= 30
fuzz: setup
	bash scripts/fuzz $(FUZZ_SECONDS)
