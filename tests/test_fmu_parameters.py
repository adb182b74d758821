"""The building's properties as FMU parameters (what another tool calibrates), in all four FMU
kinds, against the building file edited by hand; non-finite inputs refused; the state at the
start set by the start values alone; the FMI 3.0 source FMU built from its buildDescription.xml;
RPATH $ORIGIN on the binaries."""
import re
import shutil
import subprocess
import zipfile
from xml.etree import ElementTree

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.effects import fmu_parameters
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble

KINDS = ("python", "standalone", "python-fmi3", "standalone-fmi3")
N_ROWS = 2 * 96 + 1


def _component(data, name):
    return next(c for c in data["components"] if c["name"] == name)


# One value of each property kind and the same change written into the building file by hand
# (its JSON fields, as a user would edit them).
EDITS = {
    "door.conductivity_factor": (3.4, lambda d: _component(d, "door").update(conductivity_factor=3.4)),
    "floor.capacity_factor": (0.3, lambda d: _component(d, "floor").update(capacity_factor=0.3)),
    "south_wall.solar_absorptance": (0.95, lambda d: _component(d, "south_wall")["outside"].update(
        solar_absorptance=0.95)),
    "window.solar_transmittance": (0.35, lambda d: _component(d, "window").update(solar_transmittance=0.35)),
    "cell.air_change_rate": (2.5, lambda d: d["zones"][0].update(air_change_rate=2.5)),
    "cell.internal_gain": (180.0, lambda d: d["zones"][0].update(internal_gain=180.0)),
    "cell.h_conv_factor": (1.8, lambda d: d["zones"][0].update(convection_factor=1.8)),
}


@pytest.fixture(scope="module")
def fmus(tmp_path_factory, testcell):
    folder = tmp_path_factory.mktemp("parameters")
    return {kind: build_fmu(testcell, folder / f"{kind}.fmu", kind=kind) for kind in KINDS}


@pytest.fixture(scope="session")
def two_days(testcell, real_case):
    """Two days of the real case's inputs, the sun included (the absorptance and the
    transmittance act through it)."""
    return real_case.U[:N_ROWS]


def run(instance, building, U, parameters):
    """Node temperatures at t_1..t_N from T_start = 20 C: before the step from t_k the inputs of row
    k and their slope to row k+1, one backward-Euler step per row (max_step of the row's 900 s)."""
    names = [f"T[{i}]" for i in range(1, building.n_nodes + 1)]
    return instance.run(900.0, {**parameters, "max_step": 900.0}, {}, list(assemble(building).input_names), U[:-1],
                        names, slopes=np.diff(U, axis=0) / 900.0)


def test_every_property_is_a_fixed_parameter_with_unit_and_bounds_the_same_in_fmi2_and_fmi3(fmus, testcell):
    declared = {}
    for kind in ("python", "python-fmi3"):
        with zipfile.ZipFile(fmus[kind]) as archive:
            root = ElementTree.fromstring(archive.read("modelDescription.xml"))
        variables = root.find("ModelVariables")
        declared[kind] = {v.get("name"): (v if kind.endswith("fmi3") else v[0], v) for v in variables}
    start = fmu_parameters(testcell)
    assert set(EDITS) <= set(start)
    assert start["door.conductivity_factor"] == 1.0 and start["window.solar_transmittance"] == 0.8
    for name in start:
        typed2, element2 = declared["python"][name]
        typed3, element3 = declared["python-fmi3"][name]
        for element in (element2, element3):
            assert (element.get("causality"), element.get("variability")) == ("parameter", "fixed")
        for typed in (typed2, typed3):
            assert float(typed.get("min")) <= float(typed.get("start")) == start[name] <= float(typed.get("max"))
        assert {k: typed2.get(k) for k in ("start", "min", "max", "unit")} == \
            {k: typed3.get(k) for k in ("start", "min", "max", "unit")}
    assert declared["python"]["cell.air_change_rate"][0].get("unit") == "1/h"
    assert declared["python"]["cell.internal_gain"][0].get("unit") == "W"
    # an adiabatic face has no outside sun, an opaque one no transmittance
    assert "floor.solar_absorptance" not in start and "door.solar_transmittance" not in start


