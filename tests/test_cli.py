"""The command line: what it writes, and one-line errors with exit status 2 for bad input."""
import json
import re
import subprocess
import sys
import zipfile

import numpy as np
import pandas as pd
import pytest

from nodeforce.model.building_file import parse_building
from nodeforce.model.case import measured_case
from nodeforce.model.integrate import simulate
from nodeforce.iotools.measurements import read_measurements
from nodeforce.model.network import assemble
from nodeforce.model.synth import pseudo_measurements
from nodeforce.cli import main
from tests.conftest import DATA, SENSORS, record_times

pytestmark = pytest.mark.slow  # searches, diagnoses or other importers: not in `make check`


@pytest.fixture(scope="module")
def files(tmp_path_factory, testcell_data, weather):
    d = tmp_path_factory.mktemp("cli")
    building = d / "cell.json"
    building.write_text(json.dumps(testcell_data))
    measurements = pseudo_measurements(parse_building(testcell_data), weather, record_times(days=2), SENSORS)
    measured = d / "measured.csv"
    measurements.to_csv(measured, date_format="%Y-%m-%dT%H:%M:%S%z")
    weather_csv = d / "weather.csv"
    weather_csv.write_text((DATA / "miami_tmy2.csv").read_text())
    return {"dir": d, "building": building, "measurements": measured, "weather": weather_csv}


def error_of(capsys, argv):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


def test_simulate_writes_every_node_as_the_direct_model_computes(files, testcell, weather):
    out = files["dir"] / "not" / "yet" / "sim.csv"  # the output's folder is made, as README's out/ is
    assert main(["simulate", str(files["building"]), "--weather", str(files["weather"]),
                 "--measurements", str(files["measurements"]), "--force", "7,17", "-o", str(out)]) == 0
    sim = pd.read_csv(out)
    assert list(sim.columns) == ["time"] + [f"T{i}" for i in range(1, 24)]
    measurements = pd.read_csv(files["measurements"], index_col="time")
    case = measured_case(testcell, weather, read_measurements(files["measurements"]))  # the weather's history first
    force = np.zeros(23, dtype=bool)
    force[[6, 16]] = True
    direct = simulate(testcell, assemble(testcell), case.U, case.dt, case.measured, force, burn_in_steps=case.burn_in_steps,
                      steady_start=True, substeps=case.substeps, history_steps=case.history_steps)[case.history_steps:]
    assert len(sim) == len(measurements) - 1  # t_1..t_N
    assert np.abs(sim.iloc[:, 1:].to_numpy() - direct).max() < 1e-9
    assert np.array_equal(sim["T7"].to_numpy(), measurements["T7"].to_numpy()[1:])
    assert pd.read_csv(out.parent / "sim.nodes.csv")["column"].tolist() == list(sim.columns[1:])


def test_simulate_on_a_step_of_its_own_is_the_direct_model_on_that_grid(files, testcell, weather):
    """Without measurements, `--step 600` simulates from the weather's first row every 10 min, the
    weather interpolated onto the grid: what the direct model computes on that weather; a step
    beside measurements, whose times are the grid, or not positive, is refused in one line."""
    from nodeforce.model.case import simulate_building
    from nodeforce.model.weather import weather_on_grid
    out = files["dir"] / "stepped.csv"
    assert main(["simulate", str(files["building"]), "--weather", str(files["weather"]), "--step", "600",
                 "-o", str(out)]) == 0
    sim = pd.read_csv(out, index_col="time")
    grid = pd.date_range(weather.index[0], weather.index[-1], freq="600s")
    assert pd.DatetimeIndex(pd.to_datetime(sim.index)).equals(grid[1:])
    direct = simulate_building(testcell, weather_on_grid(weather, grid))
    assert np.abs(sim.to_numpy() - direct.to_numpy()).max() < 1e-6


def test_a_step_beside_measurements_or_below_zero_is_refused(files, capsys):
    argv = ["simulate", str(files["building"]), "--weather", str(files["weather"]), "-o", str(files["dir"] / "x.csv")]
    assert "--measurements" in error_of(capsys, argv + ["--step", "600", "--measurements", str(files["measurements"])])
    assert "positive" in error_of(capsys, argv + ["--step", "0"])


