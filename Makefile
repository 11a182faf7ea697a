# Two commands on a machine with only python3: `make demo` and `make test`.
# The first run creates .venv and installs the project; later runs skip the
# install unless pyproject.toml changed.
PY     ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# One BLAS thread per process: parallelism comes from pytest-xdist / joblib, and
# two-thread BLAS next to another busy process is many times slower.
export OMP_NUM_THREADS := 1
export OPENBLAS_NUM_THREADS := 1
export MKL_NUM_THREADS := 1
export MPLBACKEND := Agg

.PHONY: demo test bench lint clean

# The install: uv (a PyPI package) if the venv's own pip can install its wheel, else pip (one rule:
# `pip install uv` failing is the only fallback; an error of uv's own install stops make).  uv
# resolves the same versions as pip (pyproject's ranges, highest first: compared pip freeze) and
# installs them in parallel: measured from a fresh clone with empty caches (2 cores at load 13,
# CPU seconds user + sys), the download and install 13.7 s with uv (38.7 s wall) against 31.9 s
# with pip (92.1 s wall); pip's own upgrade, needed by pip only (with the bundled pip 23.2 the
# install took 99 s), is left out on the uv path.  Byte-compiling: compileall on every core
# leaves out the dependencies' own test suites (a quarter of their sources), which nothing here
# imports; uv's --compile-bytecode compiles them too (51.1 s against 13.7 + 34.2 s of CPU
# measured: no gain).  tests/_compile_venv.py is `compileall -qq -j 0 -x '/tests?/'` handing each
# core chunks of files instead of one file at a time (16.4-19.7 s of CPU against 20.6-23.7 s,
# 2026-11-28); leaving out the top-level packages nothing imports (OpenGL's 2,877 files ...)
# measured no gain.  As with pip's own compile, a file that does not compile does not stop the
# install (Python compiles it, or fails, on import).  uv reads none of pip's settings (pip.conf,
# PIP_*): an index or a certificate set only for pip is uv's to be told (UV_INDEX_URL, SSL_CERT_FILE).
# The build system's requirements (pyproject's [build-system] requires, read by BUILD_REQUIRES)
# are installed beside the project: tests/test_wheel.py then builds the wheel with the venv's
# setuptools (--no-build-isolation, which it takes where setuptools is new enough) instead of
# pip making an isolated build environment and fetching setuptools into it on every run (the
# venv's own setuptools, from ensurepip, is 65.5 < 77): the build 3.0-3.2 -> 0.96-1.04 s of CPU
# measured (2026-11-29, load 15), the install's extra wheel already in uv's cache from building
# the editable install.
BUILD_REQUIRES := $(BIN)/python -c "import tomllib; \
	print(*tomllib.load(open('pyproject.toml', 'rb'))['build-system']['requires'])"
$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	if $(BIN)/python -m pip install -q --only-binary=:all: uv; then \
		$(BIN)/uv pip install -q --python $(BIN)/python -e ".[dev]" $$($(BUILD_REQUIRES)); \
	else \
		echo "uv could not be installed: installing with pip"; \
		$(BIN)/python -m pip install -q --upgrade pip && \
		$(BIN)/python -m pip install -q --no-compile -e ".[dev]" $$($(BUILD_REQUIRES)); \
	fi
	$(BIN)/python tests/_compile_venv.py $(VENV)/lib || true
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/testbed demo --out out/demo

# The project's own sources are byte-compiled first: with PYTHONDONTWRITEBYTECODE set (as on the
# machines this was measured on) no process writes a .pyc, so each of the suite's processes (the
# two workers, the CLI and server subprocesses, the sweeps' loky workers) compiled every module
# it imported from source again: 0.45 s of CPU for a process that imports them all (1.30 s
# against 0.85 s), and measured on the server, startup and sweep tests (37 tests, their own
# processes included) 37.5 s of CPU without against 34.0 s with (2026-11-26, load 6).  The
# compile itself costs 1 s of CPU, on every core.  Without the variable the first import writes
# the same files: nothing changes.  A file that does not compile is pytest's to report.
# The test modules' rewritten asserts likewise (tests/_rewrite_ahead.py): each pytest worker
# rewrote every test module again, about half of its collection (collect-only: 13.1-14.5 s of
# CPU without, 8.2 s with; the step itself 4.2 s on a fresh clone, 0.4 s once written).
# tmp_path_retention_policy=failed: each passing test's tmp_path is removed by its worker when it
# ends (a failing test's is kept).  With pytest's default ("all") every session's folders are
# kept and the main process, after the last worker has ended, removes the oldest session's
# folder beyond the last three: after a full suite 13,500 files, 15 s at load 4 and 36 s in a
# fresh clone at load 4-8 (2026-11-28, faulthandler stacks: cleanup_numbered_dir -> rm_rf),
# both cores idle meanwhile.  The same files are removed either way, by the workers while the
# other works instead of by one process at the end.  Plain `pytest` keeps the default.
test: $(STAMP)
	$(BIN)/python -m compileall -qq -j 0 testbed models identify benchmarks tests || true
	$(BIN)/python tests/_rewrite_ahead.py || true
	$(BIN)/python -m pytest -n 2 --dist loadgroup -q -o tmp_path_retention_policy=failed

bench: $(STAMP)
	$(BIN)/python -m benchmarks

lint: $(STAMP)
	$(BIN)/ruff check .

clean:
	rm -rf out .pytest_cache
