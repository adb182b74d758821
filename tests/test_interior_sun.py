"""The sun inside a zone (docs/model.md section 4.1): a glazing's direct and diffuse sun as two
inputs with their own splits, and where EnergyPlus has each absorbed."""
import copy

import numpy as np
import pytest

from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case, simulate_building
from nodeforce.model.errors import InputError
from nodeforce.model.beam_trace import beam_shares, may_receive_beam
from nodeforce.model.interior_sun import beam_fractions, diffuse_fractions, window_diffuse_fractions, with_absorber
from nodeforce.model.shading import sun_vectors
from tests.traced import traced_cell
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



def test_a_face_that_would_give_more_sun_than_it_gets_is_refused(testcell_data):
    data = copy.deepcopy(testcell_data)
    window = next(c for c in data["components"] if c["name"] == "window")
    window["inside"].update(solar_absorptance=0.5, diffuse_transmittance=0.6)
    with pytest.raises(InputError, match=r"components\[\d+\]\.inside\.diffuse_transmittance: with solar_absorptance exceeds 1"):
        parse_building(data)


# ---- EnergyPlus's interior distribution (model.interior_sun) --------------------------------
# a 4 m x 4 m x 3 m box: floor (alpha 0.6), ceiling (0.3), 44 m2 of walls (0.5) and a 4 m2 window
# whose panes absorb 0.1 of the room's diffuse sun and let 0.6 of it out
AREA, ALPHA, OUT = [16.0, 16.0, 44.0, 4.0], [0.6, 0.3, 0.5, 0.1], [0.0, 0.0, 0.0, 0.6]
FLOOR = [True, False, False, False]


def test_the_diffuse_sun_goes_by_area_times_absorptance():
    """S = 16 x 0.6 + 16 x 0.3 + 44 x 0.5 + 4 x (0.1 + 0.6) = 39.2 m2: the floor takes 9.6 / 39.2,
    the window's panes 0.4 / 39.2, and 2.4 / 39.2 leaves; absorbed and leaving add up to 1."""
    phi = diffuse_fractions(AREA, ALPHA, OUT)
    assert phi == pytest.approx([9.6 / 39.2, 4.8 / 39.2, 22.0 / 39.2, 0.4 / 39.2])
    assert phi.sum() + 2.4 / 39.2 == pytest.approx(1.0)


def test_the_direct_sun_falls_on_the_floor_and_its_reflection_joins_the_diffuse():
    """The floor absorbs 0.6 and reflects 0.4 into the diffuse split: 0.6 + 0.4 x 9.6 / 39.2 on
    the floor, 0.4 x 2.4 / 39.2 leaving."""
    phi = beam_fractions(AREA, ALPHA, OUT, FLOOR)
    assert phi[0] == pytest.approx(0.6 + 0.4 * 9.6 / 39.2)
    assert phi[2] == pytest.approx(0.4 * 22.0 / 39.2)
    assert 1 - phi.sum() == pytest.approx(0.4 * 2.4 / 39.2)


def test_two_floors_take_the_direct_sun_by_area():
    """A 10 m2 floor of alpha 0.6 and a 6 m2 one of 0.3 (the box's floor split): 10/16 x 0.6 and
    6/16 x 0.3 absorbed at once, 1 - 0.4875 reflected."""
    area, alpha, out = [10.0, 6.0, 16.0, 44.0, 4.0], [0.6, 0.3, 0.3, 0.5, 0.1], [0, 0, 0, 0, 0.6]
    phi = beam_fractions(area, alpha, out, [True, True, False, False, False])
    S = 6.0 + 1.8 + 4.8 + 22.0 + 2.8
    assert phi[:2] == pytest.approx([10 / 16 * 0.6 + 0.5125 * 6.0 / S, 6 / 16 * 0.3 + 0.5125 * 1.8 / S])
    assert 1 - phi.sum() == pytest.approx(0.5125 * 2.4 / S)


def test_a_zone_without_a_window_keeps_all_its_sun():
    """No face lets any out: the fractions add up to 1, direct and diffuse."""
    area, alpha, out = AREA[:3], ALPHA[:3], OUT[:3]
    assert diffuse_fractions(area, alpha, out).sum() == pytest.approx(1.0, abs=1e-12)
    assert beam_fractions(area, alpha, out, FLOOR[:3]).sum() == pytest.approx(1.0, abs=1e-12)


