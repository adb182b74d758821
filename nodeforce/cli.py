"""The `nodeforce` command line (docs/guide.md). Bad input: one line on stderr, exit status 2; stopped
by SIGINT, SIGTERM or a lost Dask scheduler: one line saying how to resume, 130, 143 or 75
(runtime.lifetime)."""
import argparse
import importlib.util
import json
import sys
from importlib.resources import files
from pathlib import Path

from nodeforce.model.errors import InputError
from nodeforce.runtime import lifetime, tempdirs


def lazy(name):
    """The module `name`, loaded at the first use of one of its names (importlib's LazyLoader): a
    command loads what it uses, so that `convert` refuses a truncated file, and `--help` answers,
    before numpy, pandas and the model load (some 2 s)."""
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.find_spec(name)
    spec.loader = importlib.util.LazyLoader(spec.loader)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


api = lazy("nodeforce.api")
ga_checkpoint = lazy("nodeforce.ga.checkpoint")
ga_search = lazy("nodeforce.ga.search")
model_case = lazy("nodeforce.model.case")
iotools_timetable = lazy("nodeforce.iotools.timetable")
iotools_weather = lazy("nodeforce.iotools.weather")

DATA = Path(str(files("nodeforce.model") / "data"))


class Parser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"{self.prog}: {message}\n")


