"""The Python API: what a script needs; the command line (`nodeforce.cli`) is a thin layer over it.

Read a building, its weather and measurements; make the measured case; simulate; write an FMU;
open it and score a forcing (J) through it with FMPy; locate; diagnose. Every function is
re-exported by the package (`import nodeforce; nodeforce.read_building(...)`); docs/api.md
shows them at work. Bad input raises `InputError` (a ValueError) with the one-line message the
command line prints.
"""
from contextlib import contextmanager
from pathlib import Path

import pandas as pd

from nodeforce.runtime import tempdirs
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import input_table, simulate_fmu
from nodeforce.diagnosis import windows as _windows
from nodeforce.fmu_build.build import build_fmu, fmu_kind as _fmu_kind
from nodeforce.ga import locate as _locate
from nodeforce.iotools.fmu_inputs import write_fmu_inputs
from nodeforce.iotools.measurements import read_measurements
from nodeforce.iotools.phases import read_phases
from nodeforce.iotools.table import convert_table as _convert_table
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building import Building
from nodeforce.model.building_file import load_building
from nodeforce.model.case import HISTORY_DAYS, force_mask, measured_case, simulate_building
from nodeforce.model.errors import InputError
from nodeforce.model.score import Objective

__all__ = ["InputError", "read_building", "convert_idf", "read_weather", "read_measurements", "read_phases", "measured_case",
           "read_case", "read_record", "objective", "synthesize", "convert_table", "simulate", "write_fmu",
           "fmu_inputs", "write_fmu_inputs", "open_fmu", "simulate_fmu", "forcing_candidates",
           "score_forcing", "locate", "diagnose", "Record", "compare"]

# One record of a building among several in one diagnosis, or a later one: case, source, name,
# fraction, calibration_end, phases, building, read_from (diagnosis.windows.Record).
Record = _windows.Record

# The API's cases carry no file name: errors about their measurements say "measurements".
SOURCE = "measurements"


def read_building(path):
    """Read and validate a building file.

    Parameters
    ----------
    path : str or Path
        JSON, ``"format": "nodal-building/1"`` (docs/guide.md, Building file).

    Returns
    -------
    Building
        Typed records of the file (`n_nodes`, `zones`, `components`, `node_names()`, ...).

    Raises
    ------
    InputError
        Naming the file and the field: not found, not JSON, outside the format's JSON Schema or
        physically impossible.
    """
    return load_building(path)


def convert_idf(path, output=None):
    """An EnergyPlus model (IDF) as a validated building file (docs/guide.md, `nodeforce convert`),
    written to `output` if given (its `energyplus.idf` then the IDF's path from the file's folder,
    which `diagnose` writes its corrections back into).

    Returns
    -------
    Building
        Its `to_json()` is the building file; its `data["not_modelled"]` lists what the IDF held
        that the file does not, one line per object.

    Raises
    ------
    InputError
        Naming the IDF, the object and the field: an IDF the conversion cannot read.
    """
    from nodeforce.iotools.energyplus import convert
    from nodeforce.model.building_file import parse_building
    import json
    import os
    data = convert(path)
    if output is not None:
        data["energyplus"]["idf"] = os.path.relpath(Path(path).resolve(), Path(output).resolve().parent)
    building = parse_building(data, source=str(output if output is not None else path))
    if output is not None:
        Path(output).parent.mkdir(parents=True, exist_ok=True)
        Path(output).write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    return building


def objective(building, zones=None, source="zones"):
    """The zones whose measured air J sums (docs/model.md section 6).

    Parameters
    ----------
    building : Building
    zones : list of str, optional
        Zone names; default the building's first zone.
    source : str
        What an error about a zone names (the command line's option).

    Returns
    -------
    Objective
        `zones` and their `air_nodes` (node ids).
    """
    return Objective.of(building, zones, source=source)


