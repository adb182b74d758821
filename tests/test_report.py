"""The report writer: the before/after table, report.md and its plots, from a report and series
built by hand (two zones, a localisation, four candidates, the loop's decision)."""
import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from nodeforce.diagnosis.report import before_after_table, write_report
from nodeforce.diagnosis.report.formats import parameter_unit
from nodeforce.diagnosis.residuals import diagnostics
from nodeforce.model.effects import EFFECTS

PNG = b"\x89PNG\r\n\x1a\n"
NODES = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 16, 17]
ALL_PLOTS = ["air_temperature.png", "residuals.png", "residual_diagnostics.png", "node_scores.png",
             "convergence.png", "candidates.png"]


def metrics(rmse, mean, sd, n, zones=None):
    """METRICS; `zones` {name: (rmse, mean, sd, n)}, by default one zone equal to the total."""
    m = {"J": rmse ** 2 * n, "rmse": rmse, "mean": mean, "sd": sd, "n": n}
    zones = zones or {"living": (rmse, mean, sd, n)}
    return {**m, "zones": {z: {"J": r ** 2 * k, "rmse": r, "mean": mu, "sd": s, "n": k}
                           for z, (r, mu, s, k) in zones.items()}}


def two_zones(total, living, bath):
    return metrics(*total, zones={"living": living, "bath": bath})