def node_list(option, text):
    """Node ids from "1,7,9"."""
    try:
        ids = [int(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise InputError(option, text, "must be node ids separated by commas, e.g. 1,7,9") from None
    if not ids:
        raise InputError(option, text, "names no node")
    return ids


def load_inputs(args):
    """The building, the case of its weather and measurements with its burn-in (`api.read_case`),
    and the objective of --objective; what was assumed printed."""
    building, case = api.read_case(args.building, weather_of(args.weather, args), getattr(args, "measurements", None),
                                   reading(args))
    said_assumed(case.assumptions)
    return building, case, objective_of(building, args)


def weather_of(path, args):
    """The weather file to read, or, with --year, the EPW read in that year (`api.read_weather`);
    with --step (`simulate` without measurements), the weather interpolated onto that grid from
    its first row to its last, its site kept."""
    year = getattr(args, "year", None)  # `demo` reads its own CSV
    step = getattr(args, "step", None)
    weather = path if year is None and step is None else api.read_weather(path, year=year)
    if step is None:
        return weather
    if getattr(args, "measurements", None):
        raise InputError("--step", step, "the measurements' times are the grid: give --step without --measurements")
    if not step > 0:
        raise InputError("--step", step, "must be a positive number of seconds")
    import pandas as pd

    from nodeforce.model.weather import weather_on_grid
    grid = pd.date_range(weather.index[0], weather.index[-1], freq=pd.Timedelta(seconds=step))
    return weather_on_grid(weather, grid)


def said_assumed(assumptions):
    for said in dict.fromkeys(assumptions):
        print(f"assumed: {said}")


def objective_of(building, args):
    """The objective of --objective (default the building's first zone)."""
    return api.objective(building, zone_list(args.objective) if getattr(args, "objective", None) else None,
                         source="--objective")


def zone_list(text):
    """Zone names from "living,kitchen"."""
    names = [part.strip() for part in text.split(",") if part.strip()]
    if not names:
        raise InputError("--objective", text, "names no zone")
    return names


def cmd_fmu(args):
    path = api.write_fmu(api.read_building(args.building), args.output, standalone=args.standalone, fmi=args.fmi)
    print(f"wrote {path}")


def cmd_convert(args):
    from nodeforce.iotools.idf_text import closed_text
    closed_text(args.idf)  # a missing or truncated file refused before the converter loads
    building = api.convert_idf(args.idf, args.output)
    for line in building.data["not_modelled"]:
        print(f"not modelled: {line}")
    print(f"wrote {args.output}: {len(building.zones)} zones, {len(building.components)} components, "
          f"{building.n_nodes} nodes")


def cmd_simulate(args):
    import numpy as np

    from nodeforce.model.case import force_mask
    from nodeforce.iotools.node_temperatures import write_node_names, write_node_temperatures
    if args.force and not args.measurements:
        raise InputError("--force", args.force, "forcing needs --measurements to force nodes to")
    building, case, objective = load_inputs(args)
    force = force_mask(case, node_list("--force", args.force), args.measurements) if args.force else None
    with tempdirs.folder("simulate") as tmp:
        with api.open_fmu(api.write_fmu(building, Path(tmp) / "model.fmu", fmi=args.fmi)) as instance:
            T = api.simulate_fmu(instance, case, force)
    # the weather's history before the first measurement set the start; the output is the record's
    h = case.history_steps
    T, times = T[h:], case.times[h + 1:]
    write_node_temperatures(args.output, times, T)
    names = write_node_names(args.output, building)
    print(f"wrote {args.output}: nodes 1..{T.shape[1]} at {len(T)} times "
          f"({times[0].isoformat()} to {times[-1].isoformat()}, step {case.dt:g} s); node names in {names}")
    measured = objective.measured(case)[h:]
    simulated = T[:, np.array(objective.air_nodes) - 1]
    if np.isfinite(measured).any():
        for zone, m in objective.metrics(measured, simulated)["zones"].items():
            print(f"{zone} air: RMSE {m['rmse']:.3f} C against the measurements ({m['n']} scored steps)")


def cmd_inputs(args):
    if args.force and not args.measurements:
        raise InputError("--force", args.force, "forcing needs --measurements to force nodes to")
    measurements = api.read_measurements(args.measurements) if args.measurements else None
    table, start = api.fmu_inputs(api.read_building(args.building),
                                  api.read_weather(args.weather, year=args.year,
                                                   times=None if measurements is None else measurements.index),
                                  measurements,
                                  node_list("--force", args.force) if args.force else (), args.burn_in_days,
                                  args.decomposition)
    start_path = api.write_fmu_inputs(args.output, table, start)
    print(f"wrote {args.output}: {len(table.columns)} inputs at {len(table)} times (0 to {table.index[-1]:.0f} s); "
          f"start values in {start_path}")


def search_settings(args):
    """locate()'s search settings from the options, checked where they are made (a
    `SearchSettings`, before any work): the default search or, with --paper, the paper's (GA
    settings given explicitly still apply: they default to the paper's anyway)."""
    if args.paper and args.patience is not None:
        raise InputError("--patience", args.patience, "--paper runs every generation; leave out one of the two")
    settings = dict(population=args.population, generations=args.generations, pc=args.pc, pm=args.pm,
                    seed=args.seed, fmu_kind=kind_of(args), noise=noise(args),
                    nodes=node_list("--nodes", args.nodes) if args.nodes else None,
                    include_algebraic=args.include_algebraic)
    if args.paper:
        return ga_search.SearchSettings.paper(**settings)
    return ga_search.SearchSettings(**settings, patience=ga_search.PATIENCE if args.patience is None else args.patience)


def execution(args, **more):
    """Where the work runs, from --workers and --scheduler, checked where it is made."""
    return ga_search.Execution(workers=args.workers, scheduler=args.scheduler, **more)


def cmd_locate(args):
    search, where = search_settings(args), execution(args)
    building, case, objective = load_inputs(args)
    out = Path(args.output)
    result = api.locate(building, case, out, objective, search=search, execution=where, source=args.measurements)
    (out / "locate.json").write_text(json.dumps(result.to_json(), indent=2) + "\n")
    print(result.summary())
    print(f"wrote {out / 'locate.json'}")


def effect_spec(text):
    """("ground_coupling", "floor", {"U": 0.8, "T_ground": 24.0}) from "ground_coupling@floor:U=0.8,T_ground=24"."""
    from nodeforce.model.effects import EFFECTS
    try:
        head, _, assignments = text.partition(":")
        effect, target = head.split("@")
        values = {name: float(value) for name, value in (a.split("=") for a in assignments.split(",") if a)}
    except ValueError:
        raise InputError("--effect", text, "must read EFFECT@TARGET:name=value,... e.g. "
                                           "ground_coupling@floor:U=0.8,T_ground=24") from None
    if effect not in EFFECTS:
        raise InputError("--effect", effect, f"unknown effect; one of {', '.join(EFFECTS)}")
    names = {p.name for p in EFFECTS[effect].parameters}
    if set(values) - names:
        raise InputError("--effect", ",".join(sorted(set(values) - names)), f"{effect} has parameters {', '.join(sorted(names))}")
    return effect, target, values


def cmd_synth(args):
    import pandas as pd
    building = api.read_building(args.building)
    effects = [effect_spec(text) for text in args.effect or ()]  # several faults at once: each applied in turn
    for option, value, ok in (("--days", args.days, args.days >= 1), ("--step", args.step, args.step > 0),
                              ("--noise", args.noise, args.noise >= 0),
                              ("--history-days", args.history_days, args.history_days >= 0)):
        if not ok:
            raise InputError(option, value, "--days must be at least 1 (the warm-up needs a day), --step "
                                            "positive, --noise and --history-days not negative")
    if abs(86400 / args.step - round(86400 / args.step)) > 1e-9:
        raise InputError("--step", args.step, "must divide a day (the warm-up replays whole days)")
    start = iotools_timetable.instant("--start", args.start)
    times = pd.date_range(start, periods=int(args.days * 86400 / args.step) + 1,
                          freq=pd.Timedelta(seconds=args.step), name="time")
    frame = api.synthesize(building, api.read_weather(args.weather, year=args.year, times=times), times, node_list("--sensors", args.sensors),
                           effects=effects, noise=api.SensorNoise(args.noise, args.seed),
                           reading=api.Reading(history_days=args.history_days, decomposition=args.decomposition),
                           source="--effect")
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    frame.round(4).to_csv(args.output, date_format="%Y-%m-%dT%H:%M:%S%z")
    print(f"wrote {args.output}: nodes {args.sensors}, {len(times)} times from {times[0].isoformat()}, "
          f"noise {args.noise} C" + (f", with {' and '.join(args.effect)} not in {args.building}" if args.effect else ""))


def run_diagnosis(building, records, objective, out, args, later=()):
    """The loop on `records` (`api.Record`s) through `api.diagnose`, its summary printed;
    `later`: the records read for the final comparison alone."""
    search = ga_search.SearchSettings(seed=args.seed, fmu_kind=kind_of(args, "search_fmu"), noise=noise(args))
    diagnosis = api.diagnose(building, records, out, objective, search=search,
                             execution=execution(args, fmu_kind=kind_of(args)),
                             beside=api.Beside(read_reference(args.reference) if args.reference else None, later))
    print(diagnosis.summary())
    print(f"wrote {out / 'report.json'}, {out / 'report.md'}, {out / 'building_after.json'}, {out / 'model_after.fmu'}")


def check_fraction(option, fraction):
    if not 0.0 < fraction < 1.0:
        raise InputError(option, fraction, "a fraction between 0 and 1")
    return fraction


# The fields of --record: each a file or a window of one record; those not given take the option
# of the same name.
RECORD_FIELDS = ("name", "building", "weather", "measurements", "calibration-end", "calibration-fraction", "phases",
                 "burn-in-days")
# The fields of --later: a later record is read for the final comparison alone, under the building
# diagnosed and the diagnosis's burn-in, so it has no window, phases or protocol of its own.
LATER_FIELDS = ("name", "weather", "measurements")


def record_fields(text, option="--record", allowed=RECORD_FIELDS):
    """{field: value} of one --record (or `option`, whose fields are `allowed`),
    "weather=W,measurements=M,calibration-end=T,..."."""
    fields = {}
    for part in (p for p in text.split(",") if p.strip()):
        key, equals, value = part.partition("=")
        key = key.strip()
        if not equals or not value.strip():
            raise InputError(option, part, "must read FIELD=VALUE (fields: " + ", ".join(allowed) + ")")
        if key not in allowed:
            raise InputError(option, key, "no such field; the fields are " + ", ".join(allowed))
        if key in fields:
            raise InputError(option, key, f"given twice in {text!r}")
        fields[key] = value.strip()
    for key in ("weather", "measurements"):
        if key not in fields:
            raise InputError(option, key, f"missing in {text!r}: every record names its weather and measurements")
    return fields


def records_of(building, args):
    """The records of a diagnosis (`api.read_record`): each --record, or the one of --weather and
    --measurements with the window options."""
    if not args.record:
        if not (args.weather and args.measurements):
            raise InputError("--weather", args.weather or "", "diagnose needs --weather and --measurements, "
                                                              "or one --record per record")
        fields = {"weather": args.weather, "measurements": args.measurements}
        options = ("--calibration-fraction", "--calibration-end")
    elif args.weather or args.measurements:
        raise InputError("--record", "weather", "give each record's weather and measurements in its --record, "
                                                "not --weather or --measurements beside them")
    else:
        options = ("--record calibration-fraction", "--record calibration-end")
    records = [read_record(building, fields, options, args)
               for fields in ([fields] if not args.record else map(record_fields, args.record))]
    said_assumed(a for r in records for a in r.case.assumptions)
    return records


def later_of(building, args):
    """The later records of --later (`api.read_record` under the building diagnosed, with the
    diagnosis's burn-in), read before any work so that a bad one stops the run at once."""
    later = [api.read_record(building, weather_of(fields["weather"], args), fields["measurements"], name=fields.get("name"),
                             reading=reading(args))
             for fields in (record_fields(text, "--later", LATER_FIELDS) for text in args.later or ())]
    said_assumed(a for r in later for a in r.case.assumptions)
    return later


def read_record(building, fields, options, args):
    """One record of its --record `fields` (a field not given takes the option of its name);
    `options` name the fraction and the end in errors."""
    try:
        burn_in = float(fields.get("burn-in-days", args.burn_in_days))
        fraction = float(fields.get("calibration-fraction", args.calibration_fraction))
    except ValueError:
        text = ",".join(f"{key}={value}" for key, value in fields.items())
        raise InputError("--record", "burn-in-days", f"a number of days, and calibration-fraction a number, "
                                                     f"in {text!r}") from None
    end = fields.get("calibration-end", args.calibration_end)
    # a record run under another protocol (other flows, other blinds) reads the house as written for it
    return api.read_record(fields.get("building", building), weather_of(fields["weather"], args), fields["measurements"],
                           name=fields.get("name"), fraction=check_fraction(options[0], fraction),
                           calibration_end=iotools_timetable.instant(options[1], end) if end else None,
                           phases=fields.get("phases", args.phases), reading=reading(args, burn_in))


def reading(args, burn_in_days=None):
    """How the command makes a record's files its case (`api.Reading`): --burn-in-days (or a
    record's own), --decomposition and --history-days."""
    return api.Reading(args.burn_in_days if burn_in_days is None else burn_in_days, args.decomposition, history(args))


def read_reference(path):
    """Another model's RMSE for the report's scale: {"label": text, "rmse": {phase: K}}."""
    try:
        reference = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(path, "file", "not found") from None
    except json.JSONDecodeError as e:
        raise InputError(path, f"line {e.lineno}", f"not valid JSON ({e.msg})") from None
    rmse = reference.get("rmse") if isinstance(reference, dict) else None
    if not isinstance(rmse, dict) or not all(isinstance(v, (int, float)) and v >= 0 for v in rmse.values()):
        raise InputError(path, "rmse", 'must be {"phase or window": RMSE in K, ...}')
    return {"label": str(reference.get("label", "reference")), "rmse": rmse}


def cmd_diagnose(args):
    building = api.read_building(args.building)
    records = records_of(building, args)
    run_diagnosis(building, records, objective_of(building, args), Path(args.output), args, later_of(building, args))


def cmd_compare(args):
    measurements = api.read_measurements(args.measurements)
    weather = api.read_weather(args.weather, year=args.year, times=measurements.index)
    models = []
    for path in args.buildings:
        building = api.read_building(path)
        case = api.measured_case(building, weather, measurements, args.burn_in_days, args.decomposition,
                                 history(args))
        models.append((path, case.building, case, objective_of(building, args)))
    said_assumed(a for _, _, case, _ in models for a in case.assumptions)
    result = api.compare(models, Path(args.output), api.read_phases(args.phases) if args.phases else (),
                         fmu_kind=args.fmu)
    print(result.summary())
    print("wrote " + ", ".join(str(Path(args.output) / name) for name in ("compare.json", "compare.md", "compare.png")))


def cmd_table(args):
    from nodeforce.iotools.table import column_names, constants, selection
    written = api.convert_table(args.table_file, column_names(args.names, args.table_file), args.origin,
                                selection(args.select), args.output, table=args.table,
                                period=api.Period(args.start, args.end), constant=constants(args.set) if args.set else None)
    print(f"wrote {args.output}: {', '.join(written.columns)} at {len(written)} times "
          f"({written.index[0].isoformat()} to {written.index[-1].isoformat()})")


DEMO_COMMAND = ("nodeforce synth model/data/testcell_miami.json --weather model/data/miami_tmy2.csv "
                "--effect ground_coupling@floor:U=0.8,T_ground=24 --start 2001-06-10T00:00-05:00 --days 14 "
                "--history-days 7 --noise 0.1 --seed 1 -o model/data/demo_measurements.csv")


def cmd_demo(args):
    building = api.read_building(DATA / "testcell_miami.json")
    measurements = DATA / "demo_measurements.csv"
    record = read_record(building, {"weather": DATA / "miami_tmy2.csv", "measurements": measurements},
                         ("--calibration-fraction", "--calibration-end"), args)
    print(f"{building.name}: measurements {measurements.name} carry an effect the building file does "
          f"not declare (made by: {DEMO_COMMAND})")
    run_diagnosis(building, [record], api.objective(building), Path(args.output), args)


def case_arguments(s, measurements_required, output_help, output_default=None):
    """The building, weather and measurements every simulating command reads, and its output."""
    s.add_argument("building")
    s.add_argument("--weather", required=True)
    year_argument(s)
    s.add_argument("--measurements", required=measurements_required)
    s.add_argument("-o", "--output", required=output_default is None, default=output_default, help=output_help)
    decomposition_argument(s)


def year_argument(s):
    s.add_argument("--year", type=int, help="the calendar year an EPW is read in, as EnergyPlus reads any EPW "
                                            "(default: an actual year's own; a typical year's, the measurements' "
                                            f"year, else {iotools_weather.TYPICAL_YEAR})")


def decomposition_argument(s):
    from nodeforce.model.solar import DECOMPOSITIONS
    s.add_argument("--decomposition", choices=DECOMPOSITIONS, default="erbs",
                   help="the pvlib model that splits the global horizontal irradiance into direct and diffuse "
                        "where the weather has ghi alone (default erbs)")


def fmi_argument(s):
    s.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="the FMI version of the FMU (default 2)")


def kind_of(args, option="fmu"):
    """The FMU kind of --fmu (or another `option`) at --fmi (fmu_build.build.fmu_kind); "auto" is
    resolved where the buildings are known (ga.locate.evaluator_kind)."""
    from nodeforce.fmu_build.build import fmu_kind
    return fmu_kind(getattr(args, option), args.fmi)


def diagnosis_arguments(s):
    fmi_argument(s)
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--workers", type=int, help="processes (default: all cores)")
    scheduler_argument(s)
    s.add_argument("--fmu", choices=("python", "standalone"), default="python",
                   help="the FMU kind of the model before and after (model_before.fmu, model_after.fmu)")
    s.add_argument("--search-fmu", choices=("auto", "python", "standalone"), default="auto",
                   help="the FMU kind the forcing search drives (auto: standalone if a C compiler is found "
                        "and it can run the building, else python; the standalone is the faster)")
    s.add_argument("--calibration-fraction", type=float, default=0.6,
                   help="the first part of the record, by time, that calibrates; the rest validates")
    s.add_argument("--calibration-end",
                   help="the last calibration time, ISO 8601 with UTC offset (instead of the fraction)")
    s.add_argument("--reference", help='JSON {"label": ..., "rmse": {"phase": K}}: another model\'s error, '
                                       "shown beside ours in the report for scale")
    s.add_argument("--phases", help="CSV time,phase: the experiment's phases (each from its time to the next); "
                                    "every model is scored on each and a phase made worse is flagged")
    noise_argument(s)
    start_arguments(s, 1.0)


def scheduler_argument(s):
    s.add_argument("--scheduler", help="a Dask scheduler address, tcp://host:port: run on its workers "
                                       "instead of --workers processes")


def start_arguments(s, burn_in):
    """How a record starts: the weather's history before it, then its burn-in."""
    s.add_argument("--burn-in-days", type=float, default=burn_in,
                   help=f"days after the first measurement over which every measured node is forced and nothing "
                        f"is scored (docs/model.md section 5; default {burn_in:g})")
    s.add_argument("--history-days", type=float, default=model_case.HISTORY_DAYS,
                   help=f"days of the weather before the first measurement simulated before it, nothing measured "
                        f"or scored, so that the walls start from the weather's past (docs/model.md section 5; "
                        f"default {model_case.HISTORY_DAYS:g}, as far as the weather and every input reach; 0: none)")


def history(args):
    """The user's --history-days, which must not be negative."""
    if not args.history_days >= 0:
        raise InputError("--history-days", args.history_days, "days of weather before the record, not negative")
    return args.history_days


def noise_argument(s):
    s.add_argument("--noise", type=float, help="sd of the air sensors' error, C (their stated accuracy; "
                                               "default: estimated from the measured air, see the report)")


def noise(args):
    """The user's --noise (C), which must be positive, or None."""
    if args.noise is not None and not args.noise > 0:
        raise InputError("--noise", args.noise, "the sensors' error sd must be positive, in C")
    return args.noise


def objective_argument(s):
    s.add_argument("--objective", help="zones whose measured air J sums, e.g. living,kitchen "
                                       "(default: the first zone of the building file)")


def fmu_command(s):
    s.add_argument("building")
    s.add_argument("-o", "--output", required=True, help="the .fmu to write")
    s.add_argument("--standalone", action="store_true", help="C, no Python at run time (needs a C compiler)")
    fmi_argument(s)
    s.set_defaults(run=cmd_fmu)


def convert_command(s):
    s.add_argument("idf")
    s.add_argument("-o", "--output", required=True, help="the building file (JSON) to write")
    s.set_defaults(run=cmd_convert)


def simulate_command(s):
    case_arguments(s, False, "the CSV of node temperatures to write", output_default="sim.csv")
    s.add_argument("--step", type=float, help="without --measurements, the output's step in seconds, the weather "
                                              "interpolated onto it (default: the weather's own rows)")
    s.add_argument("--force", help="node ids forced to their measurements, e.g. 1,7,9")
    fmi_argument(s)
    start_arguments(s, 0.0)
    objective_argument(s)
    s.set_defaults(run=cmd_simulate)


def inputs_command(s):
    case_arguments(s, False, "the CSV to write (the start values go beside it, <stem>.start.json)")
    s.add_argument("--force", help="node ids forced to their measurements, e.g. 1,7,9")
    s.add_argument("--burn-in-days", type=float, default=0.0,
                   help="days after the first measurement over which every measured node is forced (default 0)")
    s.set_defaults(run=cmd_inputs)


def locate_command(s):
    case_arguments(s, True, "folder for locate.json")
    s.add_argument("--nodes", help="forcing candidates (default: every measured node but the air)")
    s.add_argument("--include-algebraic", action="store_true",
                   help="let the search force algebraic (radiant) nodes too")
    s.add_argument("--population", type=int, default=30)
    s.add_argument("--generations", type=int, default=400)
    s.add_argument("--pc", type=float, default=0.8, help="crossover probability")
    s.add_argument("--pm", type=float, default=0.03, help="mutation probability per gene")
    s.add_argument("--patience", type=int,
                   help=f"stop when the best J has not fallen by more than the noise for this many "
                        f"generations (default {ga_search.PATIENCE})")
    s.add_argument("--paper", action="store_true",
                   help="the paper's search: random initial population, every generation run, no "
                        "convergence criterion (with the paper's 30 x 400, pc 0.8, pm 0.03 unless given)")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--workers", type=int, help="processes (default: all cores)")
    s.add_argument("--fmu", choices=("auto", "python", "standalone"), default="auto",
                   help="the FMU kind to run (auto: standalone if a C compiler is found, else python; "
                        "the standalone is the faster, docs/performance.md)")
    scheduler_argument(s)
    fmi_argument(s)
    noise_argument(s)
    start_arguments(s, 0.0)
    objective_argument(s)
    s.set_defaults(run=cmd_locate)


def diagnose_command(s):
    s.add_argument("building")
    s.add_argument("--weather")
    year_argument(s)
    s.add_argument("--measurements")
    s.add_argument("--record", action="append",
                   help="one record of the building, instead of --weather and --measurements; repeat it for "
                        "several: weather=W,measurements=M[,name=N][,calibration-end=T][,calibration-fraction=F]"
                        "[,phases=P][,burn-in-days=D] (a field not given takes the option of its name)")
    s.add_argument("--later", action="append",
                   help="a later record of the building, read for nothing but the final comparison (no fit, "
                        "no choice, no cross-validation): the building as written and as corrected scored on "
                        "it as by compare, with the diagnosis's burn-in; repeat it for several: "
                        "weather=W,measurements=M[,name=N]")
    s.add_argument("-o", "--output", required=True, help="folder for report.json, report.md, building_after.json")
    decomposition_argument(s)
    diagnosis_arguments(s)
    objective_argument(s)
    s.set_defaults(run=cmd_diagnose)


def compare_command(s):
    s.add_argument("buildings", metavar="BUILDING", nargs="+")
    s.add_argument("--weather", required=True)
    year_argument(s)
    s.add_argument("--measurements", required=True)
    s.add_argument("-o", "--output", required=True, help="folder for compare.json, compare.md and the plot")
    s.add_argument("--phases", help="CSV time,phase: every model is scored on each phase")
    s.add_argument("--fmu", choices=("python", "standalone"), default="python", help="the FMU kind to run")
    decomposition_argument(s)
    start_arguments(s, 1.0)
    objective_argument(s)
    s.set_defaults(run=cmd_compare)


def synth_command(s):
    s.add_argument("building")
    s.add_argument("--weather", required=True)
    year_argument(s)
    s.add_argument("-o", "--output", required=True, help="the measurements CSV to write")
    s.add_argument("--start", required=True, help="first time, ISO 8601 with UTC offset")
    s.add_argument("--days", type=float, default=14.0)
    s.add_argument("--step", type=float, default=900.0, help="s")
    s.add_argument("--sensors", default="1,7,9,16,17,23", help="measured node ids")
    s.add_argument("--noise", type=float, default=0.1, help="sensor noise sd, C")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--history-days", type=float, default=7.0,
                   help="days of real weather simulated before the record")
    s.add_argument("--effect", action="append",
                   help="EFFECT@TARGET:name=value,... added to the building, e.g. "
                        "ground_coupling@floor:U=0.8,T_ground=24; repeat it for several at once")
    decomposition_argument(s)
    s.set_defaults(run=cmd_synth)


