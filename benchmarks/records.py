"""The records of the diagnosis benchmark (benchmarks/bench_diagnosis.py): a building file, a
weather, measurements, and the truth that made them, which the file does not describe.

The truth is never the diagnosis' own model:

- it is the file's building discretised finer: every stretch between two of the file's nodes or
  layer boundaries cut into `CELLS` equal cells (at least twice the nodes of every layer), the
  file's nodes keeping their ids so that a sensor reads the same point in both;
- it is simulated at `FINE_STEP` (1 min) from `TRUTH_HISTORY_DAYS` of weather before the record
  (the typical year read as cyclic, as simulation programs read it): its walls start from that
  past, long enough for the truth's own start to be forgotten, not from any state a diagnosis
  could assume; then sampled at the record's step. The weather is the typical year linearly
  interpolated to the minute, a heater's power is held over each record step (the value at a
  step's end, which is what a model stepping at the record's step reads: `model.integrate`), so
  both read the same inputs; the diagnosis reads the weather from `Spec.before` days before the
  record, a user's file that starts some days before the measurements, or with them;
- the file declares the site's ground temperature (the typical year's mean air) unless the spec
  says not (`Spec.declares_ground`); a ground fault's ground is at a stated temperature or at the
  spec's offset from the record's mean outdoor air (`truth.grounded`), which its later record keeps;
- the fault is an effect the file does not declare (or two of them together), applied to the truth with the registry's own
  `apply` (`model.effects.EFFECTS`), or one beyond the catalogue: a gain on a schedule, a gain
  through an opening the file does not have, an envelope whose materials and outside film
  coefficients are both more conductive than declared (the registry's envelope factor scales the
  materials alone);
- Gaussian noise from a seeded generator, one seed per record and draw.

The size of a fault is tuned by simulating: `subtle` puts the file's validation RMSE (noise
included) at `SUBTLE` times the noise, `strong` at `STRONG` times, by a secant search on the
faults' common scale (their parameters moved from the declared values towards `full`).

`record(name_or_spec, draw)` returns a `Record`: what a test or a script needs to diagnose it and
to judge the answer; `later_record(record)` the same building with the same fault measured again
two to four weeks after it ends, on which a correction is judged beyond its record. The truth is made in `benchmarks/truth.py`, the sizes in
`benchmarks/sizing.py`; `benchmarks/catalogue.py` lists the records (`SPECS`, `quick_specs()`).
"""
import dataclasses
import functools
import hashlib
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from benchmarks.catalogue import SPECS_BY_NAME, Spec
from benchmarks.sizing import before_error, tuned_scale
from benchmarks.truth import (CELLS, at_scale, faulty, file_building, fine_weather, frame, grounded, measured_nodes,
                              read_by_diagnosis, record_seed, record_times, truth_record)
from nodeforce.model.case import HISTORY_DAYS, measured_case
from nodeforce.model.hlc import heat_loss_coefficient
from nodeforce.model.numerical import refined

@dataclass
class Record:
    spec: Spec
    draw: int
    building: object  # the file the diagnosis reads (Building)
    truth: object  # the finer building with the fault (Building)
    weather: pd.DataFrame  # what the diagnosis reads: 1-min, every column the file names
    measurements: pd.DataFrame  # the record: columns T<id>, the step's grid, noise added
    noiseless: pd.DataFrame  # the same without noise
    scale: float  # the faults' common scale (0: none)
    values: list  # each fault's parameters in the truth, {name: value}
    before_ratio: float  # the file's validation RMSE on the noiseless record, with the noise added in quadrature, / noise
    hlc_truth: float  # W/K, the truth's heat loss coefficient (W/K)
    hlc_file: float

    @property
    def zones(self):
        """The objective zones (the first zone unless the spec names one)."""
        return [self.spec.objective or self.building.zones[0].name]

    def case(self, history_days=HISTORY_DAYS, building=None):
        """The measured case as the diagnosis of `building` (default the record's file) reads it:
        its grid, inputs, burn-in and at most `history_days` of the weather before the record."""
        return measured_case(building or self.building, self.weather, self.measurements,
                             burn_in_days=self.spec.burn_in, history_days=history_days)