def synthetic():
    """2 days at 15 min, the 2nd the validation window; a door conducting too little (node 7)
    seen by two zones, the living room and the bath."""
    times = pd.date_range("2001-06-10 00:00", periods=2 * 96, freq="15min", tz="-05:00", name="time")
    start = times[96]
    hours = np.arange(len(times)) / 4
    rng = np.random.default_rng(0)
    truth = 27 + 3 * np.sin(2 * np.pi * (hours - 9) / 24)
    zones = {}
    for i, (zone, node) in enumerate((("living", 23), ("bath", 24))):
        measured = truth - i + rng.normal(0, 0.1, len(times))
        measured[[10, 11, 12, 150]] = np.nan
        zones[zone] = {"air_node": node, "measured": measured,
                       "before": 26.3 - i + 2.2 * np.sin(2 * np.pi * (hours - 8) / 24),
                       "after": truth - i + 0.05 * np.sin(2 * np.pi * hours / 6)}
    inputs = {"T_out": 25 + 4 * np.sin(2 * np.pi * (hours - 15) / 24),
              "I_S": 600 * np.clip(np.sin(np.pi * (hours % 24 - 6) / 12), 0, None)}
    val = slice(96, None)
    residual = {state: zones["living"]["measured"][val] - zones["living"][state][val] for state in ("before", "after")}
    scores = {str(k): 300.0 + 20 * k for k in NODES}
    scores["7"] = 12.5
    scores["9"] = None  # a simulation that failed
    p_door = {"factor": {"value": 1.8734, "std": 0.0312, "identifiable": True}}
    report = {
        "period": {"calibration": [times[0].isoformat(), times[95].isoformat()],
                   "calibration_scored_from": times[8].isoformat(),
                   "validation": [start.isoformat(), times[-1].isoformat()]},
        "objective": ["living", "bath"],
        "before": {"calibration": two_zones((0.8123, 0.6034, 0.5432, 188), (0.7, 0.5, 0.5, 94), (0.9, 0.7, 0.6, 94)),
                   "validation": two_zones((0.9021, 0.7011, 0.5678, 190), (0.8, 0.6, 0.5, 95), (1.0, 0.8, 0.6, 95))},
        "localization": {
            "measured_nodes": NODES + [23, 24], "chromosome_nodes": NODES, "output_nodes": [23, 24],
            "J_unforced": 640.2, "best_nodes": [7], "J_best": 12.5, "node_scores": scores,
            "ranked_nodes": [7] + [k for k in NODES if k not in (7, 9)],
            "search": {"method": "ga", "population": 16, "generations": 12, "pc": 0.8, "pm": 0.03,
                       "seed": 3, "evaluations": 208, "unique_evaluations": 150, "seconds": 42.17,
                       "J_min": 11.9, "min_nodes": [7, 16], "tolerance": 6.4}},
        "candidates": [
            {"effect": "conductivity", "target": "door", "parameters": p_door, "derived": {},
             "calibration": metrics(0.1012, 0.001, 0.1011, 188), "validation": metrics(0.1234, 0.012, 0.1228, 190),
             "cv": {"blocks": [1.1, 0.9], "J": 2.0, "n": 188, "rmse": 0.1031}},
            {"effect": "ground_coupling", "target": "floor",
             "parameters": {"U": {"value": 0.52, "std": 0.9, "identifiable": False},
                            "T_ground": {"value": 24.3, "std": None, "identifiable": False}},
             "derived": {"ground_heat_flux": {"value": -1.7741, "std": 0.047, "unit": "W/m2"}},
             "calibration": metrics(0.7011, 0.4, 0.57, 188), "validation": metrics(0.8544, 0.6, 0.6, 190),
             "cv": {"blocks": [50.0, 45.0], "J": 95.0, "n": 188, "rmse": 0.7109}},
            {"effect": "infiltration", "target": "living",
             "parameters": {"n": {"value": 0.3, "std": 0.05, "identifiable": True}}, "derived": {},
             "calibration": {"J": None, "rmse": None, "mean": None, "sd": None, "n": 188},
             "validation": {"J": None, "rmse": None, "mean": None, "sd": None, "n": 190},
             "cv": {"blocks": [], "J": None, "n": 188, "rmse": None}},
            {"effect": "solar_absorptance", "target": "roof",
             "parameters": {"alpha": {"value": 0.71, "std": 0.02, "identifiable": True}}, "derived": {},
             "calibration": metrics(0.4011, 0.2, 0.35, 188),
             "validation": two_zones((0.5544, 0.3, 0.47, 190), (0.4321, 0.2, 0.4, 95), (0.6543, 0.4, 0.5, 95)),
             "cv": {"blocks": [16.0, 14.0], "J": 30.0, "n": 188, "rmse": 0.3995}},
        ],
        "decision": {"chosen": "conductivity@door",
                     "reason": "conductivity on door lowers the cross-validated J the most of the 2 candidates that pass.",
                     "cv_J_before": 154.6, "blocks": 2, "noise_margin": 7.25, "standard_errors": 1.0,
                     "cost": {"candidates": 4, "simulations": 310, "seconds": 12.5},
                     "candidates": {"conductivity@door": {"cv_fall": 152.6, "cv_se": 12.3, "needed": 12.3,
                                                          "passes": True, "objection": None},
                                    "ground_coupling@floor": {"cv_fall": 59.6, "cv_se": 1.0, "needed": 7.25,
                                                              "passes": True,
                                                              "objection": "U = 0.52 is not identifiable"},
                                    "infiltration@living": {"passes": False, "objection": None},
                                    "solar_absorptance@roof": {"cv_fall": 124.6, "cv_se": 2.0, "needed": 7.25,
                                                               "passes": True, "objection": None}}},
        "effect": {"effect": "conductivity", "target": "door", "parameters": p_door, "derived": {}},
        "after": {"calibration": two_zones((0.1012, 0.001, 0.1011, 188), (0.1, 0.0, 0.1, 94), (0.1, 0.002, 0.1, 94)),
                  "validation": two_zones((0.1234, 0.012, 0.1228, 190), (0.11, 0.01, 0.1, 95), (0.13, 0.02, 0.13, 95))},
        "residuals": {state: diagnostics(times[val], r, {k: v[val] for k, v in inputs.items()}, max_lag_hours=6)
                      for state, r in residual.items()},
        "noise_sigma": 0.0987,
        "noise": {"sigma": 0.0987, "given": False, "visible": True,
                  "sentence": "sensor noise of the air, estimated from its second differences: sigma = 0.099 C",
                  "numerical": 0.04, "numerical_sentence": "numerical error of the building file at the air: 0.04 C RMS"},
        "phases": [{"phase": "held at 30 C", "start": "2001-06-10T00:00:00-05:00", "end": "2001-06-11T00:00:00-05:00",
                    "n": 96, "rmse": {"before": 0.57, "conductivity@door": 0.75, "after": 0.75}},
                   {"phase": "free float", "start": "2001-06-11T00:00:00-05:00", "end": None,
                    "n": 95, "rmse": {"before": 0.90, "conductivity@door": 0.12, "after": 0.12}}],
        "sensitivity": {"conductivity@door": {"factor": {"mu_star": 85.2, "sigma": 12.1}},
                        "ground_coupling@floor": {"U": {"mu_star": 3.1, "sigma": None},
                                                  "T_ground": {"mu_star": 0.4, "sigma": 0.5}}},
        "node_names": {"7": "door, inside", "16": "floor, inside", "23": "living air", "24": "bath air"},
        "reference": {"label": "IDEAS detailed model", "rmse": {"validation": 0.4, "free float": 0.6}},
        "artifacts": {"building_after": "building_after.json", "fmu_after": "model_after.fmu", "plots": []},
    }
    series = {"times": times, "validation_start": start, "scored_from": times[8],
              "convergence": [(g, max(12.5, 640.2 / (1 + g * g))) for g in range(13)],
              "zones": zones, "inputs": inputs}
    return report, series


