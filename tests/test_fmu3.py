"""The same model as an FMI 3.0 co-simulation FMU, Python and standalone: arrays for force,
T_forced and T, units, the effect's parameters; the FMI 2.0 FMU's numbers and answers."""
import json
import zipfile
from xml.etree import ElementTree

import numpy as np
import pytest
from fmpy.validation import validate_fmu

from nodeforce.cli import main
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.diagnosis.calibrate import Candidate
from nodeforce.fmu_build import guard
from nodeforce.fmu_build.build import build_fmu, fmu_kind
from nodeforce.model.case import prepare_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import SENSORS, record_times
from tests.test_fmu_exchange import glibc_versions
from tests.test_fmu_processes import files  # noqa: F401 (the locate fixture)
from tests.test_standalone import scenario

KINDS = ("python", "standalone")
EFFECT = ("ground_coupling", "floor")


@pytest.fixture(scope="module")
def fmus(tmp_path_factory, testcell):
    """{(kind, fmi): FMU} of the test cell with the ground coupling's parameters exposed."""
    folder = tmp_path_factory.mktemp("fmi3")
    return {(kind, fmi): build_fmu(testcell, folder / f"{kind}{fmi}.fmu", effect=EFFECT, kind=fmu_kind(kind, fmi))
            for kind in KINDS for fmi in (2, 3)}


@pytest.mark.parametrize("kind", KINDS)
def test_fmi3_declares_arrays_units_and_the_effect_and_passes_fmpy_validate(fmus, kind):
    fmu = fmus[(kind, 3)]
    assert validate_fmu(str(fmu)) == []
    with zipfile.ZipFile(fmu) as archive:
        root = ElementTree.fromstring(archive.read("modelDescription.xml"))
        assert f"binaries/x86_64-linux/{root.find('CoSimulation').get('modelIdentifier')}.so" in archive.namelist()
    assert root.get("fmiVersion") == "3.0"
    declared = {v.get("name"): v for v in root.find("ModelVariables")}
    for name, tag, causality in (("force", "Boolean", "parameter"), ("T_start", "Float64", "parameter"),
                                 ("T_forced", "Float64", "input"), ("T", "Float64", "output")):
        v = declared[name]
        assert (v.tag, v.get("causality"), v.find("Dimension").get("start")) == (tag, causality, "23")
    assert declared["T_forced"].get("variability") == "discrete" and declared["T"].get("unit") == "degC"
    assert len(declared["T_forced"].get("start").split()) == 23
    assert declared["ground_coupling.U"].get("unit") == "W/m2/K"
    if kind == "python":  # its binary, the FMI 3.0 interface and the guard, asks glibc for no more than the guard
        with zipfile.ZipFile(fmu) as archive:
            binary = archive.read(f"binaries/x86_64-linux/{root.find('CoSimulation').get('modelIdentifier')}.so")
        (fmu.parent / "fmi3_guard.so").write_bytes(binary)
        versions, _ = glibc_versions(fmu.parent / "fmi3_guard.so")
        assert max(versions) == tuple(int(x) for x in guard.GUARD_GLIBC.split("."))
    # 4N scalars of FMI 2.0 became 4 arrays, with the independent time beside them
    with zipfile.ZipFile(fmus[(kind, 2)]) as archive:
        scalars = ElementTree.fromstring(archive.read("modelDescription.xml")).find("ModelVariables")
    derivatives = {name: v for name, v in declared.items() if name.startswith("der(")}
    assert len(scalars) - (len(declared) - len(derivatives)) == 4 * 22 - 1
    # FMI 3.0 has no call for input derivatives: each input's is an input declared its derivative
    inputs = [name for name, v in declared.items() if v.get("causality") == "input" and name not in derivatives]
    assert sorted(derivatives) == sorted(f"der({name})" for name in inputs)
    for name in inputs:
        assert declared[f"der({name})"].get("derivative") == declared[name].get("valueReference")


