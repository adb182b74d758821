"""The size of a record's fault: its scale tuned by simulating, so that the file's validation RMSE
(noise included) is `SUBTLE` or `STRONG` times the noise, never beyond the fault's physical
limits (`max_scale`)."""
import math

import numpy as np

from benchmarks.catalogue import BURN_IN_DAYS, CALIBRATION_FRACTION
from benchmarks.truth import at_scale, faulty, fine_weather, frame, neutral, truth_record
from nodeforce.diagnosis.policy import Policy
from nodeforce.model.case import measured_case
from nodeforce.model.effects import EFFECTS

SUBTLE, STRONG = 2.2, 6.0  # validation RMSE before / noise the sizes are tuned to
SUBTLE_BAND, STRONG_BAND = (1.5, 3.0), (4.0, 9.0)  # accepted


def before_error(building, weather, record, objective_node, burn_in=BURN_IN_DAYS):
    """The file's validation RMSE (C) on a record, as the diagnosis' "before" measures it: the
    direct model (the FMU's equal) with the history the weather gives, the burn-in and the steady
    start, on the record's last 40 %."""
    case = measured_case(building, weather, record, burn_in_days=burn_in).with_steady_start()
    h = case.history_steps
    residual = (case.measured[1:, objective_node - 1] - case.run(building, [objective_node - 1])[:, 0])[h:]
    k = int(round(CALIBRATION_FRACTION * len(residual)))
    return float(np.sqrt(np.nanmean(residual[k:] ** 2)))


def tuned_scale(spec, building, truth0, fine0, weather0, times, nodes, air):
    """The effect's scale whose noiseless validation error e puts sqrt(e^2 + noise^2) at the
    size's ratio to the noise: a secant search on log(e) against log(scale). `fine0`: the truth's
    weather; `weather0`: the part the diagnosis reads."""
    if not spec.faults:
        return 0.0, 1.0
    target = SUBTLE if spec.size == "subtle" else STRONG
    band = SUBTLE_BAND if spec.size == "subtle" else STRONG_BAND
    wanted = spec.noise * math.sqrt(target ** 2 - 1)

    def ratio_at(scale):
        values = at_scale(building, spec, scale)
        truth, extra = faulty(truth0, spec, values)
        weather = fine_weather(spec, building, times, extra) if extra else fine0
        record = frame(truth_record(truth, weather, times, nodes), times, nodes, "truth")
        e = before_error(building, weather0, record, air, spec.burn_in)
        return e, math.hypot(e, spec.noise) / spec.noise

    scale, previous = 1.0, None
    limit = max_scale(building, spec)
    for _ in range(8):
        e, ratio = ratio_at(scale)
        if band[0] <= ratio <= band[1] and abs(ratio - target) < 0.25 * target:
            return scale, ratio
        slope = 1.0
        if previous is not None and previous[1] > 0 and e > 0 and abs(math.log(scale / previous[0])) > 1e-6:
            slope = max(0.3, min(3.0, math.log(e / previous[1]) / math.log(scale / previous[0])))
        previous = (scale, e)
        new = scale * (wanted / max(e, 1e-9)) ** (1 / slope)
        new = min(new, limit)
        if new == scale:
            break
        scale = new
    return scale, ratio


def max_scale(building, spec):
    """The largest scale keeping every parameter of every fault of the spec in its effect's range
    and within its physical limits (`diagnosis.policy.Policy.limits`: a record whose fault no
    building could have, a door 19 times as conductive as its wood, inside convection at a
    twentieth, tests a refusal, not a diagnosis), and the opening smaller than its wall. A fault
    that is still not subtle at that scale is as large as physics lets it be: its record says so
    by its before/noise."""
    return min(fault_max_scale(building, fault) for fault in spec.faults)


def fault_max_scale(building, fault):
    """`max_scale` of one fault."""
    if fault.effect not in EFFECTS:
        if fault.effect == "opening":
            return 0.9 * building.component(fault.target).area / fault.full["area"]
        if fault.effect == "envelope_films":  # the envelope factor's physical limit on the whole path
            high = Policy().limits(building, "envelope_conductance", fault.target, "factor")[1]
            return 0.95 * (high - 1.0) / (fault.full["factor"] - 1.0)
        return 20.0
    effect = EFFECTS[fault.effect]
    base = neutral(building, fault)
    limit = 20.0
    for p, (low, high) in zip(effect.parameters, effect.bounds(building, fault.target)):
        physical = Policy().limits(building, fault.effect, fault.target, p.name)
        low, high = max(low, physical[0]), min(high, physical[1])
        if p.name in fault.full and p.name != "T_ground":
            delta = fault.full[p.name] - base[p.name]
            if delta > 0:
                limit = min(limit, (high - base[p.name]) / delta)
            elif delta < 0:
                limit = min(limit, (low - base[p.name]) / delta)
    return 0.95 * limit
