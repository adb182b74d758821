"""The Python API (nodeforce.api): the FMU's score of a forcing equals the one computed by hand
from the direct model, the search's candidates are the measured nodes but the air, and the API
is loaded only when used."""
import inspect
import re
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import nodeforce
from nodeforce.model.effects import EFFECTS
from tests.conftest import DATA

BURN_IN_STEPS = 96  # one day at 15 min


@pytest.fixture(scope="module")
def demo():
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    weather = nodeforce.read_weather(DATA / "miami_tmy2.csv")
    measured = nodeforce.read_measurements(DATA / "demo_measurements.csv")
    return building, weather, measured, nodeforce.measured_case(building, weather, measured, burn_in_days=1)


def test_score_through_the_fmu_equals_the_direct_models_sum_of_squares(demo, tmp_path):
    building, weather, measured, case = demo
    air = nodeforce.objective(building)
    with nodeforce.open_fmu(nodeforce.write_fmu(building, tmp_path / "cell.fmu")) as fmu:
        J = {nodes: nodeforce.score_forcing(fmu, case, nodes, air) for nodes in ((), (7,), (16,))}
    for nodes, score in J.items():
        T = nodeforce.simulate(building, weather, measured, force=nodes, burn_in_days=1)
        # t_1..t_N against the file's rows 1..N, the burn-in's day left out
        r = measured["T23"].to_numpy()[1 + BURN_IN_STEPS:] - T["T23"].to_numpy()[BURN_IN_STEPS:]
        assert score == pytest.approx(float(np.sum(r ** 2)), rel=1e-9)
    # the demo's undeclared effect is under the floor: forcing its sensor explains most of the air
    assert J[(16,)] < 0.2 * J[()] < J[(7,)]


def test_forcing_candidates_are_the_measured_nodes_but_the_air(demo):
    building, _, measured, case = demo
    ids = {int(c[1:]) for c in measured.columns}
    assert set(nodeforce.forcing_candidates(building, case)) == ids - {building.zones[0].air_node}


def test_forcing_an_unmeasured_node_is_refused(demo):
    building, _, _, case = demo
    with pytest.raises(nodeforce.InputError, match="node 5 is to be forced but has no measurement"):
        nodeforce.score_forcing(None, case, [5], nodeforce.objective(building))


@pytest.mark.slow
def test_the_api_is_loaded_only_when_used():
    code = ("import sys, nodeforce.model.case; print('nodeforce.api' in sys.modules); "
            "nodeforce.read_building; print('nodeforce.api' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "True"]


def test_compare_through_the_api_scores_each_model_as_its_own_fmu_run_does(demo, tmp_path):
    """Two models on the demo record: each one's RMSE is that of the residual of its own air
    simulated through its FMU and scored by hand from the burn-in's end."""
    building, weather, measured, case = demo
    coupled = EFFECTS["ground_coupling"].apply(building, "floor", {"U": 0.5, "T_ground": 24.0})
    objective = nodeforce.objective(building)
    models = [("written", building, case, objective),
              ("coupled", coupled, nodeforce.measured_case(coupled, weather, measured, burn_in_days=1), objective)]
    result = nodeforce.compare(models, workdir=tmp_path)
    assert [m["building"] for m in result.models] == ["written", "coupled"]
    assert type(result).read(tmp_path / "compare.json") == result
    assert result.summary().splitlines()[0].startswith("written: cell air RMSE")
    for model, (_, b, c, _) in zip(result.models, models):
        with nodeforce.open_fmu(nodeforce.write_fmu(b, tmp_path / f"{model['building']}.fmu")) as fmu:
            T = nodeforce.simulate_fmu(fmu, c)[c.history_steps:]  # the weather's week before the record first
        r = (measured["T23"].to_numpy()[1:] - T[:, 22])[BURN_IN_STEPS:]
        r = r[np.isfinite(r)]
        assert model["metrics"]["rmse"] == pytest.approx(np.sqrt(np.mean(r ** 2)), rel=1e-9)
    assert (tmp_path / "compare.json").exists() and (tmp_path / "compare.md").exists()


API_PAGE = DATA.parents[1] / "docs" / "api.md"
# A documented call, `name(arguments)` (a span may wrap a line).
DOCUMENTED_CALL = re.compile(r"`([A-Za-z_][A-Za-z0-9_]*)\(([^`]*)\)`")


def documented_calls():
    """{name: [argument names]} of every function docs/api.md writes a call of: Python's own
    (`help`) and a Building's methods (`node_names()`) left out, and "..." for arguments left
    unsaid and "*" (keywords follow) not an argument."""
    from nodeforce.model.building import Building
    calls = {}
    for name, arguments in DOCUMENTED_CALL.findall(API_PAGE.read_text(encoding="utf-8")):
        if name == "help" or hasattr(Building, name):
            continue
        named = [a.split("=")[0].strip() for a in arguments.split(",") if a.strip() not in ("", "...", "*")]
        calls[name] = sorted(set(calls.get(name, [])) | set(named))
    return calls


def test_the_api_page_lists_the_api():
    """The page's list is the one the test below reads: every name the API exports is on it."""
    assert set(documented_calls()) == set(nodeforce.api.__all__) - {"InputError"}


@pytest.mark.parametrize("name", sorted(documented_calls()))
def test_every_function_docs_api_gives_is_callable_as_written(name):
    """`nodeforce.<name>` is the API's function (not a subpackage of the same name), and it takes
    every argument the page writes, by the name the page gives it."""
    import nodeforce.diagnosis.loop  # noqa: F401  a subpackage imported first must not shadow the API
    found = getattr(nodeforce, name)
    assert found is getattr(nodeforce.api, name) and callable(found)
    parameters = inspect.signature(found).parameters
    takes_any = any(p.kind is p.VAR_KEYWORD for p in parameters.values())
    for argument in documented_calls()[name]:
        if argument.startswith("**"):
            assert takes_any, f"{name} takes no {argument}"
        else:
            assert argument in parameters, f"docs/api.md gives {name} an argument {argument!r} it does not take"
