"""The JSON Schema of the building format (model/data/nodal-building.schema.json) documents what
parse_building accepts: the bundled files and files carrying every effect validate against it,
and wrong files are refused by the schema and by the parser alike."""
import copy
import json
from pathlib import Path

import jsonschema
import pytest

from nodeforce.model.building import Boundary

from nodeforce.model.building_file import parse_building
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError

from .test_standalone import two_zones

DATA = Path(__file__).parents[1] / "model" / "data"
SCHEMA = json.loads((DATA / "nodal-building.schema.json").read_text())
TESTCELL = json.loads((DATA / "testcell.json").read_text())
# the test cell with a measured heater, 30 % radiative, supply air, a bridge to the attic and a
# blind on its window, and an annex behind a partition: something for every effect to act on
HEATED = two_zones(TESTCELL)
HEATED["zones"][0].update(heat_input="heater", heat_input_radiative_fraction=0.3,
                          supply={"flow": 30.0, "temperature": "T_supply"}, thermal_bridges={"T_attic": 1.0})
next(c for c in HEATED["components"] if c["name"] == "window")["shading"] = "blind"

# A sensible value for every effect, on the test cell element it fits.
EFFECT_CASES = {
    "ground_coupling": ("floor", {"U": 2.0, "T_ground": 24.0}),
    "infiltration": ("cell", {"n": 1.5}),
    "internal_gain": ("cell", {"Q": 150.0}),
    "inside_convection": ("cell", {"factor": 1.3}),
    "solar_absorptance": ("roof", {"alpha": 0.6}),
    "conductivity": ("roof", {"factor": 2.0}),
    "solar_transmittance": ("window", {"tau": 0.6}),
    "thermal_bridge": ("cell", {"UA": 3.0}),
    "heat_input_split": ("cell", {"f_r": 0.6}),
    "daily_gain": ("cell", {"mean": 60.0, "cos1": -60.0, "sin1": -20.0, "cos2": 10.0, "sin2": 15.0}),
    "workday_gain": ("cell", {"mean": 80.0, "cos1": -70.0, "sin1": -25.0, "cos2": 12.0}),
    "proportional_gain": ("cell->heater", {"k": -0.2}),
    "internal_mass": ("cell", {"C_m": 4e5, "H_m": 60.0}),
    "heat_input_lag": ("cell", {"C_h": 3e4, "H_h": 12.0}),
    "envelope_conductance": ("cell", {"factor": 1.4}),
    "shading_transmittance": ("cell", {"f": 0.15}),
    "boundary_conductance": ("T_attic", {"factor": 0.7}),
    "supply_flow": ("cell", {"factor": 0.5}),
    "interzone_air_exchange": ("cell|annex", {"V": 80.0}),
    "heat_input_factor": ("cell", {"factor": 0.9}),
}


@pytest.fixture(scope="module")
def validator():
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    return jsonschema.Draft202012Validator(SCHEMA)


def errors(validator, data):
    return [f"{'/'.join(map(str, e.absolute_path))}: {e.message}" for e in validator.iter_errors(data)]


def test_schema_is_valid_draft_2020_12():
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    assert SCHEMA["$schema"] == "https://json-schema.org/draft/2020-12/schema"


def test_every_property_is_described():
    missing = []

    def walk(node, path):
        if isinstance(node, dict):
            for name, sub in node.get("properties", {}).items():
                if isinstance(sub, dict) and "description" not in sub and "$ref" not in sub:
                    missing.append(f"{path}/{name}")
            for key, sub in node.items():
                if key != "if":  # conditions only select a branch
                    walk(sub, f"{path}/{key}")
        elif isinstance(node, list):
            for i, sub in enumerate(node):
                walk(sub, f"{path}/{i}")

    walk(SCHEMA, "#")
    assert missing == []


@pytest.mark.parametrize("name", ["testcell.json", "testcell_miami.json"])
def test_bundled_buildings_validate(validator, name):
    data = json.loads((DATA / name).read_text())
    assert errors(validator, data) == []
    parse_building(data)


def test_every_effect_is_covered():
    assert set(EFFECT_CASES) == set(EFFECTS)


