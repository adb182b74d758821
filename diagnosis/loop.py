"""`nodeforce diagnose`: from the residual to the missing effect, added, calibrated, and judged
on data the calibration did not see.

1. The record is split by time into a calibration window and a later validation window. The
   record's first days are a burn-in (docs/model.md: every measured node forced, not scored), so
   the walls start from what the sensors saw rather than from the warm-up's replay of the first
   day, which a record with real history does not match; the calibration window's scored steps
   are cut into blocks of whole days for the cross-validation (`diagnosis.selection`).
2. Before: the building as described, simulated through its FMU; metrics on both windows, per
   objective zone and together.
3. The forcing search (`ga.locate`) on the calibration window: which nodes it locates, and per
   component the share of J above the noise its forcing removes (the evidence).
4. Rounds. Each calibrates every physical candidate (`diagnosis.candidates.physical`: every zone
   effect of the objective zones, the component effects of the components the evidence ranks
   highest and of those no sensor sits in) on the direct model, the candidates in parallel
   worker processes or on a Dask cluster's workers (`scheduler`, as the forcing search), once
   on the whole calibration window and once per block left out
   (`diagnosis.calibrate`); where none brings the error to the noise, the shapes the residual's
   statistics point at too (`diagnosis.candidates.shapes`). One rule chooses
   (`diagnosis.selection.decide`: blocked cross-validation, the one-standard-error rule, the
   objections of physics), against the model the earlier rounds made. Rounds go on while the
   error left is above the noise, at the air or at a component's own sensors (a second fault
   the air no longer points at), and a candidate passes. The validation window plays no part in
   any choice: its before and after are an honest estimate. The decision of every round, its
   margins, its cost and its reason go into report.json, which the report reads.
5. The chosen model is built as an FMU and written (`model_after.fmu`, `building_after.json`);
   every candidate's building file is written declaring its calibrated effect
   (`candidates/<effect>@<target>.json`, a later round's in `candidates/round<n>/`).
6. The residual of the first objective zone on the validation window, before and after, is
   described (`diagnosis.residuals`): is it white, and which input or time of day does it follow.
7. Given the experiment's phases, every model is scored on each (`diagnosis.phases`), and an
   added effect that makes a phase worse is flagged in the decision's reason.
8. Given later records of the building (`later`), which no stage above reads, the building as
   written and as corrected are scored on each as `nodeforce compare` scores them: whether the
   correction holds beyond the records it was fitted and chosen on.
"""
import json
import math
import os
import sys
import time
from contextlib import nullcontext
from dataclasses import dataclass, replace
from functools import partial

import numpy as np
from tqdm import tqdm

from nodeforce import lifetime
from nodeforce.cluster import Cluster
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.diagnosis.assess import assess, columns_among, protocols
from nodeforce.diagnosis.calibrate import Candidate
from nodeforce.diagnosis.candidates import physical, shaped_inputs, shapes
from nodeforce.diagnosis.compare import compare
from nodeforce.diagnosis.loss import heat_loss
from nodeforce.diagnosis.report import write_report
from nodeforce.diagnosis.phases import phase_errors, worsened
from nodeforce.diagnosis.residuals import diagnostics as residual_diagnostics
from nodeforce.diagnosis.policy import POLICY
from nodeforce.diagnosis.result import (CrossValidation, Diagnosis, Fit, LaterRecord, OwnSensors, RecordOutcome,
                                        SensorEvidence)
from nodeforce.diagnosis.selection import block_J, blocks as blocks_of, decide, on_block
from nodeforce.diagnosis.sensitivity import sensitivity
from nodeforce.fmu_build.build import build_fmu
from nodeforce.iotools.energyplus_corrections import idf_of, write_corrections
from nodeforce.ga.locate import check_measured, evaluator_kind, locate
from nodeforce.model.case import measured_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import steps_per_day
from nodeforce.model.numerical import reference, share
from nodeforce.model.score import Noise


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


