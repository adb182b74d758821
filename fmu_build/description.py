"""The model description (modelDescription.xml) both FMUs of a building carry, and their FMU files.

The Python and the standalone FMU of one building declare the same variables (`variables.Layout`)
with their units, the same model structure and default experiment; they differ in the model
identifier, whether an execution tool (Python) is needed, and the source files. The GUID is a
hash of everything the FMU carries, so the same model gives the same FMU, byte for byte.
"""
import hashlib
import math
import zipfile
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, metadata
from xml.etree.ElementTree import Element, SubElement, indent, tostring

from nodeforce.model.building import Boundary
from nodeforce.model.effects import EFFECTS, fmu_parameters, properties
from nodeforce.model.integrate import MAX_STEP, held_inputs
from nodeforce.model.network import WIND_DIRECTION, WIND_SPEED, clock_input_names, workday_input

from .guard import GUARD_GLIBC, PYTHONFMU_GLIBC


DEFAULT_STEP = 900.0  # s, the step of the bundled data when a building declares none
# s: an importer's default run (DefaultExperiment) is a day at that step, long enough for the
# building to move and short enough for a first try; without stopTime every importer ran 1 s
DEFAULT_SPAN = 86400.0
# FMI 2.0 units: name -> (quantity, SI base-unit exponents and factor/offset to SI)
UNITS = {
    "degC": ("ThermodynamicTemperature", {"K": "1", "offset": "273.15"}),
    "K": ("ThermodynamicTemperature", {"K": "1"}),
    "W": ("Power", {"kg": "1", "m": "2", "s": "-3"}),
    "W/m2": ("Irradiance", {"kg": "1", "s": "-3"}),
    "W/K": ("ThermalConductance", {"kg": "1", "m": "2", "s": "-3", "K": "-1"}),
    "J/K": ("HeatCapacity", {"kg": "1", "m": "2", "s": "-2", "K": "-1"}),
    "W/m2/K": ("CoefficientOfHeatTransfer", {"kg": "1", "s": "-3", "K": "-1"}),
    "1/h": ("AirChangeRate", {"s": "-1", "factor": str(1 / 3600)}),
    "m3/h": ("VolumeFlowRate", {"m": "3", "s": "-1", "factor": str(1 / 3600)}),
    "s": ("Time", {"s": "1"}),
    "m/s": ("Velocity", {"m": "1", "s": "-1"}),
    "deg": ("Angle", {"rad": "1", "factor": str(math.pi / 180)}),
}
EFFECT_UNITS = {"C": "degC", "-": None}  # effects.Parameter.unit spellings that differ from FMI's
LOG_CATEGORIES = ("logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal", "logAll")
# A fixed time for every zip entry: the same content gives the same bytes.
ZIP_TIME = (1980, 1, 1, 0, 0, 0)


def nodeforce_version():
    try:
        meta = metadata("nodeforce")
    except PackageNotFoundError:  # running from a source tree that is not installed
        return "unknown", None
    return meta.get("Version", "unknown"), meta.get("License")


@dataclass(frozen=True)
class Variable:
    name: str
    causality: str  # parameter, input, output
    type: str  # Real, Boolean
    start: object  # None for a calculated output
    unit: object  # a key of UNITS or None
    description: str
    # An input an importer holds between the samples it is given (zero-order hold), never
    # interpolates: a measurement, whose NaN (not measured) must not leak into its neighbours
    discrete: bool = False
    bounds: tuple = ()  # (min, max) of a parameter an importer may set, or none
    tunable: bool = False  # a parameter that may change between steps


def variables(layout, building, effect=None):
    """The `Variable`s of a model, in value-reference order; effect: (id, target) or None."""
    n = range(1, layout.n_nodes + 1)
    found = [Variable(f"force[{i}]", "parameter", "Boolean", "false", None,
                      f"node {i} is forced to T_forced[{i}] where that is not NaN") for i in n]
    found += [Variable(f"T_start[{i}]", "parameter", "Real", "20", "degC",
                       f"temperature of node {i} at the start (a measured node: its measurement)") for i in n]
    # a zone's heat input is a power held over each step (model.integrate.held_inputs): discrete, as
    # a measurement, so that an importer holds it from one sample to the next, never interpolates it
    held = held_inputs(building, layout.input_names)
    found += [Variable(name, "input", "Real", "0", *_input_meaning(building, name), discrete=bool(h))
              for name, h in zip(layout.input_names, held)]
    found += [Variable(f"T_forced[{i}]", "input", "Real", "NaN", "degC",
                       f"measured temperature of node {i}, NaN if none; held between samples, "
                       "never interpolated", discrete=True) for i in n]
    found += [Variable(f"T[{i}]", "output", "Real", None, "degC", f"temperature of node {i}") for i in n]
    return found + parameter_variables(building, effect) + [
        Variable("max_step", "parameter", "Real", repr(MAX_STEP), "s",
                 "the longest internal step (s): a doStep of h takes ceil(h / max_step) backward-Euler steps, "
                 "the inputs linear within it", tunable=True)]


