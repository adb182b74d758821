"""The standalone FMU (no Python at run time) gives the Python FMU's numbers in a C host, FMPy,
libcosim and ecos; both FMUs declare units, calculated outputs and their dependencies, and
refuse the calls the FMI 2.0 standard forbids with fmi2Error; the Python FMU runs in a C host
(its guard loads libpython), as the README says, without crashing at exit."""
import copy
import os
import shutil
import subprocess
import sysconfig
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from nodeforce.cosim.fmi import content_id
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.building_file import parse_building
from nodeforce.model.effects import EFFECTS
from tests.importers import fmpy_validate, fmutool_check, run_ecos, run_fmpy, run_libcosim
from tests.traced import traced_cell

HOST = Path(__file__).with_name("c_host") / "host.c"
HEADERS = Path(__file__).parents[1] / "fmu_build" / "c"
KINDS = ("python", "standalone")
ERROR = 3  # fmi2Status


def two_zones(data):
    """The test cell with an annex behind a partition: a second zone, heated through a named
    input, with its own exterior wall."""
    data = copy.deepcopy(data)
    data["zones"].append({"name": "annex", "volume": 12.0, "air_node": 24, "radiant_node": 25,
                          "air_change_rate": 0.5, "heat_input": "Q_annex"})
    layers = [["fibre_cement", 0.005], ["polyurethane", 0.06], ["fibre_cement", 0.005]]
    data["components"] += [
        {"name": "partition", "area": 4.0, "tilt": 90.0, "azimuth": 90.0, "layers": layers,
         "nodes": [{"id": 26, "depth": 0.0}, {"id": 27, "depth": 0.035}, {"id": 28, "depth": 0.07}],
         "inside": {"zone": "cell", "h_conv": 3.0, "h_rad": 5.0},
         "outside": {"type": "zone", "zone": "annex", "h_conv": 3.0, "h_rad": 5.0}},
        {"name": "annex_wall", "area": 6.0, "tilt": 90.0, "azimuth": 270.0, "layers": layers,
         "nodes": [{"id": 29, "depth": 0.0}, {"id": 30, "depth": 0.07}],
         "inside": {"zone": "annex", "h_conv": 5.0, "h_rad": 5.0},
         "outside": {"type": "exterior", "h_conv": 16.0, "h_rad": 5.0, "solar_absorptance": 0.6}}]
    return data


def scriptf(data):
    """A building whose zones exchange long-wave radiation face to face (docs/model.md 3.5)."""
    data = copy.deepcopy(data)
    for z in data["zones"]:
        z["longwave"] = "scriptf"
    return data


def shaded(data):
    """The test cell with a blind on its glazing: the transmitted sun is then the product of
    two inputs, the irradiance and the blind's column."""
    data = copy.deepcopy(data)
    glazing = next(c for c in data["components"] if "solar_transmittance" in c)
    glazing["shading"] = "blind"
    return data


@pytest.fixture(scope="module")
def fmus(tmp_path_factory, testcell_data):
    """{(building, kind): FMU path} for the test cell, the two-zone building (its long-wave exchange
    by a radiant node, and by ScriptF), the shaded cell and the cell whose direct sun is traced."""
    folder = tmp_path_factory.mktemp("standalone")
    buildings = {"testcell": testcell_data, "two_zones": two_zones(testcell_data), "shaded": shaded(testcell_data),
                 "two_zones_scriptf": scriptf(two_zones(testcell_data)), "traced": traced_cell(testcell_data)}
    return {(name, kind): build_fmu(parse_building(data), folder / f"{name}_{kind}.fmu", kind=kind)
            for name, data in buildings.items() for kind in KINDS}