@pytest.mark.parametrize("kind", KINDS)
def test_fmi3_equals_fmi2_and_the_direct_model_with_forcing_and_effect(fmus, testcell, real_case, kind):
    force = np.zeros(23, dtype=bool)
    force[[0, 8, 16]] = True
    values = {"U": 0.8, "T_ground": 24.0}
    parameters = {f"{EFFECT[0]}.{k}": v for k, v in values.items()}
    results = {}
    for fmi in (2, 3):
        with FmuInstance(fmus[(kind, fmi)]) as instance:
            results[fmi] = simulate_fmu(instance, real_case, force, parameters=parameters)
    coupled = EFFECTS[EFFECT[0]].apply(testcell, EFFECT[1], values)
    direct = simulate(coupled, assemble(coupled), real_case.U, real_case.dt, real_case.measured, force, substeps=real_case.substeps)
    assert np.abs(results[3] - results[2]).max() < 1e-9
    assert np.abs(results[3] - direct).max() < 1e-9
    measured = real_case.measured[1:, 8]
    assert np.array_equal(results[3][:, 8], measured)  # forced through the T_forced array
    uncoupled = simulate(testcell, assemble(testcell), real_case.U, real_case.dt, real_case.measured, force, substeps=real_case.substeps)
    assert np.abs(direct - uncoupled).max() > 0.1  # the effect's parameters reached the model


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("fmi", (2, 3))
def test_a_value_the_fmu_refuses_mid_run_stops_the_run_naming_the_call(fmus, real_case, kind, fmi):
    """The step loop calls the FMI functions without FMPy's wrapper: a refusal (a NaN outdoor
    temperature at the sixth step, fmi2Error/fmi3Error) still raises FMPy's exception, the call
    named, and the next run of the instance is whole."""
    from fmpy.fmi1 import FMICallException
    with FmuInstance(fmus[(kind, fmi)]) as instance:
        names = ["T_out"]
        rows = np.full((10, 1), 20.0)
        rows[5, 0] = np.nan
        with pytest.raises(FMICallException) as refused:
            instance.run(600.0, {}, {}, names, rows, ["T[1]"])
        assert refused.value.status == 3
        assert str(refused.value).startswith("fmi2SetReal" if fmi == 2 else "fmi3SetFloat64")
        rows[5, 0] = 20.0
        assert np.isfinite(instance.run(600.0, {}, {}, names, rows, ["T[1]"])).all()


@pytest.mark.slow  # a search through four FMUs
def test_a_search_through_fmi3_gives_the_fmi2_answer(files, tmp_path):  # noqa: F811
    results = {}
    for kind in KINDS:
        for fmi in ("2", "3"):
            out = tmp_path / f"{kind}{fmi}"
            assert main(files + ["-o", str(out), "--fmu", kind, "--fmi", fmi, "--workers", "1"]) == 0
            results[(kind, fmi)] = json.loads((out / "locate.json").read_text())
    reference = results[("python", "2")]
    assert reference["best_nodes"] == [7]
    for found in results.values():
        assert found["best_nodes"] == reference["best_nodes"]
        for node, J in reference["node_scores"].items():
            assert abs(found["node_scores"][node] - J) <= 1e-9 * max(1.0, J)


@pytest.mark.slow  # three FMUs
def test_a_diagnosis_s_candidates_are_calibrated_on_the_equations_their_fmus_carry(tmp_path, testcell, weather):
    """The diagnosis calibrates its candidates on the direct model and builds the chosen one's
    FMU: at any parameter values, the candidate's direct simulation equals its FMU's (the standalone
    FMU through FMI 2.0 and 3.0, the Python FMU) to rounding, the effect's parameter set through
    the FMU's `<effect>.<name>`, the steady start and the burn-in included."""
    measured = pseudo_measurements(testcell, weather, record_times(days=3), SENSORS, noise_sd=0.1, seed=5)
    case = prepare_case(testcell, weather, measured).with_burn_in(1).with_steady_start()
    objective = Objective.of(testcell)
    candidate = Candidate(testcell, "envelope_conductance", "cell")
    values = [1.7]
    direct = candidate.nodes(case, objective.air_nodes, values)
    parameters = {f"envelope_conductance.{p.name}": v for p, v in zip(candidate.parameters, values)}
    for kind, fmi in (("standalone", 2), ("standalone", 3), ("python", 2)):
        fmu = build_fmu(testcell, tmp_path / f"{kind}{fmi}.fmu", effect=("envelope_conductance", "cell"),
                        kind=fmu_kind(kind, fmi))
        with FmuInstance(fmu) as instance:
            # the FMU reads the inputs the effect adds (none for the envelope's factor: the case's own)
            through = simulate_fmu(instance, case.with_inputs(EFFECTS["envelope_conductance"].apply(testcell, "cell", {})),
                                   output_ids=objective.air_nodes,
                                   parameters=parameters)
        assert np.abs(through - direct).max() < 1e-9, (kind, fmi)
    # and the factor acts: the air differs from the building's as declared
    assert np.abs(direct - candidate.nodes(case, objective.air_nodes, [1.0])).max() > 0.05


@pytest.mark.slow  # three FMUs of 281 nodes
def test_fmi3_equals_fmi2_on_the_twin_house(tmp_path, twinhouse):
    building = twinhouse
    built = {(kind, fmi): build_fmu(building, tmp_path / f"{kind}{fmi}.fmu", kind=fmu_kind(kind, fmi))
             for kind, fmi in (("python", 2), ("python", 3), ("standalone", 3))}
    parameters, inputs, outputs, n_steps = scenario(built[("python", 2)], n_steps=96)
    start = {name: value for name, value in parameters.items() if name.startswith("T_forced[")}
    fixed = {name: value for name, value in parameters.items() if name not in start}
    results = {}
    for key, fmu in built.items():
        with FmuInstance(fmu) as instance:
            results[key] = instance.run(900.0, fixed, start, list(inputs), np.column_stack(list(inputs.values())),
                                        outputs)
    reference = results[("python", 2)]
    assert np.ptp(reference).max() > 1.0
    for key in (("python", 3), ("standalone", 3)):
        assert np.abs(results[key] - reference).max() < 1e-9, key
