# Two commands for a new user: `make demo` and `make test`.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin

.PHONY: demo test check venv system-deps benchmark benchmark-energyplus clean twinhouse twinhouse-living bestest

$(BIN)/nodeforce: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test,energyplus]'
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

# The edit-test loop: everything but the searches, diagnoses and importer runs (about 2 min on 2 cores).
check: venv
	$(PYTEST) -m "not slow"

# ASHRAE 140 free-float cases (examples/bestest/README.md, docs/model.md section 10): nodeforce's
# own case 600 IDF edited as the standard defines each case, converted by `nodeforce convert`,
# simulated over the standard's Denver year (examples/bestest/data/725650TYCST.epw; another with
# make bestest WEATHER=path/to/file.epw); the table beside the reference range,
# out/bestest/results.csv and out/bestest/bestest.png
bestest: venv
	@$(BIN)/python examples/bestest/run.py out/bestest "$(WEATHER)"

# Twin House N2 (examples/twinhouse_n2/README.md, docs/real-data.md): the measurements the
# repository carries (examples/twinhouse_n2/data/, read compressed) converted; the whole house
# (every room with an air sensor) diagnosed on experiment 1 (summer 2013) and the early stretch of
# experiment 2 (spring 2014, another protocol: its own supply flows and blinds, so its own building
# file of the same house) together; then experiment 2's late stretch, which the diagnosis never
# saw, compared with the house as written and as corrected (out/twinhouse/exp2/late).
TWINHOUSE_ROOMS := living,corridor,bath,child,kitchen,doorway,bedroom
TWINHOUSE_HOUSE_OUT := out/twinhouse
# processes of the Twin House's diagnoses (make twinhouse WORKERS=1); empty: every core
WORKERS ?=
TWINHOUSE_WORKERS = $(if $(WORKERS),--workers $(WORKERS))

twinhouse: venv
	mkdir -p $(TWINHOUSE_HOUSE_OUT) $(TWINHOUSE_HOUSE_OUT)/exp2
	$(TWINHOUSE_TABLE) --select @$(TWINHOUSE_EXAMPLE)/weather_columns.txt --set shading_south=0 \
		-o $(TWINHOUSE_HOUSE_OUT)/weather.csv
	$(TWINHOUSE_TABLE) --select @$(TWINHOUSE_EXAMPLE)/measurement_columns.txt \
		--start 2013-08-27T00:00+01:00 --end 2013-10-01T00:00+01:00 -o $(TWINHOUSE_HOUSE_OUT)/measurements.csv
	$(TWINHOUSE_TABLE2) --select @$(TWINHOUSE_EXAMPLE)/weather_columns_exp2.txt \
		--set shading_south=1,shading_W27=0,shading_W33=0 -o $(TWINHOUSE_HOUSE_OUT)/exp2/weather.csv
	$(BIN)/python $(TWINHOUSE_EXAMPLE)/make_building.py --experiment 2 -o $(TWINHOUSE_HOUSE_OUT)/exp2/building_as_written.json
	@# experiment 2's record has two gaps (a row at 04-22 13:20, 6.5 h on 04-28): its two stretches
	@# between them are two records, each with its own three days of burn-in
	$(TWINHOUSE_TABLE2) --select @$(TWINHOUSE_EXAMPLE)/measurement_columns_exp2.txt \
		--start 2014-04-09T00:10+01:00 --end 2014-04-22T13:10+01:00 -o $(TWINHOUSE_HOUSE_OUT)/exp2/measurements_early.csv
	$(TWINHOUSE_TABLE2) --select @$(TWINHOUSE_EXAMPLE)/measurement_columns_exp2.txt \
		--start 2014-04-28T08:10+01:00 --end 2014-05-19T23:20+01:00 -o $(TWINHOUSE_HOUSE_OUT)/exp2/measurements_late.csv
	$(BIN)/nodeforce diagnose $(TWINHOUSE_EXAMPLE)/building.json -o $(TWINHOUSE_HOUSE_OUT) \
		--record name=exp1,weather=$(TWINHOUSE_HOUSE_OUT)/weather.csv,measurements=$(TWINHOUSE_HOUSE_OUT)/measurements.csv,calibration-end=2013-09-14T00:00+01:00,phases=$(TWINHOUSE_EXAMPLE)/phases.csv \
		--record name=exp2_early,building=$(TWINHOUSE_HOUSE_OUT)/exp2/building_as_written.json,weather=$(TWINHOUSE_HOUSE_OUT)/exp2/weather.csv,measurements=$(TWINHOUSE_HOUSE_OUT)/exp2/measurements_early.csv,calibration-end=2014-04-18T00:00+01:00,phases=$(TWINHOUSE_EXAMPLE)/phases_exp2.csv \
		--objective $(TWINHOUSE_ROOMS) --burn-in-days 3 --seed 0 --reference $(TWINHOUSE_EXAMPLE)/reference.json \
		$(TWINHOUSE_WORKERS)
	$(BIN)/nodeforce compare $(TWINHOUSE_HOUSE_OUT)/exp2/building_as_written.json $(TWINHOUSE_HOUSE_OUT)/building_after_record2.json \
		--weather $(TWINHOUSE_HOUSE_OUT)/exp2/weather.csv --measurements $(TWINHOUSE_HOUSE_OUT)/exp2/measurements_late.csv \
		-o $(TWINHOUSE_HOUSE_OUT)/exp2/late --objective $(TWINHOUSE_ROOMS) --burn-in-days 3 --phases $(TWINHOUSE_EXAMPLE)/phases_exp2.csv