def scenario(fmu, n_steps=192, seed=0):
    """Parameters, inputs and outputs of a two-day run: a sinusoidal day, the forced nodes'
    measurements with gaps (NaN), the state at the start (T_start, a measured node's its own)."""
    rng = np.random.default_rng(seed)
    variables = [v for v in read_model_description(str(fmu)).modelVariables if v.causality == "input"]
    n = sum(v.name.startswith("T_forced[") for v in variables)
    t = np.arange(1, n_steps + 1) * 900.0
    day = np.sin(2 * np.pi * t / 86400)
    inputs = {}
    for v in variables:
        if v.name in ("T_out", "T_sky"):
            inputs[v.name] = 24 + 6 * day - (8 if v.name == "T_sky" else 0)
        elif v.unit == "W/m2":  # irradiance
            inputs[v.name] = np.maximum(0, 700 * day)
        elif v.unit == "W":  # a heat input
            inputs[v.name] = 300 * (day > 0)
        elif v.description.startswith("shading of"):  # drawn and opened, not in step with the sun
            inputs[v.name] = 0.5 + 0.5 * np.cos(2 * np.pi * t / 30000)
        elif v.unit == "degC" and not v.name.startswith("T_forced["):  # a boundary or supply temperature
            inputs[v.name] = 21 + 2 * day
    forced = (1, 9, 17) if n == 23 else (1, 9, 27)
    for i in forced:
        measured = 27 + 2 * day + rng.normal(0, 0.1, n_steps)
        measured[rng.random(n_steps) < 0.1] = np.nan
        inputs[f"T_forced[{i}]"] = measured
    parameters = {**{f"T_start[{i}]": 23.0 for i in range(1, n + 1)}, "T_start[23]": 25.5,
                  **{f"force[{i}]": True for i in forced}}
    return parameters, inputs, [f"T[{i}]" for i in range(1, n + 1)], n_steps


def run_c_host(fmu, parameters, inputs, outputs, dt, n_steps, tmp_path, env=None, prefix=(), times=None,
               one_by_one=False):
    """Outputs of `fmu` run by the C host (compiled here with cc) in a process of its own,
    started through `prefix` (a tool such as valgrind) if given.

    inputs : {name: values}, value k set before step k; or, with `times`, an input file (the
    values at those times) the host applies as fmusim does, by each input's variability.
    one_by_one : read each output in a call of its own."""
    compiler = shutil.which("cc") or pytest.fail("the C host test needs a C compiler (cc)")
    host = tmp_path / "host"
    if not host.exists():
        subprocess.run([compiler, "-std=c99", "-D_GNU_SOURCE", f"-I{HEADERS}", "-o", str(host), str(HOST), "-ldl"],
                       check=True)
    md = read_model_description(str(fmu))
    vr = {v.name: v for v in md.modelVariables}
    unzipped = Path(extract(str(fmu), unzipdir=str(tmp_path / "unzipped")))
    lines = [f"{dt!r} {n_steps}", f"parameters {len(parameters)}"]
    lines += [f"{vr[name].valueReference} {'B' if vr[name].type == 'Boolean' else 'R'} {float(value)!r}"
              for name, value in parameters.items()]
    columns = np.column_stack(list(inputs.values())) if inputs else np.empty((n_steps, 0))
    if times is None:
        lines.append("inputs " + " ".join(str(n) for n in [len(inputs)] + [vr[name].valueReference for name in inputs]))
    else:
        kinds = " ".join(f"{vr[name].valueReference} {vr[name].variability[0]}" for name in inputs)
        lines.append(f"table {len(inputs)} {len(times)} {kinds}")
        columns = np.column_stack([times, columns])
    lines.append("outputs " + " ".join(str(n) for n in [len(outputs)] + [vr[name].valueReference for name in outputs]))
    lines += [" ".join(repr(float(x)) for x in row) for row in (columns if times is not None else columns[:n_steps])]
    (tmp_path / "scenario.txt").write_text("\n".join(lines) + "\n")
    library = unzipped / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    done = subprocess.run([*prefix, str(host), str(library), (unzipped / "resources").as_uri(), md.guid,
                           str(tmp_path / "scenario.txt"), *(["one-by-one"] if one_by_one else [])],
                          capture_output=True, text=True, env=env, timeout=600)
    shutil.rmtree(unzipped)
    return done, (np.loadtxt(done.stdout.splitlines(), ndmin=2) if done.returncode == 0 else None)


