# Two commands for a new user: `make demo` and `make test`.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin

.PHONY: demo test check venv system-deps benchmark clean

$(BIN)/nodeforce: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $@

venv: $(BIN)/nodeforce

# ecospy's native library links against oneTBB, which comes from Debian.
system-deps:
	@dpkg -s libtbb12 >/dev/null 2>&1 || { apt-get update -qq && apt-get install -y -qq libtbb12; }

demo: venv
	$(BIN)/nodeforce demo -o out/demo

test: venv system-deps
	$(BIN)/python -m pytest -q

# The edit-test loop: everything but the searches, diagnoses and importer runs (under a minute).
check: venv
	$(BIN)/python -m pytest -q -m "not slow"

benchmark: venv
	$(BIN)/python benchmarks/bench_search.py

clean:
	rm -rf $(VENV) out
