# contactfx: `make demo` (the main job) and `make test` (the suite, serial and mpirun -n 2).
# Each target creates .venv with python3.12 and installs what is missing by itself.

VENV      := .venv
PY        := $(VENV)/bin/python
MPIRUN    := $(VENV)/bin/mpirun
STAMP     := $(VENV)/.installed
# python3.12 may be a pyenv shim that is not activated: fall back to pyenv's own 3.12.
PYTHON312 := $(shell python3.12 -c 'import sys' >/dev/null 2>&1 && echo python3.12 || \
               ls -d $$HOME/.pyenv/versions/3.12*/bin/python3.12 2>/dev/null | tail -n 1)
export OPENBLAS_NUM_THREADS := 1
export OMP_NUM_THREADS := 1

.PHONY: demo test docs bench bench-scale bench-scaling clean venv lock

venv: $(STAMP)

# The venv gets the versions of requirements.lock (every package pinned, the test and docs
# extras included); `make demo`/`make test` install the package with its test extra under the
# lock's constraints, so they need none of the docs packages; without the file the venv
# resolves pyproject.toml's ranges. `make lock` re-resolves the file.
LOCK      := requirements.lock
UV        := uv==0.13.9
PIP       := pip==26.3

# PYTHONWARNINGS=ignore: setuptools' editable wheel prints a banner about folders named like
# the package (a warning of the build backend, which pip's --quiet passes through).
QUIET_PIP := PYTHONWARNINGS=ignore $(PY) -m pip install --quiet

$(STAMP): pyproject.toml $(wildcard $(LOCK))
	@test -n "$(PYTHON312)" || { echo "python3.12 not found" >&2; exit 1; }
	@test -x $(PY) || $(PYTHON312) -m venv $(VENV)
	$(PY) -m pip install --quiet $(PIP)
	@if [ -f $(LOCK) ]; then \
	  $(QUIET_PIP) -c $(LOCK) -e ".[test]" ; \
	else \
	  $(QUIET_PIP) -e ".[test]" ; \
	fi
	@touch $(STAMP)

# Re-resolve the lock from pyproject.toml's ranges (newest versions the index serves today).
lock:
	@test -x $(PY) || $(PYTHON312) -m venv $(VENV)
	$(PY) -m pip install --quiet $(UV)
	$(VENV)/bin/uv pip compile pyproject.toml --extra test --extra docs --python-version 3.12 --universal \
	  --no-header --quiet -o $(LOCK)

demo: $(STAMP)
	$(PY) demos/demo_blocks.py

# In-process tests on both cores (pytest-xdist); then the mpirun -n 2 tests, one at a time.
test: $(STAMP)
	$(PY) -m ruff check contactfx tests demos benchmarks
	$(PY) -m ruff format --check contactfx tests demos benchmarks
	$(PY) -m mypy
	$(VENV)/bin/lint-imports
	$(PY) tools/layout_check.py 400 250 120
	$(PY) -m pytest -q -n 2 -m serial tests
	$(PY) -m pytest -q -m mpi tests

# The site in docs/_build/html: the demos executed (CONTACTFX_QUICK=1 make docs: at the test
# suite's small sizes), the references generated from the code, warnings as errors; -E: a fresh
# environment, as the generated pages are rewritten on every build anyway.
DOCS_STAMP := $(VENV)/.docs-installed
$(DOCS_STAMP): $(STAMP)
	@if [ -f $(LOCK) ]; then \
	  $(QUIET_PIP) -c $(LOCK) -e ".[docs]" ; \
	else \
	  $(QUIET_PIP) -e ".[docs]" ; \
	fi
	@touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	$(PY) -m sphinx -b html -E -W --keep-going docs docs/_build/html

bench: $(STAMP)
	$(PY) benchmarks/run.py

# The condensed solver against MUMPS from 100k to 10M dofs (about 25 min).
bench-scale: $(STAMP)
	$(PY) benchmarks/scale.py

# The scaling table of the accurate family, 1 and 2 ranks (docs/scale.md, "Scaling").
bench-scaling: $(STAMP)
	$(PY) benchmarks/scaling.py --sizes 100e3,400e3,1e6,2e6 --ranks 1,2
	$(PY) benchmarks/scaling.py --sizes 100e3,400e3,1e6,2e6 --ranks 1,2 --solver mumps

clean:
	rm -rf results .pytest_cache docs/_build docs/demos docs/reference/api docs/reference/scene_file.md