@pytest.mark.parametrize("building", ["testcell", "two_zones", "shaded", "two_zones_scriptf", "traced"])
def test_standalone_in_a_c_host_equals_the_python_fmu_in_fmpy(fmus, building, tmp_path):
    python_fmu, standalone = fmus[(building, "python")], fmus[(building, "standalone")]
    parameters, inputs, outputs, n_steps = scenario(python_fmu)
    reference = run_fmpy(python_fmu, parameters, inputs, outputs, 900.0, n_steps)
    done, in_c = run_c_host(standalone, parameters, inputs, outputs, 900.0, n_steps, tmp_path)
    assert done.returncode == 0, done.stderr
    assert np.abs(in_c - reference).max() < 1e-9
    # a moving model, forced where measured and free in the gaps
    assert np.ptp(reference[:, 22]) > 1.0
    measured = inputs["T_forced[9]"]
    assert np.array_equal(in_c[np.isfinite(measured), 8], measured[np.isfinite(measured)])
    if building == "traced":  # each face's share of the direct sun is an input of its own
        faces = [name for name in inputs if name.startswith("Itb_window@")]
        assert len(faces) == 4
        dark = run_fmpy(python_fmu, parameters, {**inputs, **{f: 0 * inputs[f] for f in faces}}, outputs, 900.0,
                        n_steps)
        assert np.abs(dark - reference).max() > 0.1
    if building == "shaded":  # the blind matters: the same run without it differs
        unshaded = run_fmpy(fmus[("testcell", "python")], parameters,
                            {name: x for name, x in inputs.items() if name != "blind"}, outputs, 900.0, n_steps)
        assert np.abs(unshaded - reference).max() > 0.1


def test_an_effect_on_a_shaded_glazing_is_carried_by_the_standalone_fmu(fmus, testcell_data, tmp_path):
    """A corrected transmittance scales the product of inputs itself: its coefficient is a term
    of the effect's parameter. Both FMUs at a tau other than the declared one agree."""
    building = parse_building(shaded(testcell_data))
    glazing = next(c.name for c in building.components if c.shading)
    effect = ("solar_transmittance", glazing)
    built = {kind: build_fmu(building, tmp_path / f"{kind}.fmu", effect=effect, kind=kind) for kind in KINDS}
    parameters, inputs, outputs, n_steps = scenario(built["python"], n_steps=96)
    at_declared = run_fmpy(built["python"], parameters, inputs, outputs, 900.0, n_steps)
    parameters["solar_transmittance.tau"] = 0.3
    reference = run_fmpy(built["python"], parameters, inputs, outputs, 900.0, n_steps)
    assert np.abs(reference - at_declared).max() > 0.1  # tau matters
    done, in_c = run_c_host(built["standalone"], parameters, inputs, outputs, 900.0, n_steps, tmp_path)
    assert done.returncode == 0, done.stderr
    assert np.abs(in_c - reference).max() < 1e-9


def test_a_closed_shadings_leak_is_carried_by_both_fmus(testcell_data, tmp_path):
    """shading_transmittance scales the product of inputs and adds a term of the irradiance
    alone: both FMUs at f = 0.4 agree, with each other and with the building declaring it."""
    building = parse_building(shaded(testcell_data))
    effect = ("shading_transmittance", "cell")
    built = {kind: build_fmu(building, tmp_path / f"{kind}.fmu", effect=effect, kind=kind) for kind in KINDS}
    parameters, inputs, outputs, n_steps = scenario(built["python"], n_steps=96)
    at_declared = run_fmpy(built["python"], parameters, inputs, outputs, 900.0, n_steps)
    parameters["shading_transmittance.f"] = 0.4
    reference = run_fmpy(built["python"], parameters, inputs, outputs, 900.0, n_steps)
    assert np.abs(reference - at_declared).max() > 0.1  # the leak matters while the blind is drawn
    declared = build_fmu(EFFECTS["shading_transmittance"].apply(building, "cell", {"f": 0.4}), tmp_path / "f.fmu")
    del parameters["shading_transmittance.f"]
    assert np.abs(run_fmpy(declared, parameters, inputs, outputs, 900.0, n_steps) - reference).max() < 1e-9
    parameters["shading_transmittance.f"] = 0.4
    done, in_c = run_c_host(built["standalone"], parameters, inputs, outputs, 900.0, n_steps, tmp_path)
    assert done.returncode == 0, done.stderr
    assert np.abs(in_c - reference).max() < 1e-9