@dataclass
class Windows:
    """The records as the loop reads them: each one's case (steady start), the row k of its last
    calibration time, its calibration window, its measured objective air (N_t, zones), the
    cross-validation blocks of all records in order, (record index, mask), and each one's other
    sensed nodes (`sensors`: the measured nodes besides the objective air, a wall's surface, a
    neighbouring zone's air) with their measurements (`sensed`, (N_t, len(sensors)), NaN where
    not scored)."""
    records: list
    cases: list
    ks: list
    calibrations: list
    measured: list
    blocks: list
    sensors: list
    sensed: list
    numerical: list = None
    sensor_numerical: list = None

    @classmethod
    def of(cls, records, objective):
        cases, ks, calibrations, measured, blocks, sensors, sensed = [], [], [], [], [], [], []
        for i, record in enumerate(records):
            # what no sensor sets (every wall of an air-only record) starts from the steady state of
            # the first day, not at the air's temperature: a heavy component would carry that guess
            # for weeks, and the candidates' slow parameters would fit it
            case = record.case if record.case.steady_start else record.case.with_steady_start()
            k = split(case, record.source, record.fraction, record.calibration_end)
            cases.append(case)
            ks.append(k)
            calibrations.append(case.window(0, k))
            measured.append(objective.measured(case))
            blocks += [(i, m) for m in blocks_of(k, case.burn_in_steps, case.dt, record.source)]
            sensors.append([node for node in case.measured_ids if node not in objective.air_nodes])
            sensed.append(case.scored([node - 1 for node in sensors[-1]]))
        return cls(list(records), cases, ks, calibrations, measured, blocks, sensors, sensed)

    def metrics(self, objective, runs, record=None):
        """{"calibration", "validation"}: the objective's metrics of `runs` (one (N_t, zones) per
        record) on every record's window together, or on `record`'s (an index) alone."""
        chosen = range(len(self.cases)) if record is None else [record]
        return {window: objective.metrics(*(np.concatenate([part[i][rows(self.ks[i])] for i in chosen])
                                            for part in (self.measured, runs)))
                for window, rows in (("calibration", lambda k: slice(None, k)),
                                     ("validation", lambda k: slice(k, None)))}

    def block_J(self, runs):
        """J (C2) of `runs` on every block, the records' in order, each less the share of the
        file's numerical error (`model.numerical.share`) the other blocks hold, as a candidate's
        left-out block is scored (`diagnosis.calibrate`)."""
        residuals = [m[:k] - run[:k] for m, run, k in zip(self.measured, runs, self.ks)]
        errors = self.calibration_numerical() or [np.zeros_like(r) for r in residuals]
        r, e = (np.concatenate([a.ravel() for a in parts]) for parts in (residuals, errors))
        out = []
        for i, mask in self.blocks:
            s = share(r, e, ~np.concatenate([rows.ravel() for rows in on_block([a.shape for a in residuals], i, mask)]))
            out.append(block_J(residuals[i] + s * errors[i], [mask])[0])
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
        parts = [((self.sensed[i][:self.ks[i]] - sensed[i][:self.ks[i]])[m], weights[i]) for i, m in self.blocks]
        return (np.array([float(np.nansum(w * np.square(r))) for r, w in parts]),
                np.concatenate([(w * r)[np.isfinite(r)] for r, w in parts]),
                int(sum(np.isfinite(r).sum() for r, _ in parts)),
                float(sum((np.isfinite(r) * w ** 2).sum() for r, w in parts)))

    def sensed_by(self, model):
        """Per record, `model`'s temperatures (C, (N_t, len(sensors))) at the other sensed nodes,
        under the record's protocol's building (`Model.bases`)."""
        out = []
        for case, ids, base in zip(self.cases, self.sensors, model.bases):
            building = base or model.building
            out.append(case.with_inputs(building).run(building, np.asarray(ids, dtype=int) - 1) if ids
                       else np.empty((len(case.times) - 1, 0)))
        return out

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
        for i, ids in enumerate(self.sensors):
            k = self.ks[i]
            if not ids:
                out.append(np.zeros(0))
                continue
            misfit = np.min([np.nanmean(np.square(self.sensed[i][:k] - run[i][:k]), axis=0) for run in runs], axis=0)
            out.append(POLICY.sensor_weight(sigma, np.maximum(misfit, np.finfo(float).tiny)))
        return out

    def own_columns(self, nodes):
        """Per record, the columns of its other sensors (`sensors`) that are among `nodes` (ids):
        a component's own sensors (`columns_among`)."""
        return columns_among(self.sensors, nodes)

    def own_J(self, sensed, columns):
        """J (C2) of the other sensors' `columns` (`own_columns`) on every block, the records' in
        order, unweighted, for the runs `sensed` (one (N_t, len(sensors)) per record); and the
        readings they score."""
        parts = [(self.sensed[i][:self.ks[i]] - sensed[i][:self.ks[i]])[m][:, columns[i]] for i, m in self.blocks]
        return (np.array([float(np.nansum(np.square(r))) for r in parts]),
                int(sum(np.isfinite(r).sum() for r in parts)))

    def own_numerical(self, columns):
        """The root mean square (C) of the file's own numerical error (`sensor_numerical`) at the
        sensors' `columns` (one list per record), over the calibration window's scored readings."""
        errors = [e[:k][:, c][np.isfinite(m[:k][:, c])] for e, k, m, c in
                  zip(self.sensor_numerical or [], self.ks, self.sensed, columns)]
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
            if n and not POLICY.at_noise(float(J.sum()), n, math.hypot(sigma, self.own_numerical(columns))):
                out.append(c.name)
        return out

    def with_numerical(self, runs, sensed, building, bases, objective):
        """The windows with the building file's own numerical error at the objective air (C, one
        (N_t, zones) per record) and at the other sensors (`sensor_numerical`, one (N_t,
        len(sensors)) per record): the file as run (`runs` at the air, `sensed` at the sensors,
        under the record's protocol's building in `bases`, else `building`) minus the file
        refined (`model.numerical.reference`)."""
        numerical, at_sensors = [], []
        for run, at, case, base, ids in zip(runs, sensed, self.cases, bases, self.sensors):
            fine = reference(case, base or building, list(objective.air_nodes) + list(ids))
            numerical.append(run - fine[:, :len(objective.air_nodes)])
            at_sensors.append(at - fine[:, len(objective.air_nodes):])
        return replace(self, numerical=numerical, sensor_numerical=at_sensors)

    def numerical_rms(self):
        """The root mean square (C) of the file's numerical error over the residuals the blocks score."""
        squares = [np.square(e[:k])[np.isfinite(m[:k])] for e, k, m in zip(self.numerical, self.ks, self.measured)]
        return float(np.sqrt(np.concatenate(squares).mean()))

    def calibration_numerical(self, sensors=False):
        """The file's numerical error on each record's calibration window, at the objective air
        (or at the other `sensors`), None if not known."""
        errors = self.sensor_numerical if sensors else self.numerical
        return None if errors is None else [e[:k] for e, k in zip(errors, self.ks)]

    def scored(self):
        """Residuals the blocks score, on every record."""
        return sum(int(np.isfinite(m[:k]).sum()) for m, k in zip(self.measured, self.ks))

    def groups(self):
        """Per record, its name, the indices of its blocks and the residuals they score: what
        `selection.decide` needs to see a candidate that harms one record; [] for one record."""
        if len(self.records) < 2:
            return []
        return [{"record": r.name, "blocks": [b for b, (i, _) in enumerate(self.blocks) if i == j],
                 "n": int(np.isfinite(self.measured[j][:self.ks[j]]).sum())} for j, r in enumerate(self.records)]
