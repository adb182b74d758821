"""A measured case on its simulation grid: the inputs and measurements every simulation reads.

`prepare_case` turns a building, its weather and its measurements into arrays on one uniform
time grid: the measurement grid when there are measurements (weather interpolated onto it),
else the weather's own. It never fills a gap: a missing measurement stays NaN (the node is then
computed, docs/model.md section 5) and a missing input is refused.

Where the weather starts before the first measurement, the grid reaches back over it (the
history, at most `HISTORY_DAYS`): a building measured from some date had a past, and its heavy
components carry it for weeks. Simulated over that weather, nothing measured or scored, the
model reaches the first measurement in the state the weather left it, as the building did,
rather than in the steady state of the record's first day (docs/model.md 5.7).
"""
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from .errors import InputError
from .integrate import Plan, held_inputs, history_block, initial_state, simulate, steps_per_day, substeps
from .building import DAY_TERMS, WORKDAY_TERMS, WORKDAYS, traced_input
from .network import (WIND_DIRECTION, WIND_SPEED, assemble, clock_input_names, day_input, input_names,
                      slowest_time_constant, workday_input)
from .units import check_celsius
from .geometry import outward_normal
from .beam_trace import beam_shares
from .shading import sky_diffuse_ratio, sun_vectors, sunlit_fraction
from .site import run_building, standard_offset
from .solar import (DECOMPOSITIONS, complete_irradiance, incident_irradiance, measured_irradiance, sky_temperature,
                    solar_position, transmitted_irradiance, transmitted_split)
from .weather import IRRADIANCE_COLUMNS, check_columns, weather_on_grid


# Days of weather before the first measurement a measured case simulates at most, in steps of up
# to 3 h (`integrate.HISTORY_STEP`), from the steady state of their mean conditions. Measured on 30
# weeks of the test cell's air alone (three climates, a 90-day past, benchmarks/records.py's
# truth), the file missed the record by 0.33 C RMS on average (1.3 at worst) without a history,
# 0.21 (0.61) after 14 days, 0.10 (0.26) after 30 and 0.066 (0.09) after 60, its coarser walls'
# own error: the test cell's floor above its adiabatic face has a mode of 14.7 days, and 60 days
# leave e^-4 of what the start got wrong. Their 480 steps cost about the two days' replay of the
# first day (at 5-min steps) they replace.
HISTORY_DAYS = 60.0

STEADY_START = ("the nodes no measurement sets start from the steady state of the first day's mean conditions, "
                "then the first day is replayed (the warm-up): a heavy component starts with "
                "the gradient those conditions give it, not at the air's temperature")