def with_people(data):
    """The test cell with four people at 120 W whose sensible heat follows its air (docs/model.md
    3.4), at all hours: their declared power and slope the polynomial's line at 24 C (69.5314 W and
    -4.69664 W/K a person, test_energyplus_reading.py)."""
    data = copy.deepcopy(data)
    data["zones"][0]["gains"] = [{"name": "people", "power": 4 * 69.5314, "radiant_fraction": 0.3,
                                  "temperature_slope": 4 * -4.69664, "reference_temperature": 24.0,
                                  "people": {"number": 4, "activity": 120}}]
    return data


def at_outdoor_density(data):
    """The building whose air flows carry heat at the outdoor air's density: the test cell's
    infiltration, none as declared, which its air change rate opens as an FMU parameter."""
    data = copy.deepcopy(data)
    data["site"]["flow_density"] = "outdoor"
    return data


def followed_buildings():
    """{name: (JSON data of the test cell -> building data, the kinds of followed coefficient it
    carries)}: each kind the direct model follows (model/network.py, `Convection`) in one at least."""
    from tests.test_air_flows import controlled_and_windy
    from tests.test_convection import enclosed, followed
    from tests.test_windows import window_data
    return {"tarp_doe2_longwave": (followed, {"inside", "outside", "longwave"}),
            "window_panes_and_gap": (lambda data: window_data(), {"windows", "gaps"}),
            "scriptf_outdoor_density": (lambda data: at_outdoor_density(enclosed(data)), {"pairs", "flows"}),
            "people": (with_people, {"people"}),
            "flows_with_controls_and_wind": (controlled_and_windy, {"flows"})}


@pytest.mark.parametrize("fmi", (2, 3))
@pytest.mark.parametrize("name", list(followed_buildings()))
def test_the_standalone_fmu_steps_followed_coefficients_as_the_direct_model(testcell_data, tmp_path, name, fmi):
    """Two days of random inputs (the wind round the compass, the sky 10 K below the air) through
    the standalone FMU, at the declared parameters and with every property moved (a zone's
    convection factor scales its faces' A phi, a conductivity factor a gap's A f): the direct
    model of the building edited alike, to 1e-9 K. The followed terms matter: the direct model
    without them is 0.01 K away at least."""
    from dataclasses import replace

    from nodeforce.cosim.fmi import FmuInstance
    from nodeforce.fmu_build.build import fmu_kind
    from nodeforce.model.effects import properties, with_fmu_parameters
    from nodeforce.model.integrate import simulate
    from nodeforce.model.network import WIND_DIRECTION, assemble
    from tests.test_fmu_parameters import run
    declare, kinds = followed_buildings()[name]
    building = parse_building(declare(testcell_data))
    network = assemble(building)
    assert {kind for kind in kinds if len(getattr(network.convection, kind))} == kinds
    rng = np.random.default_rng(5)
    U = rng.uniform(0.0, 20.0, (2 * 96 + 1, len(network.input_names)))
    columns = list(network.input_names)
    if "T_sky" in columns:
        U[:, columns.index("T_sky")] = U[:, columns.index("T_out")] - 10.0
    if WIND_DIRECTION in columns:
        U[:, columns.index(WIND_DIRECTION)] = rng.uniform(0.0, 360.0, len(U))
    moved = {}
    for parameter, p, target in properties(building):
        low, high = p.bounds(p.read(building, target))
        moved[parameter] = float(rng.uniform(-100.0, 100.0) if p.parameter.unit == "W"
                                 else rng.uniform(max(low, 0.5), min(high, 2.0)))
    fmu = build_fmu(building, tmp_path / f"{name}.fmu", kind=fmu_kind("standalone", fmi))
    with FmuInstance(fmu) as instance:
        for values in ({}, moved):
            edited = with_fmu_parameters(building, None, values)
            edited_network = assemble(edited)
            expected = simulate(edited, edited_network, U, 900.0, warmup_days=0)
            held = simulate(edited, replace(edited_network, convection=None), U, 900.0, warmup_days=0)
            assert np.abs(held - expected).max() > 0.01
            assert np.abs(run(instance, building, U, values) - expected).max() < 1e-9


