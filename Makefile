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

# pip does not byte-compile: compileall does it on every core instead (pip's one-core compile was
# about 38 s of the install's 66 s of CPU), leaving out the dependencies' own test suites (a
# quarter of their sources), which nothing here imports.  As with pip's own compile, a file that
# does not compile does not stop the install (Python compiles it, or fails, on import).
$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q --no-compile -e ".[dev]"
	$(BIN)/python -m compileall -qq -j 0 -x '/tests?/' $(VENV)/lib || true
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/testbed demo --out out/demo

test: $(STAMP)
	$(BIN)/python -m pytest -n 2 --dist loadgroup -q

bench: $(STAMP)
	$(BIN)/python -m benchmarks

lint: $(STAMP)
	$(BIN)/ruff check .

clean:
	rm -rf out .pytest_cache