def table_command(s):
    s.add_argument("table_file", metavar="TABLE")
    s.add_argument("--names", required=True, help="the table's column names, time first: a,b,c or a CSV "
                                                  "file with a 'name' column (and optionally 'column_1based')")
    s.add_argument("--origin", required=True, help="the time of 0 s, ISO 8601 with UTC offset")
    s.add_argument("--select", required=True, help="OUT=IN,... (IN a name of --names, OUT the name written) "
                                                   "or @FILE with one OUT=IN a line")
    s.add_argument("-o", "--output", required=True, help="the CSV to write")
    s.add_argument("--table", help="the table's name, when the file holds several")
    s.add_argument("--start", help="first time kept, ISO 8601 with UTC offset (inclusive)")
    s.add_argument("--end", help="last time kept, ISO 8601 with UTC offset (inclusive)")
    s.add_argument("--set", help="NAME=VALUE,...: constant columns the user states, e.g. shading_south=0")
    s.set_defaults(run=cmd_table)


def demo_command(s):
    s.add_argument("-o", "--output", default="out/demo")
    diagnosis_arguments(s)
    s.set_defaults(run=cmd_demo, decomposition="erbs")


# Each command: its help, and what adds its arguments (the parser of the command run is the only
# one built whole, so that a command loads only the modules its own defaults come from).
COMMANDS = {
    "fmu": ("build the FMU of a building file", fmu_command),
    "convert": ("an EnergyPlus model (IDF) as a building file", convert_command),
    "simulate": ("simulate a building through its FMU", simulate_command),
    "inputs": ("the FMU's input table of a record and its start values, for another tool", inputs_command),
    "locate": ("search the forcing that best explains the measured air", locate_command),
    "diagnose": ("localise, add the missing effect, calibrate, report before/after", diagnose_command),
    "compare": ("building files run on one record none was fitted on: RMSE, mean, sd, per phase, heat loss coefficient",
               compare_command),
    "synth": ("measurements of a building, optionally with an effect its file does not declare", synth_command),
    "table": ("columns of a Modelica CombiTimeTable text file as a weather or measurements CSV", table_command),
    "demo": ("diagnose the bundled test cell, whose measurements carry an undeclared effect", demo_command),
}


def parser(command=None):
    """The command line's parser: every command's name and help, and the arguments of `command`
    (None: of none, for the list of commands)."""
    p = Parser(prog="nodeforce", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for name, (help_text, arguments) in COMMANDS.items():
        s = sub.add_parser(name, help=help_text)
        if command == name:
            arguments(s)
    return p


def main(argv=None):
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    command = next((a for a in argv if not a.startswith("-")), None)  # the first word that is no option
    args = parser(command).parse_args(argv)
    signals = lifetime.Signals()
    try:
        with lifetime.stop_on_signals() as signals:
            tempdirs.sweep()  # the folders of runs killed outright
            args.run(args)
    except InputError as e:
        print(f"nodeforce: {e}", file=sys.stderr)
        return 2
    except BaseException as e:
        stop = lifetime.stopped(e, signals)  # a signal or a lost cluster: one line, its own exit status
        if stop is None:
            raise
        status, why = stop
        searched = args.command in ("locate", "diagnose", "demo")
        print(f"nodeforce: {why}; " + (ga_checkpoint.resume_hint(Path(args.output) / ga_checkpoint.NAME) if searched else
                                       "run the same command again"), file=sys.stderr)
        return status
    return 0


if __name__ == "__main__":
    sys.exit(main())