@pytest.mark.parametrize("kind", KINDS)
def test_each_property_set_gives_the_building_file_edited_the_same_way(fmus, testcell, two_days, kind):
    declared = simulate(testcell, assemble(testcell), two_days, 900.0, warmup_days=0)
    with FmuInstance(fmus[kind]) as instance:
        assert np.abs(run(instance, testcell, two_days, {}) - declared).max() < 1e-9
        for name, (value, change) in EDITS.items():
            by_hand = testcell.edited(change)
            expected = simulate(by_hand, assemble(by_hand), two_days, 900.0, warmup_days=0)
            T = run(instance, testcell, two_days, {name: value})
            assert np.abs(T - expected).max() < 1e-9, name
            assert np.abs(expected - declared).max() > 0.01, name  # the property does act
        # all at once: the properties of a component and of its zone act on the same entries
        every = testcell
        for _, change in EDITS.values():
            every = every.edited(change)
        T = run(instance, testcell, two_days, {name: value for name, (value, _) in EDITS.items()})
        assert np.abs(T - simulate(every, assemble(every), two_days, 900.0, warmup_days=0)).max() < 1e-9


@pytest.mark.parametrize("kind", ("python", "standalone"))
def test_a_property_under_an_effect_that_scales_it_too(testcell, two_days, tmp_path, kind):
    """The envelope factor multiplies the door's conductances with its conductivity factor (a
    term of both in the standalone FMU); the conductivity effect on the door sets the door's
    factor itself, which the FMU then declares once, as the effect's."""
    fmu = build_fmu(testcell, tmp_path / "envelope.fmu", effect=("envelope_conductance", "cell"), kind=kind)
    by_hand = testcell.edited(lambda d: (d["zones"][0].update(envelope_factor=1.6),
                                          _component(d, "door").update(conductivity_factor=2.5)))
    with FmuInstance(fmu) as instance:
        T = run(instance, testcell, two_days, {"envelope_conductance.factor": 1.6, "door.conductivity_factor": 2.5})
    assert np.abs(T - simulate(by_hand, assemble(by_hand), two_days, 900.0, warmup_days=0)).max() < 1e-9
    names = {v.name for v in read_model_description(str(build_fmu(
        testcell, tmp_path / "conductivity.fmu", effect=("conductivity", "door"), kind=kind))).modelVariables}
    assert "conductivity.factor" in names and "door.conductivity_factor" not in names
    assert "roof.conductivity_factor" in names


def slave(fmu, tmp_path):
    """(FMPy slave, {name: value reference}, FMI 3.0) of an FMU, instantiated."""
    md = read_model_description(str(fmu))
    cls = FMU3Slave if md.fmiVersion == "3.0" else FMU2Slave
    s = cls(guid=md.guid, unzipDirectory=extract(str(fmu), unzipdir=str(tmp_path / "u")),
            modelIdentifier=md.coSimulation.modelIdentifier, instanceName="check")
    s.instantiate()
    return s, {v.name: v.valueReference for v in md.modelVariables}, md.fmiVersion == "3.0"


def set_reals(s, fmi3, refs, values):
    (s.setFloat64 if fmi3 else s.setReal)(refs, values)


def initialise(s, fmi3):
    if fmi3:
        s.enterInitializationMode(startTime=0.0)
    else:
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()


@pytest.mark.parametrize("kind", KINDS)
def test_a_non_finite_weather_sample_is_an_error_named_and_timed(fmus, tmp_path, capfd, kind):
    s, vr, fmi3 = slave(fmus[kind], tmp_path)
    initialise(s, fmi3)
    s.exitInitializationMode()
    s.doStep(0.0, 900.0)
    get = (lambda refs: s.getFloat64(refs, 23)) if fmi3 else s.getReal
    T_ref = vr["T"] if fmi3 else vr["T[23]"]
    before = get([T_ref])
    capfd.readouterr()
    with pytest.raises(FMICallException) as refused:
        set_reals(s, fmi3, [vr["T_out"]], [float("nan")])
    assert refused.value.status == 3  # fmi2Error, fmi3Error
    logged = capfd.readouterr().out
    assert "T_out" in logged and "t = 900 s" in logged and f"value reference {vr['T_out']} " in logged
    with pytest.raises(FMICallException):
        set_reals(s, fmi3, [vr["T_sky"]], [float("inf")])
    # nothing changed: the state steps on, finite
    assert get([T_ref]) == before
    s.doStep(900.0, 900.0)
    assert np.isfinite(get([T_ref])).all()
    # NaN keeps its one meaning on a measurement: "not measured"
    if fmi3:
        set_reals(s, fmi3, [vr["T_forced"]], [float("nan")] * 23)
    else:
        set_reals(s, fmi3, [vr["T_forced[9]"]], [float("nan")])
    s.terminate()
    s.freeInstance()