def read_case(building, weather, measurements=None, *, burn_in_days=0, decomposition="erbs",
              history_days=HISTORY_DAYS):
    """The files of one record read and made its measured case: what every command that
    simulates reads first.

    Parameters
    ----------
    building : str or Path, or a Building already read
    weather : str or Path, or a DataFrame already read
        The weather CSV or EPW (`read_weather`; an EPW typical year in the measurements' year).
    measurements : str or Path, optional
        The measurements CSV (`read_measurements`); None: a simulation without them.
    burn_in_days, decomposition, history_days
        `measured_case`'s: days forced after the first measurement, the pvlib model that splits
        ghi alone, days of weather simulated before the record at most.

    Returns
    -------
    (Building, Case)
        The case's `assumptions` say what was assumed about the files (the weather's history).
    """
    building, read_from = _read(building, weather, measurements, burn_in_days, decomposition, history_days)
    return building, measured_case(building, **read_from)


def _read(building, weather, measurements, burn_in_days, decomposition, history_days):
    """The building (read, unless given read) and the other arguments of `measured_case`, its
    files read: what `read_case` makes a case of, and what a `Record` keeps (`read_from`)."""
    building = building if isinstance(building, Building) else load_building(building)
    measurements = read_measurements(measurements) if measurements else None
    if not isinstance(weather, pd.DataFrame):
        weather = read_weather(weather, times=None if measurements is None else measurements.index)
    return building, {"weather": weather, "measurements": measurements,
                      "burn_in_days": burn_in_days, "decomposition": decomposition, "history_days": history_days}


def read_record(building, weather, measurements, *, name=None, fraction=0.6, calibration_end=None, phases=None,
                burn_in_days=0, decomposition="erbs", history_days=HISTORY_DAYS):
    """One record of a building for `diagnose`, read from its files.

    Parameters
    ----------
    building : str or Path, or a Building already read
        The building as written for this record's protocol (its own supply flows, blinds): the
        house the diagnosis corrects, or the same house node for node.
    weather, measurements : str or Path
        The record's files (the weather may be a DataFrame already read, `read_case`); errors
        about the measurements name their file.
    name : str, optional
        The record's name in the report; default the measurement file's name before its first dot.
    fraction, calibration_end
        The calibration window: the first `fraction` of the record by time, or up to
        `calibration_end` (a pandas Timestamp, the row at or before it).
    phases : str or Path, optional
        The record's `time,phase` CSV (`read_phases`).
    burn_in_days, decomposition, history_days
        As `read_case`.

    Returns
    -------
    Record
        Its `read_from` keeps the files as read, from which `diagnose` prepares a later record's
        case for the building as corrected.
    """
    building, read_from = _read(building, weather, measurements, burn_in_days, decomposition, history_days)
    return Record(measured_case(building, **read_from), str(measurements),
                  name or Path(measurements).name.split(".")[0], fraction, calibration_end,
                  tuple(read_phases(phases)) if phases else (), building, read_from)


def synthesize(building, weather, times, sensors, *, effects=(), noise_sd=0.0, seed=0, history_days=0.0,
               decomposition="erbs", source="effects"):
    """What the sensors of a building would read under a weather, with effects its file does not
    declare (`nodeforce synth`).

    Parameters
    ----------
    building : Building
    weather : DataFrame from `read_weather`, covering the history and `times`
    times : uniform DatetimeIndex of the record
    sensors : sequence of int
        The node ids measured.
    effects : sequence of (effect, target, {parameter: value})
        Effects of `model.effects.EFFECTS` added to the building, each in turn (several faults at once).
    noise_sd : float
        Standard deviation (C) of the Gaussian sensor noise added.
    seed : int
        The noise's.
    history_days, decomposition
        Days of the weather simulated before the record; pvlib's split of ghi alone.
    source : str
        What an error about an effect that does not apply names (the command line: `--effect`).

    Returns
    -------
    DataFrame
        Indexed by time, columns ``T<id>`` (C): a measurements file's content.
    """
    from nodeforce.model.effects import EFFECTS
    from nodeforce.model.synth import pseudo_measurements
    for effect, target, values in effects:
        if not EFFECTS[effect].applies(building, target):
            raise InputError(source, f"{effect}@{target}", f"does not apply to {building.source}")
        building = EFFECTS[effect].apply(building, target, values)
    return pseudo_measurements(building, weather, times, list(sensors), noise_sd=noise_sd, seed=seed,
                               history_days=history_days, decomposition=decomposition)