def no_effect(report, series):
    report, series = copy.deepcopy(report), copy.deepcopy(series)
    report["effect"] = {"effect": "none", "target": None, "parameters": {}}
    report["after"] = copy.deepcopy(report["before"])
    report["localization"]["best_nodes"] = []
    report["localization"]["J_best"] = report["localization"]["J_unforced"]
    report["decision"].update(chosen=None, reason="No candidate beats the model without an effect on both tests.",
                              candidates={k: {"passes": False, "objection": None}
                                          for k in report["decision"]["candidates"]})
    for zone in series["zones"].values():
        zone["after"] = zone["before"].copy()
    return report, series


def row(table, start):
    return next(line for line in table.splitlines() if line.startswith(start)).split()


def test_table_gives_the_rmse_before_and_after_per_zone_and_the_chosen_effect():
    report, _ = synthetic()
    table = before_after_table(report)
    assert table.splitlines()[0] == "Effect added: conductivity on door: factor = 1.873 +- 0.031"
    assert row(table, "calibration all zones") == ["calibration", "all", "zones", "|", "0.812", "+0.603", "0.543",
                                                   "188", "|", "0.101", "+0.001", "0.101", "188"]
    assert row(table, "validation bath")[3:8] == ["1.000", "+0.800", "0.600", "95", "|"]
    assert row(table, "validation living")[8] == "0.110"
    assert "2001-06-11 00:00 UTC-05:00" in table
    assert table.splitlines()[-1] == ("for scale, IDEAS detailed model: RMSE 0.400 C (validation), "
                                      "0.600 C (free float)")


def test_table_of_a_single_zone_has_one_row_per_window():
    report, _ = synthetic()
    report["objective"] = ["living"]
    report.pop("reference")
    table = before_after_table(report)
    assert [line.split()[0] for line in table.splitlines() if " | " in line][2:] == ["calibration", "validation"]
    assert "for scale" not in table


def test_table_flags_parameters_that_are_not_identifiable_with_the_registry_units():
    report, _ = synthetic()
    report["effect"] = copy.deepcopy({k: report["candidates"][1][k] for k in ("effect", "target", "parameters", "derived")})
    header = before_after_table(report).splitlines()
    assert header[0].startswith("Effect added: ground_coupling on floor: U = 0.52 +- 0.90 W/m2/K (not identifiable)")
    assert "T_ground = 24.30 +- n/a C (not identifiable)" in header[0]
    assert header[1] == "  the data determine ground heat flux = -1.774 +- 0.047 W/m2"