def parameter_variables(building, effect=None):
    """The `Variable`s of the building's properties and of the effect's parameters
    (`model.effects.fmu_parameters`), with their units and the bounds an importer may set."""
    start = fmu_parameters(building, effect)
    meaning = {}
    for name, p, target in properties(building):
        meaning[name] = (p.parameter.unit, p.bounds(start.get(name, 0.0)),
                         f"{p.name.replace('_', ' ')} of {p.of} {target} (declared: {start.get(name)!r})")
    if effect is not None:
        record = EFFECTS[effect[0]]
        for p, (low, high) in zip(record.parameters, record.bounds(building, effect[1])):
            name = f"{effect[0]}.{p.name}"
            meaning[name] = (p.unit, (min(low, start[name]), max(high, start[name])),
                             f"{effect[0]} of {effect[1]}: {p.name}")
    variables = []
    for name, value in start.items():
        unit, bounds, description = meaning[name]
        variables.append(Variable(name, "parameter", "Real", repr(float(value)), EFFECT_UNITS.get(unit, unit),
                                  description, bounds=tuple(float(b) for b in bounds)))
    return variables


def _input_meaning(building, name):
    """(unit, description) of an input of the network (docs/model.md sections 1 and 4)."""
    if name == "T_out":
        return "degC", "outdoor air temperature"
    if name == "T_sky":
        return "degC", "sky temperature"
    if name == WIND_SPEED:
        return "m/s", "the weather station's wind speed (10 m in open country)"
    if name == WIND_DIRECTION:
        return "deg", "the direction the wind comes from, clockwise from north"
    if name in clock_input_names(building):
        site = f"at the site ({building.site['timezone']})"
        if name == workday_input("mean"):
            return None, f"1 on a working day (Monday to Friday) of the local calendar {site}, else 0"
        workday = name.startswith(workday_input(""))
        term = name.removeprefix(workday_input("") if workday else "day_")
        function, h = term[:3], term[3:]
        return None, (f"{'workday_mean times ' if workday else ''}{function}(2 pi {h} tau / 24 h), tau the local "
                      f"clock time of day (h) {site}, the basis of the zones' {'workday' if workday else 'daily'} gains")
    if name in building.schedule_inputs:
        return None, f"schedule {name} of the building file, on the site's local clock"
    glazings = [(c, k) for c in building.components for k, (sun, _) in enumerate(c.sun_inputs)
                if sun == name and sun != c.irradiance_input]
    if glazings:
        c, k = glazings[0]
        part = "" if len(c.sun_inputs) == 1 else ("diffuse " if k == 1 else "direct ")
        applied = " (its angular transmittance applied)" if c.angular is not None else ""
        # a traced direct sun is one input a face it falls on, and one for what falls on none
        falls = "" if not c.traced_beam or k == 1 else (
            f", the part that falls on {c.traced_beam[k - 2][0]}" if k else ", the part that falls on no traced face")
        return "W/m2", f"{part}sun {c.name} lets in per m2 over its normal-incidence transmittance{applied}{falls}"
    panes = [(c, side) for c in building.exterior_components for sun, side in c.absorbed_inputs if sun == name]
    if panes:
        c, side = panes[0]
        return "W/m2", (f"sun the {'outer' if side == 'outside' else 'inner'} panes of {c.name} absorb per m2 over "
                        "their normal-incidence absorptance (their angular absorptance applied)")
    faces = [c.name for c in building.exterior_components if c.irradiance_input == name]
    if faces:
        return "W/m2", f"solar irradiance on the outside face of {', '.join(faces)}"
    for zone in building.zones:
        if name in zone.heat_input:
            return "W", (f"measured heat input {name} of zone {zone.name}, the mean power over the step from "
                         "the time it is set; held between samples, never interpolated")
        if zone.supply is not None and zone.supply.temperature == name:
            return "degC", f"supply air temperature of zone {zone.name}"
        if name in dict(zone.thermal_bridges):
            return "degC", f"temperature beyond a thermal bridge of zone {zone.name}"
    for c in building.components:
        if isinstance(c.outside, Boundary) and c.outside.temperature == name:
            return "degC", f"boundary temperature {name} beyond {c.name}"
        if c.shading == name:
            return None, f"shading of {c.name}, 0 (closed) to 1 (open)"
    return None, f"measured input column {name}"