@dataclass
class Model:
    """A model of the loop: its building, its objective air simulated over each whole record
    (`runs`), its metrics on every record's windows together, and per record the building it
    runs under that record's protocol (None: `building`)."""
    building: object
    runs: list
    metrics: dict
    bases: list

    def adding(self, effect, target, values, runs, metrics):
        """The model with the effect at `values` added to its building and to every record's."""
        return Model(EFFECTS[effect].apply(self.building, target, values), runs, metrics,
                     [None if b is None else EFFECTS[effect].apply(b, target, values) for b in self.bases])


def assess_all(model, pairs, windows, objective, sigma, folder, seed, pool=None, cluster=None):
    """Each (effect, target) added to `model`, calibrated on every record's calibration window
    (t_0..t_k) with a fold per block, and run over each record, in the worker processes of
    `pool` (`lifetime.worker_pool`; None: in this process), or on the workers of `cluster` (a
    `nodeforce.cluster.Cluster`), each candidate's building file written in `folder`: their
    `Assessed`, in the order of `pairs`. `sigma`: the sensors' noise (C), against which a
    component's own nodes are weighed in its fit (`calibrate.own_weights`)."""
    shared = (model.building, model.bases, windows.calibrations, windows.cases, objective, windows.blocks,
              windows.sensors, windows.calibration_numerical(), windows.calibration_numerical(sensors=True), sigma,
              seed)
    with tqdm(total=len(pairs), desc="calibrating candidate effects", unit="candidate",
              disable=not sys.stderr.isatty()) as bar:
        if cluster is not None:
            assessed = cluster.map(assess, pairs, cluster.share(shared), done=lambda *_: bar.update())
            for outcome in assessed:
                if isinstance(outcome, BaseException):
                    raise outcome
        else:
            assessed = []
            for outcome in (pool.map if pool else map)(partial(assess, shared), pairs):
                assessed.append(outcome)
                bar.update()
    for (effect, target), a in zip(pairs, assessed):
        (folder / f"{effect}@{target}.json").write_text(json.dumps(a.building, indent=2) + "\n")
    return list(assessed)


