"""The report writer: the before/after table, report.md and its plots, from a synthetic report."""
import copy

import numpy as np
import pandas as pd
import pytest

from nodeforce.diagnose.report import before_after_table, write_report

PNG = b"\x89PNG\r\n\x1a\n"
NODES = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 16, 17]


def metrics(rmse, mean, sd, n):
    return {"J": rmse ** 2 * n, "rmse": rmse, "mean": mean, "sd": sd, "n": n}


def synthetic():
    """2 days at 15 min, the 2nd the validation window; a door conducting too little (node 7)."""
    times = pd.date_range("2001-06-10 00:00", periods=2 * 96 + 1, freq="15min", tz="-05:00", name="time")
    start = times[96]
    hours = np.arange(len(times)) / 4
    rng = np.random.default_rng(0)
    truth = 27 + 3 * np.sin(2 * np.pi * (hours - 9) / 24)
    measured = truth + rng.normal(0, 0.1, len(times))
    measured[[10, 11, 12, 150]] = np.nan
    before = 26.3 + 2.2 * np.sin(2 * np.pi * (hours - 8) / 24)
    after = truth + 0.05 * np.sin(2 * np.pi * hours / 6)
    scores = {str(k): 300.0 + 20 * k for k in NODES}
    scores["7"] = 12.5
    scores["9"] = None  # a simulation that failed
    report = {
        "period": {"calibration": [times[0].isoformat(), times[95].isoformat()],
                   "validation": [start.isoformat(), times[-1].isoformat()]},
        "before": {"calibration": metrics(0.8123, 0.6034, 0.5432, 94),
                   "validation": metrics(0.9021, 0.7011, 0.5678, 96)},
        "localization": {
            "measured_nodes": NODES + [23], "chromosome_nodes": NODES, "output_node": 23,
            "J_unforced": 640.2, "best_nodes": [7], "J_best": 12.5, "node_scores": scores,
            "ranked_nodes": [7] + [k for k in NODES if k not in (7, 9)],
            "search": {"method": "ga", "population": 16, "generations": 12, "pc": 0.8, "pm": 0.03,
                       "seed": 3, "evaluations": 208, "unique_evaluations": 150, "seconds": 42.17,
                       "J_min": 11.9, "min_nodes": [7, 16], "tolerance": 6.4}},
        "candidates": [
            {"effect": "conductivity", "target": "door",
             "parameters": {"factor": {"value": 1.8734, "std": 0.0312, "identifiable": True}},
             "calibration": metrics(0.1012, 0.001, 0.1011, 94), "validation": metrics(0.1234, 0.012, 0.1228, 96),
             "bic": -412.3, "bic_baseline": -35.1},
            {"effect": "ground_coupling", "target": "floor",
             "parameters": {"U": {"value": 0.52, "std": 0.9, "identifiable": False},
                            "T_ground": {"value": 24.3, "std": None, "identifiable": False}},
             "calibration": metrics(0.7011, 0.4, 0.57, 94), "validation": metrics(0.8544, 0.6, 0.6, 96),
             "bic": -20.0, "bic_baseline": -35.1},
            {"effect": "infiltration", "target": None,
             "parameters": {"n": {"value": 0.3, "std": 0.05, "identifiable": True}},
             "calibration": {"J": None, "rmse": None, "mean": None, "sd": None, "n": 94},
             "validation": {"J": None, "rmse": None, "mean": None, "sd": None, "n": 96},
             "bic": None, "bic_baseline": -35.1},
            {"effect": "solar_absorptance", "target": "roof",
             "parameters": {"alpha": {"value": 0.71, "std": 0.02, "identifiable": True}},
             "calibration": metrics(0.4011, 0.2, 0.35, 94), "validation": metrics(0.5544, 0.3, 0.47, 96),
             "bic": -150.0, "bic_baseline": -35.1},
        ],
        "effect": {"effect": "conductivity", "target": "door",
                   "parameters": {"factor": {"value": 1.8734, "std": 0.0312, "identifiable": True}}},
        "after": {"calibration": metrics(0.1012, 0.001, 0.1011, 94),
                  "validation": metrics(0.1234, 0.012, 0.1228, 96)},
        "sensitivity": {"conductivity@door": {"factor": {"mu_star": 85.2, "sigma": 12.1}},
                        "ground_coupling@floor": {"U": {"mu_star": 3.1, "sigma": None},
                                                  "T_ground": {"mu_star": 0.4, "sigma": 0.5}}},
        "artifacts": {"building_after": "building_after.json", "fmu_after": "model_after.fmu", "plots": []},
    }
    series = {"times": times, "measured": measured, "before": before, "after": after,
              "validation_start": start, "convergence": [(g, max(12.5, 640.2 / (1 + g * g))) for g in range(13)],
              "air_node": 23}
    return report, series


def no_effect(report, series):
    report, series = copy.deepcopy(report), dict(series)
    report["effect"] = {"effect": "none", "target": None, "parameters": {}}
    report["after"] = copy.deepcopy(report["before"])
    report["localization"]["best_nodes"] = []
    report["localization"]["J_best"] = report["localization"]["J_unforced"]
    for c in report["candidates"]:
        c["bic"] = 10.0
    series["after"] = series["before"].copy()
    return report, series


