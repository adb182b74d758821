"""The heat loss coefficient (docs/model.md section 8) against hand-solved steady states."""
import copy

import numpy as np
import pytest

from nodeforce.model.building_file import parse_building
from nodeforce.model.hlc import heat_loss_coefficient

from .test_zones import RHO_C, two_zones


def series(*conductances):
    return 1.0 / sum(1.0 / g for g in conductances)


def layers_conductance(component_data, materials):
    """W/m2/K of a component's layers in series."""
    return 1.0 / sum(t / materials[m]["conductivity"] for m, t in component_data["layers"])


def test_the_test_cell_loses_what_its_surfaces_and_radiant_star_pass_to_the_outside(testcell_data):
    """The test cell's one zone: each surface j is joined to the air (A h_c), to the radiant node
    (A h_r) and, through its layers and outside coefficients, to 0 C (g_o: zero for the adiabatic
    floor). The radiant node, with no capacity, settles at the h_r-weighted mean of the surfaces,
    which gives it a closed form; the HLC is the heat the surfaces pass outwards, plus the air
    change."""
    data = copy.deepcopy(testcell_data)
    data["zones"][0]["air_change_rate"] = 0.7
    materials = data["materials"]
    g_c, g_r, g_o = [], [], []
    for c in data["components"]:
        area, inside, outside = c["area"], c["inside"], c["outside"]
        g_c.append(area * inside["h_conv"])
        g_r.append(area * inside["h_rad"])
        if outside["type"] == "exterior":
            g_o.append(series(area * layers_conductance(c, materials),
                              area * (outside["h_conv"] + outside["h_rad"])))
        else:
            assert outside["type"] == "adiabatic"
            g_o.append(0.0)
    g_c, g_r, g_o = map(np.array, (g_c, g_r, g_o))
    S = g_c + g_r + g_o
    # surface j: S_j T_j = g_c,j + g_r,j T_r; radiant node: sum g_r,j (T_j - T_r) = 0
    T_r = (g_r * g_c / S).sum() / (g_r.sum() - (g_r ** 2 / S).sum())
    T_s = (g_c + g_r * T_r) / S
    infiltration = RHO_C * data["zones"][0]["volume"] * 0.7 / 3600
    expected = (g_o * T_s).sum() + infiltration

    assert heat_loss_coefficient(parse_building(data)) == pytest.approx(expected, rel=1e-9)


def test_two_zones_lose_through_their_walls_and_the_supply_air_but_not_through_the_air_between_them():
    """Zone A gets supply air at 16 C which flows on to B: with both airs at 1 C and the supply
    at 0 C, the supply air carries (rho c) V / 3600 per kelvin away, the flow from A to B none.
    Each zone has one wall, so its radiant node passes nothing and the wall is A h_c in series
    with the board and the outside coefficients."""
    b = parse_building(two_zones())

    def wall(area):
        return series(area * 3.0, area * 0.5 / 0.1, area * (16.0 + 5.0))

    expected = wall(12.0) + wall(8.0) + RHO_C * 90.0 / 3600
    assert heat_loss_coefficient(b) == pytest.approx(expected, rel=1e-9)


def test_a_zone_closed_on_every_side_loses_nothing_and_the_hlc_is_linear_in_conductances(testcell_data):
    closed = copy.deepcopy(testcell_data)
    for c in closed["components"]:
        c["outside"] = {"type": "adiabatic"}
        c.pop("solar_transmittance", None)
        c.pop("transmitted_solar_to", None)
    assert heat_loss_coefficient(parse_building(closed)) == pytest.approx(0.0, abs=1e-12)

    # a thermal bridge of UA W/K from the air adds exactly UA
    bridged = copy.deepcopy(testcell_data)
    bridged["zones"][0]["thermal_bridges"] = {"outdoor": 7.5}
    base = heat_loss_coefficient(parse_building(testcell_data))
    assert heat_loss_coefficient(parse_building(bridged)) == pytest.approx(base + 7.5, rel=1e-12)