@pytest.mark.parametrize("effect", sorted(EFFECT_CASES))
def test_building_with_an_effect_validates_and_loads(validator, effect):
    target, values = EFFECT_CASES[effect]
    building = parse_building(HEATED)
    assert EFFECTS[effect].applies(building, target)
    data = EFFECTS[effect].apply(building, target, values).to_json()
    assert data != HEATED
    assert errors(validator, data) == []
    parse_building(data)


def test_building_with_all_effects_validates_and_loads(validator):
    building = parse_building(HEATED)
    for effect, (target, values) in EFFECT_CASES.items():
        building = EFFECTS[effect].apply(building, target, values)
    assert errors(validator, building.to_json()) == []
    b = parse_building(building.to_json())
    assert b.component("floor").outside == Boundary(temperature=24.0, h=2.0)
    assert b.component("roof").conductivity_factor == 2.0
    assert b.zone("cell").convection_factor == 1.3


def test_boundary_temperature_may_be_a_column_name(validator):
    data = copy.deepcopy(TESTCELL)
    data["components"][-1]["outside"] = {"type": "boundary", "temperature": "T_cellar", "h": 3.0}
    assert errors(validator, data) == []
    assert parse_building(data).input_columns == ("T_cellar",)


def _component(data, name):
    return next(c for c in data["components"] if c["name"] == name)


def _unknown_outside_type(d):
    _component(d, "floor")["outside"] = {"type": "ground"}


def _negative_area(d):
    _component(d, "roof")["area"] = -9.0


def _tilt_200(d):
    _component(d, "roof")["tilt"] = 200.0


def _missing_layers(d):
    del _component(d, "door")["layers"]


def _absorptance_1_5(d):
    _component(d, "roof")["outside"]["solar_absorptance"] = 1.5


def _zero_conductivity(d):
    d["materials"]["wood"]["conductivity"] = 0.0


def _boundary_without_h(d):
    _component(d, "floor")["outside"] = {"type": "boundary", "temperature": 20.0}


def _exterior_without_absorptance(d):
    del _component(d, "door")["outside"]["solar_absorptance"]


def _negative_air_change_rate(d):
    d["zones"][0]["air_change_rate"] = -0.5


def _zero_convection_factor(d):
    d["zones"][0]["convection_factor"] = 0.0


def _layer_without_thickness(d):
    _component(d, "door")["layers"] = [["wood"]]


def _latitude_100(d):
    d["site"]["latitude"] = 100.0


def _unknown_sky(d):
    d["site"]["sky_diffuse"] = "perez"


def _glazing_without_target(d):
    del _component(d, "window")["transmitted_solar_to"]


def _shading_leak_above_one(d):
    d["zones"][0]["shading_transmittance"] = 1.2


def _wrong_format(d):
    d["format"] = "nodal-building/2"


def _negative_boundary_factor(d):  # a field the file had not: the boundary_conductance effect's
    d["boundary_conductance_factors"] = {"T_cellar": -0.5}


def _unknown_field(d):
    d["boundary_factors"] = {"T_cellar": 0.5}


@pytest.mark.parametrize("mutate", [
    _unknown_outside_type, _negative_area, _tilt_200, _missing_layers, _absorptance_1_5,
    _zero_conductivity, _boundary_without_h, _exterior_without_absorptance,
    _negative_air_change_rate, _zero_convection_factor, _layer_without_thickness,
    _latitude_100, _unknown_sky, _glazing_without_target, _shading_leak_above_one, _wrong_format,
], ids=lambda f: f.__name__.strip("_"))
def test_wrong_file_is_refused_by_schema_and_parser(validator, mutate):
    data = copy.deepcopy(TESTCELL)
    mutate(data)
    assert errors(validator, data), "the schema accepts it"
    with pytest.raises(InputError):
        parse_building(data, source="cell.json")


def _window(d):
    return _component(d, "window")