def test_auto_picks_the_standalone_fmu_for_coefficients_that_follow_the_state(testcell_data):
    """The search's "auto" runs the FMU that steps a building fastest, the standalone, where the
    coefficients follow the state too (where a compiler is at hand to export it)."""
    from nodeforce.ga.locate import evaluator_kind
    from nodeforce.runtime.compiler import find_compiler
    buildings = [parse_building(declare(testcell_data)) for declare, _ in followed_buildings().values()]
    assert all(b.followed_coefficients and not b.switched for b in buildings)
    expected = "standalone" if find_compiler() else "python"
    assert evaluator_kind("auto", buildings) == expected
    assert evaluator_kind("auto-fmi3", buildings) == expected + "-fmi3"


@pytest.mark.slow  # two FMUs of 281 nodes
def test_standalone_equals_the_python_fmu_on_the_twin_house(tmp_path, twinhouse):
    """The Twin House's south glazings have blinds (shading_south) and its coefficients follow
    the state: both FMUs, a day."""
    building = twinhouse
    python_fmu, standalone = (build_fmu(building, tmp_path / f"{kind}.fmu", kind=kind) for kind in KINDS)
    parameters, inputs, outputs, n_steps = scenario(python_fmu, n_steps=96)
    assert "shading_south" in inputs
    reference = run_fmpy(python_fmu, parameters, inputs, outputs, 900.0, n_steps)
    done, in_c = run_c_host(standalone, parameters, inputs, outputs, 900.0, n_steps, tmp_path)
    assert done.returncode == 0, done.stderr
    assert np.abs(in_c - reference).max() < 1e-9
    assert np.ptp(reference).max() > 1.0


def test_the_standalone_binary_needs_no_python(fmus, tmp_path):
    with zipfile.ZipFile(fmus[("testcell", "standalone")]) as fmu:
        library = tmp_path / "lib.so"
        library.write_bytes(fmu.read("binaries/linux64/nodeforce_standalone.so"))
        assert "sources/nodeforce_fmu.c" in fmu.namelist()
    needed = subprocess.run(["ldd", str(library)], capture_output=True, text=True).stdout
    assert "python" not in needed and "stdc++" not in needed


@pytest.mark.parametrize("kind", ["standalone", "standalone-fmi3", "python"])
def test_an_export_compiles_its_c_library_once_per_process(testcell_data, tmp_path, monkeypatch, kind):
    # the building is the FMU's data: another building's FMU carries the same binary, copied
    first = build_fmu(parse_building(testcell_data), tmp_path / "first.fmu", kind=kind)
    other = copy.deepcopy(testcell_data)
    other["zones"][0]["internal_gain"] = 10.0

    def no_compiler(command, **_):
        raise AssertionError(f"compiled again: {command}")
    monkeypatch.setattr(subprocess, "run", no_compiler)
    second = build_fmu(parse_building(other), tmp_path / "second.fmu", kind=kind)
    with zipfile.ZipFile(first) as a, zipfile.ZipFile(second) as b:
        binaries = [name for name in a.namelist() if name.startswith("binaries/") and name.endswith(".so")]
        assert binaries and all(a.read(name) == b.read(name) for name in binaries)
        assert a.read("modelDescription.xml") != b.read("modelDescription.xml")