def test_fmu_command_writes_a_valid_fmu(files):
    from fmpy.validation import validate_fmu
    out = files["dir"] / "cell.fmu"
    assert main(["fmu", str(files["building"]), "-o", str(out)]) == 0
    assert validate_fmu(str(out)) == []


def write_building(files, name, mutate):
    data = json.loads(files["building"].read_text())
    mutate(data)
    path = files["dir"] / name
    path.write_text(json.dumps(data))
    return str(path)


def test_bad_building_files(files, capsys):
    def run(path):
        return error_of(capsys, ["simulate", path, "--weather", str(files["weather"])])
    gap = write_building(files, "gap.json", lambda d: d["zones"][0].update(air_node=30))
    assert "gap.json: nodes: node ids must be 1..23" in run(gap)
    deep = write_building(files, "deep.json", lambda d: d["components"][0]["nodes"][1].update(depth=0.5))
    assert "deep.json: components[0].nodes[1].depth" in run(deep)
    odd = write_building(files, "odd.json", lambda d: d["components"][0]["layers"][0].__setitem__(0, "cheese"))
    assert "odd.json: components[0].layers[0]: unknown material 'cheese'" in run(odd)


def rewrite_csv(files, source, name, edit):
    frame = pd.read_csv(files[source])
    frame = edit(frame)
    path = files["dir"] / name
    frame.to_csv(path, index=False)
    return str(path)


def test_bad_weather_files(files, capsys):
    def run(path):
        return error_of(capsys, ["simulate", str(files["building"]), "--weather", path])
    # ghi with dhi is enough (dni by closure); without ghi and one of the others, nothing to work from
    no_sun = rewrite_csv(files, "weather", "no_sun.csv", lambda f: f.drop(columns=["ghi", "dni"]))
    assert "no_sun.csv: ghi" in run(no_sun)
    shuffled = rewrite_csv(files, "weather", "shuffled.csv", lambda f: f.iloc[[0, 2, 1, *range(3, len(f))]])
    assert "shuffled.csv: time" in run(shuffled)
    twice = rewrite_csv(files, "weather", "twice.csv", lambda f: pd.concat([f.iloc[:5], f.iloc[4:]]))
    assert "twice.csv: time" in run(twice)
    kelvin = rewrite_csv(files, "weather", "kelvin.csv", lambda f: f.assign(T_out=f["T_out"] + 273.15))
    assert "kelvin.csv: T_out" in run(kelvin) and "elvin" in run(kelvin)


def test_bad_measurements_and_forcing(files, capsys):
    def run(path, *extra):
        return error_of(capsys, ["simulate", str(files["building"]), "--weather", str(files["weather"]),
                                 "--measurements", path, *extra])
    kelvin = rewrite_csv(files, "measurements", "mk.csv", lambda f: f.assign(T7=f["T7"] + 273.15))
    assert "mk.csv: T7" in run(kelvin)
    err = run(str(files["measurements"]), "--force", "7,12")
    assert "T12" in err and "no measurement column" in err
    assert "--force" in error_of(capsys, ["simulate", str(files["building"]), "--weather",
                                          str(files["weather"]), "--force", "7"])