def convert_table(path, names, origin, select, output, *, table=None, start=None, end=None, constant=None):
    """Columns of a Modelica CombiTimeTable text file written as a weather or measurements CSV
    (`nodeforce table`; the arguments are `nodeforce.iotools.table.convert_table`'s).

    Returns
    -------
    DataFrame
        What was written, indexed by time.
    """
    return _convert_table(path, names, origin, select, output, table=table, start=start, end=end, constant=constant)


def simulate(building, weather, measurements=None, force=(), burn_in_days=0):
    """Every node's temperature (C), with the direct model (the FMU gives the same within 1e-9 C).

    Parameters
    ----------
    building : Building
    weather : DataFrame from `read_weather`
    measurements : DataFrame from `read_measurements`, optional
        Sets the time grid, the initial state and the values forced nodes take.
    force : sequence of int
        Node ids forced to their measurements for the whole run.
    burn_in_days : float
        Days after t_0 over which every measured node is forced (docs/model.md section 5).

    Returns
    -------
    DataFrame
        Indexed by time t_1..t_N, columns ``T1..TN``.
    """
    return simulate_building(building, weather, measurements, force=force, burn_in_days=burn_in_days)


def write_fmu(building, path, standalone=False, fmi=2):
    """Write the building's co-simulation FMU (docs/fmu.md).

    Parameters
    ----------
    building : Building
    path : str or Path
        The .fmu to write.
    standalone : bool
        False: the Python FMU (pythonfmu), the one the search drives. True: the same model in C,
        no Python at run time (a C compiler is needed to export it).
    fmi : int
        The FMI version, 2 or 3.

    Returns
    -------
    Path
        The FMU written.
    """
    return build_fmu(building, path, kind=_fmu_kind("standalone" if standalone else "python", fmi))


def fmu_inputs(building, weather, measurements=None, force=(), burn_in_days=0, decomposition="erbs"):
    """The FMU's inputs over a record, as another tool sets them, and its start values
    (docs/fmu.md): what `nodeforce inputs` writes.

    Parameters
    ----------
    building : Building
    weather : DataFrame from `read_weather`
    measurements : DataFrame from `read_measurements`, optional
        Sets the time grid (else the weather's), the start values and the forced nodes' inputs.
    force : sequence of int
        Node ids forced to their measurements over the whole record.
    burn_in_days : float
        Days after t_0 over which every measured node is forced (docs/model.md section 5).
    decomposition : str
        The split of a global horizontal irradiance alone (`nodeforce.model.solar.DECOMPOSITIONS`).

    Returns
    -------
    (DataFrame, dict)
        The table, indexed by `time` (s from t_0), one column per FMU input: row n is what is set
        before the step from t_n (`nodeforce.cosim.run.input_table`); and {name: value} of the
        start values, `T_start[i]` for every node and `force[i]` true for each node forced.
    """
    case = measured_case(building, weather, measurements, burn_in_days, decomposition, history_days=0)
    source = measurements.attrs.get("source", SOURCE) if measurements is not None else SOURCE
    return input_table(case, force_mask(case, [int(i) for i in force], source) if len(force) else None)


def open_fmu(path):
    """Extract and instantiate an FMU once, for many runs (FMPy).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    FmuInstance
        A context manager; `close()` frees the instance and removes the extracted files. Each run
        (`simulate_fmu`, `score_forcing`) resets it first.
    """
    return FmuInstance(path)