# The living room alone, on experiment 1 (examples/twinhouse_n2/README.md), into out/twinhouse_living:
# diagnosed on its air, then experiment 2 (spring 2014, another protocol) converted and the house
# as written and as corrected on experiment 1 compared on it, a record the correction never saw.
TWINHOUSE_EXAMPLE := examples/twinhouse_n2
TWINHOUSE_DATA := $(TWINHOUSE_EXAMPLE)/data/exp1
TWINHOUSE_DATA2 := $(TWINHOUSE_EXAMPLE)/data/exp2
TWINHOUSE_OUT := out/twinhouse_living
TWINHOUSE_OUT2 := $(TWINHOUSE_OUT)/exp2
TWINHOUSE_TABLE = $(BIN)/nodeforce table $(TWINHOUSE_DATA)/validationdataN2Exp1.txt.gz \
	--names $(TWINHOUSE_DATA)/columns.csv --origin 2013-01-01T00:00+01:00
TWINHOUSE_TABLE2 = $(BIN)/nodeforce table $(TWINHOUSE_DATA2)/validationdataExp2.txt.gz \
	--names $(TWINHOUSE_DATA2)/columns.csv --origin 2014-01-01T00:00+01:00

twinhouse-living: venv
	mkdir -p $(TWINHOUSE_OUT) $(TWINHOUSE_OUT2)
	$(TWINHOUSE_TABLE) --select @$(TWINHOUSE_EXAMPLE)/weather_columns.txt --set shading_south=0 \
		-o $(TWINHOUSE_OUT)/weather.csv
	$(TWINHOUSE_TABLE) --select @$(TWINHOUSE_EXAMPLE)/measurement_columns.txt \
		--start 2013-08-27T00:00+01:00 --end 2013-10-01T00:00+01:00 -o $(TWINHOUSE_OUT)/measurements.csv
	$(BIN)/nodeforce diagnose $(TWINHOUSE_EXAMPLE)/building.json --weather $(TWINHOUSE_OUT)/weather.csv \
		--measurements $(TWINHOUSE_OUT)/measurements.csv -o $(TWINHOUSE_OUT) --objective living \
		--calibration-end 2013-09-14T00:00+01:00 --burn-in-days 3 --seed 0 \
		--reference $(TWINHOUSE_EXAMPLE)/reference.json --phases $(TWINHOUSE_EXAMPLE)/phases.csv $(TWINHOUSE_WORKERS)
	$(TWINHOUSE_TABLE2) --select @$(TWINHOUSE_EXAMPLE)/weather_columns_exp2.txt \
		--set shading_south=1,shading_W27=0,shading_W33=0 -o $(TWINHOUSE_OUT2)/weather.csv
	$(BIN)/python $(TWINHOUSE_EXAMPLE)/make_building.py --experiment 2 -o $(TWINHOUSE_OUT2)/building_as_written.json
	$(BIN)/python $(TWINHOUSE_EXAMPLE)/make_building.py --experiment 2 --corrected-by $(TWINHOUSE_OUT)/report.json \
		-o $(TWINHOUSE_OUT2)/building_corrected_on_exp1.json
	@# experiment 2's record has two gaps (a row at 04-22 13:20, 6.5 h on 04-28): it is compared on the
	@# two stretches between them, each with its own three days of burn-in
	$(call twinhouse_exp2_part,early,2014-04-09T00:10+01:00,2014-04-22T13:10+01:00)
	$(call twinhouse_exp2_part,late,2014-04-28T08:10+01:00,2014-05-19T23:20+01:00)

# $(call twinhouse_exp2_part,NAME,START,END): experiment 2's measurements from START to END, and the
# comparison of the two building files on them in out/twinhouse_living/exp2/NAME
define twinhouse_exp2_part
$(TWINHOUSE_TABLE2) --select @$(TWINHOUSE_EXAMPLE)/measurement_columns_exp2.txt --start $(2) --end $(3) \
	-o $(TWINHOUSE_OUT2)/measurements_$(1).csv
$(BIN)/nodeforce compare $(TWINHOUSE_OUT2)/building_as_written.json $(TWINHOUSE_OUT2)/building_corrected_on_exp1.json \
	--weather $(TWINHOUSE_OUT2)/weather.csv --measurements $(TWINHOUSE_OUT2)/measurements_$(1).csv \
	-o $(TWINHOUSE_OUT2)/$(1) --objective living --burn-in-days 3 --phases $(TWINHOUSE_EXAMPLE)/phases_exp2.csv
endef

# The forcing search's speed, then the diagnosis on 62 records x 3 noise draws (about an hour on
# 2 cores; finished records are kept in out/bench_diagnosis and skipped by a rerun):
# docs/performance.md, docs/benchmark_diagnosis.md
benchmark: venv
	$(BIN)/python benchmarks/bench_search.py
	$(BIN)/python benchmarks/bench_diagnosis.py

# The diagnosis judged against EnergyPlus (docs/benchmark_energyplus.md): ASHRAE 140's light and
# heavy buildings, each with a change EnergyPlus simulates and the diagnosed IDF does not declare,
# 3 noise draws, model_after.idf run by EnergyPlus on a later record (the venv has the
# `energyplus` extra; finished records are kept in out/bench_energyplus_diagnosis and skipped)
benchmark-energyplus: venv
	$(BIN)/python benchmarks/bench_energyplus_diagnosis.py

clean:
	rm -rf $(VENV) out