def fits_of(model, base, pairs, assessed, windows, objective, sigma, number=1, on_top_of=()):
    """The candidates' `Fit`s and their `Model`s by label, from their `Assessed`: what each
    predicts of the air left out and of the other sensors over the blocks, each sensor weighted
    by the least misfit the model or any of these candidates leaves there
    (`Windows.sensor_weights`), and of its own component's sensors (`OwnSensors`); `base`: the
    model's other sensed nodes (`Windows.sensed_by`); `sigma`: the air sensors' noise (C);
    `number`: the round; `on_top_of`: the labels of the effects `model` holds."""
    n = windows.scored()
    sensed = {i for ids in windows.sensors for i in ids}
    weights = windows.sensor_weights([base] + [a.sensed for a in assessed], sigma)
    results, models = [], {}
    for (effect, target), a in zip(pairs, assessed):
        metrics = windows.metrics(objective, a.runs)
        sensor_blocks, sensor_residuals, readings, counted = windows.sensor_scores(a.sensed, weights)
        physics = POLICY.facts(model.building, effect, target, sensed)
        fit = Fit(effect, target, a.parameters, a.determined, physics,
                  CrossValidation([float(np.nansum(np.square(f["residuals"]))) for f in a.folds], n,
                                  [f["values"] for f in a.folds],
                                  # each block's left-out residuals, in one order for every candidate
                                  np.concatenate([f["residuals"][np.isfinite(f["residuals"])] for f in a.folds])),
                  # the other sensors over the blocks, which no fit read
                  SensorEvidence([float(v) for v in sensor_blocks], readings, counted, sensor_residuals,
                                 own_sensors(model.building, target, windows, base, a.sensed)
                                 if physics["sensed"] else None),
                  metrics, number, tuple(on_top_of))
        models[fit.label] = model.adding(effect, target, fit.values, a.runs, metrics)
        results.append(fit)
    return results, models


def own_sensors(building, component, windows, base, sensed):
    """`OwnSensors` of a candidate on `component`: its own sensors' J (C2) per block under the
    model (its other sensed nodes `base`) and under the candidate (`sensed`), unweighted, and
    the file's numerical error there (`Windows.own_numerical`)."""
    columns = windows.own_columns(set(building.component(component).node_ids))
    before, n = windows.own_J(base, columns)
    after, _ = windows.own_J(sensed, columns)
    return OwnSensors([float(v) for v in before], [float(v) for v in after], n, windows.own_numerical(columns))