# The rules the parser once checked by hand and the schema now states: each refused by the
# schema alone, and by parse_building naming the field (and, for a rule of fields that go
# together, the field that asks for the other).
SCHEMA_RULES = {
    "shading on an opaque component": (lambda d: _component(d, "roof").update(shading="blind"),
                                       "components[4]", "'solar_transmittance' is a required property (with shading)"),
    "angular transmittance on an opaque component": (
        lambda d: _component(d, "roof").update(angular_transmittance={"angles": [0, 60], "factors": [1, 0.5],
                                                                       "diffuse": 0.8}),
        "components[4]", "(with angular_transmittance)"),
    "solar distribution on an opaque component": (
        lambda d: _component(d, "roof").update(solar_distribution={"floor": 1.0}), "components[4]",
        "(with solar_distribution)"),
    "an empty solar distribution": (lambda d: _window(d).update(solar_distribution={}),
                                    "components[6].solar_distribution", "should be non-empty"),
    "inner absorptance behind an adiabatic face": (
        lambda d: _component(d, "floor").update(inner_solar_absorptance=0.1), "components[7].outside.type",
        "'exterior' was expected (with inner_solar_absorptance)"),
    "a heater's lag without a heat input": (
        lambda d: d["zones"][0].update(heat_input_lag={"capacity": 1.0, "conductance": 1.0}), "zones[0]",
        "'heat_input' is a required property (with heat_input_lag)"),
    "a heat input factor on a null heat input": (
        lambda d: d["zones"][0].update(heat_input=None, heat_input_factor=0.9), "zones[0].heat_input",
        "not be null (with heat_input_factor)"),
    "an air node without its radiant node": (lambda d: d["zones"][0].pop("radiant_node"), "zones[0]",
                                             "'radiant_node' is a dependency of 'air_node'"),
    "a schedule's hour past 24": (
        lambda d: d.update(schedules={"s": {"days": {"a": [[25, 1.0]]},
                                            "periods": [{"through": "12-31", "week": ["a"] * 7}]}}),
        "schedules.s.days.a[0][0]", "25 is greater than the maximum of 24"),
    "a schedule's date in month 13": (
        lambda d: d.update(schedules={"s": {"days": {"a": [[24, 1.0]]},
                                            "periods": [{"through": "13-01", "week": ["a"] * 7}]}}),
        "schedules.s.periods[0].through", "does not match"),
    "a sensor named as a node column": (lambda d: d.update(sensors={"T7": {"zone": "cell"}}), "sensors.T7",
                                        "must not look like a node column"),
}


@pytest.mark.parametrize("rule", SCHEMA_RULES)
def test_rules_of_fields_are_the_schemas_and_name_the_field(validator, rule):
    change, field, says = SCHEMA_RULES[rule]
    data = copy.deepcopy(TESTCELL)
    change(data)
    assert errors(validator, data), "the schema accepts it"
    with pytest.raises(InputError) as refused:
        parse_building(data, source="cell.json")
    assert (refused.value.source, refused.value.field) == ("cell.json", field)
    assert says in refused.value.problem


@pytest.mark.parametrize("value, says", [(float("nan"), "nan is not of type 'number'"),
                                         (float("inf"), "inf is not of type 'number'")])
def test_a_number_that_json_has_not_is_refused(value, says):
    """Python's json reads NaN and Infinity, which a plain JSON Schema validator takes for numbers
    and compares as false with any bound: the parser's schema refuses them."""
    data = copy.deepcopy(TESTCELL)
    data["zones"][0]["volume"] = value
    with pytest.raises(InputError, match=r"zones\[0\]\.volume: " + says):
        parse_building(data, source="cell.json")


def test_a_node_id_is_a_json_integer(validator):
    data = copy.deepcopy(TESTCELL)
    _component(data, "roof")["nodes"][0]["id"] = float(_component(data, "roof")["nodes"][0]["id"])
    assert errors(validator, data) == []  # JSON Schema's integer holds 1.0
    with pytest.raises(InputError, match=r"components\[4\]\.nodes\[0\]\.id: .* is not of type 'integer'"):
        parse_building(data, source="cell.json")


