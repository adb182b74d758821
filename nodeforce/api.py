"""The Python API: what a script needs; the command line (`nodeforce.cli`) is a thin layer over it.

Read a building, its weather and measurements; make the measured case; simulate; write an FMU;
open it and score a forcing (J) through it with FMPy; locate; diagnose. Every function is
re-exported by the package (`import nodeforce; nodeforce.read_building(...)`); docs/api.md
shows them at work. Bad input raises `InputError` (a ValueError) with the one-line message the
command line prints.
"""
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from nodeforce.runtime import tempdirs
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import input_table, simulate_fmu
from nodeforce.diagnosis import windows as _windows
from nodeforce.fmu_build.build import build_fmu, fmu_kind as _fmu_kind
from nodeforce.ga import locate as _locate
from nodeforce.ga.search import Execution, SearchSettings
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
           "score_forcing", "locate", "diagnose", "Record", "SearchSettings", "Execution", "Beside", "compare",
           "Reading", "SensorNoise", "Period"]

# One record of a building among several in one diagnosis, or a later one: case, source, name,
# fraction, calibration_end, phases, building, read_from (diagnosis.windows.Record).
Record = _windows.Record
# What the forcing search found: locate.json's content (ga.locate.Localization).
Localization = _locate.Localization
# What a diagnosis's report sets beside it: another model's error, later records (diagnosis.windows.Beside).
Beside = _windows.Beside

# The API's cases carry no file name: errors about their measurements say "measurements".
SOURCE = "measurements"


@dataclass(frozen=True)
class Reading:
    """How a record's files are made its case (`measured_case`'s settings, which it checks):
    `burn_in_days`, the days forced after the first measurement; `decomposition`, the pvlib model
    that splits ghi alone (`nodeforce.model.solar.DECOMPOSITIONS`); `history_days`, the days of
    weather simulated before the record at most."""
    burn_in_days: float = 0
    decomposition: str = "erbs"
    history_days: float = HISTORY_DAYS


@dataclass(frozen=True)
class SensorNoise:
    """The Gaussian noise `synthesize` adds to what the sensors read: its standard deviation `sd`
    (C) and the `seed` of its draws."""
    sd: float = 0.0
    seed: int = 0


@dataclass(frozen=True)
class Period:
    """The rows `convert_table` keeps: from `start` to `end` (ISO 8601 times with UTC offset, both
    ends included; None: the table's first or last row), parsed where the table is read."""
    start: str | None = None
    end: str | None = None


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


def read_case(building, weather, measurements=None, reading=Reading()):
    """The files of one record read and made its measured case: what every command that
    simulates reads first.

    Parameters
    ----------
    building : str or Path, or a Building already read
    weather : str or Path, or a DataFrame already read
        The weather CSV or EPW (`read_weather`; an EPW typical year in the measurements' year).
    measurements : str or Path, optional
        The measurements CSV (`read_measurements`); None: a simulation without them.
    reading : Reading
        `measured_case`'s settings: `burn_in_days`, days forced after the first measurement;
        `decomposition`, the pvlib model that splits ghi alone; `history_days`, days of weather
        simulated before the record at most.

    Returns
    -------
    (Building, Case)
        The building as run, at the site the weather gives (`nodeforce.model.site.run_building`:
        an EPW recorded elsewhere moves it there), the one to build its FMU from; the case's
        `assumptions` say what was assumed about the files (the weather's site, its history).
    """
    building, read_from = _read(building, weather, measurements, reading)
    case = measured_case(building, **read_from)
    return case.building, case


def _read(building, weather, measurements, reading):
    """The building (read, unless given read) and the other arguments of `measured_case`, its
    files read: what `read_case` makes a case of, and what a `Record` keeps (`read_from`)."""
    building = building if isinstance(building, Building) else load_building(building)
    measurements = read_measurements(measurements) if measurements else None
    if not isinstance(weather, pd.DataFrame):
        weather = read_weather(weather, times=None if measurements is None else measurements.index)
    return building, {"weather": weather, "measurements": measurements, "burn_in_days": reading.burn_in_days,
                      "decomposition": reading.decomposition, "history_days": reading.history_days}