@dataclass(frozen=True)
class Case:
    times: pd.DatetimeIndex  # t_0..t_N, uniform
    dt: float  # s
    input_names: tuple  # columns of U, as `model.network.input_names`
    U: np.ndarray  # (N_t+1, n_inputs) inputs at t_0..t_N
    measured: np.ndarray  # (N_t+1, N) node temperatures (C), NaN where not measured
    burn_in_steps: int = 0  # B: t_1..t_B force every measured node and are not scored
    assumptions: tuple = ()  # sentences: what the case computed that the files did not give
    steady_start: bool = False  # the warm-up starts from the first day's steady state (`with_steady_start`)
    fluxes: dict = field(default_factory=dict)  # flux sensor -> (N_t+1,) W/m2 measured, NaN where missing
    building: object = None  # the Building whose nodes `measured` holds (its state at t_0: `start_state`)
    substeps: int = 1  # integration steps per sample (`integrate.substeps`: of at most MAX_STEP)
    history_steps: int = 0  # H: t_1..t_H the weather before the first measurement (t_H), part of the burn-in
    annual_air: float | None = None  # C: the weather's mean outdoor air over its whole years (`annual_mean_air`)
    # the `integrate.Plan` of the last layouts run (`run`), by layout
    _plans: dict = field(default_factory=dict, init=False, repr=False, compare=False)
    PLANS = 4

    # the plans are not pickled: they are the case's arrays again, larger, and a worker that reads
    # the case makes its own
    def __getstate__(self):
        return {name: value for name, value in self.__dict__.items() if name != "_plans"}

    def __setstate__(self, state):
        self.__dict__.update(state, _plans={})

    def start_state(self, T_default=20.0):
        """(N,) node temperatures (C) at t_0 of the case's building, N its nodes (those its
        effects add included): the measured ones at their value, the others by the rule of
        `integrate.initial_state`."""
        if self.building is None:
            raise ValueError("a case without its building has no state at t_0 (Case(..., building=...))")
        n = self.building.n_nodes
        measured0 = np.concatenate([self.measured[0], np.full(n - self.measured.shape[1], np.nan)])
        return initial_state(self.building, measured0, T_default)

    @property
    def measured_ids(self):
        """Ids of the nodes with at least one measurement."""
        return [int(i) + 1 for i in np.flatnonzero(np.isfinite(self.measured).any(axis=0))]

    def steps(self, days):
        """Number of steps in `days`."""
        return int(round(days * 86400 / self.dt))

    def with_burn_in(self, days, source="--burn-in-days"):
        """The case whose first `days` after the first measurement are a burn-in, after the
        history (docs/model.md section 5)."""
        steps = self.steps(days)
        if days < 0 or abs(steps * self.dt - days * 86400) > 1e-6 * self.dt:
            raise InputError(source, days, f"must be a whole number of {self.dt:g} s steps, not negative")
        if self.history_steps + steps >= len(self.times) - 1:
            raise InputError(source, days, "the burn-in must be shorter than the record")
        return replace(self, burn_in_steps=self.history_steps + steps)

    @property
    def start(self):
        """The time of the first measurement, t_H (t_0 without a history)."""
        return self.times[self.history_steps]

    def with_steady_start(self):
        """The case whose runs take, before the replay warm-up, one long step at the first day's
        mean conditions (`integrate.steady_inputs`), stated among its assumptions."""
        if self.steady_start:
            return self
        said = STEADY_START if self.building is None else f"{STEADY_START}; {start_memory(self.building)}"
        return replace(self, steady_start=True, assumptions=self.assumptions + (said,))

    def scored(self, columns):
        """(N_t, k) measurements of the node indices `columns` at t_1..t_N, NaN where missing and
        over the burn-in, which is not scored."""
        measured = self.measured[1:, columns].copy()
        measured[:self.burn_in_steps] = np.nan
        return measured

    def with_inputs(self, building):
        """The case of `building`, with the inputs it reads (`model.network.input_names`): its own
        columns, and the time-of-day basis computed from its times, for a building that differs
        from the case's by an effect (a daily gain adds the basis; no effect adds a measured column).
        """
        columns = dict(zip(self.input_names, self.U.T))
        columns.update(clock_inputs(building, self.times))
        columns.update(schedule_inputs(building, self.times))
        names = input_names(building)
        absent = [n for n in names if n not in columns]
        if absent:
            raise InputError(building.source, absent[0], "an input column the case was not prepared with")
        return replace(self, input_names=names, U=np.column_stack([columns[n] for n in names]), building=building)

    def run(self, building, nodes=None, network=None, derivatives=(), start_offset=None):
        """The temperatures (C) at t_1..t_N of the `nodes` of `building` (indices, default every
        node) on this case, with the direct model, as a diagnosis runs it: its burn-in, its
        steady start and its sub-steps. The case must carry the inputs `building` reads
        (`with_inputs`). `network`: the building's, where the caller has assembled it;
        `derivatives`: its `network.Derivative` with respect to each of k parameters, whose
        derivatives (N_t, len(nodes), k) are returned too (`integrate.simulate`); `start_offset`:
        (N,) K added to the state at the history's start (`integrate.Plan.run`, `model.start`).

        The run's `integrate.Plan` is kept for its layout (its nodes, its inputs and which are
        held): a calibration runs one building's network at hundreds of values."""
        network = assemble(building) if network is None else network
        held = held_inputs(building, network.input_names)
        key = (network.n_nodes, tuple(network.input_names), held.tobytes())
        plan = self._plans.get(key)
        if plan is None:
            plan = self._plans[key] = Plan(network, held, self.U, self.dt, self.measured,
                                           burn_in_steps=self.burn_in_steps, steady_start=self.steady_start,
                                           substeps=self.substeps, history_steps=self.history_steps)
            while len(self._plans) > self.PLANS:
                self._plans.pop(next(iter(self._plans)))
        return plan.run(building, network, nodes, derivatives, start_offset=start_offset)

    def window(self, start, stop):
        """The sub-case on rows start..stop (inclusive), t_start becoming its t_0; the burn-in
        stays with a window that starts at t_0 and is left behind by one that starts later."""
        rows = slice(start, stop + 1)
        return replace(self, times=self.times[rows], U=self.U[rows], measured=self.measured[rows],
                       burn_in_steps=self.burn_in_steps if start == 0 else 0,
                       history_steps=self.history_steps if start == 0 else 0,
                       fluxes={name: values[rows] for name, values in self.fluxes.items()})