def test_parameter_units_come_from_the_effect_registry():
    for effect, record in EFFECTS.items():
        for p in record.parameters:
            assert parameter_unit(effect, p.name) == ("" if p.unit == "-" else p.unit)
    assert parameter_unit("no_such_effect", "x") == "" and parameter_unit("ground_coupling", "x") == ""


def test_table_with_no_effect_and_missing_values():
    report, _ = no_effect(*synthetic())
    report["after"]["validation"]["zones"]["bath"] = {"J": None, "rmse": None, "mean": float("nan"), "sd": None, "n": None}
    table = before_after_table(report)
    assert table.splitlines()[0] == "Effect added: none: no candidate passes the choice on the calibration window"
    assert row(table, "validation bath")[-4:] == ["n/a"] * 4
    assert before_after_table({}).splitlines()[0].endswith("none: no candidate passes the choice on the calibration window")


def test_a_diagnosis_that_adds_nothing_says_where_the_validation_is_beyond_the_error_floor():
    """An error floor of 0.1 C on 100 validation residuals leaves J up to 100 x 0.1^2 = 1.0 C2 and
    3 sds of its change, 3 x 0.01 x sqrt(200) = 0.424 C2: J 4.0 C2 (0.2 C) is beyond it, twice
    the floor, and the header says a fault may be there; J 1.2 C2 is within it, and it says not."""
    report, _ = no_effect(*synthetic())
    report["noise"] = {"floor": 0.1}
    report["before"]["validation"].update(J=4.0, n=100, rmse=0.2)
    header = before_after_table(report).splitlines()[0]
    assert header == ("Effect added: none: no candidate passes the choice on the calibration window; the validation "
                      "error, 0.200 C, is 2.00 times the error floor of 0.100 C, beyond what it leaves: a fault these "
                      "calibration days do not show may be there")
    report["before"]["validation"].update(J=1.42, n=100, rmse=0.119)
    assert before_after_table(report).splitlines()[0].endswith("on the calibration window")
    report["before"]["validation"].update(J=1.43)
    assert "may be there" in before_after_table(report).splitlines()[0]


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
    md = check_report(tmp_path / "out", report, series, ALL_PLOTS)
    # Table 4: every node's score with its name, the failed one marked
    for k in NODES:
        assert f"\n| {k} | " in md
    assert "| 7 | door, inside | 12.50 | 2.0 % | 1 | yes |" in md
    assert "| 9 |  | n/a (simulation failed) |" in md
    # Table 5 per zone and window, the reference beside our RMSE where it has the window
    assert "| bath | validation |" in md and "| +0.800 | +0.012 |" not in md
    assert "| living | validation | 2001-06-11 00:00 UTC-05:00 to 2001-06-11 23:45 UTC-05:00 | +0.600 | +0.010 |" in md
    assert "| 0.902 | 0.123 | 0.400 |" in md and "RMSE IDEAS detailed model (C)" in md
    assert "| bath | validation |" in md and "| 1.000 | 0.130 |  |" in md  # the reference is the objective's
    assert "For scale, the IDEAS detailed model: RMSE 0.400 C (validation), 0.600 C (free float)." in md
    # the decision as the loop wrote it, with its margins; the verdicts are read, not re-derived
    assert report["decision"]["reason"] in md
    assert "- numerical error of the building file at the air: 0.04 C RMS" in md
    assert "numerical error could (7.250 C²)" in md and "4 candidates, 310 simulations, 12.5 s" in md
    # the cross-validated fall of J, the fall it needed, the verdict and physics' objection
    assert "| solar_absorptance | roof |" in md and "| 124.6 | 7.250 | yes |  |" in md
    assert "| 152.6 | 12.30 | yes |  |" in md
    assert "| 59.60 | 7.250 | yes | U = 0.52 is not identifiable |" in md
    # each phase, before, every candidate and after; the phase made worse is marked
    assert "| held at 30 C | 2001-06-10 00:00 UTC-05:00 | 96 | 0.570 | 0.750 ▲ | 0.750 ▲ |" in md
    assert "| free float | 2001-06-11 00:00 UTC-05:00 | 95 | 0.900 | 0.120 | 0.120 |" in md
    for c in ("conductivity (chosen)", "ground_coupling", "infiltration", "solar_absorptance"):
        assert c in md
    assert "factor = 1.873 ± 0.031" in md and "(not identifiable)" in md
    assert "ground heat flux = -1.774 ± 0.047 W/m2" in md
    # validation RMSE of the candidates per zone
    assert "| solar_absorptance@roof | 0.432 | 0.654 |" in md
    # residual diagnostics before and after, each its sentence
    for state in ("before", "after"):
        assert f"- {state}: {report['residuals'][state]['sentence']}" in md
    assert "Morris" in md and "conductivity@door" in md
    assert "[building_after.json](building_after.json)" in md
    assert "scored from 2001-06-10 02:00 UTC-05:00" in md and "sigma = 0.099 C" in md