def diagnose(building, records, objective, workdir, *, source="measurements", fraction=0.6, calibration_end=None,
             seed=0, workers=None, scheduler=None, population=30, generations=400, fmu_kind="auto", reference=None,
             noise=None, phases=None, later=()):
    """Run the whole loop, its stages in order (`prepare`, `localise`, `rounds`, `write`); write the
    artifacts in `workdir`; return the `Diagnosis` (report.json is its `to_json()`).

    `records` is a Case (one record: `source`, `fraction`, `calibration_end` and `phases` are
    its) or a list of `Record`s of the same building, each with its own windows and phases: the
    fits minimise the sum of every record's calibration J, the choice reads every record's
    blocks, and a candidate that harms one record is refused (`selection.decide`). The forcing
    search reads every record's calibration window together, then, reported, each one's alone.
    `reference` ({"label", "rmse": {phase: K}}), another model's error, is reported for scale;
    `noise` (C) is the air sensors' noise sd if the user knows it, else it is estimated from
    every record's air. `fmu_kind`: the FMUs built, run and written (`ga.locate.locate`; "auto": the
    standalone FMU where a C compiler is at hand). `scheduler` ("tcp://host:port"): the forcing
    search and every round's candidates run on that Dask cluster's workers (`nodeforce.cluster`)
    instead of `workers` processes; an unreachable one is an InputError before any work.
    `later`: `Record`s of the same building under the building file's protocol, read from their
    files (`nodeforce.read_record`), which nothing but the final comparison reads (`scored_later`):
    no fit, no choice, no cross-validation."""
    if not isinstance(records, (list, tuple)):
        records = [Record(records, source, source, fraction, calibration_end, tuple(phases or ()))]
    names = [r.name for r in [*records, *later]]
    for r in [*records, *later]:
        if names.count(r.name) > 1:
            raise InputError(r.source, "name", f"two records are named {r.name!r}: each needs its own name")
        check_measured(objective, r.case, r.source)
    for r in later:
        if r.read_from is None or protocol(building, r) is not None:
            raise InputError(r.source, "later", f"record {r.name}: a later record is read from its files "
                                                f"(read_record) for the building diagnosed, {building.source}")
    fmu_kind = evaluator_kind(building) if fmu_kind == "auto" else fmu_kind
    with Cluster(scheduler) if scheduler is not None else nullcontext() as cluster:
        prepared = prepare(building, records, objective, workdir, fmu_kind, noise)
        search = dict(seed=seed, workers=workers, scheduler=scheduler, population=population,
                      generations=generations, fmu_kind=fmu_kind,
                      noise=prepared.noise.sigma if prepared.noise.given else None)
        located = localise(building, prepared, objective, workdir, search)
        made = rounds(prepared, located.localization, objective, workdir, seed, workers, cluster)
    return write(building, prepared, located, made, objective, workdir, fmu_kind, reference, later)


@dataclass
class Prepared:
    """What every stage reads (`prepare`): the records, their windows (with the file's numerical
    error), each record's protocol's building (`bases`, None: the building's), the model as
    described (its runs over each record and its metrics), the noise, and the residuals the
    blocks score (`n`)."""
    records: list
    windows: Windows
    bases: list
    model: Model
    noise: Noise
    n: int


@dataclass
class Located:
    """The forcing search on every record's calibration window together (`localization`,
    locate.json's content), on each record alone (`alone`, where there are several), and its best
    J per generation (`convergence`)."""
    localization: dict
    alone: list
    convergence: list


@dataclass
class Made:
    """What the rounds made: each round's `Decision`, every candidate tried (its `Fit`, as
    report.json keeps it), their runs by label, the Morris screening of each chosen effect, and
    the model they leave."""
    decisions: list
    results: list
    runs: dict
    sensitivities: dict
    model: Model

    @property
    def added(self):
        """The effects added, in order (their `Fit`s)."""
        return [d.chosen for d in self.decisions if d.chosen is not None]


def prepare(building, records, objective, workdir, fmu_kind, noise):
    """Stage 1: the records' windows; the building as described (each record's protocol's)
    built as an FMU and run over each record (`model_before.fmu`); the file's own numerical error
    beside it; the noise (C), `noise` if the user gave it."""
    windows = Windows.of(records, objective)
    bases = [protocol(building, r) for r in records]
    before_runs = []
    for i, (case, base) in enumerate(zip(windows.cases, bases)):
        name = "model_before.fmu" if base is None else f"model_before_{i + 1}.fmu"
        with FmuInstance(build_fmu(base or building, workdir / name, kind=fmu_kind)) as fmu:
            before_runs.append(simulate_fmu(fmu, case, output_ids=objective.air_nodes))
    model = Model(building, before_runs, windows.metrics(objective, before_runs), bases)
    windows = windows.with_numerical(before_runs, windows.sensed_by(model), building, bases, objective)
    noise = Noise.of_records(windows.measured, noise).with_numerical(windows.numerical_rms())
    return Prepared(list(records), windows, bases, model, noise, windows.scored())