def test_a_user_mistake_never_shows_a_traceback():
    result = subprocess.run([sys.executable, "-m", "nodeforce", "simulate", "missing.json",
                             "--weather", "nowhere.csv"], capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.strip() == "nodeforce: missing.json: file: not found"


@pytest.mark.parametrize("option,value", [("--population", "1"), ("--generations", "0"), ("--pc", "1.5"),
                                          ("--pm", "-0.1"), ("--workers", "0")])
def test_bad_search_settings_name_the_option(files, capsys, option, value):
    err = error_of(capsys, ["locate", str(files["building"]), "--weather", str(files["weather"]),
                            "--measurements", str(files["measurements"]), "-o", str(files["dir"] / "loc"),
                            option, value])
    assert err.startswith(f"nodeforce: {option}: {value}: ")


def test_an_unreachable_scheduler_is_a_one_line_error(files, capsys):
    err = error_of(capsys, ["locate", str(files["building"]), "--weather", str(files["weather"]),
                            "--measurements", str(files["measurements"]), "-o", str(files["dir"] / "loc"),
                            "--scheduler", "tcp://127.0.0.1:1"])
    assert err.startswith("nodeforce: --scheduler: tcp://127.0.0.1:1: cannot reach a Dask scheduler")


def test_a_diagnosis_says_its_scheduler_is_unreachable_before_any_work(files, capsys):
    out = files["dir"] / "unreached"
    err = error_of(capsys, ["diagnose", str(files["building"]), "--weather", str(files["weather"]),
                            "--measurements", str(files["measurements"]), "-o", str(out),
                            "--scheduler", "tcp://127.0.0.1:1"])
    assert err.startswith("nodeforce: --scheduler: tcp://127.0.0.1:1: cannot reach a Dask scheduler")
    assert not any(out.iterdir())  # no FMU built, no search begun


def test_a_record_shorter_than_the_warm_up_is_refused_unless_the_weather_gives_a_history(files, capsys, tmp_path):
    short = rewrite_csv(files, "measurements", "short.csv", lambda f: f.iloc[:40])
    command = ["simulate", str(files["building"]), "--weather", str(files["weather"]), "--measurements", short]
    err = error_of(capsys, command + ["--history-days", "0"])
    assert "short.csv: time: 39 steps of 900 s" in err and "one day" in err
    # the replay of a first day is what needs the day; a history takes its place
    assert main(command + ["-o", str(tmp_path / "short_sim.csv")]) == 0
    assert len(pd.read_csv(tmp_path / "short_sim.csv")) == 39


def test_synth_refuses_impossible_settings(files, capsys):
    base = ["synth", str(files["building"]), "--weather", str(files["weather"]), "-o",
            str(files["dir"] / "s.csv"), "--start", "2001-06-10T00:00-05:00"]
    assert "--step" in error_of(capsys, base + ["--step", "700"])
    assert "--days" in error_of(capsys, base + ["--days", "0.5"])
    assert "--effect" in error_of(capsys, base + ["--effect", "ground_coupling@roof:U=1"])
    assert "--start" in error_of(capsys, base[:-1] + ["2001-06-10T00:00"])


def test_synth_writes_measurements_that_carry_the_undeclared_effect(files, capsys):
    base = ["synth", str(files["building"]), "--weather", str(files["weather"]), "--start",
            "2001-06-10T00:00-05:00", "--days", "2", "--history-days", "1", "--noise", "0"]
    plain, coupled = files["dir"] / "plain.csv", files["dir"] / "coupled.csv"
    assert main(base + ["-o", str(plain)]) == 0
    assert main(base + ["-o", str(coupled), "--effect", "ground_coupling@floor:U=2,T_ground=15"]) == 0
    a, b = read_measurements(plain), read_measurements(coupled)
    assert list(a.columns) == [f"T{i}" for i in SENSORS] and len(a) == 2 * 96 + 1
    # a cold ground under the floor cools the floor most, then the air
    assert (a["T17"] - b["T17"]).mean() > 1.0
    assert (a["T23"] - b["T23"]).mean() > 0.1


def test_diagnose_refuses_a_fraction_outside_0_1(files, capsys):
    err = error_of(capsys, ["diagnose", str(files["building"]), "--weather", str(files["weather"]),
                            "--measurements", str(files["measurements"]), "-o", str(files["dir"] / "d"),
                            "--calibration-fraction", "1.2"])
    assert err.startswith("nodeforce: --calibration-fraction: 1.2: ")


def test_demo_finds_the_ground_coupling_and_python_writes_the_same_report(tmp_path, capsys):
    assert main(["demo", "-o", str(tmp_path), "--workers", "1"]) == 0
    out = capsys.readouterr().out
    assert "validation" in out and "calibration" in out
    report = json.loads((tmp_path / "report.json").read_text())
    # the first screen, in the terminal (after the demo's line on its data) and atop report.md: where,
    # what was added, what the data fix (U, with the ground's temperature weighed with its prior,
    # the site's deep ground: the data fix the flux, not U and T_ground apart), before and after
    screen = out.split("\n\n")[0].splitlines()[1:]
    md = (tmp_path / "report.md").read_text()
    top = md.split("\n\n")[:2]
    assert top[0] == "# nodeforce diagnosis report" and len(top[1].splitlines()) == len(screen) <= 8
    for lines in (screen, top[1].splitlines()):
        assert lines[0].startswith(("Fault: in floor: forcing node 16", "Fault: in floor: forcing node 17",
                                    "**Fault:** in floor: forcing node 16", "**Fault:** in floor: forcing node 17"))
        assert "ground_coupling on floor" in lines[1]
        assert "with T_ground = " in lines[2] and "(prior 24.31 +- 1.5 C, the site's ground temperature" in lines[2]
        assert not any("not identifiable" in line for line in lines)
    U = report["effect"]["parameters"]["U"]
    # the data fix the flux, and U only as well as T_ground's prior allows: said so, not given a value
    assert "ground heat flux = " in screen[2] and "U alone not fixed" in screen[2]
    # the synthesis's U is 0.8 on a ground at 24 C, the prior 0.31 K off: U is fitted within a quarter of it
    assert abs(U["value"] - 0.8) < 0.25 * 0.8
    validation = [report[s]["validation"] for s in ("before", "after")]
    assert f"RMSE {validation[0]['rmse']:.3f} -> {validation[1]['rmse']:.3f} C" in screen[3]
    # the Decision gives each reason once: the refused gains grouped
    decision = md.split("## Decision", 1)[1].split("\n## ", 1)[0]
    refused = report["decision"]["suggestions"]
    assert refused and decision.count("negative gain") == 1
    counts = re.findall(r"^- (\d+) candidates? the data support, not added: ", decision, flags=re.M)
    assert sum(int(n) for n in counts) == len(refused) and len(counts) == len(set(re.findall(
        r"^- \d+ candidates? the data support, not added: (?:it|each) (.*?): ", decision, flags=re.M)))
    assert all(s["candidate"] in decision for s in refused)
    assert report["localization"]["best_nodes"] in ([16], [17])
    assert report["after"]["validation"]["rmse"] < 0.5 * report["before"]["validation"]["rmse"]
    for name in ("report.md", "building_after.json", "model_after.fmu", "air_temperature.png"):
        assert (tmp_path / name).stat().st_size > 0
    # the search drives the standalone FMU where it can (--search-fmu auto); the model before and
    # after, which the candidates are measured against and the user takes away, the Python FMU
    from nodeforce.runtime.compiler import find_compiler
    standalone = {name: "resources/network.txt" in zipfile.ZipFile(tmp_path / name).namelist()
                  for name in ("model.fmu", "model_before.fmu", "model_after.fmu")}
    assert standalone == {"model.fmu": bool(find_compiler()), "model_before.fmu": False, "model_after.fmu": False}
    # the same inputs through Python: the same report.json, byte for byte, timings and folders aside
    import nodeforce
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    case = nodeforce.measured_case(building, nodeforce.read_weather(DATA / "miami_tmy2.csv"),
                                   nodeforce.read_measurements(DATA / "demo_measurements.csv"), burn_in_days=1)
    nodeforce.diagnose(building, case, tmp_path / "api", search=nodeforce.SearchSettings(seed=0),
                       execution=nodeforce.Execution(workers=1))
    cli, python = (untimed(folder / "report.json", folder) for folder in (tmp_path, tmp_path / "api"))
    assert cli == python


def untimed(path, folder):
    """A report.json's text with its timings (`seconds`) set to 0 and its folder called OUT."""
    text = path.read_text().replace(str(folder), "OUT")
    return re.sub(r'"seconds": [0-9.e+-]+', '"seconds": 0', text)


def test_locate_with_a_burn_in_points_at_the_floor_of_the_demo_data(tmp_path, capsys):
    # the bundled record has real history: its first day carries the warm-up's transient
    assert main(["locate", str(DATA / "testcell_miami.json"), "--weather", str(DATA / "miami_tmy2.csv"),
                 "--measurements", str(DATA / "demo_measurements.csv"), "-o", str(tmp_path),
                 "--burn-in-days", "1", "--workers", "1"]) == 0
    result = json.loads((tmp_path / "locate.json").read_text())
    assert result["search"]["method"] == "exhaustive"
    assert result["best_nodes"] in ([16], [17]) and sorted(result["ranked_nodes"][:2]) == [16, 17]
    # ranked by their scores, not by id
    scores = [result["node_scores"][str(i)] for i in result["ranked_nodes"]]
    assert scores == sorted(scores)
    assert "--burn-in-days" in error_of(capsys, ["locate", str(DATA / "testcell_miami.json"), "--weather",
                                                 str(DATA / "miami_tmy2.csv"), "--measurements",
                                                 str(DATA / "demo_measurements.csv"), "-o", str(tmp_path),
                                                 "--burn-in-days", "30"])


def test_a_reference_without_rmse_figures_is_a_one_line_error(files, capsys):
    bad = files["dir"] / "reference.json"
    bad.write_text(json.dumps({"label": "IDEAS", "rmse": {"free float": "0.6 K"}}))
    err = error_of(capsys, ["diagnose", str(files["building"]), "--weather", str(files["weather"]),
                            "--measurements", str(files["measurements"]), "-o", str(files["dir"] / "d"),
                            "--reference", str(bad)])
    assert err.startswith(f"nodeforce: {bad}: rmse:")


def test_bad_records_stop_with_one_line_naming_the_field(files, capsys, tmp_path):
    b, w, m = str(files["building"]), str(files["weather"]), str(files["measurements"])
    base = ["diagnose", b, "-o", str(tmp_path / "out")]
    err = error_of(capsys, base + ["--record", f"weather={w},measurements={m},colour=blue"])
    assert "--record: colour: no such field" in err
    err = error_of(capsys, base + ["--record", f"weather={w}"])
    assert "--record: measurements: missing" in err
    err = error_of(capsys, base + ["--record", f"weather={w},measurements={m},weather={w}"])
    assert "--record: weather: given twice" in err
    err = error_of(capsys, base + ["--weather", w, "--record", f"weather={w},measurements={m}"])
    assert err.startswith("nodeforce: --record: weather:")
    err = error_of(capsys, base + ["--record", f"weather={w},measurements={m},burn-in-days=two"])
    assert "--record: burn-in-days:" in err
    err = error_of(capsys, base)
    assert "--weather and --measurements, or one --record per record" in err
    # two records under one name
    err = error_of(capsys, base + ["--record", f"weather={w},measurements={m},name=a"] * 2)
    assert "name: two records are named 'a'" in err


def test_two_records_on_the_command_line_find_the_demos_ground_coupling(tmp_path, capsys):
    """The demo's fortnight cut into two weeks, each a --record with its own window: one
    diagnosis of both finds the floor's coupling to the ground, reports before and after per
    record and pools the cross-validation's days of both."""
    measured = pd.read_csv(DATA / "demo_measurements.csv")
    for half, rows in (("first", measured.iloc[:673]), ("second", measured.iloc[672:])):
        rows.to_csv(tmp_path / f"{half}.csv", index=False)
    out = tmp_path / "out"
    records = [f"name={half},weather={DATA / 'miami_tmy2.csv'},measurements={tmp_path / f'{half}.csv'}"
               for half in ("first", "second")]
    assert main(["diagnose", str(DATA / "testcell_miami.json"), "-o", str(out), "--workers", "1",
                 "--record", records[0], "--record", records[1] + ",calibration-fraction=0.7"]) == 0
    report = json.loads((out / "report.json").read_text())
    assert (report["effect"]["effect"], report["effect"]["target"]) == ("ground_coupling", "floor")
    assert [r["name"] for r in report["records"]] == ["first", "second"]
    # 7 days: 1 of burn-in, then 0.6 x 7 = 4.2 days and 0.7 x 7 = 4.9 days of calibration: 3 whole days each
    assert report["decision"]["blocks"] == 3 + 3
    for r in report["records"]:
        assert r["after"]["validation"]["rmse"] < 0.6 * r["before"]["validation"]["rmse"]
    assert "The 2 records apart" in (out / "report.md").read_text()


def test_every_command_reads_a_typical_year_epw_as_energyplus_does(tmp_path, capsys):
    """ASHRAE 140's Denver typical year, whose months come from different years: simulate reads it
    in 2017 (no measurements) as its conversion to one year does, and synth, inputs, compare and
    diagnose in the year of their record, 2013."""
    bestest = DATA.parents[1] / "examples" / "bestest"
    building, epw = str(bestest / "case600.json"), str(bestest / "data" / "725650TYCST.epw")
    assert main(["simulate", building, "--weather", epw, "-o", str(tmp_path / "epw.csv")]) == 0
    # the EPW was recorded at Denver's airport (39.83, -104.65, 1650 m), not at the IDF's site (39.76,
    # -104.86, 1609 m): the run is at the airport, as EnergyPlus's is, which the CSV, with no site, is
    # not unless the building file says so; the air's density follows the standard atmosphere's pressure
    from nodeforce.iotools.typical_year import convert_typical_year
    convert_typical_year(epw, tmp_path / "denver.csv", year=2017)
    given = json.loads((bestest / "case600.json").read_text())
    p = lambda z: 101325.0 * (1.0 - 2.25577e-5 * z) ** 5.2559  # noqa: E731
    airport = {**given, "site": {**given["site"], "latitude": 39.83, "longitude": -104.65, "altitude": 1650.0,
                                 "air_density": given["site"]["air_density"] * p(1650.0) / p(1609.0)}}
    (tmp_path / "airport.json").write_text(json.dumps(airport))
    for name, b in (("csv.csv", building), ("airport.csv", str(tmp_path / "airport.json"))):
        assert main(["simulate", b, "--weather", str(tmp_path / "denver.csv"), "-o", str(tmp_path / name)]) == 0
    from_epw, from_csv, at_airport = (pd.read_csv(tmp_path / name, index_col=0)
                                      for name in ("epw.csv", "csv.csv", "airport.csv"))
    assert from_epw.index.equals(at_airport.index) and from_epw.index[0].startswith("2017-01-01")
    assert np.allclose(from_epw.to_numpy(), at_airport.to_numpy(), atol=1e-3)  # the CSV's 6 digits
    assert not np.allclose(from_epw.to_numpy(), from_csv.to_numpy(), atol=1e-3)

    air = str(parse_building(json.loads((bestest / "case600.json").read_text())).zones[0].air_node)
    measured = str(tmp_path / "m.csv")
    assert main(["synth", building, "--weather", epw, "-o", measured, "--start", "2013-07-01T00:00-07:00",
                 "--days", "6", "--step", "900", "--sensors", air, "--noise", "0.1", "--history-days", "5"]) == 0
    assert read_measurements(measured).index[0] == pd.Timestamp("2013-07-01T00:00-07:00")
    assert main(["inputs", building, "--weather", epw, "--measurements", measured, "-o", str(tmp_path / "in.csv")]) == 0
    assert main(["compare", building, "--weather", epw, "--measurements", measured, "-o", str(tmp_path / "cmp")]) == 0
    [model] = json.loads((tmp_path / "cmp" / "compare.json").read_text())["models"]
    # the file's own weather, read in the record's year: the RMSE is the sensors' noise
    assert 0.07 < next(iter(model["metrics"]["zones"].values()))["rmse"] < 0.13
    assert main(["diagnose", building, "--weather", epw, "--measurements", measured, "-o", str(tmp_path / "dg"),
                 "--workers", "1"]) == 0
    report = json.loads((tmp_path / "dg" / "report.json").read_text())
    assert report["effects"] == []  # nothing to add
    said = [a for a in report["assumptions"] if a.startswith("The weather file's site")]
    assert len(said) == 1 and "DENVER INTL AP 725650" in said[0] and "latitude 39.83, longitude -104.65" in said[0]
    # the building file written back keeps the user's site
    assert json.loads((tmp_path / "dg" / "building_after.json").read_text())["site"] == given["site"]
    site = re.search(r"Site:Location,.*?!- Elevation", (tmp_path / "dg" / "model_after.idf").read_text(), re.S)
    assert re.findall(r"(-?[\d.]+)[,;]\s+!-", site.group(0)) == ["39.76", "-104.86", "-7.0", "1609"]
    # a year given reads the EPW in it: a record of 2013 is then not covered
    capsys.readouterr()
    assert main(["compare", building, "--weather", epw, "--year", "2015", "--measurements", measured,
                 "-o", str(tmp_path / "cmp15")]) == 2
    assert "does not cover" in capsys.readouterr().err
