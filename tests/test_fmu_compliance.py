"""One FMU file, the same numbers in three FMI 2.0 importers, and two independent checkers."""
import numpy as np
import pytest

from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.building_file import parse_building
from tests.importers import fmpy_validate, fmutool_check, run_ecos, run_fmpy, run_libcosim

pytestmark = pytest.mark.slow  # searches, diagnoses or other importers: not in `make check`

N_STEPS = 96
DT = 900.0


@pytest.fixture(scope="module")
def fmu(tmp_path_factory, testcell_data):
    return build_fmu(parse_building(testcell_data), tmp_path_factory.mktemp("compliance") / "testcell.fmu")


@pytest.fixture(scope="module")
def scenario(real_case):
    """A day of real weather, node 9 forced to a measurement with a gap of an hour."""
    rows = slice(1, N_STEPS + 1)
    inputs = {name: real_case.U[rows, j] for j, name in enumerate(real_case.input_names)}
    measured_9 = real_case.measured[rows, 8].copy()
    measured_9[30:34] = np.nan
    inputs["T_forced[9]"] = measured_9
    parameters = {"force[9]": True, **{f"T_start[{i}]": 24.0 for i in range(1, 24)}}
    outputs = [f"T[{i}]" for i in range(1, 24)]
    return parameters, inputs, outputs


def test_fmpy_validate(fmu):
    assert fmpy_validate(fmu) == []


def test_fmutool_check(fmu):
    ok, output = fmutool_check(fmu)
    assert ok, output


def test_forcing_through_fmi_holds_the_measurement_and_frees_the_node_in_gaps(fmu, scenario):
    parameters, inputs, outputs = scenario
    T = run_fmpy(fmu, parameters, inputs, outputs, DT, N_STEPS)
    measured = inputs["T_forced[9]"]
    have = np.isfinite(measured)
    assert np.array_equal(T[have, 8], measured[have])
    assert np.all(np.isfinite(T[~have, 8]))


@pytest.mark.parametrize("runner", [run_libcosim, run_ecos], ids=["libcosim", "ecos"])
def test_same_outputs_in_other_importers(fmu, scenario, runner):
    parameters, inputs, outputs = scenario
    reference = run_fmpy(fmu, parameters, inputs, outputs, DT, N_STEPS)
    other = runner(fmu, parameters, inputs, outputs, DT, N_STEPS)
    assert np.isfinite(reference).all()
    # the day changes the temperatures: the importers are compared on a moving model
    assert np.ptp(reference[:, 22]) > 1.0
    np.testing.assert_allclose(other, reference, rtol=0, atol=1e-9)