def initial_dependencies(layout):
    """{node index (0-based): value references} the initial T of each node depends on: its
    T_start, nothing else (the start values alone set the state)."""
    return {i: [layout.T_start.start + i] for i in range(layout.n_nodes)}


def model_description(layout, building, guid, identifier, name, effect=None, standalone=False,
                      source_files=(), step=DEFAULT_STEP, span=DEFAULT_SPAN, fmi=2, interpolates=True):
    """modelDescription.xml (bytes) of a model.

    Parameters
    ----------
    layout : variables.Layout; building : model.building.Building
    guid : the content hash (`content_guid`); identifier : the model identifier (binary name)
    name : model name; effect : (id, target) of the added effect, or None
    standalone : the FMU needs no Python; source_files : names under sources/ (FMI 2.0)
    step, span : default communication step and stop time (s) of the DefaultExperiment
    fmi : 2 (scalars) or 3 (`force`, `T_forced` and `T` as arrays of N; c/fmi3.c)
    interpolates : the binary takes input derivatives (fmi2SetRealInputDerivatives): every FMU
        but the Python one without its guard (pythonfmu refuses them). FMI 3.0 has no such call.
    """
    version, licence = nodeforce_version()
    header = {"fmiVersion": "2.0", "modelName": name, "guid": guid} if fmi == 2 else \
        {"fmiVersion": "3.0", "modelName": name, "instantiationToken": guid}
    root = Element("fmiModelDescription", {
        **header,
        "description": "Nodal (RC network) building thermal model with a forcing input per node",
        "author": "nodeforce", "version": version,
        "license": f"nodeforce: {licence or 'see the nodeforce distribution'}"
                   + ("" if standalone else "; pythonfmu runtime: MIT"),
        "generationTool": f"nodeforce {version}" + ("" if standalone else " with pythonfmu"),
        "variableNamingConvention": "structured", **({"numberOfEventIndicators": "0"} if fmi == 2 else {})})
    capabilities = {"modelIdentifier": identifier, "needsExecutionTool": "false" if standalone else "true",
                    "canHandleVariableCommunicationStepSize": "true",
                    "canBeInstantiatedOnlyOncePerProcess": "false"}
    if fmi == 2:
        capabilities.update({"canInterpolateInputs": "true" if interpolates else "false",
                             "canNotUseMemoryManagementFunctions": "true",
                             "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true"})
    else:
        capabilities.update({"canGetAndSetFMUState": "true", "canSerializeFMUState": "true",
                             "hasEventMode": "false", "providesIntermediateUpdate": "false"})
    cosim = SubElement(root, "CoSimulation", capabilities)
    if source_files and fmi == 2:
        files = SubElement(cosim, "SourceFiles")
        for file in source_files:
            SubElement(files, "File", {"name": file})
    declared = variables(layout, building, effect)
    units = SubElement(root, "UnitDefinitions")
    for unit in sorted({v.unit for v in declared if v.unit}):
        SubElement(SubElement(units, "Unit", {"name": unit}), "BaseUnit", UNITS[unit][1])
    categories = SubElement(root, "LogCategories")
    for category in LOG_CATEGORIES:
        SubElement(categories, "Category", {"name": category})
    SubElement(root, "DefaultExperiment", {"startTime": "0", "stopTime": repr(float(span)),
                                           "stepSize": repr(float(step))})
    (_variables2 if fmi == 2 else _variables3)(root, declared, building, layout)
    indent(root, "  ")
    return tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def _attributes(v):
    """The attributes of a variable's element that both FMI versions spell alike."""
    attributes = {"name": v.name, "description": v.description, "causality": v.causality}
    if v.causality == "parameter":
        attributes.update(variability="tunable" if v.tunable else "fixed", initial="exact")
    if v.discrete:
        attributes["variability"] = "discrete"
    return attributes


