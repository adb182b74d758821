"""The Python API: what a script needs, as thin functions over the modules the command line uses.

Read a building, its weather and measurements; make the measured case; simulate; write an FMU;
open it and score a forcing (J) through it with FMPy; locate; diagnose. Every function is
re-exported by the package (`import nodeforce; nodeforce.read_building(...)`); docs/api.md
shows them at work. Bad input raises `InputError` (a ValueError) with the one-line message the
command line prints.
"""
from contextlib import contextmanager
from pathlib import Path

from nodeforce import tempdirs
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.diagnose import compare as _compare, loop as _loop
from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga import locate as _locate
from nodeforce.iotools.measurements import read_measurements
from nodeforce.iotools.phases import read_phases
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building import load_building
from nodeforce.model.case import force_mask, measured_case, simulate_building
from nodeforce.model.errors import InputError
from nodeforce.model.score import Objective

__all__ = ["InputError", "read_building", "convert_idf", "read_weather", "read_measurements", "read_phases", "measured_case",
           "objective", "simulate", "write_fmu", "open_fmu", "simulate_fmu", "forcing_candidates",
           "score_forcing", "locate", "diagnose", "Record", "compare"]

# One record of a building among several in one diagnosis: case, source, name, fraction,
# calibration_end, phases (diagnose.loop.Record).
Record = _loop.Record

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
    from nodeforce.model.building import check_schema, parse_building
    import json
    import os
    data = convert(path)
    if output is not None:
        data["energyplus"]["idf"] = os.path.relpath(Path(path).resolve(), Path(output).resolve().parent)
    building = parse_building(data, source=str(output if output is not None else path))
    check_schema(data, str(path))
    if output is not None:
        Path(output).parent.mkdir(parents=True, exist_ok=True)
        Path(output).write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    return building


def objective(building, zones=None):
    """The zones whose measured air J sums (docs/model.md section 6).

    Parameters
    ----------
    building : Building
    zones : list of str, optional
        Zone names; default the building's first zone.

    Returns
    -------
    Objective
        `zones` and their `air_nodes` (node ids).
    """
    return Objective.of(building, zones, source="zones")


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


def write_fmu(building, path, standalone=False):
    """Write the building's FMI 2.0 co-simulation FMU (docs/fmu.md).

    Parameters
    ----------
    building : Building
    path : str or Path
        The .fmu to write.
    standalone : bool
        False: the Python FMU (pythonfmu), the one the search drives. True: the same model in C,
        no Python at run time (a C compiler is needed to export it).

    Returns
    -------
    Path
        The FMU written.
    """
    return build_fmu(building, path, kind="standalone" if standalone else "python")


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


def locate(building, case, objective=None, workdir=None, **search):
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
                              source=SOURCE, **search)


def diagnose(building, case, workdir, objective=None, **options):
    """The whole loop of `nodeforce diagnose`; writes its files in `workdir` and returns report.json's
    content (docs/guide.md, Output files).

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
    **options
        `nodeforce.diagnose.loop.diagnose`'s: fraction, calibration_end (a pandas Timestamp) and
        phases (from `read_phases`) of a single case (a `Record` carries its own), seed, workers,
        fmu_kind, noise, reference. Worker
        processes as for `locate`.

    Returns
    -------
    dict
    """
    with _folder(workdir) as folder:
        return _loop.diagnose(building, case, objective or Objective.of(building), folder, source=SOURCE, **options)


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
    result, series = _compare.compare(models, phases, fmu_kind=fmu_kind)
    if workdir is not None:
        Path(workdir).mkdir(parents=True, exist_ok=True)
        _compare.write_compare(Path(workdir), result, series)
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