def forcing_candidates(building, case, objective=None, include_algebraic=False):
    """The nodes the forcing search may force: every measured node but the objective's air and,
    unless `include_algebraic`, the algebraic radiant nodes; nearest the zone's air first.

    Parameters
    ----------
    building : Building
    case : Case from `measured_case`, with measurements
    objective : Objective, optional
        Default: the building's first zone.
    include_algebraic : bool

    Returns
    -------
    list of int
        Node ids, the chromosome of `nodeforce locate`, in its order.
    """
    objective = objective or Objective.of(building)
    return _locate.chromosome_nodes(building, case, objective, SOURCE, include_algebraic=include_algebraic)


def score_forcing(instance, case, nodes, objective):
    """J (C2): the sum of squared residuals of the objective's measured air with `nodes` forced to
    their measurements, simulated through an open FMU, warm-up included (docs/model.md sections 5, 6).

    Parameters
    ----------
    instance : FmuInstance from `open_fmu`, of the case's building
    case : Case from `measured_case`, with measurements
    nodes : sequence of int
        Node ids to force; each must be measured. Empty: the unforced model.
    objective : Objective

    Returns
    -------
    float
        J over the scored steps (after the burn-in, where the air is measured).
    """
    force = force_mask(case, [int(i) for i in nodes], SOURCE)
    air = simulate_fmu(instance, case, force, output_ids=objective.air_nodes)
    return objective.J(objective.measured(case), air)


def locate(building, case, objective=None, workdir=None, source=SOURCE, **search):
    """The forcing search of `nodeforce locate`: the content of locate.json (docs/guide.md).

    Parameters
    ----------
    building : Building
    case : Case from `measured_case`, with measurements
    objective : Objective, optional
        Default: the building's first zone.
    workdir : str or Path, optional
        Folder for the FMU and the search's checkpoint (a run started again resumes); default a
        temporary folder, removed at the end.
    source : str
        What an error about the measurements names (their file).
    **search
        `nodeforce.ga.locate.locate`'s settings: nodes, include_algebraic, population,
        generations, pc, pm, patience, seeded, seed, workers, scheduler, fmu_kind, noise, progress.
        Worker processes (`workers`, default all cores) are spawned: a script that uses more
        than one runs this under ``if __name__ == "__main__":``.

    Returns
    -------
    dict
        `best_nodes`, `J_unforced`, `J_best`, `node_scores`, `ranked_nodes`, `search`, `finding`, ...
    """
    with _folder(workdir) as folder:
        return _locate.locate(building, case, objective or Objective.of(building), folder,
                              source=source, **search)