@pytest.mark.parametrize("kind", ("python", "standalone"))
def test_input_derivatives_are_taken_for_inputs_only_first_order_and_finite(fmus, tmp_path, capfd, kind):
    """fmi2SetRealInputDerivatives (canInterpolateInputs="true"): order 1 of an input or of
    T_forced, finite; anything else is refused (fmi2Error) with the reason logged."""
    assert read_model_description(str(fmus[kind])).coSimulation.canInterpolateInputs
    s, vr, _ = slave(fmus[kind], tmp_path)
    initialise(s, False)
    s.exitInitializationMode()
    for refs, order, value, says in (([vr["T[23]"]], [1], [0.1], "is an output"),
                                     ([vr["max_step"]], [1], [0.1], "is not an input"),
                                     ([vr["T_out"]], [2], [0.1], "order 2"),
                                     ([vr["T_forced[9]"]], [1], [float("nan")], "only a finite first derivative")):
        capfd.readouterr()
        with pytest.raises(FMICallException) as refused:
            s.setRealInputDerivatives(refs, order, value)
        assert refused.value.status == 3
        assert says in capfd.readouterr().out
    s.setRealInputDerivatives([vr["T_out"], vr["T_forced[9]"]], [1, 1], [0.01, 0.0])
    s.doStep(0.0, 900.0)
    s.terminate()
    s.freeInstance()


@pytest.mark.parametrize("kind", ("python-fmi3", "standalone-fmi3"))
def test_fmi3_messages_quote_fmi3_value_references(fmus, tmp_path, capfd, kind):
    s, vr, _ = slave(fmus[kind], tmp_path)
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    capfd.readouterr()
    with pytest.raises(FMICallException):
        s.setFloat64([vr["T"]], [30.0] * 23)
    logged = capfd.readouterr().out
    assert f"value reference {vr['T']} (T, element 1) is an output" in logged
    fmi2 = {v.name: v.valueReference for v in read_model_description(str(fmus[kind.split("-")[0]])).modelVariables}
    assert f"value reference {fmi2['T[1]']} " not in logged
    s.terminate()
    s.freeInstance()


@pytest.mark.parametrize("kind", KINDS)
def test_the_start_values_alone_set_the_state_whatever_is_applied_at_t0(fmus, tmp_path, kind):
    """An importer may apply the input file's first sample (a measurement included) during
    initialisation, or not: the state after it is T_start either way."""
    states = []
    for measured in (None, 31.0):
        s, vr, fmi3 = slave(fmus[kind], tmp_path / str(measured))
        initialise(s, fmi3)
        starts = 19.0 + np.arange(23) / 10
        s.setBoolean([vr["force"]] if fmi3 else [vr["force[9]"]], [i == 8 for i in range(23)] if fmi3 else [True])
        if fmi3:
            set_reals(s, fmi3, [vr["T_start"]], list(starts))
        else:
            set_reals(s, fmi3, [vr[f"T_start[{i}]"] for i in range(1, 24)], list(starts))
        if measured is not None:
            if fmi3:
                set_reals(s, fmi3, [vr["T_forced"]], [measured if i == 8 else float("nan") for i in range(23)])
            else:
                set_reals(s, fmi3, [vr["T_forced[9]"]], [measured])
        s.exitInitializationMode()
        T = (s.getFloat64([vr["T"]], 23) if fmi3 else s.getReal([vr[f"T[{i}]"] for i in range(1, 24)]))
        states.append(np.array(T))
        s.terminate()
        s.freeInstance()
    assert np.array_equal(states[0], states[1]) and np.array_equal(states[0], starts)