def read_record(building, weather, measurements, *, name=None, fraction=0.6, calibration_end=None, phases=None,
                reading=Reading()):
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
    reading : Reading
        As `read_case`'s.

    Returns
    -------
    Record
        Its `read_from` keeps the files as read, from which `diagnose` prepares a later record's
        case for the building as corrected.
    """
    building, read_from = _read(building, weather, measurements, reading)
    return Record(measured_case(building, **read_from), str(measurements),
                  name or Path(measurements).name.split(".")[0], fraction, calibration_end,
                  tuple(read_phases(phases)) if phases else (), building, read_from)


def synthesize(building, weather, times, sensors, *, effects=(), noise=SensorNoise(), reading=Reading(history_days=0.0),
               source="effects"):
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
    noise : SensorNoise
        The Gaussian sensor noise added: its standard deviation `sd` (C) and its `seed`.
    reading : Reading
        Its `history_days`, days of the weather simulated before the record (default here 0),
        and `decomposition`, pvlib's split of ghi alone; its `burn_in_days` is not read.
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
    return pseudo_measurements(building, weather, times, list(sensors), noise_sd=noise.sd, seed=noise.seed,
                               history_days=reading.history_days, decomposition=reading.decomposition)


def convert_table(path, names, origin, select, output, *, table=None, period=Period(), constant=None):
    """Columns of a Modelica CombiTimeTable text file written as a weather or measurements CSV
    (`nodeforce table`; the arguments are `nodeforce.iotools.table.convert_table`'s, its `start`
    and `end` the `Period`'s).

    Returns
    -------
    DataFrame
        What was written, indexed by time.
    """
    return _convert_table(path, names, origin, select, output, table=table, start=period.start, end=period.end,
                          constant=constant)


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
        Indexed by time t_1..t_N, columns ``T1..TN``, of the building at the site the weather
        gives (`nodeforce.model.site.run_building`).
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


def locate(building, case, workdir=None, objective=None, *, search=SearchSettings(), execution=Execution(),
           source=SOURCE):
    """The forcing search of `nodeforce locate`: the content of locate.json (docs/guide.md).

    Parameters
    ----------
    building : Building
    case : Case from `measured_case`, with measurements
    workdir : str or Path, optional
        Folder for the FMU and the search's checkpoint (a run started again resumes); default a
        temporary folder, removed at the end.
    objective : Objective, optional
        Default: the building's first zone.
    search : SearchSettings
        The search's settings (`nodeforce.ga.search.SearchSettings`, checked where it is made):
        seed, population, generations, pc, pm, patience, seeded (`SearchSettings.paper()`: the
        paper's search), the nodes it may force and include_algebraic, the FMUs it drives
        (fmu_kind, default "auto"), warmup_days, and the air sensors' noise sd (C) if known.
    execution : Execution
        Where it runs (`nodeforce.ga.search.Execution`): workers, scheduler, and progress, called
        after every generation. Worker processes (`workers`, default all cores) are spawned: a
        script that uses more than one runs this under ``if __name__ == "__main__":``.
    source : str
        What an error about the measurements names (their file).

    Returns
    -------
    Localization
        locate.json's content as an object (`nodeforce.ga.locate.Localization`): `best_nodes`,
        `J_unforced`, `J_best`, `node_scores`, `ranked_nodes`, `search`, `finding`, ...;
        `summary()` what `nodeforce locate` prints, `to_json()` locate.json, `Localization.read(path)`
        one read back.
    """
    with _folder(workdir) as folder:
        return _locate.locate(building, case, folder, objective or Objective.of(building),
                              search=search, execution=execution, source=source)


def diagnose(building, case, workdir, objective=None, *, search=SearchSettings(), execution=Execution(),
             beside=Beside(), policy=None):
    """The whole loop of `nodeforce diagnose`; writes its files in `workdir` (docs/guide.md, Output
    files) and returns the `Diagnosis`: `summary()` the first screen, `to_json()` report.json's
    content, `added` the effects added, `rounds` each round's decision, `candidates` every fit.

    Parameters
    ----------
    building : Building
    case : Case from `measured_case`, with measurements (its burn-in is `diagnose`'s; the command
        line's default is one day), its calibration window the first 60% of it by time; or a
        list of `Record`s, several records of the same building (each its case, name,
        calibration window, `fraction` or `calibration_end`, and phases, from `read_phases`): the
        fits minimise the sum of their calibration windows' J, the choice reads every record's
        days, and a correction that harms one record is refused
    workdir : str or Path
        Folder for report.json, report.md, the plots, building_after.json and model_after.fmu.
    objective : Objective, optional
        Default: the building's first zone.
    search : SearchSettings
        The forcing search's (`nodeforce.ga.search.SearchSettings`): its `seed`, every random
        choice's (the forcing search, the screening); its GA settings (`population`,
        `generations`, ...); `fmu_kind`, the FMUs the forcing search drives (`model.fmu`),
        default "auto", as `locate`'s: the standalone, 4 to 6 times faster a simulation on the
        test cell (docs/performance.md), whose J differs from the Python FMU's by rounding, far
        below the noise its choice of nodes reads; and `noise`, the air sensors' noise sd (C)
        where the user knows it, default estimated from the air.
    execution : Execution
        Where the work runs (`nodeforce.ga.search.Execution`): `workers` processes (default all
        cores), spawned as for `locate`; or `scheduler`, a Dask scheduler's address,
        "tcp://host:port": the forcing search and every round's candidates run on its workers
        instead (docs/performance.md). The answer is the same; a worker lost midway costs none; a
        lost scheduler raises `runtime.lifetime.RunStopped`, an unreachable one `InputError`.
        Its `fmu_kind`: the FMUs of the model before and after, run and written
        (`model_before.fmu`, `model_after.fmu`): "python" (the default, as on the command line),
        "standalone", or "auto", the standalone where a C compiler is at hand and it can run the
        building; each with "-fmi3" for FMI 3.0. The candidates are fitted on the direct model,
        and the model they are measured against runs through this FMU: the Python FMU repeats
        the direct model's arithmetic (to 1e-14 C), the C FMU differs by rounding (1e-12 C),
        which a candidate the data do not determine can turn into another of its many equally
        good fits.
    beside : Beside
        What the report sets beside the diagnosis (`nodeforce.diagnosis.windows.Beside`), which
        no fit, choice or cross-validation reads: `reference`, {"label", "rmse": {phase: K}},
        another model's error, reported for scale; `later`, later records of the same building,
        each from `read_record` (the building diagnosed, the diagnosis's burn-in): after the
        rounds the building as written and as corrected are scored on each as `compare` scores
        them (`Diagnosis.later`, report.json's `later`, a line of the first screen).
    policy : Policy, optional
        Every threshold, table and order of the choice (`nodeforce.diagnosis.policy.Policy`),
        default `Policy()`; report.json records it, and `Diagnosis.replay` judges under it.

    Returns
    -------
    Diagnosis
    """
    from nodeforce.diagnosis import loop  # here: the report's plotting and statistics load with it
    with _folder(workdir) as folder:
        records = case if isinstance(case, (list, tuple)) else [Record(case, SOURCE, SOURCE)]
        return loop.diagnose(building, records, folder, objective or Objective.of(building), search=search,
                             execution=execution, beside=beside, policy=policy)


def compare(models, workdir=None, phases=(), fmu_kind="python"):
    """`nodeforce compare`: building files scored on one record none of them was fitted on.

    Parameters
    ----------
    models : list of (name, Building, Case, Objective)
        Each building as run (the case's `building`, at the site the weather gives) with the
        record prepared for it by `measured_case` (same times and burn-in for all) and its
        objective (the same zone names for all); `name` labels it in the output.
    workdir : str or Path, optional
        Folder for compare.json, compare.md and the plot; None writes nothing.
    phases : list of Phase, optional
        From `read_phases`: every model is also scored on each.
    fmu_kind : str
        "python" or "standalone" (or their "-fmi3" forms): the FMU each model runs through.

    Returns
    -------
    Comparison
        compare.json's content as an object (`nodeforce.diagnosis.compare.Comparison`): `models`,
        per model its heat loss coefficient (W/K) and the RMSE, mean and sd (C) of each objective
        zone's air residual, overall and per phase; `summary()` what `nodeforce compare` prints,
        `to_json()` compare.json, `Comparison.read(path)` one read back.
    """
    from nodeforce.diagnosis.compare import Comparison, compare as scored, write_compare  # as `diagnose`'s loop
    result, series = scored(models, phases, fmu_kind=fmu_kind)
    if workdir is not None:
        Path(workdir).mkdir(parents=True, exist_ok=True)
        write_compare(Path(workdir), result, series)
    return Comparison.of(result)


@contextmanager
def _folder(workdir):
    """`workdir` as a Path, made if absent; None: a temporary folder, removed afterwards."""
    if workdir is not None:
        Path(workdir).mkdir(parents=True, exist_ok=True)
        yield Path(workdir)
        return
    with tempdirs.folder("api") as tmp:
        yield Path(tmp)