@pytest.mark.parametrize("mutate", [
    _unknown_outside_type, _negative_area, _missing_layers, _absorptance_1_5, _zero_conductivity,
    _negative_air_change_rate, _latitude_100, _glazing_without_target, _wrong_format,
    _negative_boundary_factor, _unknown_field, *(change for change, _, _ in SCHEMA_RULES.values()),
], ids=lambda f: getattr(f, "__name__", "rule").strip("_"))
def test_an_edit_is_refused_as_the_file_it_makes_would_be(mutate):
    """An edit (an effect's, at each step of a calibration) is checked against the schema where it
    changed the building only: with the same words as the whole file it makes."""
    data = copy.deepcopy(TESTCELL)
    mutate(data)
    with pytest.raises(InputError) as whole:
        parse_building(data, source="cell.json")
    with pytest.raises(InputError) as edit:
        parse_building(TESTCELL, source="cell.json").edited(mutate)
    assert str(edit.value) == str(whole.value)


def test_the_checks_references_inlined_find_the_errors_of_the_schema_as_written():
    """The parser's validators have the schema's references inlined (a reference is resolved at
    every visit): on random changes of a file, of each field and of each item an edit checks
    alone, they find the error the schema as written finds, at the same field, in the same words,
    of the same rule."""
    import random

    from nodeforce.model.building_file import ITEMS, _validator

    def as_written(definition):
        schema = SCHEMA if definition is None else {"$defs": SCHEMA["$defs"], "$ref": f"#/$defs/{definition}"}
        types = _validator(None).TYPE_CHECKER  # the parser's finite numbers and int ids
        return jsonschema.validators.extend(jsonschema.Draft202012Validator, type_checker=types)(schema)

    def best(validator, instance):
        e = jsonschema.exceptions.best_match(validator.iter_errors(instance))
        return e and (list(e.absolute_path), e.message, e.validator, e.schema.get("description"))

    def places(node, path=()):
        yield path
        children = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
        for key, child in children:
            yield from places(child, (*path, key))

    rng = random.Random(45)
    values = [None, "x", "", -1, 0, 2, 1.5, -1e-3, 1e9, True, [], {}, [1], {"a": 1}, "outdoor", [0.0, 1.0]]
    checks = [(None, HEATED)] + [(ITEMS[key], item) for key in ITEMS for item in HEATED[key]]
    found = 0
    for definition, instance in checks:
        inlined, written = _validator(definition), as_written(definition)
        assert best(inlined, instance) is None and best(written, instance) is None
        where = [p for p in places(instance) if p]
        for _ in range(80):
            changed = copy.deepcopy(instance)
            *parent_path, key = rng.choice(where)
            parent = changed
            for k in parent_path:
                parent = parent[k]
            if rng.random() < 0.7:
                parent[key] = copy.deepcopy(rng.choice(values))
            else:
                del parent[key]
            error = best(written, changed)
            found += error is not None
            assert best(inlined, changed) == error
    assert found > 40 * len(checks)  # most changes break a rule: the comparison is of errors, not of silence


def test_the_parser_reads_its_defaults_from_the_schema(monkeypatch):
    """An optional field the file leaves out takes the schema's `default`, the one place it is
    written: a default changed there is what the parser gives (and the air's density the
    network's default, `model.network.AIR_DENSITY`)."""
    from nodeforce.model import building_file, network
    bare = copy.deepcopy(TESTCELL)
    del bare["site"]["ground_albedo"]
    plain = parse_building(bare)
    assert plain.site["ground_albedo"] == SCHEMA["$defs"]["site"]["properties"]["ground_albedo"]["default"]
    assert plain.zones[0].envelope_factor == SCHEMA["$defs"]["zone"]["properties"]["envelope_factor"]["default"]
    assert network.AIR_DENSITY == SCHEMA["$defs"]["site"]["properties"]["air_density"]["default"]
    edited = copy.deepcopy(building_file.SCHEMA)
    edited["$defs"]["site"]["properties"]["ground_albedo"]["default"] = 0.35
    edited["$defs"]["zone"]["properties"]["envelope_factor"]["default"] = 1.5
    edited["$defs"]["component"]["properties"]["capacity_factor"]["default"] = 2.0
    monkeypatch.setattr(building_file, "SCHEMA", edited)
    changed = building_file.parse_checked(bare)
    assert changed.site["ground_albedo"] == 0.35 and changed.zones[0].envelope_factor == 1.5
    assert all(c.capacity_factor == 2.0 for c in changed.components if "capacity_factor" not in
               next(raw for raw in TESTCELL["components"] if raw["name"] == c.name))