def as_cases(case):
    """A list of Cases from a Case or a sequence of them (the records of one building)."""
    return list(case) if isinstance(case, (list, tuple)) else [case]


def uniform_grid(times, source):
    """The uniform grid spanning `times` (their most common step, s), or InputError where a
    time falls off it. Rows absent from a file become grid rows with nothing measured."""
    if len(times) < 2:
        raise InputError(source, "time", "needs at least two time stamps")
    seconds = (times - times[0]).total_seconds().to_numpy()
    dt = float(pd.Series(np.diff(seconds)).mode().iloc[0])
    off = np.abs(seconds / dt - np.round(seconds / dt)) > 1e-6
    if off.any():
        raise InputError(source, "time", f"{times[np.argmax(off)].isoformat()} is not on the {dt:g} s grid "
                                         "of the other rows (samples must be uniform)")
    return pd.date_range(times[0], times[-1], freq=pd.Timedelta(seconds=dt), name="time"), dt



def local_times(times, timezone, source):
    """tz-aware `times` on a site's `timezone` (an IANA name, Etc/GMT+-N or +hh:mm): the wall
    clock and calendar a schedule follows, daylight saving included."""
    try:
        return times.tz_convert(timezone)
    except Exception as e:  # pandas raises several kinds for an unknown zone
        raise InputError(source, "site.timezone", f"{timezone!r} is not a time zone ({e})") from None


def clock_hours(times, timezone, source):
    """Local clock time of day (h, 0 <= tau < 24) of tz-aware `times` at a site's `timezone`
    (`local_times`)."""
    local = local_times(times, timezone, source)
    return local.hour + local.minute / 60 + (local.second + local.microsecond / 1e6) / 3600


def working_day(times, timezone, source):
    """1 on the working days (`model.building.WORKDAYS`, Monday to Friday) of the site's local
    calendar at `times`, 0 on the others (no unit)."""
    return np.isin(local_times(times, timezone, source).day_of_week, WORKDAYS).astype(float)


def day_basis(tau, term):
    """cos or sin of 2 pi h tau / 24 h (no unit) for a `DAY_TERMS` term ("cos1", "sin2", ...) at
    local clock times tau (h)."""
    function, h = {"cos": np.cos, "sin": np.sin}[term[:3]], int(term[3:])
    return function(2 * np.pi * h * np.asarray(tau, dtype=float) / 24.0)


def clock_inputs(building, times):
    """{input name: values at `times`} of the clock's inputs the building's daily and workday gains
    need (`model.network.clock_input_names`): the time-of-day basis, and the same times the
    working-day indicator (`working_day`), with the indicator itself as the workday mean's; {}
    when no zone declares either."""
    names = set(clock_input_names(building))
    if not names:
        return {}
    site, source = building.site, building.source
    tau = clock_hours(times, site["timezone"], source)
    out = {day_input(t): day_basis(tau, t) for t in DAY_TERMS if day_input(t) in names}
    if workday_input("mean") in names:
        on = working_day(times, site["timezone"], source)
        out[workday_input("mean")] = on
        out.update({workday_input(t): on * day_basis(tau, t) for t in DAY_TERMS})
    return out


def schedule_inputs(building, times):
    """{schedule name: values at `times`} of the schedules the building reads as inputs
    (`Building.schedule_inputs`), on the site's local clock (docs/model.md section 1.2): at t_n,
    the schedule's mean over the step (t_n-1, t_n] of the uniform `times` (a heat gain's energy
    over the step, held by the integration as a heat input is), at the first time its value."""
    if not building.schedule_inputs:
        return {}
    clock_hours(times[:1], building.site["timezone"], building.source)  # a time zone that is none
    if len(times) < 2:
        return {name: building.schedules[name].on(times, building.site["timezone"]) for name in building.schedule_inputs}
    dt = (times[1] - times[0]).total_seconds()
    k = max(1, int(np.ceil(dt / SCHEDULE_RESOLUTION)))
    # k points evenly inside each step, read once for all steps
    offsets = [pd.Timedelta(seconds=dt * (j + 0.5) / k - dt) for j in range(k)]
    out = {}
    for name in building.schedule_inputs:
        s = building.schedules[name]
        means = np.mean([s.on(times + o, building.site["timezone"]) for o in offsets], axis=0)
        means[0] = s.on(times[:1], building.site["timezone"])[0]
        out[name] = means
    return out