@pytest.mark.parametrize("kind", KINDS)
def test_checkers_and_importers_agree(fmus, kind):
    fmu = fmus[("testcell", kind)]
    assert fmpy_validate(fmu) == []
    ok, output = fmutool_check(fmu)
    assert ok, output
    parameters, inputs, outputs, _ = scenario(fmu)
    reference = run_fmpy(fmus[("testcell", "python")], parameters, inputs, outputs, 900.0, 96)
    for runner in (run_fmpy, run_libcosim, run_ecos):
        assert np.abs(runner(fmu, parameters, inputs, outputs, 900.0, 96) - reference).max() < 1e-9


@pytest.mark.parametrize("kind", KINDS)
def test_model_description_declares_units_initial_and_dependencies(fmus, kind):
    with zipfile.ZipFile(fmus[("two_zones", kind)]) as fmu:
        root = ElementTree.fromstring(fmu.read("modelDescription.xml"))
        assert "documentation/index.html" in fmu.namelist()
    units = {u.get("name"): u.find("BaseUnit").attrib for u in root.iter("Unit")}
    assert units["degC"] == {"K": "1", "offset": "273.15"}
    variables = root.find("ModelVariables").findall("ScalarVariable")
    by_name = {v.get("name"): (index, v) for index, v in enumerate(variables, start=1)}
    unit = lambda name: by_name[name][1][0].get("unit")
    assert [unit(n) for n in ("T[1]", "T_out", "I_roof", "Q_annex", "T_forced[3]", "T_start[3]")] == \
        ["degC", "degC", "W/m2", "W", "degC", "degC"]
    assert float(root.find("DefaultExperiment").get("stepSize")) == 900.0
    assert root.get("version") and root.get("license")
    outputs = [v for v in variables if v.get("causality") == "output"]
    assert len(outputs) == 30 and all(v.get("initial") == "calculated" and v[0].get("start") is None for v in outputs)
    structure = root.find("ModelStructure")
    assert all(u.get("dependencies") == "" for u in structure.find("Outputs"))
    initial = {int(u.get("index")): {int(d) for d in u.get("dependencies").split()}
               for u in structure.find("InitialUnknowns")}
    index = lambda name: by_name[name][0]
    # the start values alone set the state: node i's T_start, no input an importer applies at t_0
    assert initial == {index(f"T[{i}]"): {index(f"T_start[{i}]")} for i in range(1, 31)}


@pytest.mark.parametrize("kind", KINDS)
def test_same_model_same_bytes_and_the_guid_is_its_identity(fmus, testcell_data, tmp_path, kind):
    again = build_fmu(parse_building(testcell_data), tmp_path / "again.fmu", kind=kind)
    assert again.read_bytes() == fmus[("testcell", kind)].read_bytes()
    other = copy.deepcopy(testcell_data)
    other["zones"][0]["internal_gain"] = 10.0
    assert content_id(build_fmu(parse_building(other), tmp_path / "other.fmu", kind=kind)) != content_id(again)


def slave_of(fmu, tmp_path, initialise=True):
    md = read_model_description(str(fmu))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu), unzipdir=str(tmp_path / "u")),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="calls")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    if initialise:
        slave.enterInitializationMode()
        slave.exitInitializationMode()
    return slave, {v.name: v.valueReference for v in md.modelVariables}


def status(call, *args):
    """The fmi2Status of a call through FMPy (which raises on any status above warning)."""
    try:
        call(*args)
    except FMICallException as e:
        return e.status
    return 0