def test_a_windows_diffuse_sun_first_meets_the_faces_it_sees():
    """The box's window sees the floor by 0.3, the ceiling by 0.3 and the walls by 0.4, not
    itself: the first bounce absorbs 0.3 x 0.6 + 0.3 x 0.3 + 0.4 x 0.5 = 0.47 and reflects 0.53
    into the pool of area x absorptance (S = 39.2 m2), of which 0.53 x 2.4 / 39.2 leaves; what the
    window itself absorbs is only its share of the reflected pool."""
    view = [0.3, 0.3, 0.4, 0.0]
    phi = window_diffuse_fractions(AREA, ALPHA, OUT, view)
    assert phi == pytest.approx([0.18 + 0.53 * 9.6 / 39.2, 0.09 + 0.53 * 4.8 / 39.2, 0.2 + 0.53 * 22.0 / 39.2,
                                 0.53 * 0.4 / 39.2])
    assert 1 - phi.sum() == pytest.approx(0.53 * 2.4 / 39.2)


def test_a_window_that_sees_another_window_loses_its_first_bounce_through_it():
    """A second window (back absorptance 0.1, diffuse transmittance 0.6, reflectance 0.3) seen by
    0.5: 0.5 x 0.6 leaves at once, 0.5 x 0.1 is absorbed; the floor, seen by the rest, absorbs
    0.5 x 0.6 and the reflected 0.5 x 0.3 + 0.5 x 0.4 = 0.35 joins the pool; sun is conserved."""
    area, alpha, out = [16.0, 4.0, 4.0], [0.6, 0.1, 0.1], [0.0, 0.6, 0.6]
    phi = window_diffuse_fractions(area, alpha, out, [0.5, 0.0, 0.5])
    S = 16 * 0.6 + 8 * 0.7
    assert phi == pytest.approx([0.3 + 0.35 * 9.6 / S, 0.35 * 0.4 / S, 0.05 + 0.35 * 0.4 / S])
    assert phi.sum() + 0.3 + 0.35 * 4.8 / S == pytest.approx(1.0)


# an internal mass of 12 m2 of absorptance 0.7 in the box: 8.4 m2 more in the pool's 39.2
MASS_AREA, MASS_ALPHA = 12.0, 0.7


@pytest.mark.parametrize("split, recomputed", [
    (lambda a, al, o: beam_fractions(a, al, o, FLOOR), lambda a, al, o: beam_fractions(a, al, o, FLOOR + [False])),
    (lambda a, al, o: window_diffuse_fractions(a, al, o, [0.3, 0.3, 0.4, 0.0]),
     lambda a, al, o: window_diffuse_fractions(a, al, o, [0.3, 0.3, 0.4, 0.0, 0.0])),
    (diffuse_fractions, diffuse_fractions)], ids=["beam on the floor", "window's diffuse", "pool"])
def test_an_internal_mass_takes_the_pools_share_as_the_splits_computed_again_with_it(split, recomputed):
    """The zone's splits computed afresh with the mass as one more face that the first bounce does
    not reach (EnergyPlus traces no beam onto an InternalMass; the window's view factors are the
    box's) equal the declared splits with the mass added, which reads only the splits and the
    faces: the direct sun's reflected 0.4 gives the mass 0.4 x 8.4 / (39.2 + 8.4)."""
    shares, mass = with_absorber(split(AREA, ALPHA, OUT), AREA, ALPHA, OUT, MASS_AREA * MASS_ALPHA)
    again = recomputed(AREA + [MASS_AREA], ALPHA + [MASS_ALPHA], OUT + [0.0])
    assert [*shares, mass] == pytest.approx(list(again), abs=1e-12)
    assert with_absorber(beam_fractions(AREA, ALPHA, OUT, FLOOR), AREA, ALPHA, OUT, 8.4)[1] == pytest.approx(
        0.4 * 8.4 / 47.6)


