"""A diagnosis's corrections written back into the EnergyPlus model a building file was converted
from (`model_after.idf`, docs/guide.md): each effect applied to the objects it belongs to, every
other object left as the user wrote it (idfkit keeps their text). An effect no EnergyPlus object
holds (a shape in time, a heater's lag, a factor on a zone's envelope) is said so, not forced in.
"""
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from ..model import glazing
from ..model.building import MASS_EMISSIVITY, MASS_SOLAR_ABSORPTANCE, WORKDAY_TERMS, mass_area
from ..model.case import day_basis
from ..model.effects import CONSTRUCTION, EFFECTS, MATERIAL, members
from .energyplus import SCHEMA_MIN, _field

ALWAYS_ON = "nodeforce always on"
# The single layer an InternalMass the diagnosis adds is made of: thin and conductive, so that
# its capacity acts as the lumped node's (its conduction resistance 0.02 m2K/W beside 1/h_c)
MASS_THICKNESS, MASS_CONDUCTIVITY, MASS_DENSITY = 0.02, 1.0, 1000.0  # m, W/m/K, kg/m3


def idf_of(building):
    """The IDF a building file was converted from (its `energyplus.idf`, relative to the file), or None."""
    source = (building.data.get("energyplus") or {}).get("idf")
    if source is None:
        return None
    return Path(building.source).parent / source


def write_corrections(before, after, effects, idf, out):
    """Write `out`, the IDF `idf` with the `effects` (the diagnosis's added effects, (effect,
    target) pairs) applied as `after` (the corrected building) holds them; return
    {"idf_after", "changes": [{"object", "name", "field", "old", "new"}], "not_written": [str]}."""
    import idfkit
    doc = idfkit.load_idf(str(idf), preserve_formatting=True,
                          version=None if tuple(idfkit.get_idf_version(str(idf))[:2]) >= SCHEMA_MIN[:2] else SCHEMA_MIN)
    writer = _Writer(doc, before, after)
    for effect, target in effects:
        handler = EFFECTS[effect].energyplus  # the effect's record says how it is written back
        if handler is None:
            writer.not_written.append(f"{effect} on {target}: no EnergyPlus object holds it; "
                                      "the corrected building file carries it")
        else:
            handler(writer, target)
    idfkit.save_idf(doc, str(out))
    return {"idf_after": str(out), "changes": writer.changes, "not_written": writer.not_written}