def test_write_report_with_no_effect_and_an_exhaustive_search(tmp_path):
    report, series = no_effect(*synthetic())
    report["localization"]["search"] = {"method": "exhaustive", "evaluations": 64, "unique_evaluations": 64}
    report["localization"]["node_scores"] = {str(k): None for k in NODES}
    report["localization"]["J_unforced"] = None
    for key in ("sensitivity", "residuals", "reference", "node_names"):
        report.pop(key)
    series["convergence"] = []
    md = check_report(tmp_path, report, series, ["air_temperature.png", "residuals.png", "node_scores.png",
                                                 "candidates.png"])
    assert "none: no candidate passes the choice on the calibration window" in md
    assert "exhaustive" in md and "no convergence curve" in md
    assert "No candidate beats the model without an effect on both tests." in md and "- chosen: none" in md
    assert "No residual diagnostics in this report." in md
    assert "Morris" not in md and "For scale" not in md


def test_write_report_from_an_almost_empty_report(tmp_path):
    report, series = synthetic()
    minimal = {"period": report["period"], "before": report["before"], "effect": {"effect": "none"},
               "after": {"calibration": None, "validation": None}}
    for zone in series["zones"].values():
        zone["after"] = None
    md = check_report(tmp_path, minimal, dict(series, convergence=None), ["air_temperature.png", "residuals.png"])
    assert "No candidate effect was tried" in md and "The loop recorded no decision" in md


@pytest.mark.parametrize("tz,label,first", [(None, "time", "2001-06-10 00:00"),
                                             ("UTC", "time (UTC+00:00)", "2001-06-10 05:00")])
def test_write_report_times_without_offset_or_in_utc(tmp_path, monkeypatch, tz, label, first):
    """Times without an offset are plotted as they are, under "time"; times in UTC at their UTC
    clock (the record's first time, 00:00 at UTC-05:00, at 05:00), the axis naming the offset."""
    from nodeforce.diagnosis.report import figures
    report, series = synthetic()
    times = series["times"].tz_convert(tz) if tz else series["times"].tz_localize(None)
    saved = {}
    original = figures._save
    monkeypatch.setattr(figures, "_save", lambda fig, path: saved.setdefault(Path(path).name, fig) and original(fig, path))
    check_report(tmp_path, report, dict(series, times=times, validation_start=times[96], scored_from=times[8]),
                 ALL_PLOTS)
    for name in ("air_temperature.png", "residuals.png"):
        axes = saved[name].axes
        assert {ax.get_xlabel() for ax in axes if ax.get_xlabel()} == {label}, name
    plotted = saved["air_temperature.png"].axes[0].get_lines()[0].get_xdata()[0]
    assert pd.Timestamp(plotted).strftime("%Y-%m-%d %H:%M") == first


