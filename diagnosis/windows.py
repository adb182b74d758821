"""The records as the diagnosis reads them (`diagnosis.loop`): each record's calibration and
validation windows, its cross-validation blocks of whole days, its measured objective air and
other sensors, and the building file's own numerical error on them; the scores every candidate
and the model are read by on those windows."""
import math
from dataclasses import dataclass, replace

import numpy as np

from nodeforce.diagnosis.assess import columns_among
from nodeforce.diagnosis.selection import block_J, blocks as blocks_of, on_block
from nodeforce.model.case import measured_case
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import steps_per_day
from nodeforce.model.numerical import reference, share
from nodeforce.model.start import fitted_start, free_response


def split(case, source, fraction=None, end=None):
    """Row index k of the last calibration time: t_0..t_k calibrate, t_k+1..t_N validate.

    Parameters
    ----------
    case : Case (its burn-in must fit in the calibration window, with a day to score)
    source : the measurement file, for errors
    fraction : the part of the record, by time, that calibrates
    end : pandas Timestamp, the last calibration time (the row at or before it)
    """
    n, h = len(case.times) - 1, case.history_steps
    if end is not None:
        k = int(case.times.searchsorted(end, side="right")) - 1
        what = f"a calibration ending {end.isoformat()}"
    else:  # of the measured record: the weather's history before it is no part of either window
        k = h + int(round(fraction * (n - h)))
        what = f"a split {fraction:.0%} / {1 - fraction:.0%}"
    day = steps_per_day(case.dt)
    if k < case.burn_in_steps + day or n - k < day:
        raise InputError(source, "time", f"{n - h} steps of {case.dt:g} s from {case.start.isoformat()}: {what} "
                                         f"leaves no calibration window of the burn-in plus a day, or no "
                                         f"validation window of a day")
    return k


@dataclass
class Record:
    """One record of the building: its case (burn-in set), the measurement file it came from (for
    errors), its name in the report, where its calibration window ends (`calibration_end`, a
    pandas Timestamp, else the `fraction` of it by time), its phases (iotools.phases.Phase) and,
    for a record run under another protocol than the building file's (other supply flows, other
    blinds), the building as written for that protocol (`building`, the case's): the same house,
    node for node, to which every correction is added as to the building file. `read_from`:
    `measured_case`'s arguments but the building (the weather and measurements DataFrames, the
    burn-in, ...) where it was read from files (`nodeforce.read_record`), from which a later
    record's case is prepared for each building compared (`case_for`)."""
    case: object
    source: str = "measurements"
    name: str = None
    fraction: float = 0.6
    calibration_end: object = None
    phases: tuple = ()
    building: object = None
    read_from: dict = None

    def case_for(self, building):
        """The record's case as `nodeforce compare` prepares it for `building` (`measured_case`
        of the files it was read from, its burn-in the same)."""
        return measured_case(building, **self.read_from)


@dataclass(frozen=True)
class Beside:
    """What a diagnosis's report sets beside it, which no fit, choice or cross-validation reads:
    `reference` ({"label", "rmse": {phase: K}}), another model's error, reported for scale; and
    `later`, `Record`s of the same building under the building file's protocol, read from their
    files (`nodeforce.read_record`), on which the building as written and as corrected are scored
    after the rounds (`diagnosis.loop.scored_later`)."""
    reference: dict | None = None
    later: tuple = ()

    def __post_init__(self):
        object.__setattr__(self, "later", tuple(self.later))


@dataclass
class RecordWindow:
    """One record as the loop reads it (`Windows`): its `Record`, its case (steady start), the row
    k of its last calibration time, its calibration window, its measured objective air (N_t,
    zones), its other sensed nodes (`sensors`: the measured nodes besides the objective air, a
    wall's surface, a neighbouring zone's air) with their measurements (`sensed`, (N_t,
    len(sensors)), NaN where not scored), and the building file's own numerical error at the air
    ((N_t, zones)) and at those sensors (None until `Windows.with_numerical`)."""
    record: Record
    case: object
    k: int
    calibration: object
    measured: np.ndarray
    sensors: list
    sensed: np.ndarray
    numerical: np.ndarray = None
    sensor_numerical: np.ndarray = None