@pytest.mark.parametrize("kind", KINDS)
def test_forbidden_calls_get_fmi2_error_and_change_nothing(fmus, tmp_path, kind):
    """Both FMUs (the Python one through its guard) answer what the standard forbids with
    fmi2Error (not pythonfmu's fmi2Discard or fmi2Fatal), and the state stays as it was."""
    slave, vr = slave_of(fmus[("testcell", kind)], tmp_path)
    outputs = [vr[f"T[{i}]"] for i in range(1, 24)]
    before = slave.getReal(outputs)
    assert status(slave.doStep, 0.0, 0.0) == ERROR
    assert status(slave.doStep, 0.0, -900.0) == ERROR
    assert status(slave.setReal, [vr["T[23]"]], [99.0]) == ERROR  # an output
    assert status(slave.setReal, [vr["T_start[3]"]], [99.0]) == ERROR  # fixed, after initialisation
    assert status(slave.setBoolean, [vr["force[9]"]], [True]) == ERROR
    assert status(slave.getReal, [vr["force[9]"]]) == ERROR  # a Boolean
    assert status(slave.getBoolean, [vr["T_start[3]"]]) == ERROR  # a Real
    assert status(slave.getReal, [10 ** 6]) == ERROR
    assert status(slave.getInteger, [0]) == ERROR  # no Integer variables
    # nothing refused changed anything, and the slave steps on
    assert slave.getReal(outputs) == before
    assert slave.getBoolean([vr["force[9]"]]) == [False]
    slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=900.0)
    after = slave.getReal(outputs)
    assert np.isfinite(after).all() and after != before
    slave.terminate()
    slave.freeInstance()


def test_the_guard_keeps_the_slave_state_across_fmu_states(fmus, tmp_path):
    """The guard's own state travels with an FMU state: restored to initialisation, a fixed
    parameter may be set again; serialised and read back, the state gives the same step."""
    slave, vr = slave_of(fmus[("testcell", "python")], tmp_path, initialise=False)
    slave.enterInitializationMode()
    during = slave.getFMUstate()
    slave.exitInitializationMode()
    assert status(slave.setReal, [vr["T_start[3]"]], [25.0]) == ERROR
    slave.setFMUstate(during)
    slave.setReal([vr["T_start[3]"]], [25.0])  # allowed again
    slave.exitInitializationMode()
    stepping = slave.getFMUstate()
    restored = slave.deSerializeFMUstate(slave.serializeFMUstate(stepping))
    slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=900.0)
    once = slave.getReal([vr["T[23]"]])
    slave.setFMUstate(restored)
    slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=900.0)
    assert slave.getReal([vr["T[23]"]]) == once
    for state in (during, stepping, restored):
        slave.freeFMUstate(state)
    slave.terminate()
    slave.freeInstance()


def python_host_environment():
    """A C host's environment for the Python FMU: numpy importable; no LD_PRELOAD, the guard
    loads libpython itself."""
    env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    return dict(env, PYTHONPATH=sysconfig.get_paths()["purelib"])


@pytest.mark.slow  # processes, a cluster or a whole diagnosis: not in `make check`
def test_python_fmu_in_a_c_host_runs_twenty_times_without_a_crash_at_exit(fmus, tmp_path):
    fmu = fmus[("testcell", "python")]
    parameters, inputs, outputs, _ = scenario(fmu)
    reference = run_fmpy(fmu, parameters, inputs, outputs, 900.0, 24)
    env = python_host_environment()
    for run in range(20):
        done, T = run_c_host(fmu, parameters, inputs, outputs, 900.0, 24, tmp_path, env=env)
        assert done.returncode == 0 and "corrupted" not in done.stderr and "free()" not in done.stderr, \
            f"run {run}: exit {done.returncode}\n{done.stderr}"
        assert np.abs(T - reference).max() < 1e-9


def test_a_c_host_without_libpython_gets_one_logged_line(fmus, tmp_path):
    fmu = fmus[("testcell", "python")]
    parameters, inputs, outputs, _ = scenario(fmu)
    env = dict(python_host_environment(), NODEFORCE_LIBPYTHON=str(tmp_path / "libpython-missing.so"))
    done, _ = run_c_host(fmu, parameters, inputs, outputs, 900.0, 2, tmp_path, env=env)
    assert done.returncode == 1
    logged = [line for line in done.stderr.splitlines() if "libpython" in line]
    assert len(logged) == 1 and "NODEFORCE_LIBPYTHON" in logged[0] and "libpython-missing.so" in logged[0]