def _typed(v):
    """start, quantity and unit of a variable."""
    typed = {} if v.start is None else {"start": v.start}
    if v.unit:
        typed.update(quantity=UNITS[v.unit][0], unit=v.unit)
    if v.bounds:
        typed.update(min=repr(v.bounds[0]), max=repr(v.bounds[1]))
    return typed


def _variables2(root, declared, building, layout):
    """FMI 2.0 ModelVariables (one ScalarVariable per value, value reference = layout index)
    and ModelStructure."""
    model_variables = SubElement(root, "ModelVariables")
    for vr, v in enumerate(declared):
        attributes = {**_attributes(v), "valueReference": str(vr)}
        if v.causality == "output":
            attributes["initial"] = "calculated"
        SubElement(SubElement(model_variables, "ScalarVariable", attributes), v.type, _typed(v))
    structure = SubElement(root, "ModelStructure")
    outputs = SubElement(structure, "Outputs")
    initial = SubElement(structure, "InitialUnknowns")
    depends = initial_dependencies(layout)
    for node, vr in enumerate(range(layout.T.start, layout.T.stop)):
        # A co-simulation output is the state after doStep: no direct feed-through from inputs.
        SubElement(outputs, "Unknown", {"index": str(vr + 1), "dependencies": ""})
        SubElement(initial, "Unknown", {"index": str(vr + 1),
                                        "dependencies": " ".join(str(d + 1) for d in depends[node])})


ARRAYS = {"force": "node i is forced to T_forced[i] where that is not NaN",
          "T_start": "temperature of node i at the start (a measured node: its measurement)",
          "T_forced": "measured temperature of node i, NaN if none; held between samples, never interpolated",
          "T": "temperature of node i"}
FMI3_TYPES = {"Real": "Float64", "Boolean": "Boolean"}


def _variables3(root, declared, building, layout):
    """FMI 3.0 ModelVariables: time (value reference 0), then the FMI 2.0 variables in their
    order, `force[i]`, `T_start[i]`, `T_forced[i]` and `T[i]` each one array of N (c/fmi3.c); and
    ModelStructure, where T depends initially on T_start alone."""
    model_variables = SubElement(root, "ModelVariables")
    SubElement(model_variables, "Float64", {"name": "time", "valueReference": "0", "causality": "independent",
                                            "variability": "continuous", "description": "simulation time"})
    refs, k = {}, 0
    while k < len(declared):
        v = declared[k]
        array = v.name.split("[")[0] if "[" in v.name else None
        n = layout.n_nodes if array else 1
        vr = refs[array or v.name] = len(refs) + 1
        attributes = {**_attributes(v), "name": array or v.name, "valueReference": str(vr)}
        if array:
            attributes["description"] = ARRAYS[array]
        typed = _typed(v)
        if "start" in typed and array:
            typed["start"] = " ".join(variable.start for variable in declared[k:k + n])
        element = SubElement(model_variables, FMI3_TYPES[v.type], {**attributes, **typed})
        if array:
            SubElement(element, "Dimension", {"start": str(n)})
        k += n
    # FMI 3.0 has no call for input derivatives: each input's is an input of its own, declared
    # as its derivative (c/fmi3.c gives them to the FMI 2.0 instance's fmi2SetRealInputDerivatives)
    discrete = {v.name.split("[")[0] for v in declared if v.causality == "input" and v.discrete}
    for name in list(layout.input_names) + ["T_forced"]:
        array = name == "T_forced"
        attributes = {"name": f"der({name})", "valueReference": str(len(refs) + 1), "causality": "input",
                      "derivative": str(refs[name]), "start": " ".join(["0"] * layout.n_nodes) if array else "0",
                      "description": f"first time derivative (per s) of {name} over the next step, 0 if not set"}
        if name in discrete:
            attributes["variability"] = "discrete"
        refs[f"der({name})"] = len(refs) + 1
        element = SubElement(model_variables, "Float64", attributes)
        if array:
            SubElement(element, "Dimension", {"start": str(layout.n_nodes)})
    structure = SubElement(root, "ModelStructure")
    SubElement(structure, "Output", {"valueReference": str(refs["T"]), "dependencies": ""})
    SubElement(structure, "InitialUnknown", {"valueReference": str(refs["T"]),
                                             "dependencies": f"{refs['T_start']}"})