@dataclass
class Windows:
    """The records as the loop reads them: one `RecordWindow` per record (`each`), the
    cross-validation blocks of all records in order, (record index, mask), and the
    `diagnosis.policy.Policy` the scores on them are judged by. The per-record lists (`cases`,
    `ks`, ...) are views of `each`, in the records' order."""
    each: list
    blocks: list
    policy: object

    @classmethod
    def of(cls, records, objective, policy):
        each, blocks = [], []
        for i, record in enumerate(records):
            # what no sensor sets (every wall of an air-only record) starts from the steady state of
            # the first day, not at the air's temperature: a heavy component would carry that guess
            # for weeks, and the candidates' slow parameters would fit it
            case = record.case if record.case.steady_start else record.case.with_steady_start()
            k = split(case, record.source, record.fraction, record.calibration_end)
            blocks += [(i, m) for m in blocks_of(k, case.burn_in_steps, case.dt, policy, record.source)]
            sensors = [node for node in case.measured_ids if node not in objective.air_nodes]
            each.append(RecordWindow(record, case, k, case.window(0, k), objective.measured(case), sensors,
                                     case.scored([node - 1 for node in sensors])))
        return cls(each, blocks, policy)

    # the per-record views, in the records' order
    records = property(lambda self: [w.record for w in self.each])
    cases = property(lambda self: [w.case for w in self.each])
    ks = property(lambda self: [w.k for w in self.each])
    calibrations = property(lambda self: [w.calibration for w in self.each])
    measured = property(lambda self: [w.measured for w in self.each])
    sensors = property(lambda self: [w.sensors for w in self.each])
    sensed = property(lambda self: [w.sensed for w in self.each])

    @property
    def numerical(self):
        """Per record the file's numerical error at the objective air, None if not known."""
        return None if any(w.numerical is None for w in self.each) else [w.numerical for w in self.each]

    @property
    def sensor_numerical(self):
        """Per record the file's numerical error at the other sensors, None if not known."""
        return None if any(w.sensor_numerical is None for w in self.each) else [w.sensor_numerical for w in self.each]

    def starts(self, building, bases, air_nodes):
        """Per record, the free response of its slow modes' start at the objective air over the
        whole record, (N_t, zones, m), and the `model.start.SlowModes`, under the record's
        protocol's building (`bases`, None: `building`): `model.start.free_response`."""
        return [free_response(w.case, base or building, air_nodes) for w, base in zip(self.each, bases)]

    def start_fitted(self, residual, starts, sigma, record, without=None):
        """The amplitudes (m,) K of `record`'s start, and their covariance, fitted to its
        `residual` on the calibration window ((k, zones) C, NaN where not scored), the rows of
        the block `without` (a mask of the window's steps) left out where given
        (`model.start.fitted_start`, sigma the noise's sd, C)."""
        F, modes = starts[record]
        rows = np.isfinite(residual)
        if without is not None:
            rows &= ~without[:, None]
        return fitted_start(F[:len(residual)][rows], residual[rows], modes.sd, sigma)

    def metrics(self, objective, runs, record=None):
        """{"calibration", "validation"}: the objective's metrics of `runs` (one (N_t, zones) per
        record) on every record's window together, or on `record`'s (an index) alone."""
        chosen = range(len(self.each)) if record is None else [record]
        return {window: objective.metrics(*(np.concatenate([part[i][rows(self.each[i].k)] for i in chosen])
                                            for part in (self.measured, runs)))
                for window, rows in (("calibration", lambda k: slice(None, k)),
                                     ("validation", lambda k: slice(k, None)))}

    def block_J(self, runs, starts=None, sigma=None):
        """J (C2) of `runs` on every block, the records' in order, each less the share of the
        file's numerical error (`model.numerical.share`) the other blocks hold, and, where the
        records' free responses `starts` (`Windows.starts`) are given, less the start its
        record's other blocks fit (`start_fitted`, sigma the noise's sd, C), as a candidate's
        left-out block is scored (`diagnosis.calibrate`)."""
        residuals = [w.measured[:w.k] - run[:w.k] for w, run in zip(self.each, runs)]
        errors = self.calibration_numerical() or [np.zeros_like(r) for r in residuals]
        r, e = (np.concatenate([a.ravel() for a in parts]) for parts in (residuals, errors))
        out = []
        for i, mask in self.blocks:
            s = share(r, e, ~np.concatenate([rows.ravel() for rows in on_block([a.shape for a in residuals], i, mask)]))
            left = residuals[i] + s * errors[i]
            if starts is not None:
                left = left - starts[i][0][:len(left)] @ self.start_fitted(left, starts, sigma, i, mask)[0]
            out.append(block_J(left, [mask])[0])
        return np.array(out)

    def sensor_scores(self, sensed, weights):
        """What a candidate predicts of what the other sensors saw (its own component's, where its
        fit read them, by the fold without each block: `assess`): their J (C2) on every block,
        the records' in order, each sensor's squares times its weight
        (`sensor_weights`); the weighted residuals w r there (C, every block's in one order),
        from which the noise makes 2 sigma |w (r_a - r_b)| of a difference (`selection`); and
        the readings, and what the noise counts of them, sum w^2.

        sensed : the other sensed nodes' runs, one (N_t, len(sensors)) per record
        weights : one (len(sensors),) per record"""
        parts = [((self.each[i].sensed[:self.each[i].k] - sensed[i][:self.each[i].k])[m], weights[i])
                 for i, m in self.blocks]
        return (np.array([float(np.nansum(w * np.square(r))) for r, w in parts]),
                np.concatenate([(w * r)[np.isfinite(r)] for r, w in parts]),
                int(sum(np.isfinite(r).sum() for r, _ in parts)),
                float(sum((np.isfinite(r) * w ** 2).sum() for r, w in parts)))

    def nodes(self, building, bases, ids):
        """Per record, the temperatures (C, (N_t, len(ids))) of its nodes `ids` (one sequence per
        record) under its protocol's building (`bases`, None: `building`)."""
        out = []
        for w, nodes, base in zip(self.each, ids, bases):
            case = w.case
            run = base or building
            out.append(case.with_inputs(run).run(run, np.asarray(nodes, dtype=int) - 1) if len(nodes)
                       else np.empty((len(case.times) - 1, 0)))
        return out

    def sensed_by(self, model):
        """Per record, `model`'s temperatures (C, (N_t, len(sensors))) at the other sensed nodes,
        under the record's protocol's building (`Model.bases`)."""
        return self.nodes(model.building, model.bases, self.sensors)

    def sensor_weights(self, runs, sigma):
        """Per record, each other sensor's weight in the choice: sigma^2 over the least mean
        squared residual (over the calibration window) that any of `runs` leaves there
        (`Policy.sensor_weight`); `runs`: the model's and each candidate's other sensed nodes
        (`sensed_by`, `Assessed.sensed`), one (N_t, len(sensors)) per record each.

        A sensor the model follows to the noise counts fully. One that every candidate misses
        by far more (a real house's surface the model sees through a simplified wall, a heavy
        wall still carrying the start the model does not know) counts as a measurement whose
        error is that misfit: its residual is what no candidate is about, and unweighted it
        would choose, among the explanations of the air, the one that mends it best (on the
        real Twin House, a west-sun gain in the living room whose validation error doubled).
        A sensor that a candidate mends counts as its noise: a component's own surface, which
        disagrees with the model as written because that component is wrong, is the evidence
        that places the fault there, not a misfit to discount."""
        out = []
        for i, w in enumerate(self.each):
            ids, k = w.sensors, w.k
            if not ids:
                out.append(np.zeros(0))
                continue
            misfit = np.min([np.nanmean(np.square(w.sensed[:k] - run[i][:k]), axis=0) for run in runs], axis=0)
            out.append(self.policy.sensor_weight(sigma, np.maximum(misfit, np.finfo(float).tiny)))
        return out

    def own_columns(self, nodes):
        """Per record, the columns of its other sensors (`sensors`) that are among `nodes` (ids):
        a component's own sensors (`columns_among`)."""
        return columns_among(self.sensors, nodes)

    def own_J(self, sensed, columns):
        """J (C2) of the other sensors' `columns` (`own_columns`) on every block, the records' in
        order, unweighted, for the runs `sensed` (one (N_t, len(sensors)) per record); and the
        readings they score."""
        parts = [(self.each[i].sensed[:self.each[i].k] - sensed[i][:self.each[i].k])[m][:, columns[i]]
                 for i, m in self.blocks]
        return (np.array([float(np.nansum(np.square(r))) for r in parts]),
                int(sum(np.isfinite(r).sum() for r in parts)))

    def own_numerical(self, columns):
        """The root mean square (C) of the file's own numerical error (`sensor_numerical`) at the
        sensors' `columns` (one list per record), over the calibration window's scored readings."""
        errors = [w.sensor_numerical[:w.k][:, c][np.isfinite(w.sensed[:w.k][:, c])]
                  for w, c in zip(self.each, columns)] if self.sensor_numerical is not None else []
        squares = np.concatenate(errors) ** 2 if errors else np.zeros(0)
        return math.sqrt(float(squares.mean())) if squares.size else 0.0

    def disagreeing(self, building, sensed, sigma):
        """The components whose own sensors the model (its other sensed nodes `sensed`, one per
        record) misses by more than the noise and the file's numerical error there could
        (`Policy.at_noise` on their J over the blocks): a component the air may no longer point
        at, whose own surface still says it is wrong."""
        out = []
        for c in building.components:
            columns = self.own_columns(set(c.node_ids))
            if not any(columns):
                continue
            J, n = self.own_J(sensed, columns)
            if n and not self.policy.at_noise(float(J.sum()), n, math.hypot(sigma, self.own_numerical(columns))):
                out.append(c.name)
        return out

    def with_numerical(self, runs, sensed, building, bases, objective):
        """The windows with the building file's own numerical error at the objective air (C, one
        (N_t, zones) per record) and at the other sensors (`sensor_numerical`, one (N_t,
        len(sensors)) per record): the file as run (`runs` at the air, `sensed` at the sensors,
        under the record's protocol's building in `bases`, else `building`) minus the file
        refined (`model.numerical.reference`)."""
        each = []
        for run, at, w, base in zip(runs, sensed, self.each, bases):
            fine = reference(w.case, base or building, list(objective.air_nodes) + list(w.sensors))
            each.append(replace(w, numerical=run - fine[:, :len(objective.air_nodes)],
                                sensor_numerical=at - fine[:, len(objective.air_nodes):]))
        return replace(self, each=each)

    def numerical_rms(self):
        """The root mean square (C) of the file's numerical error over the residuals the blocks score."""
        squares = [np.square(w.numerical[:w.k])[np.isfinite(w.measured[:w.k])] for w in self.each]
        return float(np.sqrt(np.concatenate(squares).mean()))

    def calibration_numerical(self, sensors=False):
        """The file's numerical error on each record's calibration window, at the objective air
        (or at the other `sensors`), None if not known."""
        errors = self.sensor_numerical if sensors else self.numerical
        return None if errors is None else [e[:w.k] for e, w in zip(errors, self.each)]

    def scored(self):
        """Residuals the blocks score, on every record."""
        return sum(int(np.isfinite(w.measured[:w.k]).sum()) for w in self.each)

    def groups(self):
        """Per record, its name, the indices of its blocks and the residuals they score: what
        `selection.decide` needs to see a candidate that harms one record; [] for one record."""
        if len(self.each) < 2:
            return []
        return [{"record": w.record.name, "blocks": [b for b, (i, _) in enumerate(self.blocks) if i == j],
                 "n": int(np.isfinite(w.measured[:w.k]).sum())} for j, w in enumerate(self.each)]


def period(windows, i):
    """The calibration and validation spans of record i, where its scoring starts and its blocks."""
    w = windows.each[i]
    times, k, case = w.case.times, w.k, w.case
    return {"calibration": [case.start.isoformat(), times[k].isoformat()],
            "calibration_scored_from": times[case.burn_in_steps + 1].isoformat(),
            "validation": [times[k + 1].isoformat(), times[-1].isoformat()],
            "blocks": [[times[1:k + 1][m][0].isoformat(), times[1:k + 1][m][-1].isoformat()]
                       for j, m in windows.blocks if j == i],
            "roles": {"calibration": "the forcing search and the candidates' fits read it; each of its "
                                     "blocks of whole days ('blocks') is left out of a fit in turn and "
                                     "predicted, and the choice is made on those predictions",
                      "validation": "reports before and after only; no part in any choice"}}