def localise(building, prepared, objective, workdir, search):
    """Stage 2: the forcing search (`ga.locate`) on every record's calibration window together,
    a forcing applying to all; and on each record alone, reported: a record's own sensors
    (experiment 2's surfaces) may point where the records together do not."""
    windows, records, bases = prepared.windows, prepared.records, prepared.bases
    convergence = []
    localization = locate(building, windows.calibrations, objective, workdir, source=records[0].source,
                          protocols=bases, progress=lambda generation, total, J, unique: convergence.append((generation, J)),
                          **search)
    alone = []
    for i, record in enumerate(records if len(records) > 1 else ()):
        into = workdir / "locate" / record.name
        into.mkdir(parents=True, exist_ok=True)
        alone.append(locate(building, [windows.calibrations[i]], objective, into, source=record.source,
                            protocols=[bases[i]], **search))
    return Located(localization, alone, convergence)


def rounds(prepared, localization, objective, workdir, seed, workers, cluster=None):
    """Stage 3: rounds of candidates, `POLICY.max_rounds` at most, each on top of the last,
    while the error left is above the noise and one is chosen (`selection.decide`); the
    candidates in `workers` processes, one pool for every round (a worker's start, its imports,
    paid once), or on `cluster`'s workers (`assess_all`)."""
    n_workers = (workers or os.cpu_count()) if cluster is None else 1
    with lifetime.worker_pool(n_workers) if n_workers > 1 else nullcontext() as pool:
        windows, n, noise = prepared.windows, prepared.n, prepared.noise
        folder = workdir / "candidates"
        folder.mkdir(exist_ok=True)
        measured_ids = sorted({i for case in windows.cases for i in case.measured_ids})
        model, decisions, results, runs, sensitivities = prepared.model, [], [], {}, {}
        for number in range(POLICY.max_rounds):
            base_blocks = windows.block_J(model.runs)
            air_at_noise = bool(number) and POLICY.at_noise(base_blocks.sum(), n, noise.floor_sd)
            base_sensed = windows.sensed_by(model)  # the round's model at the other sensors: one run per record
            if air_at_noise and not windows.disagreeing(model.building, base_sensed, noise.sigma):
                break  # the error left is the noise's, at the air and at every component's own sensors
            done = [d.chosen.label for d in decisions]  # every earlier round chose: a round without a choice ends them
            started = time.perf_counter()
            # a later round's candidates, on top of the earlier choices, are building files of their own
            into = folder / f"round{number + 1}" if number else folder
            into.mkdir(exist_ok=True)
            pairs = [p for p in physical(model.building, localization["components"], objective.zones,
                                         measured_ids, localization["best_nodes"]) if "@".join(p) not in done]
            assessed = assess_all(model, pairs, windows, objective, noise.sigma, into, seed, pool, cluster)
            tried, models = fits_of(model, base_sensed, pairs, assessed, windows, objective, noise.sigma, number + 1,
                                    done)
            # shapes only where no physical candidate physics admits brings the error left to the
            # noise; the residual's statistics then choose which
            if not any(POLICY.at_noise(r.cv.J, n, noise.floor_sd) and not POLICY.objection_of(
                    r.effect, r.parameters, r.derived, r.physics) for r in tried):
                more = [p for p in shapes(model.building, left_by(windows, model), objective.zones)
                        if "@".join(p) not in done]
                pairs, assessed = pairs + more, assessed + assess_all(model, more, windows, objective, noise.sigma,
                                                                      into, seed, pool, cluster)
                # every sensor's weight from the least misfit any candidate of the round leaves
                tried, models = fits_of(model, base_sensed, pairs, assessed, windows, objective, noise.sigma,
                                        number + 1, done)
            simulations = sum(a.simulations for a in assessed)
            # a round run for a component's own sensors alone: only they can make a candidate pass
            decision = decide(tried, base_blocks, noise.sigma, n, windows.groups(), noise.floor_sd,
                              air_at_noise=air_at_noise)
            decision.cost = {"candidates": len(tried), "simulations": simulations,
                             "seconds": round(time.perf_counter() - started, 1)}
            decisions.append(decision)
            # the residuals themselves go (the decision keeps what the choice read of them, the
            # distances of every two admissible candidates'): a house's rounds would hold gigabytes
            results += [replace(r, cv=replace(r.cv, left_out=None), sensors=replace(r.sensors, residuals=None))
                        for r in tried]
            runs.update({(key if not number else f"{key} (round {number + 1})"): m.runs for key, m in models.items()})
            chosen = decision.chosen
            if not chosen:
                break
            # the Morris screening of the chosen effect's parameters, on the model it is added to: a
            # screening of every candidate would cost a quarter of a round's simulations
            screened = Candidate(model.building, chosen.effect, chosen.target,
                                 protocols(model.bases, windows.calibrations))
            sensitivities[chosen.label] = sensitivity(screened, windows.calibrations, objective, seed=seed)
            model = models[chosen.label]
        return Made(decisions, results, runs, sensitivities, model)