def test_a_split_that_puts_all_its_sun_on_one_face_gives_the_mass_none():
    """Declared all on the floor (nothing reflected), the split stays as declared."""
    shares, mass = with_absorber([1.0, 0.0, 0.0, 0.0], AREA, ALPHA, OUT, 8.4)
    assert mass == 0.0 and list(shares) == [1.0, 0.0, 0.0, 0.0]


# ASHRAE 140's box (8 m east-west, 6 m north-south, 2.7 m high) and a south window 3 m wide and 2 m
# high, 0.2 m above the floor, each polygon counterclockwise seen from outside
BOX_W, BOX_D, BOX_H = 8.0, 6.0, 2.7
SOUTH_WINDOW = [(1, 0, 0.2), (4, 0, 0.2), (4, 0, 2.2), (1, 0, 2.2)]
BOX = {"floor": ([(0, 0, 0), (0, BOX_D, 0), (BOX_W, BOX_D, 0), (BOX_W, 0, 0)], ()),
       "roof": ([(0, 0, BOX_H), (BOX_W, 0, BOX_H), (BOX_W, BOX_D, BOX_H), (0, BOX_D, BOX_H)], ()),
       "south": ([(0, 0, 0), (BOX_W, 0, 0), (BOX_W, 0, BOX_H), (0, 0, BOX_H)], (SOUTH_WINDOW,)),
       "north": ([(BOX_W, BOX_D, 0), (0, BOX_D, 0), (0, BOX_D, BOX_H), (BOX_W, BOX_D, BOX_H)], ()),
       "east": ([(BOX_W, 0, 0), (BOX_W, BOX_D, 0), (BOX_W, BOX_D, BOX_H), (BOX_W, 0, BOX_H)], ()),
       "west": ([(0, BOX_D, 0), (0, 0, 0), (0, 0, BOX_H), (0, BOX_D, BOX_H)], ())}


def box_shares(zenith, azimuth):
    shares = beam_shares(SOUTH_WINDOW, list(BOX.values()), sun_vectors([zenith], [azimuth]))[0]
    return dict(zip(BOX, shares))


def test_a_high_southern_sun_puts_the_whole_beam_on_the_floor():
    """At 45 deg altitude from the south a ray through the window at height z drops z while it
    goes z north: the patch spans y = 0.2 to 2.2 m, all on the floor."""
    s = box_shares(45.0, 180.0)
    assert s["floor"] == pytest.approx(1.0, abs=1e-9)
    assert sum(s.values()) == pytest.approx(1.0, abs=1e-9)


def test_a_low_southern_sun_reaches_the_north_wall():
    """At 20 deg altitude a ray through height z reaches y = z / tan 20 deg: past the north wall's
    6 m above z* = 6 tan 20 deg = 2.184 m, so the window's strip from z* to 2.2 m (of its 2 m
    height) lights the north wall and the rest the floor; the window's own wall gets none."""
    z_star = BOX_D * np.tan(np.radians(20.0))
    s = box_shares(70.0, 180.0)
    assert s["north"] == pytest.approx((2.2 - z_star) / 2.0, rel=1e-9)
    assert s["floor"] == pytest.approx((z_star - 0.2) / 2.0, rel=1e-9)
    assert s["south"] == s["east"] == s["west"] == s["roof"] == 0.0


def test_a_south_western_sun_lights_a_corner_of_the_east_wall():
    """At 20 deg altitude from azimuth 225 deg a ray through (x, z) goes k z east and k z north,
    k = sin 45 deg / tan 20 deg, reaching the floor at y = k z < 6 m: it meets the east wall where
    x + k z > 8 m, a triangle of the window of legs 4 - (8 - 2.2 k) in x and 2.2 - 4 / k in z."""
    k = np.sin(np.radians(45.0)) / np.tan(np.radians(20.0))
    triangle = 0.5 * (4.0 - (BOX_W - 2.2 * k)) * (2.2 - (BOX_W - 4.0) / k)
    s = box_shares(70.0, 225.0)
    assert s["east"] == pytest.approx(triangle / 6.0, rel=1e-9)
    assert s["floor"] == pytest.approx(1.0 - triangle / 6.0, rel=1e-9)