def build_description(identifier, sources, libraries, defines):
    """sources/buildDescription.xml of an FMI 3.0 source FMU (bytes): one C99 build of the
    model identifier's library from `sources` (in sources/), with `defines` and `libraries`."""
    root = Element("fmiBuildDescription", {"fmiVersion": "3.0"})
    configuration = SubElement(root, "BuildConfiguration", {"modelIdentifier": identifier})
    files = SubElement(configuration, "SourceFileSet", {"language": "C99"})
    for name in sources:
        SubElement(files, "SourceFile", {"name": name})
    for name in defines:
        SubElement(files, "PreprocessorDefinition", {"name": name})
    for name in libraries:
        SubElement(configuration, "Library", {"name": name})
    indent(root, "  ")
    return tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def content_hash(*parts):
    """sha256 (hex) of bytes or str parts."""
    digest = hashlib.sha256()
    for part in parts:
        digest.update(part.encode() if isinstance(part, str) else part)
        digest.update(b"\0")
    return digest.hexdigest()


def content_guid(*parts):
    """A GUID that is a hash of the FMU's content (bytes or str parts)."""
    h = content_hash(*parts)
    return "{" + f"{h[:8]}-{h[8:12]}-{h[12:16]}-{h[16:20]}-{h[20:32]}" + "}"


