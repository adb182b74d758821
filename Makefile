# Two commands for a new user: `make demo` and `make test`.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin

.PHONY: demo test check venv system-deps benchmark clean twinhouse

$(BIN)/nodeforce: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $@

venv: $(BIN)/nodeforce

# ecospy's native library links against oneTBB, which comes from Debian; valgrind checks that the
# Python FMU's host never touches freed memory (tests/test_fmu_memory.py).
SYSTEM_PACKAGES := libtbb12 valgrind
system-deps:
	@dpkg -s $(SYSTEM_PACKAGES) >/dev/null 2>&1 || { apt-get update -qq && apt-get install -y -qq $(SYSTEM_PACKAGES); }

demo: venv
	$(BIN)/nodeforce demo -o out/demo

# Two pytest-xdist workers, one per core; a test file stays on one worker, so its module fixtures
# (a shared diagnosis, say) are computed once.
PYTEST := $(BIN)/python -m pytest -q -n 2 --dist loadfile

test: venv system-deps
	$(PYTEST)

# The edit-test loop: everything but the searches, diagnoses and importer runs (under a minute).
check: venv
	$(PYTEST) -m "not slow"

# Twin House N2, experiment 1 (examples/twinhouse_n2/README.md): the shared measurements converted,
# then diagnosed on the living room. The data are not in the repository (SOURCES.md of the data).
TWINHOUSE_DATA ?= ../shared/data/twinhouse_n2_exp1
TWINHOUSE_EXAMPLE := examples/twinhouse_n2
TWINHOUSE_OUT := out/twinhouse
TWINHOUSE_TABLE = $(BIN)/nodeforce table $(TWINHOUSE_DATA)/validationdataN2Exp1.txt \
	--names $(TWINHOUSE_DATA)/columns.csv --origin 2013-01-01T00:00+01:00

twinhouse: venv
	@for f in validationdataN2Exp1.txt columns.csv; do test -f $(TWINHOUSE_DATA)/$$f || { \
	  echo "twinhouse: $(TWINHOUSE_DATA)/$$f is missing: the Twin House N2 data folder (../shared/data/twinhouse_n2_exp1) is needed; validationdataN2Exp1.txt is IDEAS/Resources/measurements/validationdataN2Exp1.txt of github.com/open-ideas/IDEAS (commit 272d82aef8da5484b3ed729ba6d6cc1db9754f1e), columns.csv its column list (the data's SOURCES.md)" >&2; \
	  exit 2; }; done
	mkdir -p $(TWINHOUSE_OUT)
	$(TWINHOUSE_TABLE) --select @$(TWINHOUSE_EXAMPLE)/weather_columns.txt --set shading_south=0 \
		-o $(TWINHOUSE_OUT)/weather.csv
	$(TWINHOUSE_TABLE) --select @$(TWINHOUSE_EXAMPLE)/measurement_columns.txt \
		--start 2013-08-27T00:00+01:00 --end 2013-10-01T00:00+01:00 -o $(TWINHOUSE_OUT)/measurements.csv
	$(BIN)/nodeforce diagnose $(TWINHOUSE_EXAMPLE)/building.json --weather $(TWINHOUSE_OUT)/weather.csv \
		--measurements $(TWINHOUSE_OUT)/measurements.csv -o $(TWINHOUSE_OUT) --objective living \
		--calibration-end 2013-09-14T00:00+01:00 --burn-in-days 3 --seed 0 \
		--reference $(TWINHOUSE_EXAMPLE)/reference.json --phases $(TWINHOUSE_EXAMPLE)/phases.csv

benchmark: venv
	$(BIN)/python benchmarks/bench_search.py

clean:
	rm -rf $(VENV) out