def test_table_gives_the_rmse_before_and_after_and_the_chosen_effect():
    report, _ = synthetic()
    table = before_after_table(report)
    lines = table.splitlines()
    assert lines[0] == "Effect added: conductivity on door: factor = 1.873 +- 0.031"
    calibration = next(line for line in lines if line.startswith("calibration "))
    validation = next(line for line in lines if line.startswith("validation "))
    assert calibration.split() == ["calibration", "|", "0.812", "+0.603", "0.543", "94",
                                   "|", "0.101", "+0.001", "0.101", "94"]
    assert validation.split()[2] == "0.902" and validation.split()[7] == "0.123"
    assert "2001-06-11 00:00 UTC-05:00" in table


def test_table_flags_parameters_that_are_not_identifiable():
    report, _ = synthetic()
    report["effect"] = copy.deepcopy({k: report["candidates"][1][k] for k in ("effect", "target", "parameters")})
    header = before_after_table(report).splitlines()[0]
    assert header.startswith("Effect added: ground_coupling on floor: U = 0.52 +- 0.90 W/m2/K (not identifiable)")
    assert "T_ground = 24.30 +- n/a C (not identifiable)" in header


def test_table_with_no_effect_and_missing_values():
    report, series = no_effect(*synthetic())
    report["after"]["validation"] = {"J": None, "rmse": None, "mean": float("nan"), "sd": None, "n": None}
    table = before_after_table(report)
    assert table.splitlines()[0] == "Effect added: none: no effect improves the validation error"
    validation = next(line for line in table.splitlines() if line.startswith("validation "))
    assert validation.split()[-4:] == ["n/a"] * 4
    assert before_after_table({}).splitlines()[0].endswith("none: no effect improves the validation error")


def check_report(tmp_path, report, series, expected_plots):
    plots = write_report(tmp_path, report, series)
    assert [p.name for p in plots] == expected_plots
    for p in plots:
        assert p.parent == tmp_path and p.stat().st_size > 5000
        assert p.read_bytes()[:8] == PNG
    md = (tmp_path / "report.md").read_text(encoding="utf-8")
    for p in plots:
        assert f"]({p.name})" in md
    return md


def test_write_report_with_an_effect(tmp_path):
    report, series = synthetic()
    report["period"]["calibration_scored_from"] = series["times"][8].isoformat()
    report["noise_sigma"] = 0.0987
    md = check_report(tmp_path / "out", report, series, ["air_temperature.png", "residuals.png", "node_scores.png",
                                                         "convergence.png", "candidates.png"])
    # Table 4: every node's score, the failed one marked
    for k in NODES:
        assert f"\n| {k} | " in md
    assert "| 7 | 12.50 | 2.0 % | 1 | yes |" in md
    assert "| 9 | n/a (simulation failed) |" in md
    # Table 5 and the candidates
    assert "| calibration |" in md and "| +0.603 | +0.001 | 0.543 | 0.101 | 0.812 | 0.101 |" in md
    for c in ("conductivity (chosen)", "ground_coupling", "infiltration", "solar_absorptance"):
        assert c in md
    assert "factor = 1.873 ± 0.031" in md and "(not identifiable)" in md
    assert "lowest validation RMSE (0.123 C, 0.902 C before)" in md
    assert "Morris" in md and "conductivity@door" in md
    assert "[building_after.json](building_after.json)" in md
    assert "scored from 2001-06-10 02:00 UTC-05:00" in md and "sigma = 0.099 C" in md


def test_no_effect_when_the_gain_is_within_the_noise(tmp_path):
    report, series = no_effect(*synthetic())
    report["candidates"][3]["bic"] = -150.0
    md = check_report(tmp_path, report, series, ["air_temperature.png", "residuals.png", "node_scores.png",
                                                 "convergence.png", "candidates.png"])
    assert "the best, solar_absorptance on roof, lowers the validation RMSE only from 0.902 C to 0.554 C" in md


def test_write_report_with_no_effect_and_an_exhaustive_search(tmp_path):
    report, series = no_effect(*synthetic())
    report["localization"]["search"] = {"method": "exhaustive", "evaluations": 64, "unique_evaluations": 64}
    report["localization"]["node_scores"] = {str(k): None for k in NODES}
    report["localization"]["J_unforced"] = None
    report.pop("sensitivity")
    series["convergence"] = []
    md = check_report(tmp_path, report, series, ["air_temperature.png", "residuals.png", "node_scores.png",
                                                 "candidates.png"])
    assert "none: no effect improves the validation error" in md
    assert "exhaustive" in md and "no convergence curve" in md
    assert "None of the 4 candidates lowers the BIC" in md
    assert "Morris" not in md


def test_write_report_from_an_almost_empty_report(tmp_path):
    report, series = synthetic()
    minimal = {"period": report["period"], "before": report["before"], "effect": {"effect": "none"},
               "after": {"calibration": None, "validation": None}}
    series = dict(series, convergence=None, after=None)
    md = check_report(tmp_path, minimal, series, ["air_temperature.png", "residuals.png"])
    assert "No candidate effect was tried" in md


@pytest.mark.parametrize("tz", [None, "UTC"])
def test_write_report_times_without_offset_or_in_utc(tmp_path, tz):
    report, series = synthetic()
    times = series["times"].tz_convert(tz) if tz else series["times"].tz_localize(None)
    start = times[96]
    check_report(tmp_path, report, dict(series, times=times, validation_start=start),
                 ["air_temperature.png", "residuals.png", "node_scores.png", "convergence.png", "candidates.png"])
