"""The sun inside a zone (docs/model.md section 4.1): a glazing's direct and diffuse sun as two
inputs with their own splits, and where EnergyPlus has each absorbed."""
import copy

import numpy as np
import pytest

from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case, simulate_building
from nodeforce.model.errors import InputError
from nodeforce.model.network import assemble


def split_cell(data, direct, diffuse):
    data = copy.deepcopy(data)
    window = next(c for c in data["components"] if c["name"] == "window")
    window["solar_distribution"] = direct
    if diffuse is not None:
        window["diffuse_distribution"] = diffuse
    return parse_building(data)


def test_direct_and_diffuse_inputs_add_up_to_the_sun_on_the_glazing(testcell_data, weather):
    """Without an angular table the two inputs are the isotropic sky's two terms, dni cos theta
    and the sky's and ground's diffuse: together the face's irradiance; the direct one is 0 at
    night."""
    b = split_cell(testcell_data, {"floor": 0.9}, {"floor": 0.5, "roof": 0.3})
    case = prepare_case(b, weather.iloc[:24 * 14])
    column = {name: case.U[:, k] for k, name in enumerate(case.input_names)}
    direct, diffuse = column["Itb_window"], column["Itd_window"]
    assert direct + diffuse == pytest.approx(column["I_window"], abs=1e-9)
    night = column["I_window"] == 0
    assert night.any() and (direct[night] == 0).all()
    assert (diffuse > 0).any() and ((direct > 0) & (diffuse > 0)).any()


def test_each_input_lands_by_its_own_split(testcell_data):
    """B[face, input] = tau A phi: 0.8 x A x the fraction of each split, the window's face its own
    irradiance's absorbed part alone."""
    b = split_cell(testcell_data, {"floor": 0.9}, {"floor": 0.5, "roof": 0.3})
    net = assemble(b)
    w, floor, roof = (b.component(n) for n in ("window", "floor", "roof"))
    col = {name: k for k, name in enumerate(net.input_names)}
    assert net.B[floor.node_ids[0] - 1, col["Itb_window"]] == pytest.approx(0.8 * w.area * 0.9)
    assert net.B[floor.node_ids[0] - 1, col["Itd_window"]] == pytest.approx(0.8 * w.area * 0.5)
    assert net.B[roof.node_ids[0] - 1, col["Itd_window"]] == pytest.approx(0.8 * w.area * 0.3)
    assert net.B[roof.node_ids[0] - 1, col["Itb_window"]] == 0.0
    assert net.B[floor.node_ids[0] - 1, col["I_window"]] == 0.0


def test_one_split_declared_twice_is_the_undeclared_building(testcell_data, weather):
    """The same split for the direct and the diffuse sun is, by superposition, the one split the
    file gives for both without a diffuse_distribution: the same temperatures."""
    split = {"floor": 0.7, "roof": 0.1, "north_wall": 0.1}
    one = simulate_building(split_cell(testcell_data, split, None), weather.iloc[:24 * 10])
    two = simulate_building(split_cell(testcell_data, split, split), weather.iloc[:24 * 10])
    assert np.abs(one.to_numpy() - two.to_numpy()).max() < 1e-9


def test_a_split_glazing_refuses_a_measured_irradiance(testcell_data, weather):
    b = split_cell(testcell_data, {"floor": 0.9}, {"floor": 0.5})
    measured = weather.iloc[:48].assign(I_window=100.0)
    measured.attrs = weather.attrs
    with pytest.raises(InputError, match="diffuse_distribution"):
        prepare_case(b, measured)


def test_a_diffuse_distribution_is_refused_where_it_adds_up_over_1_or_names_no_component(testcell_data):
    with pytest.raises(InputError, match="diffuse_distribution.*at most 1"):
        split_cell(testcell_data, {"floor": 0.9}, {"floor": 0.8, "roof": 0.3})
    with pytest.raises(InputError, match="diffuse_distribution.attic"):
        split_cell(testcell_data, {"floor": 0.9}, {"attic": 0.5})