# The finest step of a schedule a step's mean resolves (s): EnergyPlus's schedules change on the
# minute at the finest, a quarter hour in most files
SCHEDULE_RESOLUTION = 60.0


def measured_matrix(building, measurements, times):
    """(len(times), N) node temperatures (C) from the measurement columns, NaN where not measured.

    A column `T<id>` measures node id, a column named as one of the building's sensors measures
    that sensor's node; a heat flux sensor's column is not a temperature (`measured_fluxes`); any
    other column is an InputError naming the measurement file and the column, as is a column
    whose temperatures look like kelvin.
    """
    source = measurements.attrs.get("source", "measurements")
    matrix = np.full((len(times), building.n_nodes), np.nan)
    on_grid = measurements.reindex(times)
    temperatures = [c for c in measurements.columns if c not in building.flux_sensors]
    for column in temperatures:
        node = building.node_of(column)
        if node is None:
            hint = (": the building reads it as an input, which belongs in the weather file"
                    if column in building.input_columns else "")
            raise InputError(source, column, f"names no node: a measurement column is T<node id> or a sensor "
                                             f"of {building.source} ({', '.join(building.sensors) or 'none declared'})"
                                             + hint)
        if not 1 <= node <= building.n_nodes:
            raise InputError(source, column, f"node {node} does not exist (the building has nodes 1..{building.n_nodes})")
        if node in building.added_nodes:
            zone, what = building.added_nodes[node]
            raise InputError(source, column, f"node {node} is the {what} of zone {zone} a model effect adds, "
                                             "which stands for no sensor's position and is never measured")
        matrix[:, node - 1] = on_grid[column].to_numpy(float)
    check_celsius(measurements, temperatures)  # once every column is known to be a temperature
    return matrix


def measured_fluxes(building, measurements, times):
    """{flux sensor: (len(times),) heat flux density (W/m2) through its face, positive into the
    component, NaN where not measured} of the columns that name the building's heat flux sensors."""
    on_grid = measurements.reindex(times)
    return {c: on_grid[c].to_numpy(float) for c in measurements.columns if c in building.flux_sensors}