def test_a_long_effect_name_keeps_the_time_plots_legend_inside_the_figure(tmp_path, monkeypatch):
    from nodeforce.diagnosis.report import figures
    report, series = synthetic()
    report["effect"]["target"] = "living->west_facade_global_vertical_irradiance_measured"
    saved = []
    original = figures._save
    monkeypatch.setattr(figures, "_save", lambda fig, path: saved.append(fig) or original(fig, path))
    figures.plot_temperature(tmp_path / "t.png", report, series)
    figures.plot_residuals(tmp_path / "r.png", report, series)
    for fig in saved:
        renderer = fig.canvas.get_renderer()
        box, frame = fig.legends[0].get_window_extent(renderer), fig.bbox
        assert frame.x0 <= box.x0 and box.x1 <= frame.x1, (box, frame)


def test_a_candidate_tried_again_on_top_is_judged_and_marked_in_its_own_round(tmp_path):
    from nodeforce.diagnosis.report import content
    report, _ = synthetic()
    first = next(c for c in report["candidates"] if c["effect"] == "conductivity")
    again = {**copy.deepcopy(first), "on_top_of": ["conductivity@door"], "effect": "solar_absorptance",
             "target": "roof"}
    roof = next(c for c in report["candidates"] if c["effect"] == "solar_absorptance")
    report["candidates"].append(again)
    report["effects"] = [{"effect": "conductivity", "target": "door"}, {"effect": "solar_absorptance", "target": "roof"}]
    report["decision"]["chosen"] = "solar_absorptance@roof"
    first_round = {**report["decision"], "chosen": "conductivity@door"}
    report["decision"]["rounds"] = [first_round, {"chosen": "solar_absorptance@roof", "candidates": {
        "solar_absorptance@roof": {"cv_fall": 3.0, "passes": True, "needed": 1.5, "objection": None}}}]
    # the first round's roof: its own verdict, not chosen; the same label on top: chosen, its verdict
    assert content.verdict(report, roof) == first_round["candidates"]["solar_absorptance@roof"]
    assert not content.is_chosen(report, roof) and content.is_chosen(report, first)
    assert content.verdict(report, again)["needed"] == 1.5 and content.is_chosen(report, again)


def first_screen_of(md):
    """report.md's title and the block under it (the first screen)."""
    title, block = md.split("\n\n")[:2]
    return [title] + block.splitlines()


def test_the_first_screen_says_where_what_how_sure_and_what_is_left_in_ten_lines(tmp_path):
    report, series = synthetic()
    report["heat_loss_coefficient"] = {"before": 60.04, "after": 64.1, "after_sd": 1.23, "split": None}
    write_report(tmp_path, report, series)
    screen = first_screen_of((tmp_path / "report.md").read_text(encoding="utf-8"))
    assert len(screen) <= 10 and screen[0] == "# nodeforce diagnosis report"
    # share of J above the noise the forcing removes, by hand: no noise floor here, (640.2 - 12.5) / 640.2
    assert screen[1] == "**Fault:** in door, inside: forcing node 7 (door, inside) removes 98% of J.  "
    assert screen[2] == "**Added:** conductivity on door.  "
    assert screen[3] == "**The data determine:** factor = 1.873 ± 0.031.  "
    assert screen[4].startswith("**Validation:** RMSE 0.902 -> 0.123 C, mean error +0.701 -> +0.012 C")
    assert screen[5] == "**Heat loss coefficient:** 60.0 W/K as described, 64.1 ± 1.2 W/K as corrected.  "
    assert screen[6].startswith("**Left:** ") and report["residuals"]["after"]["sentence"][1:-1] in screen[6]