@functools.lru_cache(maxsize=8)
def _noiseless(spec, scale=None):
    """(building, truth, weather, noiseless frame, scale, values, ratio) of a spec, the scale
    tuned unless given."""
    building = file_building(spec)
    times = record_times(spec)
    nodes = measured_nodes(spec, building)
    air = building.zone(spec.objective).air_node if spec.objective else building.zones[0].air_node
    truth0 = refined(building, CELLS)
    fine0 = fine_weather(spec, building, times, {})
    weather0 = read_by_diagnosis(spec, building, fine0, times)
    if scale is None:
        scale, ratio = tuned_scale(spec, building, truth0, fine0, weather0, times, nodes, air)
    values = at_scale(building, spec, scale)
    truth, extra = faulty(truth0, spec, values)
    weather = fine_weather(spec, building, times, extra) if extra else fine0
    clean = frame(truth_record(truth, weather, times, nodes), times, nodes, f"{spec.name} (noiseless)")
    ratio = math.hypot(before_error(building, weather0, clean, air, spec.burn_in), spec.noise) / spec.noise
    return building, truth, weather0, clean, scale, values, ratio


def record(name_or_spec, draw=0, scale=None):
    """The record `name_or_spec` (a name of `SPECS` or a `Spec`) under noise draw `draw`.

    `scale` fixes the faults' scale (skipping the tuning); None tunes it to the spec's size.
    The diagnosis reads `building`, `weather` and `measurements`; the truth and the rest judge it.
    """
    spec = name_or_spec if isinstance(name_or_spec, Spec) else SPECS_BY_NAME[name_or_spec]
    building, truth, weather, clean, scale, values, ratio = _noiseless(spec, scale)
    rng = np.random.default_rng(record_seed(spec.name, draw))
    noisy = frame(clean.to_numpy() + rng.normal(0.0, spec.noise, clean.shape), clean.index,
                  [int(c[1:]) for c in clean.columns], f"{spec.name} draw {draw}")
    return Record(spec=spec, draw=draw, building=building, truth=truth, weather=weather, measurements=noisy,
                  noiseless=clean, scale=scale, values=values, before_ratio=ratio,
                  hlc_truth=heat_loss_coefficient(truth), hlc_file=heat_loss_coefficient(building))


# When a record's later record starts after its own end (days): the same building measured
# again some weeks on, under other weather, the fault still there.
LATER_DAYS = (14, 28)


def later_spec(spec):
    """The spec of the same building, fault, sensors, step and length starting two to four weeks
    after `spec` ends, inside the typical year: the span drawn from the scenario's name (the part of the
    record's name before "/"), so that a scenario's records are measured again on the same days,
    the same every run; its ground where `spec`'s is (`truth.grounded`), not at its own offset."""
    scenario = spec.name.split("/")[0]
    seed = int.from_bytes(hashlib.sha1(scenario.encode()).digest()[:4], "little")
    days = int(np.random.default_rng(seed).integers(LATER_DAYS[0], LATER_DAYS[1] + 1))
    start = pd.Timestamp(f"2001-{spec.start}")  # any year without a 29 February: a month-day
    start = min(start + pd.Timedelta(days=spec.days + days), pd.Timestamp("2001-12-31") - pd.Timedelta(days=spec.days))
    return dataclasses.replace(grounded(spec), start=start.strftime("%m-%d"), name=f"{spec.name}+later")


def later_record(r):
    """The `Record` of `later_spec(r.spec)` under the same draw, its fault at `r`'s scale."""
    return record(later_spec(r.spec), r.draw, scale=r.scale)