def diagnose(building, case, workdir, objective=None, *, fraction=0.6, calibration_end=None, phases=(), seed=0,
             workers=None, scheduler=None, fmu_kind="python", search_fmu="auto", noise=None, reference=None,
             population=30, generations=400, later=(), policy=None):
    """The whole loop of `nodeforce diagnose`; writes its files in `workdir` (docs/guide.md, Output
    files) and returns the `Diagnosis`: `summary()` the first screen, `to_json()` report.json's
    content, `added` the effects added, `rounds` each round's decision, `candidates` every fit.

    Parameters
    ----------
    building : Building
    case : Case from `measured_case`, with measurements (its burn-in is `diagnose`'s; the command
        line's default is one day); or a list of `Record`s, several records of the same building
        (each its case, name, calibration window and phases): the fits minimise the sum of their
        calibration windows' J, the choice reads every record's days, and a correction that
        harms one record is refused
    workdir : str or Path
        Folder for report.json, report.md, the plots, building_after.json and model_after.fmu.
    objective : Objective, optional
        Default: the building's first zone.
    fraction, calibration_end, phases
        The calibration window of a single case: the first `fraction` of it by time, or up to
        `calibration_end` (a pandas Timestamp); its phases (from `read_phases`). A `Record`
        carries its own.
    seed : int
        Every random choice's (the forcing search, the screening).
    workers : int, optional
        Worker processes (default all cores), spawned as for `locate`.
    scheduler : str, optional
        A Dask scheduler's address, "tcp://host:port": the forcing search and every round's
        candidates run on its workers instead of `workers` processes (docs/performance.md). The
        answer is the same; a worker lost midway costs none; a lost scheduler raises
        `runtime.lifetime.RunStopped`, an unreachable one `InputError`.
    fmu_kind : str
        The FMUs of the model before and after, run and written (`model_before.fmu`,
        `model_after.fmu`): "python" (the default, as on the command line), "standalone", or
        "auto", the standalone where a C compiler is at hand and it can run the building; each
        with "-fmi3" for FMI 3.0. The candidates are fitted on the direct model, and the model
        they are measured against runs through this FMU: the Python FMU repeats the direct
        model's arithmetic (to 1e-14 C), the C FMU differs by rounding (1e-12 C), which a
        candidate the data do not determine can turn into another of its many equally good fits.
    search_fmu : str
        The FMUs the forcing search drives (`model.fmu`), of the same kinds; default "auto", as
        `locate`'s: the standalone, 4 to 6 times faster a simulation on the test cell
        (docs/performance.md). Its J differs from the Python FMU's by rounding, far below the
        noise its choice of nodes reads.
    noise : float, optional
        The air sensors' noise sd (C) where the user knows it; default estimated from the air.
    reference : dict, optional
        {"label", "rmse": {phase: K}}: another model's error, reported for scale.
    population, generations : int
        The forcing search's GA settings.
    later : list of Record, optional
        Later records of the same building, each from `read_record` (the building diagnosed, the
        diagnosis's burn-in), which no fit, choice or cross-validation reads: after the rounds the
        building as written and as corrected are scored on each as `compare` scores them
        (`Diagnosis.later`, report.json's `later`, a line of the first screen).
    policy : Policy, optional
        Every threshold, table and order of the choice (`nodeforce.diagnosis.policy.Policy`),
        default `Policy()`; report.json records it, and `Diagnosis.replay` judges under it.

    Returns
    -------
    Diagnosis
    """
    from nodeforce.diagnosis import loop  # here: the report's plotting and statistics load with it
    with _folder(workdir) as folder:
        records = case if isinstance(case, (list, tuple)) else \
            [Record(case, SOURCE, SOURCE, fraction, calibration_end, tuple(phases or ()))]
        return loop.diagnose(building, records, folder, objective or Objective.of(building),
                             search=_locate.SearchSettings(seed, population, generations, search_fmu),
                             execution=_locate.Execution(workers, scheduler, fmu_kind), noise=noise,
                             reference=reference, later=list(later), policy=policy)


def compare(models, workdir=None, phases=(), fmu_kind="python"):
    """`nodeforce compare`: building files scored on one record none of them was fitted on.

    Parameters
    ----------
    models : list of (name, Building, Case, Objective)
        Each building with the record prepared for it by `measured_case` (same times and burn-in
        for all) and its objective (the same zone names for all); `name` labels it in the output.
    workdir : str or Path, optional
        Folder for compare.json, compare.md and the plot; None writes nothing.
    phases : list of Phase, optional
        From `read_phases`: every model is also scored on each.
    fmu_kind : str
        "python" or "standalone" (or their "-fmi3" forms): the FMU each model runs through.

    Returns
    -------
    dict
        compare.json's content: per model its heat loss coefficient (W/K) and the RMSE, mean and
        sd (C) of each objective zone's air residual, overall and per phase.
    """
    from nodeforce.diagnosis.compare import compare as scored, write_compare  # as `diagnose`'s loop
    result, series = scored(models, phases, fmu_kind=fmu_kind)
    if workdir is not None:
        Path(workdir).mkdir(parents=True, exist_ok=True)
        write_compare(Path(workdir), result, series)
    return result


@contextmanager
def _folder(workdir):
    """`workdir` as a Path, made if absent; None: a temporary folder, removed afterwards."""
    if workdir is not None:
        Path(workdir).mkdir(parents=True, exist_ok=True)
        yield Path(workdir)
        return
    with tempdirs.folder("api") as tmp:
        yield Path(tmp)