def left_by(windows, model):
    """What the model's residual on the first record's calibration window follows (an input, the
    time of day)."""
    first, k0 = windows.cases[0], windows.ks[0]
    shaped = shaped_inputs(model.building)
    inputs = {name: values for name, values in zip(first.input_names, first.U[1:k0 + 1].T) if name in shaped}
    return residual_diagnostics(windows.calibrations[0].times[1:],
                                windows.measured[0][:k0][:, 0] - model.runs[0][:k0, 0], inputs)


def priors_stated(building, added):
    """The building with a sentence in its description for each parameter of an added effect
    (`Fit`s) held at its physical prior: a modeller reading the file learns which of its values
    the data did not fix and where it comes from."""
    said = [f"{fit.effect} on {fit.target}: {name} = {p['value']:.4g} {EFFECTS[fit.effect].parameter(name).unit}, "
            f"held at {p['prior']}: the data fixed the effect, not {name} apart (nodeforce diagnose)."
            for fit in added for name, p in fit.parameters.items() if p.get("prior")]
    if not said:
        return building
    return building.edited(lambda data: data.update(description=" ".join([data.get("description", "")] + said).strip()))


def write(building, prepared, located, made, objective, workdir, fmu_kind, reference, later=()):
    """Stage 4: the model the rounds leave written (`building_after.json`, `model_after.fmu`,
    each protocol's building, `model_after.idf` for a converted EnergyPlus model), scored on
    each later record (`scored_later`), the `Diagnosis`, written as report.json, report.md and
    the plots; returns it."""
    windows, records, model, added = prepared.windows, prepared.records, made.model, made.added
    (workdir / "building_after.json").write_text(json.dumps(priors_stated(model.building, added).to_json(), indent=2)
                                                 + "\n")
    later = [scored_later(record, (building.source, building), (workdir / "building_after.json", model.building),
                          objective, fmu_kind) for record in later]
    fmu_after = build_fmu(model.building, workdir / "model_after.fmu", kind=fmu_kind)
    # a record under another protocol: its own building as corrected, for `nodeforce compare`
    protocols_after = {i: workdir / f"building_after_record{i + 1}.json" for i, b in enumerate(model.bases) if b is not None}
    for i, path in protocols_after.items():
        path.write_text(json.dumps(model.bases[i].to_json(), indent=2) + "\n")
    by_phase = phase_rows(prepared, made, objective)
    diagnosis = Diagnosis(
        objective=list(objective.zones), period=period(windows, 0), before=prepared.model.metrics,
        after=model.metrics, localization=located.localization, candidates=made.results, rounds=made.decisions,
        structure_left=left_by(windows, model)["sentence"],
        heat_loss=heat_loss(building, model.building, added, made.results, prepared.noise.sigma),
        residuals=validation_residuals(prepared, made), sensitivity=made.sensitivities, noise=prepared.noise,
        assumptions=list(dict.fromkeys(a for case in windows.cases for a in case.assumptions)),
        node_names={str(i): name for i, name in building.node_names().items()},
        artifacts={"building_after": str(workdir / "building_after.json"), "fmu_after": str(fmu_after)},
        records=[RecordOutcome(r.name, str(r.source), period(windows, i),
                               windows.metrics(objective, prepared.model.runs, i),
                               windows.metrics(objective, model.runs, i), located.alone[i],
                               str(protocols_after[i]) if i in protocols_after else None)
                 for i, r in enumerate(records)] if len(records) > 1 else [],
        worsened_phases=worsened(by_phase, "before", "after") if by_phase and added else None,
        phases=by_phase or None, reference=reference or None, later=later)
    idf = idf_of(building)
    if idf is not None:  # a converted EnergyPlus model: its corrections written back into it
        diagnosis.energyplus = write_corrections(building, model.building, [(a.effect, a.target) for a in added],
                                                 idf, workdir / "model_after.idf")
        diagnosis.artifacts["idf_after"] = diagnosis.energyplus["idf_after"]
    plots = write_report(workdir, diagnosis.to_json(), plotted(prepared, located, made, objective))
    diagnosis.artifacts["plots"] = [str(p) for p in plots]
    diagnosis.artifacts["report"] = str(workdir / "report.md")
    diagnosis.write(workdir / "report.json")
    return diagnosis