def prepare_case(building, weather, measurements=None, decomposition="erbs", history_days=0.0):
    """The `Case` of a building under a weather, measured or not.

    Parameters
    ----------
    building : Building
    weather : DataFrame from `nodeforce.iotools.weather.read_weather`
    measurements : DataFrame from `nodeforce.iotools.measurements.read_measurements`, or None
    decomposition : the pvlib model (`model.solar.DECOMPOSITIONS`) that splits `ghi` into `dni`
        and `dhi` where the weather has only `ghi`
    history_days : days of the weather before the first measurement the case reaches back over
        at most, on the measurements' grid (its `history_steps`, a burn-in with nothing measured,
        from the steady state of its first day): as far as every input is given without a gap,
        never further than the weather; `measured_case` reaches `HISTORY_DAYS` back, as the
        command line does

    Returns
    -------
    Case of the building at the site its run computes at (`model.site.run_building`: an EPW
    recorded elsewhere moves it there, said first among the case's assumptions; the case's
    `building` is the one run) with inputs `T_out`, `T_sky` (C), `I_<component>` (W/m2, the
    weather's measured column if `model.solar.measured_irradiance` finds one, else the transposition under the site's sky
    (`model.solar.incident_irradiance`: isotropic unless it declares `sky_diffuse`) of
    `ghi`, `dni`, `dhi`, those the weather lacks from the others: `model.solar.complete_irradiance`,
    stated in the case's `assumptions`), the building's named columns and, where a zone declares a daily gain,
    the time-of-day basis `day_cos1`, ..., or a workday gain, `workday_mean`, ... (`clock_inputs`).

    Raises
    ------
    InputError
        Naming the weather file and the column: a column the building has no use for
        (`model.weather.check_columns`), `ghi` missing (and not both `dni` and `dhi` given) where
        a face's irradiance is computed (naming the face), a named column missing, a gap in an input; naming the
        measurement file: times off a uniform grid, a column that measures no node; naming the
        building file: a site timezone that is none, where a daily gain needs the local time.
    """
    source = weather.attrs.get("source", "weather")
    building, moved = run_building(building, weather)
    check_columns(building, weather)
    if measurements is not None:
        times, dt = uniform_grid(measurements.index, measurements.attrs.get("source", "measurements"))
        before = min(int(history_days * 86400 // dt), int((times[0] - weather.index[0]).total_seconds() // dt))
        if before > 0:
            times = pd.date_range(times[0] - before * pd.Timedelta(seconds=dt), times[-1],
                                  freq=pd.Timedelta(seconds=dt), name="time")
    else:
        times, dt, before = *uniform_grid(weather.index, source), 0
    w = weather_on_grid(weather, times)
    site = building.site
    columns = {
        "T_out": w["T_out"].to_numpy(float),
        "T_sky": sky_temperature(w["T_out"], ir_h=w.get("ir_h"), T_sky=w.get("T_sky")),
    }
    for name in building.input_columns:
        if name not in w:
            raise InputError(source, name, f"the building {building.source} refers to this input column, "
                                            "which the weather file does not have")
        columns[name] = w[name].to_numpy(float)
    computed = []
    for c in building.exterior_components:
        measured_sun = measured_irradiance(c, w.columns)
        if measured_sun is None:
            computed.append(c)
        elif c.angular is not None or c.diffuse_distribution or c.angular_absorptance is not None:
            declared = ("an angular_transmittance" if c.angular is not None else "a diffuse_distribution"
                        if c.diffuse_distribution else "an angular_absorptance")
            raise InputError(source, measured_sun, f"{c.name} declares {declared}, which needs the "
                                                   "direct and diffuse sun apart: its irradiance is computed from "
                                                   "ghi, dni, dhi, not read from a measured column")
        else:
            columns[c.irradiance_input] = w[measured_sun].to_numpy(float)
    assumptions = [moved] if moved else []
    if computed:
        given = {name: w[name].to_numpy(float) for name in IRRADIANCE_COLUMNS if name in w}
        if "ghi" not in given and len(given) < 2:
            raise InputError(source, "ghi", f"needed to compute the solar irradiance on {computed[0].name}: the weather "
                                            f"has no global horizontal irradiance (ghi) and no measured irradiance on "
                                            f"that face (I_{computed[0].name}, or a column its outside names)")
        if decomposition not in DECOMPOSITIONS:
            raise InputError("--decomposition", decomposition, f"one of pvlib's {', '.join(DECOMPOSITIONS)}")
        sun = site.get("solar_position", "spa")
        offset = standard_offset(site["timezone"], times[0], building.source) if sun == "energyplus" else None
        position = solar_position(times, site["latitude"], site["longitude"], site["altitude"], sun, offset)
        ghi, dni, dhi, said = complete_irradiance(position, **given, decomposition=decomposition)
        if said:
            assumptions.append(f"The weather {source} lacks {', '.join(n for n in IRRADIANCE_COLUMNS if n not in given)}: "
                               f"{said}.")
        sky_model = {"sky_model": site.get("sky_diffuse", "isotropic"), "altitude": site["altitude"]}
        for c in computed:
            sunlit, sky = face_shading(c, building.shades_of(c.name), position)
            columns[f"I_{c.name}"] = incident_irradiance(position, ghi, dni, dhi, c.tilt, c.azimuth,
                                                         site["ground_albedo"], sunlit, sky, **sky_model)
            table = () if c.angular is None else (c.angular.angles, c.angular.factors, c.angular.diffuse)
            if c.diffuse_distribution:
                (direct, _), (diffuse, _) = c.sun_inputs[:2]
                columns[direct], columns[diffuse] = transmitted_split(
                    position, ghi, dni, dhi, c.tilt, c.azimuth, site["ground_albedo"], *table, sunlit=sunlit, sky=sky,
                    **sky_model)
                if c.traced_beam:
                    columns.update(traced_beam_columns(building, c, position, columns[direct]))
            elif c.angular is not None:
                columns[c.transmitted_input] = transmitted_irradiance(
                    position, ghi, dni, dhi, c.tilt, c.azimuth, site["ground_albedo"], *table, sunlit=sunlit, sky=sky,
                    **sky_model)
            for name, side in c.absorbed_inputs:
                columns[name] = transmitted_irradiance(
                    position, ghi, dni, dhi, c.tilt, c.azimuth, site["ground_albedo"], *c.angular_absorptance.table(side),
                    sunlit=sunlit, sky=sky, **sky_model)
    columns.update(clock_inputs(building, times))
    columns.update(schedule_inputs(building, times))
    names = input_names(building)
    for name in set(names) & {WIND_SPEED, WIND_DIRECTION}:
        if name not in w:
            raise InputError(source, name, f"{building.reads_wind} of {building.source} follows the wind: the "
                                           "weather file has no such column")
        columns[name] = w[name].to_numpy(float)
    U = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    missing = ~np.isfinite(U)
    # the history begins after the last row before the first measurement that misses an input
    incomplete = np.flatnonzero(missing[:before].any(axis=1))
    cut = int(incomplete[-1]) + 1 if len(incomplete) else 0
    cut += (before - cut) % history_block(dt)  # a whole number of the history's steps
    times, U, missing, before = times[cut:], U[cut:], missing[cut:], before - cut
    if missing.any():
        row, col = np.argwhere(missing)[0]
        raise InputError(source, names[col], f"no value at {times[row].isoformat()}: every input is needed "
                                             "at every step, and a gap is not filled in")
    if before:  # no measurement sets the history's first state: the steady state of its mean conditions does
        assumptions.append(f"The {before * dt / 86400:.3g} days of weather before the first measurement "
                           f"({times[0].isoformat()} to {times[before].isoformat()}) are simulated before it from "
                           "the steady state of their mean conditions, nothing measured or scored: the walls "
                           f"start from the weather's past; {start_memory(building, before * dt)}.")
    measured = (measured_matrix(building, measurements, times) if measurements is not None
                else np.full((len(times), building.n_nodes), np.nan))
    fluxes = measured_fluxes(building, measurements, times) if measurements is not None else {}
    return Case(times=times, dt=dt, input_names=names, U=U, measured=measured, assumptions=tuple(assumptions),
                fluxes=fluxes, building=building, substeps=substeps(dt), burn_in_steps=before, history_steps=before,
                steady_start=bool(before), annual_air=annual_mean_air(weather))


def annual_mean_air(weather):
    """The mean outdoor air temperature (C) of a weather over as many whole years (365 days) as it
    spans from its first time (each time the end of its step: a typical year of 8760 hours spans
    one), NaN ignored; None where it spans less than a year. A season's mean is not the year's:
    the deep ground under a building follows the year's (`model.effects.deep_ground_temperature`)."""
    if len(weather.index) < 2:
        return None
    first, step = weather.index[0], weather.index[1] - weather.index[0]
    years = int((weather.index[-1] - first + step) / pd.Timedelta(days=365))
    if years < 1:
        return None
    whole = weather["T_out"][weather.index < first + years * pd.Timedelta(days=365)]
    return float(np.nanmean(whole.to_numpy(float)))


def face_shading(component, shades, position):
    """(sunlit fraction at each time of `position` (-), the part of its sky diffuse it gets (-))
    of an exterior face under shading polygons (`model.shading`, docs/model.md section 4.2):
    (1.0, 1.0) where none shades it."""
    if not shades:
        return 1.0, 1.0
    normal = outward_normal(component.vertices)
    sun = sun_vectors(position["apparent_zenith"], position["azimuth"])
    sun[np.asarray(position["apparent_zenith"]) >= 90] = 0.0  # no direct sun at night: no shadow to cast
    return (sunlit_fraction(component.vertices, normal, shades, sun, component.holes),
            sky_diffuse_ratio(component.vertices, normal, shades, component.holes))


def traced_beam_columns(building, window, position, direct):
    """{input: W/m2} of a glazing that traces its direct sun (docs/model.md section 4.1): the part
    of its direct sun `direct` (W/m2, `Itb_<window>`) that falls on each face of its traced_beam
    at each time of `position` (`model.beam_trace.beam_shares`), and under `Itb_<window>` the
    part that falls on none."""
    faces = [building.component(face) for face, _ in window.traced_beam]
    sun = sun_vectors(position["apparent_zenith"], position["azimuth"])
    sun[np.asarray(position["apparent_zenith"]) >= 90] = 0.0  # no direct sun at night
    shares = beam_shares(window.vertices, [(f.vertices, f.holes) for f in faces], sun)
    columns = {traced_input(window.name, f.name): direct * shares[:, k] for k, f in enumerate(faces)}
    columns[f"Itb_{window.name}"] = direct * (1.0 - shares.sum(axis=1))
    return columns


def start_memory(building, seconds=None):
    """What a run's start carries into the record, said: the building's slowest time constant
    (`network.slowest_time_constant`, every node free), in which what the start got wrong falls
    by a factor e, and the share of it left `seconds` (s) after the start, where given."""
    tau = slowest_time_constant(assemble(building))
    said = f"what that start gets wrong falls by a factor e in {tau / 86400:.3g} days (the building's slowest time constant)"
    return said if seconds is None else f"{said}: {np.exp(-seconds / tau):.0%} of it is left at the first measurement"


def check_warmup(case, source):
    """InputError naming `source` unless the warm-up can replay the case's first day (docs/model.md
    section 5): the step must divide a day and the record must hold one."""
    try:
        per_day = steps_per_day(case.dt)
    except ValueError as e:
        raise InputError(source, "time", f"{e}: the warm-up replays whole days") from None
    if len(case.times) - 1 < per_day:
        raise InputError(source, "time", f"{len(case.times) - 1} steps of {case.dt:g} s: the warm-up needs "
                                          f"at least one day ({per_day} steps)")


def measured_case(building, weather, measurements=None, burn_in_days=0, decomposition="erbs",
                  history_days=HISTORY_DAYS):
    """The `Case` of `prepare_case` (`decomposition` its split of ghi alone, `history_days` the
    weather before the first measurement it simulates at most), checked to hold the warm-up's day
    (`check_warmup`), with the first `burn_in_days` after the first measurement a burn-in
    (`Case.with_burn_in`); InputError naming the measurement file (else the weather file) or the
    burn-in."""
    case = prepare_case(building, weather, measurements, decomposition, history_days)
    timed = measurements if measurements is not None else weather
    check_warmup(case, timed.attrs.get("source", "measurements" if measurements is not None else "weather"))
    return case.with_burn_in(burn_in_days)


def force_mask(case, ids, source):
    """(N,) bool mask of the forced node `ids`; InputError naming `source` for a node without a
    measurement to be forced to."""
    mask = np.zeros(case.measured.shape[1], dtype=bool)
    measured = set(case.measured_ids)
    for i in ids:
        if i not in measured:
            raise InputError(source, f"T{i}", f"node {i} is to be forced but has no measurement column T{i}")
        mask[i - 1] = True
    return mask


def simulate_building(building, weather, measurements=None, force=(), warmup_days=2, burn_in_days=0,
                      steady_start=False):
    """Every node's temperature (C) under a weather, with the direct model: the plain Python API.

    Parameters
    ----------
    building : Building (`model.building_file.load_building`)
    weather : DataFrame from `nodeforce.iotools.weather.read_weather`
    measurements : DataFrame from `nodeforce.iotools.measurements.read_measurements`, or None; it sets the
        time grid, the initial state (where the weather does not start before it: `prepare_case`'s
        history) and the values forced nodes take
    force : node ids forced to their measurements for the whole run
    warmup_days : passes over the first day before the run (docs/model.md section 5)
    burn_in_days : days after the first measurement over which every measured node is forced
        (docs/model.md section 5)
    steady_start : start from the steady state of the first day's mean conditions before the
        warm-up (docs/model.md section 5.4), as a diagnosis does; without it, where the weather
        does not start before the measurements, from `initial_state` (20 C where nothing is
        measured)

    Returns
    -------
    DataFrame indexed by the measurements' times after the first (the weather's without them),
    columns `T1..TN`
    """
    case = measured_case(building, weather, measurements, burn_in_days)
    case = case.with_steady_start() if steady_start else case
    building = case.building  # at the site the weather gives (`model.site.run_building`)
    mask = force_mask(case, force, "force")
    T = simulate(building, assemble(building), case.U, case.dt, case.measured, mask, warmup_days,
                 burn_in_steps=case.burn_in_steps, steady_start=case.steady_start, substeps=case.substeps,
                 history_steps=case.history_steps)
    h = case.history_steps
    return pd.DataFrame(T[h:], index=case.times[h + 1:], columns=[f"T{i}" for i in range(1, building.n_nodes + 1)])