class _Writer:
    def __init__(self, doc, before, after):
        self.doc, self.before, self.after = doc, before, after
        self.changes, self.not_written = [], []

    def _objects(self, kind):
        return [o for o in self.doc.all_objects if o.obj_type.upper() == kind.upper()]

    def _get(self, kinds, name):
        for o in self.doc.all_objects:
            if o.obj_type.upper() in [k.upper() for k in kinds] and str(o.name).upper() == str(name).upper():
                return o
        return None

    def _set(self, obj, field, value):
        old = _field(obj, field)
        setattr(obj, field, value)
        self.changes.append({"object": obj.obj_type, "name": obj.name, "field": field, "old": old, "new": value})

    def _add(self, kind, name, fields):
        obj = self.doc.add(kind, name, fields)
        self.changes.append({"object": kind, "name": name, "field": "(new object)", "old": None, "new": fields})
        return obj

    def _always_on(self):
        if self._get(("Schedule:Constant",), ALWAYS_ON) is None:
            self._add("Schedule:Constant", ALWAYS_ON, {"hourly_value": 1.0})
        return ALWAYS_ON

    # ---- the corrections an effect's record writes back (`model.effects.Effect.energyplus`) ----
    def infiltration(self, zone):
        z0, z1 = self.before.zone(zone), self.after.zone(zone)
        delta = (z1.air_change_rate - z0.air_change_rate) * z0.volume / 3600.0  # m3/s
        for o in self._objects("ZoneInfiltration:DesignFlowRate"):
            if str(_field(o, "zone_or_zonelist_name")).upper() != zone.upper():
                continue
            method = str(_field(o, "design_flow_rate_calculation_method")).lower()
            schedule = self._get(("Schedule:Constant",), _field(o, "schedule_name"))
            scale = float(_field(o, "constant_term_coefficient") or 1.0) * (
                float(schedule.hourly_value) if schedule is not None else 1.0)
            if scale <= 0:
                continue
            if method == "flow/zone":
                self._set(o, "design_flow_rate", float(_field(o, "design_flow_rate")) + delta / scale)
                return
            if method == "airchanges/hour":
                self._set(o, "air_changes_per_hour",
                          float(_field(o, "air_changes_per_hour")) + (z1.air_change_rate - z0.air_change_rate) / scale)
                return
        # no object of this zone alone to change: one more, of the added flow
        self._add("ZoneInfiltration:DesignFlowRate", f"nodeforce infiltration {zone}",
                  {"zone_or_zonelist_name": zone, "schedule_name": self._always_on(),
                   "design_flow_rate_calculation_method": "Flow/Zone", "design_flow_rate": delta,
                   "constant_term_coefficient": 1, "temperature_term_coefficient": 0,
                   "velocity_term_coefficient": 0, "velocity_squared_term_coefficient": 0})

    def internal_gain(self, zone):
        Q = self.after.zone(zone).internal_gain - self.before.zone(zone).internal_gain
        self._add("OtherEquipment", f"nodeforce gain {zone}",
                  {"fuel_type": "None", "zone_or_zonelist_name": zone, "schedule_name": self._always_on(),
                   "design_level_calculation_method": "EquipmentLevel", "design_level": Q,
                   "fraction_latent": 0, "fraction_radiant": 0, "fraction_lost": 0})

    def workday_gain(self, zone):
        """The added profile, each hour's mean (W), on EnergyPlus's weekdays and 0 on every other
        day: an OtherEquipment of 1 W on a Schedule:Compact of its positive part, and where it
        dips below zero one of -1 W on its negative part (EnergyPlus refuses a gain's schedule
        value below 0, not a negative design level)."""
        terms = {t: dict(self.after.zone(zone).workday_gain).get(t, 0.0) - dict(self.before.zone(zone).workday_gain).get(t, 0.0)
                 for t in WORKDAY_TERMS}
        minutes = (np.arange(24 * 60) + 0.5) / 60.0  # h, each minute's middle
        profile = terms["mean"] + sum(W * day_basis(minutes, t) for t, W in terms.items() if t != "mean")
        hourly = profile.reshape(24, 60).mean(axis=1)
        for sign, part, suffix in ((1.0, np.maximum(hourly, 0.0), ""), (-1.0, np.maximum(-hourly, 0.0), " (negative)")):
            if not part.any():
                continue
            name = f"nodeforce workday gain {zone}{suffix}"
            fields = ["Through: 12/31", "For: Weekdays"]
            for hour, W in enumerate(part, 1):
                fields += [f"Until: {hour:02d}:00", f"{W:.6g}"]
            fields += ["For: AllOtherDays", "Until: 24:00", "0"]
            self._add("Schedule:Compact", name, {"data": [{"field": f} for f in fields]})
            self._add("OtherEquipment", name,
                      {"fuel_type": "None", "zone_or_zonelist_name": zone, "schedule_name": name,
                       "design_level_calculation_method": "EquipmentLevel", "design_level": sign,
                       "fraction_latent": 0, "fraction_radiant": 0, "fraction_lost": 0})

    def internal_mass(self, zone):
        mass = self.after.zone(zone).internal_mass
        area = mass_area(mass)
        # EnergyPlus holds an InternalMass's other face at its first's temperature: a single
        # layer stores through the zone's face as half its thickness would, so it is twice C_m
        specific_heat = 2.0 * mass.capacity / (area * MASS_THICKNESS * MASS_DENSITY)
        name = f"nodeforce mass {zone}"
        self._add("Material", name, {"roughness": "MediumSmooth", "thickness": MASS_THICKNESS,
                                     "conductivity": MASS_CONDUCTIVITY, "density": MASS_DENSITY,
                                     "specific_heat": specific_heat, "thermal_absorptance": MASS_EMISSIVITY,
                                     "solar_absorptance": MASS_SOLAR_ABSORPTANCE})
        self._add("Construction", name, {"outside_layer": name})
        self._add("InternalMass", name, {"construction_name": name, "zone_or_zonelist_name": zone,
                                         "surface_area": area})

    def _surface(self, component):
        kinds = ("BuildingSurface:Detailed", "Wall:Detailed", "RoofCeiling:Detailed", "Floor:Detailed",
                 "FenestrationSurface:Detailed", "Window", "Door", "GlazedDoor")
        return self._get(kinds, component)

    def _own_construction(self, surface, layers):
        """A new Construction of `layers` for this surface alone, named after it."""
        name = f"{_field(surface, 'construction_name')} for {surface.name} (nodeforce)"
        self._add("Construction", name, _layer_fields(layers))
        self._set(surface, "construction_name", name)

    def _layers(self, construction):
        return [v for k, v in construction.to_dict().items() if k != "name" and v not in (None, "")]

    def _material(self, name):
        return self._get(("Material", "Material:NoMass", "Material:AirGap", "WindowMaterial:Glazing",
                          "WindowMaterial:Gas", "WindowMaterial:SimpleGlazingSystem"), name)

    def _copy(self, obj, suffix, changes):
        fields = {k: v for k, v in obj.to_dict().items() if k != "name"}
        fields.update(changes)
        name = f"{obj.name} {suffix}"
        self._add(obj.obj_type, name, fields)
        return name

    def _relayer(self, target, change):
        """Give `target`'s construction the layers `change(layers)` returns (its material names,
        outside first; None: nothing written): a `construction:` target's Construction object
        itself, every surface built of it with it, as the modeller would; a component's surface
        a Construction of its own, the others of its construction left as they are."""
        if target.startswith(CONSTRUCTION):
            construction = self._get(("Construction",), target[len(CONSTRUCTION):])
            layers = change(self._layers(construction))
            if layers is not None:
                for field, value in _layer_fields(layers).items():
                    if _field(construction, field) != value:
                        self._set(construction, field, value)
            return
        surface = self._surface(target)
        layers = change(self._layers(self._get(("Construction",), _field(surface, "construction_name"))))
        if layers is not None:
            self._own_construction(surface, layers)

    def _partition(self, target):
        """Whether a component of `target` is a partition, whose construction is its pair's too."""
        surfaces = [self._surface(name) for name in members(self.before, target)]
        return any(s is None or str(_field(s, "outside_boundary_condition") or "").lower() in ("surface", "zone")
                   for s in surfaces)

    def conductivity(self, target):
        factor = EFFECTS["conductivity"].read(self.after, target)["factor"]
        if target.startswith(MATERIAL):
            m = self._material(target[len(MATERIAL):])
            if m is not None and m.obj_type.upper() == "MATERIAL":
                self._set(m, "conductivity", float(m.conductivity) * factor)
            elif m is not None and m.obj_type.upper() in ("MATERIAL:NOMASS", "MATERIAL:AIRGAP"):
                self._set(m, "thermal_resistance", float(m.thermal_resistance) / factor)
            else:
                self.not_written.append(f"conductivity on {target}: no opaque Material of that name; the factor "
                                        f"{factor:.4g} is in the corrected building file")
            return
        if self._partition(target):
            self.not_written.append(f"conductivity on {target}: a partition's construction is its pair's too; "
                                    f"the factor {factor:.4g} is in the corrected building file")
            return

        def scaled(names):
            layers = []
            for name in names:
                m = self._material(name)
                kind = m.obj_type.upper()
                if kind == "MATERIAL":
                    layers.append(self._copy(m, f"x{factor:.4g}", {"conductivity": float(m.conductivity) * factor}))
                elif kind in ("MATERIAL:NOMASS", "MATERIAL:AIRGAP"):
                    layers.append(self._copy(m, f"x{factor:.4g}",
                                             {"thermal_resistance": float(m.thermal_resistance) / factor}))
                else:
                    self.not_written.append(f"conductivity on {target}: a window's layers are not scaled; the "
                                            f"factor {factor:.4g} is in the corrected building file")
                    return None
            return layers
        self._relayer(target, scaled)

    def solar_absorptance(self, target):
        alpha = EFFECTS["solar_absorptance"].read(self.after, target)["alpha"]

        def absorbing(layers):
            outer = self._material(layers[0])
            if outer.obj_type.upper() not in ("MATERIAL", "MATERIAL:NOMASS"):
                self.not_written.append(f"solar_absorptance on {target}: its outer layer {outer.name} has none")
                return None
            return [self._copy(outer, f"alpha {alpha:.4g}", {"solar_absorptance": alpha}), *layers[1:]]
        self._relayer(target, absorbing)

    def solar_transmittance(self, target):
        tau = EFFECTS["solar_transmittance"].read(self.after, target)["tau"]

        def transmitting(layers):
            objs = [self._material(n) for n in layers]
            kinds = [o.obj_type.upper() for o in objs]
            if kinds == ["WINDOWMATERIAL:SIMPLEGLAZINGSYSTEM"]:
                U = float(objs[0].u_factor)
                shgc = brentq(lambda s: glazing.simple_glazing_transmittance(U, s) - tau, 1e-4, 1.0)
                return [self._copy(objs[0], f"tau {tau:.4g}", {"solar_heat_gain_coefficient": shgc})]
            panes = [(float(o.solar_transmittance_at_normal_incidence),
                      float(o.front_side_solar_reflectance_at_normal_incidence))
                     for o in objs if o.obj_type.upper() == "WINDOWMATERIAL:GLAZING"]
            R0 = panes[0][1]
            top = 1.0 - R0 - 1e-6
            T0 = brentq(lambda t: float(glazing.stack_transmittance([(t, R0)] + panes[1:], 0.0)) - tau, 1e-4, top)
            return [self._copy(objs[0], f"tau {tau:.4g}", {"solar_transmittance_at_normal_incidence": T0}),
                    *layers[1:]]
        self._relayer(target, transmitting)


def _layer_fields(layers):
    """The layer fields of a Construction of `layers` (material names, outside first)."""
    return {"outside_layer": layers[0], **{f"layer_{k}": n for k, n in enumerate(layers[1:], start=2)}}