def scored_later(record, written, corrected, objective, fmu_kind):
    """The later `record` scored as `nodeforce compare` scores it (`diagnosis.compare`): the
    building as written and as corrected, each (path, Building), run through its FMU on the
    record's case prepared for it; their `LaterRecord`."""
    result, _ = compare([(path, b, record.case_for(b), objective) for path, b in (written, corrected)],
                        fmu_kind=fmu_kind)
    before, after = (m["metrics"] for m in result["models"])
    return LaterRecord(record.name, str(record.source), result["record"], result["scored_from"], before, after)


def validation_residuals(prepared, made):
    """What the first objective zone's residual on the first record's validation window follows
    (`diagnosis.residuals`), before and after."""
    windows = prepared.windows
    first, k, measured = windows.cases[0], windows.ks[0], windows.measured[0]
    validation = slice(k, None)
    return {state: residual_diagnostics(first.times[1:][validation], measured[validation, 0] - run[0][validation, 0],
                                        {name: values[validation] for name, values in
                                         zip(first.input_names, first.U[1:].T)})
            for state, run in (("before", prepared.model.runs), ("after", made.model.runs))}


def phase_rows(prepared, made, objective):
    """Every model's error on every record's phases (`diagnosis.phases`), each phase named with its
    record's name where there are several."""
    windows, records, rows = prepared.windows, prepared.records, []
    for i, (record, case) in enumerate(zip(records, windows.cases)):
        runs = {"before": prepared.model.runs[i], **{key: r[i] for key, r in made.runs.items()},
                "after": made.model.runs[i]}
        rows += [{**row, "phase": f"{record.name}: {row['phase']}", "record": record.name} if len(records) > 1
                 else row for row in phase_errors(record.phases, case.times[1:], windows.measured[i], runs,
                                                  zones=objective.zones)]
    return rows


def plotted(prepared, located, made, objective):
    """The series the plots draw, from the first measurement: the weather's history before it is
    not the record."""
    windows = prepared.windows
    first, k, measured = windows.cases[0], windows.ks[0], windows.measured[0]
    times, h = first.times, first.history_steps
    return {"times": times[h + 1:], "validation_start": times[k + 1], "scored_from": times[first.burn_in_steps + 1],
            "convergence": located.convergence,
            "zones": {zone: {"air_node": air, "measured": measured[h:, j], "before": prepared.model.runs[0][h:, j],
                             "after": made.model.runs[0][h:, j]}
                      for j, (zone, air) in enumerate(zip(objective.zones, objective.air_nodes))},
            "inputs": dict(zip(first.input_names, first.U[h + 1:].T))}


def protocol(building, record):
    """The record's own building (its protocol's), None where it is `building`; InputError naming
    its file where it is not the same house node for node."""
    other = record.building if record.building is not None else record.case.building
    if other is None or other is building or other.to_json() == building.to_json():
        return None
    for what, of in (("zones", lambda b: [z.name for z in b.zones]),
                     ("components", lambda b: [c.name for c in b.components]),
                     ("nodes", lambda b: b.n_nodes)):
        if of(other) != of(building):
            raise InputError(other.source, what, f"record {record.name}'s building is not {building.source}'s house "
                                                 f"under another protocol: its {what} differ")
    return other


def period(windows, i):
    """The calibration and validation spans of record i, where its scoring starts and its blocks."""
    times, k, case = windows.cases[i].times, windows.ks[i], windows.cases[i]
    return {"calibration": [case.start.isoformat(), times[k].isoformat()],
            "calibration_scored_from": times[case.burn_in_steps + 1].isoformat(),
            "validation": [times[k + 1].isoformat(), times[-1].isoformat()],
            "blocks": [[times[1:k + 1][m][0].isoformat(), times[1:k + 1][m][-1].isoformat()]
                       for j, m in windows.blocks if j == i],
            "roles": {"calibration": "the forcing search and the candidates' fits read it; each of its "
                                     "blocks of whole days ('blocks') is left out of a fit in turn and "
                                     "predicted, and the choice is made on those predictions",
                      "validation": "reports before and after only; no part in any choice"}}