def test_only_the_faces_some_sun_reaches_through_the_window_are_traced():
    """Through a south window, a sun above the horizon reaches the floor and the north, east and
    west walls, never the ceiling (the rays go down), the window's own wall nor a window beside
    it (in its plane); the shares of the others are 0 at every sun in front of the window."""
    beside = [(5, 0, 0.2), (7, 0, 0.2), (7, 0, 2.2), (5, 0, 2.2)]
    faces = dict(BOX, beside=(beside, ()))
    reached = {name for name, (vertices, _) in faces.items() if may_receive_beam(SOUTH_WINDOW, vertices)}
    assert reached == {"floor", "north", "east", "west"}
    altitude, azimuth = np.meshgrid(np.arange(1.0, 90.0, 3.0), np.arange(91.0, 270.0, 3.0))
    shares = beam_shares(SOUTH_WINDOW, list(faces.values()), sun_vectors(90 - altitude.ravel(), azimuth.ravel()))
    never = [k for k, name in enumerate(faces) if name not in reached]
    assert (shares[:, never] == 0).all()
    assert shares.sum(axis=1) == pytest.approx(1.0, abs=1e-9)


def test_no_beam_is_traced_with_the_sun_down_or_behind_the_window():
    """A sun down (its vector 0) or in the north, behind the south window, lets no beam in."""
    sun = np.vstack([np.zeros(3), sun_vectors([60.0], [0.0])])
    assert (beam_shares(SOUTH_WINDOW, list(BOX.values()), sun) == 0).all()


def test_the_traced_beam_is_the_glazings_direct_sun_shared_out(testcell_data, weather):
    """The inputs of the traced direct sun, one a face and one for what falls on none, add up to
    the direct sun of the same window untraced; Miami's low December sun reaches the floor and, in
    the morning and the evening, the west and east walls."""
    days = weather.iloc[24 * 335:24 * 342]
    case = prepare_case(parse_building(traced_cell(testcell_data)), days)
    plain = prepare_case(split_cell(testcell_data, {"floor": 0.5}, {"floor": 0.3}), days)
    column = {name: case.U[:, k] for k, name in enumerate(case.input_names)}
    traced = [name for name in case.input_names if name.startswith("Itb_window")]
    assert len(traced) == 5
    total = sum(column[name] for name in traced)
    assert total == pytest.approx(plain.U[:, plain.input_names.index("Itb_window")], abs=1e-9)
    assert all(column[f"Itb_window@{face}"].max() > 0 for face in ("floor", "east_wall", "west_wall"))


def test_a_traced_beam_split_alike_everywhere_is_the_untraced_building(testcell_data, weather):
    """Where every face splits what falls on it as the window splits the untraced direct sun, the
    traced inputs add up to that direct sun, and by superposition the temperatures are the same."""
    split = {"floor": 0.5, "north_wall": 0.1}
    same = {face: split for face in ("floor", "north_wall", "east_wall", "west_wall")}
    days = weather.iloc[24 * 160:24 * 170]
    traced = simulate_building(parse_building(traced_cell(testcell_data, same, split)), days)
    plain = copy.deepcopy(traced_cell(testcell_data, residual=split))
    del plain["components"][[c["name"] for c in plain["components"]].index("window")]["traced_beam"]
    untraced = simulate_building(parse_building(plain), days)
    assert np.abs(traced.to_numpy() - untraced.to_numpy()).max() < 1e-9
    # and the split matters: the beam all absorbed where it falls is another building
    absorbed = simulate_building(parse_building(traced_cell(testcell_data)), days)
    assert np.abs(absorbed.to_numpy() - untraced.to_numpy()).max() > 0.01


@pytest.mark.parametrize("edit, field", [
    (lambda w, c: w.pop("diffuse_distribution"), "traced_beam"),
    (lambda w, c: c["floor"].pop("vertices"), "traced_beam.floor"),
    (lambda w, c: w["traced_beam"].update(attic={"floor": 0.5}), "traced_beam.attic"),
    (lambda w, c: w["traced_beam"].update(floor={"floor": 0.7, "roof": 0.5}), "traced_beam.floor"),
])
def test_a_traced_beam_is_refused_without_what_it_needs(testcell_data, edit, field):
    data = traced_cell(testcell_data)
    components = {c["name"]: c for c in data["components"]}
    edit(components["window"], components)
    with pytest.raises(InputError) as e:
        parse_building(data)
    assert e.value.field.endswith(field)
