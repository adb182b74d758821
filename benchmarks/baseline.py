"""The plain baseline the diagnosis is judged against (issue 27): each catalogue effect alone,
fitted by least squares to the objective air, chosen by BIC.

For every effect of the registry (`model.effects.EFFECTS`) and every target it applies to that
concerns the objective zones (the zone itself, a component facing it, a `zone->column` target of
the zone), the effect's parameters are fitted, within the registry's bounds, by
`scipy.optimize.least_squares` to the objective air on the calibration window (the record's
first `fraction`, after the burn-in), with the direct model (`model.integrate.simulate`, the
FMU's equal to 1e-9 C) started as the diagnosis starts (the weather's history, the steady state,
the burn-in's forcing). The candidate of lowest BIC = n log(J/n) + k log(n) is the answer if its BIC is
more than `BIC_MARGIN` below the file's as given; else "none". No localisation, no residual
statistics, no rule beyond that one.
"""
import math
import time

import numpy as np
from scipy.optimize import least_squares

from nodeforce.model.building import Surface
from nodeforce.model.case import working_day
from nodeforce.model.effects import BRIDGE_TO, EFFECTS, PAIR, bridge_parts, pair_parts

BIC_MARGIN = 10.0
MAX_EVALUATIONS = 40  # least-squares residual evaluations per parameter and candidate


def concerns(building, effect, target, zones):
    """Whether an effect's target acts on one of the objective `zones`."""
    if effect == "thermal_bridge":
        return bridge_parts(target)[0] in zones
    if BRIDGE_TO in target:
        return target.partition(BRIDGE_TO)[0] in zones
    if target in {z.name for z in building.zones}:
        return target in zones
    if PAIR in target:  # air exchanged between two zones
        return bool(set(pair_parts(target)) & set(zones))
    if target in building.boundary_columns:  # every conductance to a boundary, the house's
        return True
    c = building.component(target)
    return c.inside.zone in zones or (isinstance(c.outside, Surface) and c.outside.zone in zones)


def air_run(building, case, air_nodes):
    """(N_t, zones) simulated air (C) of `building` on `case`, as the diagnosis runs it."""
    return case.with_inputs(building).run(building, np.array(air_nodes) - 1)


def fit_one(building, case, effect, target, air_nodes, rows):
    """(values, J on `rows`, the fitted building) of `effect` on `target` fitted alone."""
    record = EFFECTS[effect]
    names = [p.name for p in record.parameters]
    low, high = np.array(record.bounds(building, target), dtype=float).T
    start = np.clip([record.read(building, target)[n] for n in names], low, high)
    # a start on a bound (no mass, no gain) leaves the solver's first step one-sided: start inside
    start = np.where(start <= low, low + 1e-3 * (high - low), np.where(start >= high, high - 1e-3 * (high - low), start))
    scale = np.maximum(np.abs(start), 1e-2 * (high - low))
    measured = case.measured[1:, np.array(air_nodes) - 1][rows]
    # the inputs the effect reads, at any of its values: one case, whose runs share their plan
    inputs = case.with_inputs(record.apply(building, target, {}))

    def residual(x):
        try:
            fitted = record.apply(building, target, dict(zip(names, x)))
            r = (measured - inputs.run(fitted, np.array(air_nodes) - 1)[rows]).ravel()
        except ValueError:  # a value the building refuses (the InputError of an impossible field)
            return np.full(measured.size, 1e3)
        return r if np.all(np.isfinite(r)) else np.full(r.size, 1e3)

    solution = least_squares(residual, start, bounds=(low, high), x_scale=scale,
                             max_nfev=MAX_EVALUATIONS * len(names))
    values = dict(zip(names, map(float, solution.x)))
    J = float(solution.fun @ solution.fun)
    return values, J, record.apply(building, target, values)


def bic(J, n, k):
    return n * math.log(J / n) + k * math.log(n)


def baseline(building, case, zones, fraction=0.6):
    """The baseline's answer on `case` (a Case with its burn-in and steady start set).

    Returns {"effect", "target" (None for "none"), "values", "delta_bic" (the file's BIC minus the
    best candidate's; > BIC_MARGIN to be chosen), "validation_rmse" before and after, "candidates"
    (how many fitted), "seconds"}.
    """
    started = time.time()
    air_nodes = [building.zone(z).air_node for z in zones]
    n_steps, h = len(case.times) - 1, case.history_steps
    k = h + int(round(fraction * (n_steps - h)))  # of the measured record, as the diagnosis splits it
    rows = np.arange(case.burn_in_steps, k)
    measured = case.measured[1:, np.array(air_nodes) - 1]
    ok = np.isfinite(measured[rows]).all(axis=1)
    rows = rows[ok]
    n = rows.size * len(air_nodes)
    before = air_run(building, case, air_nodes)
    J0 = float(np.sum((measured[rows] - before[rows]) ** 2))
    best = {"effect": "none", "target": None, "values": {}, "bic": bic(J0, n, 0), "building": building}
    tried = 0
    # a gain on working days is the daily gain where the window scores no rest day: the loop
    # offers it only where the window holds both kinds of day, and so does the baseline
    rested = (1.0 - working_day(case.times[1:][rows], building.site["timezone"], building.source)).any()
    for effect, record in EFFECTS.items():
        if effect == "workday_gain" and not rested:
            continue
        for target in record.targets(building):
            if not concerns(building, effect, target, zones):
                continue
            values, J, fitted = fit_one(building, case, effect, target, air_nodes, rows)
            tried += 1
            b = bic(J, n, len(values))
            if b < best["bic"]:
                best = {"effect": effect, "target": target, "values": values, "bic": b, "building": fitted}
    delta = bic(J0, n, 0) - best["bic"]
    if delta <= BIC_MARGIN:
        best = {"effect": "none", "target": None, "values": {}, "building": building}
    after = air_run(best["building"], case, air_nodes)

    def rmse(simulated):
        r = (measured[k:] - simulated[k:]).ravel()
        return float(np.sqrt(np.nanmean(r ** 2)))
    return {"effect": best["effect"], "target": best["target"], "values": best["values"], "delta_bic": float(delta),
            "validation_rmse": {"before": rmse(before), "after": rmse(after)}, "candidates": tried,
            "seconds": time.time() - started}