def test_the_first_screen_gives_what_the_data_fix_not_the_parameters_they_cannot(tmp_path):
    report, series = synthetic()
    report["effect"] = copy.deepcopy({k: report["candidates"][1][k] for k in ("effect", "target", "parameters", "derived")})
    report["localization"].update(best_nodes=[], search={**report["localization"]["search"], "J_noise": 40.2, "J_min": 400.2})
    write_report(tmp_path, report, series)
    md = (tmp_path / "report.md").read_text(encoding="utf-8")
    screen = first_screen_of(md)
    assert len(screen) <= 10
    # (640.2 - 400.2) / (640.2 - 40.2) of the best forcing found, which did not locate the fault
    assert screen[1] == ("**Fault:** not located: the best forcing, nodes 7 (door, inside), 16 (floor, inside), "
                         "removes only 40% of J above the noise floor.  ")
    assert screen[3] == ("**The data determine:** ground heat flux = -1.774 ± 0.047 W/m2 (U and T_ground each not "
                         "fixed by these data: candidates table).  ")
    assert not any("not identifiable" in line or "U = " in line for line in screen)
    assert "U = 0.52 ± 0.90 W/m2/K (not identifiable)" in md  # below, in the result and the candidates


def test_the_decision_says_each_refusal_reason_once(tmp_path):
    from nodeforce.diagnosis.report.summary import chosen_sentence
    report, series = synthetic()
    gains = [("internal_gain@living", "Q = -2.81 W is a negative gain (a heat sink) [0, inf]"),
             ("daily_gain@living", "mean = -2.82 W is a negative gain (a heat sink) [0, inf]"),
             ("proportional_gain@living->I_S", "k = -0.0245 - is a negative gain (a heat sink) [0, inf]")]
    other = [("ground_coupling@floor", "U = 0.52 +- 0.9 W/m2/K is not identifiable from these data; "
                                       "T_ground = 24.3 C ends on a bound of its range")]
    suggestions = [{"candidate": c, "reason": r, "cv_rmse": 0.2} for c, r in gains[:2]]
    first = "Conductivity on door predicts the left-out days best."
    # refused candidates of two rounds: the report says them grouped by reason, across rounds
    report["decision"].update(suggestions=suggestions, reason=first)
    report["decision"]["rounds"] = [dict(report["decision"]), {
        "chosen": None, "suggestions": [{"candidate": c, "reason": r, "cv_rmse": 0.2} for c, r in gains[2:] + other]}]
    assert chosen_sentence(report) == first
    write_report(tmp_path, report, series)
    md = (tmp_path / "report.md").read_text(encoding="utf-8")
    decision = md.split("## Decision", 1)[1].split("\n## ", 1)[0]
    assert decision.count("negative gain") == 1 and decision.count("not identifiable") == 1
    assert ("- 3 candidates the data support, not added: each is a negative gain (a heat sink): "
            "internal_gain@living (Q = -2.81 W), daily_gain@living (mean = -2.82 W), "
            "proportional_gain@living->I_S (k = -0.0245)") in decision
    assert ("- 1 candidate the data support, not added: it is not identifiable from these data; and ends on a bound "
            "of its range: ground_coupling@floor (U = 0.52 +- 0.9 W/m2/K; T_ground = 24.3 C)") in decision
    for candidate, _ in gains + other:
        assert decision.count(candidate) == 1


def test_the_phases_table_of_a_whole_house_keeps_the_chosen_candidates():
    """Beyond PHASE_COLUMNS candidates (a house of seven rooms tries 163) the table shows before,
    each round's chosen candidate and after; report.json keeps them all."""
    from nodeforce.diagnosis.report import tables
    labels = [f"conductivity@W{i}" for i in range(tables.PHASE_COLUMNS + 2)]
    rmse = {"before": 1.0, **{label: 0.9 for label in labels}, "gain@x (round 2)": 0.5, "after": 0.5}
    report = {"phases": [{"phase": "free float", "start": "2014-04-17T07:30:00+01:00", "end": None, "n": 10,
                          "rmse": rmse}],
              "decision": {"rounds": [{"chosen": "conductivity@W3"}, {"chosen": "gain@x"}]}}
    header = tables.phases(report).splitlines()[0]
    assert header == "| phase | from | n | before | conductivity@W3 | gain@x (round 2) | after |"