def test_the_fmi3_source_fmu_builds_from_its_build_description_alone(fmus, tmp_path, testcell, two_days):
    """What an importer does with a source FMU: compile sources/ as buildDescription.xml says
    (files, preprocessor definitions, libraries), nothing else; that library gives the shipped
    binary's numbers."""
    compiler = shutil.which("gcc") or pytest.fail("needs gcc")
    fmu = fmus["standalone-fmi3"]
    unzipped = tmp_path / "unzipped"
    extract(str(fmu), unzipdir=str(unzipped))
    build = ElementTree.parse(unzipped / "sources" / "buildDescription.xml").getroot()
    assert build.get("fmiVersion") == "3.0"
    configuration = build.find("BuildConfiguration")
    identifier = configuration.get("modelIdentifier")
    assert identifier == read_model_description(str(fmu)).coSimulation.modelIdentifier
    command = [compiler, "-shared", "-fPIC", f"-I{unzipped / 'sources'}", "-o", str(tmp_path / f"{identifier}.so")]
    for files in configuration.findall("SourceFileSet"):
        command += [f"-std={files.get('language', 'C99').lower()}"]
        command += [f"-D{d.get('name')}" + (f"={d.get('value')}" if d.get("value") else "")
                    for d in files.findall("PreprocessorDefinition")]
        command += [str(unzipped / "sources" / f.get("name")) for f in files.findall("SourceFile")]
    command += [f"-l{library.get('name')}" for library in configuration.findall("Library")]
    done = subprocess.run(command, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    exported = set(re.findall(r" T (fmi\w+)", subprocess.run(["nm", "-D", "--defined-only", str(tmp_path / f"{identifier}.so")],
                                                            capture_output=True, text=True).stdout))
    assert "fmi3DoStep" in exported and not any(name.startswith("fmi2") for name in exported)
    with FmuInstance(fmu) as instance:
        shipped = run(instance, testcell, two_days, {"door.conductivity_factor": 2.0})
    binary = unzipped / "binaries" / "x86_64-linux" / f"{identifier}.so"
    shutil.copy(tmp_path / f"{identifier}.so", binary)
    rebuilt = tmp_path / "rebuilt.fmu"
    shutil.make_archive(str(rebuilt.with_suffix("")), "zip", unzipped)
    rebuilt.with_suffix(".zip").rename(rebuilt)
    with FmuInstance(rebuilt) as instance:
        assert np.abs(run(instance, testcell, two_days, {"door.conductivity_factor": 2.0}) - shipped).max() < 1e-12


@pytest.mark.parametrize("kind", KINDS)
def test_the_linux_binaries_find_their_neighbours_by_rpath_origin(fmus, tmp_path, kind):
    with zipfile.ZipFile(fmus[kind]) as archive:
        root = ElementTree.fromstring(archive.read("modelDescription.xml"))
        identifier = root.find("CoSimulation").get("modelIdentifier")
        folder = "x86_64-linux" if kind.endswith("fmi3") else "linux64"
        (tmp_path / "lib.so").write_bytes(archive.read(f"binaries/{folder}/{identifier}.so"))
    dynamic = subprocess.run(["readelf", "-d", str(tmp_path / "lib.so")], capture_output=True, text=True).stdout
    assert re.search(r"\(RPATH\)\s+Library rpath: \[\$ORIGIN\]", dynamic), dynamic


def test_the_twin_houses_properties_through_the_standalone_fmu(tmp_path, twinhouse):
    """Every property of a real house at once, and one zone's alone, at values drawn within
    their bounds: the standalone FMU (its properties found in batches of nodes apart) against
    the direct model of the building with those values (281 nodes, shaded glazings, coefficients
    that follow the state)."""
    from nodeforce.model.effects import properties, with_fmu_parameters
    building = twinhouse
    network = assemble(building)
    rng = np.random.default_rng(3)
    U = rng.uniform(0.0, 30.0, (97, len(network.input_names)))
    drawn = {}
    for name, p, target in properties(building):
        low, high = p.bounds(p.read(building, target))
        gain = p.parameter.unit == "W"
        drawn[name] = float(rng.uniform(-300.0, 300.0) if gain else rng.uniform(max(low, 0.3), min(high, 3.0)))
    zone = building.zones[0].name
    alone = {name: value for name, value in drawn.items() if name.startswith(f"{zone}.")}
    fmu = build_fmu(building, tmp_path / "twinhouse.fmu", kind="standalone")
    with FmuInstance(fmu) as instance:
        for values in (drawn, alone):
            edited = with_fmu_parameters(building, None, values)
            expected = simulate(edited, assemble(edited), U, 900.0, warmup_days=0)
            assert np.abs(run(instance, building, U, values) - expected).max() < 1e-9