def write_fmu(destination, files):
    """Write an FMU (zip) of {archive name: bytes} in name order with fixed times: the same
    files give the same bytes."""
    with zipfile.ZipFile(destination, "w", zipfile.ZIP_DEFLATED) as fmu:
        for name in sorted(files):
            info = zipfile.ZipInfo(name, ZIP_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = (0o755 if name.startswith("binaries/") else 0o644) << 16
            fmu.writestr(info, files[name])
    return destination


def documentation(name, standalone, guarded=True, python_minimum="3.10", fmi=2):
    """documentation/index.html: what an importer needs to run this FMU.

    standalone : the C FMU; else the Python FMU, with its guard (guard.py) or, exported without a
    C compiler, without it; fmi : 2 or 3 (the FMI 3.0 interface over the FMI 2.0 one)."""
    if standalone:
        needs = ("<p>This FMU needs no Python: <code>binaries/linux64</code> holds a C library "
                 "that links only the C library (symbols up to glibc 2.14). For another platform compile "
                 "<code>sources/*.c</code> (C99) into a shared library named after the model "
                 "identifier. Calls the FMI 2.0 standard forbids get fmi2Error, the reason logged.</p>")
    elif guarded:
        needs = (f"<p>This FMU runs Python code (pythonfmu): the importing machine needs Python "
                 f"{python_minimum} or newer with numpy. A Python host (FMPy, libcosimpy, ecospy) runs it as "
                 "is. In a process without Python, the FMU's binary (a guard in front of pythonfmu's, "
                 "<code>binaries/linux64/*.pythonfmu.so</code>) loads libpython: the one the environment "
                 "variable <code>NODEFORCE_LIBPYTHON</code> names if it is set, else the first found of "
                 "the exporting machine's (recorded in <code>resources/guard.txt</code>), the one of the "
                 "<code>python3</code> on <code>PATH</code>, the exporting version's through the dynamic "
                 "linker (a system Python), in <code>/usr/local/lib</code> and in "
                 "<code>$CONDA_PREFIX/lib</code>; the logged error names each one tried. numpy must be "
                 "importable there (e.g. on <code>PYTHONPATH</code>). Calls the FMI 2.0 standard forbids "
                 "get fmi2Error, the reason logged. A call in which the model raises (an effect parameter "
                 "it refuses, for example) gets fmi2Error too, not pythonfmu's fmi2Fatal: fmi2Reset then "
                 f"gives a new instance. The guard needs glibc {GUARD_GLIBC}; pythonfmu's Linux binary "
                 f"needs glibc {PYTHONFMU_GLIBC} and the C++ runtime of GCC 12; there "
                 "is no macOS binary, and the win64 one has no guard. Where that is not available, export "
                 "the standalone FMU: <code>nodeforce fmu BUILDING --standalone -o MODEL.fmu</code>.</p>")
    else:
        needs = (f"<p>This FMU runs Python code (pythonfmu) and was exported without a C compiler, so "
                 f"without its guard. The importing process must contain Python {python_minimum} or newer "
                 "with numpy: a Python host (FMPy, libcosimpy, ecospy) already does; a C host must preload "
                 "libpython, e.g. <code>LD_PRELOAD=$(python3 -c 'import sysconfig as s; "
                 "print(s.get_config_var(\"LIBDIR\") + \"/\" + s.get_config_var(\"LDLIBRARY\"))')</code>, "
                 "with numpy on <code>PYTHONPATH</code>. Calls the FMI 2.0 standard forbids are refused "
                 "with the reason logged, but reported as fmi2Discard (doStep) or fmi2Fatal (get/set). "
                 "pythonfmu's binary releases Python objects twice when the model raises and when the "
                 "process ends, which can corrupt the host's memory: do not call an instance again after "
                 f"fmi2Fatal. The Linux binary needs glibc {PYTHONFMU_GLIBC} and the C++ runtime of GCC 12; there is "
                 "no macOS "
                 "binary. Where that is not available, export the standalone FMU: "
                 "<code>nodeforce fmu BUILDING --standalone -o MODEL.fmu</code>.</p>")
    if fmi == 3:  # the same binaries under FMI 3.0's platform name, the same answers in FMI 3.0's words
        needs = (needs.replace("binaries/linux64", "binaries/x86_64-linux").replace("FMI 2.0", "FMI 3.0")
                 .replace("fmi2Error", "fmi3Error").replace("fmi2Reset", "fmi3Reset")
                 .replace(", and the win64 one has no guard", ""))
        needs += ("<p>FMI 3.0: <code>force</code>, <code>T_start</code>, <code>T_forced</code> and <code>T</code> are arrays of N "
                  "(element i is node i), and <code>time</code> is the independent variable; the binary is "
                  "the FMU's FMI 3.0 interface over its FMI 2.0 one (<code>fmi3DoStep</code> is "
                  "<code>fmi2DoStep</code>), so its numbers are the FMI 2.0 FMU's. No event mode.</p>")
    return (f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{name}</title></head><body>\n"
            f"<h1>{name}</h1>\n{needs}\n"
            "<p>Variables: parameters <code>force[i]</code> (node i is forced), <code>T_start[i]</code> "
            "(degC, node i's temperature at the start) and the building's properties "
            "<code>&lt;component&gt;.conductivity_factor</code>, <code>.capacity_factor</code>, "
            "<code>.solar_absorptance</code>, <code>.solar_transmittance</code>, "
            "<code>&lt;zone&gt;.air_change_rate</code> (1/h), <code>.internal_gain</code> (W), "
            "<code>.h_conv_factor</code>, each at the building file's value, within its min and max: set "
            "before initialisation ends, they give the model of the building file edited the same way; "
            "inputs <code>T_out</code>, <code>T_sky</code> (degC), <code>I_&lt;component&gt;</code> "
            "(W/m2), the building's named columns and <code>T_forced[i]</code> (degC, NaN: no "
            "measurement); outputs <code>T[i]</code> (degC). The start values alone set the state at "
            "the start: give a measured node its measurement at t_0 as <code>T_start[i]</code>; no input "
            "applied at t_0 changes it. A Real set that is not finite is refused (Error, the variable and "
            "the time logged), but <code>T_forced</code>'s NaN. The inputs set before "
            "<code>fmi2DoStep(t, h)</code> are those at t; with their first derivatives "
            "(<code>fmi2SetRealInputDerivatives</code>, where <code>canInterpolateInputs</code> is true; "
            "in FMI 3.0 the inputs <code>der(...)</code>) they are linear over the step, else held. "
            "The step takes ceil(h / <code>max_step</code>) backward-Euler steps (<code>max_step</code>, "
            f"a tunable parameter, {MAX_STEP:g} s), each with the inputs at its end. A heat input is "
            "the mean power over the step.</p>\n"
            "<p><code>T_forced[i]</code> and the heat inputs are discrete inputs: an importer that reads an "
            "input file holds each sample until the next one, NaN included, and never interpolates it, so a "
            "gap means \"not measured\" over exactly the steps whose sample is NaN, in every importer. "
            f"The default experiment is a day ({DEFAULT_SPAN:.0f} s) of {DEFAULT_STEP:.0f}-s steps. "
            "Without input derivatives, step at 1 minute: a held input lags by half a step.</p>\n"
            "</body></html>\n").encode()
