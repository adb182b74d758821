"""The nodal building model as an FMI 2.0 co-simulation slave (pythonfmu).

This file is copied into each FMU as `<module>.py`, with the physics package beside it as
`<module>_model` and the building description as `resources/building.json`; `<module>` is unique
to the FMU's content, because pythonfmu imports the slave by module name and Python's module
cache would otherwise run the first FMU's code for the second.

Variables (INTERFACE.md): parameters `force[i]` and `T_start`; inputs `T_out`, `T_sky`,
`I_<component>`, the building's named columns and `T_forced[i]` (NaN: no measurement);
outputs `T[i]`. One doStep of h seconds is one backward-Euler step with the inputs set before
it. During initialisation, the `T_forced[i]` values set are the measurements at t_0, from which
the initial state follows PHYSICS.md section 5 (`T_start` where nothing is measured).
"""
import importlib
import json
import os

import numpy as np
from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Initial

_physics = {name: importlib.import_module(f"{__name__}_model.{name}")
             for name in ("building", "effects", "integrate", "network")}

# Reset re-constructs the slave: keep what depends only on the model's description per process,
# for each set of effect parameter values (a calibration tries many), and its declared variables.
_MODELS = {}
_VARIABLES = {}


def _read(resources):
    """The building data and the added effect ((id, target) or None) an FMU carries."""
    with open(os.path.join(resources, "building.json"), encoding="utf-8") as f:
        data = json.load(f)
    effect = None
    path = os.path.join(resources, "effect.json")
    if os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            spec = json.load(f)
        effect = (spec["effect"], spec["target"])
    return data, effect


def _model(resources, values=()):
    """(building, network, steppers) for the FMU's building with its effect at `values`."""
    key = (resources, values)
    model = _MODELS.get(key)
    if model is None:
        data, effect = _read(resources)
        building = _physics["building"].parse_building(data, source="building.json")
        if values:
            effect_id, target = effect
            building = _physics["effects"].EFFECTS[effect_id].apply(building, target, dict(values))
        model = _MODELS[key] = (building, _physics["network"].assemble(building), {})
    return model


class NodalBuilding(Fmi2Slave):

    author = "nodeforce"
    description = "Nodal (RC network) building thermal model with a forcing input per node"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        _, self._effect = _read(self.resources)
        self.building, self.network, self._steppers = _model(self.resources)
        n = self.network.n_nodes
        names = self.network.input_names
        effect_start = (_physics["effects"].EFFECTS[self._effect[0]].read(self.building, self._effect[1])
                        if self._effect else {})
        self._parameter_names = tuple(effect_start)
        # One array holds every variable's value, indexed by value reference, in the order the
        # variables are declared: get/set become numpy indexing instead of per-variable getters.
        self._T_start = n
        self._inputs = slice(n + 1, n + 1 + len(names))
        self._forced = slice(self._inputs.stop, self._inputs.stop + n)
        self._T = slice(self._forced.stop, self._forced.stop + n)
        self._parameters = slice(self._T.stop, self._T.stop + len(effect_start))
        self._values = np.zeros(self._parameters.stop)
        self._values[self._T_start] = 20.0
        self._values[self._forced] = np.nan
        self._values[self._T] = 20.0
        self._values[self._parameters] = list(effect_start.values())
        self._is_real = np.ones(len(self._values), dtype=bool)
        self._is_real[:n] = False
        # Every accessor reads self._values, so the declarations are the same for every instance
        # of this FMU: made once, not again at each Reset.
        declared = _VARIABLES.get(self.resources)
        if declared is None:
            self._declare(n, names)
            _VARIABLES[self.resources] = self.vars
        else:
            self.vars = declared
        self._force = np.zeros(n, dtype=bool)
        self._any_forced = False
        self._indices = {}
        self._initialised = False

    def _declare(self, n, names):
        """Register the variables, in the order of the value array's layout."""
        for i in range(1, n + 1):
            self.register_variable(Boolean(
                f"force[{i}]", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
                description=f"node {i} is forced to T_forced[{i}]"))
        self.register_variable(Real(
            "T_start", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description="initial temperature of a node no measurement informs [degC]"))
        for name in names:
            self.register_variable(Real(name, causality=Fmi2Causality.input,
                                        description=_input_description(name)))
        for i in range(1, n + 1):
            self.register_variable(Real(
                f"T_forced[{i}]", causality=Fmi2Causality.input,
                description=f"measured temperature of node {i}, NaN if none [degC]"))
        for i in range(1, n + 1):
            self.register_variable(Real(
                f"T[{i}]", causality=Fmi2Causality.output, initial=Fmi2Initial.exact,
                description=f"temperature of node {i} [degC]"))
        for name in self._parameter_names:
            self.register_variable(Real(
                f"{self._effect[0]}.{name}", causality=Fmi2Causality.parameter,
                variability=Fmi2Variability.fixed,
                description=f"{self._effect[0]} of {self._effect[1]}: {name}"), nested=False)

    def _stepper(self, dt):
        stepper = self._steppers.get(dt)
        if stepper is None:
            stepper = self._steppers[dt] = _physics["integrate"].ImplicitEuler(self.network, dt)
        return stepper

    def exit_initialization_mode(self):
        # force[i] and the effect parameters are fixed once initialised: read them once here
        self._force = self._values[: self.network.n_nodes] != 0.0
        self._any_forced = bool(self._force.any())
        if self._parameter_names:
            values = tuple(zip(self._parameter_names, self._values[self._parameters].tolist()))
            self.building, self.network, self._steppers = _model(self.resources, values)
        self._values[self._T] = _physics["integrate"].initial_state(
            self.building, self._values[self._forced], self._values[self._T_start])
        self._initialised = True

    def do_step(self, current_time, step_size):
        values = self._values
        T_forced = values[self._forced]
        forced = _physics["integrate"].imposed(self._force, T_forced) if self._any_forced else self._force
        source = self.network.sources(values[self._inputs])
        values[self._T] = self._stepper(step_size).step(values[self._T], source, forced, T_forced)
        return True

    def _index(self, vrs, real):
        """Index array of value references, checked once to be all Real (or all Boolean):
        an importer sets and gets the same lists every step."""
        key = (tuple(vrs), real)
        index = self._indices.get(key)
        if index is None:
            index = np.array(vrs, dtype=np.intp)
            if (self._is_real[index] != real).any():
                raise TypeError(f"value references {vrs} are not all {'Real' if real else 'Boolean'}")
            self._indices[key] = index
        return index

    def get_real(self, vrs):
        return self._values[self._index(vrs, True)].tolist()

    def set_real(self, vrs, values):
        self._values[self._index(vrs, True)] = values

    def get_boolean(self, vrs):
        return (self._values[self._index(vrs, False)] != 0.0).tolist()

    def set_boolean(self, vrs, values):
        self._values[self._index(vrs, False)] = values

    def _get_fmu_state(self):
        return {"values": self._values.copy(), "initialised": self._initialised}

    def _set_fmu_state(self, state):
        self._values[:] = state["values"]
        self._initialised = state["initialised"]

    @staticmethod
    def _fmu_state_to_bytes(state):
        # json writes NaN as a bare token, which json reads back: no value is lost.
        return json.dumps({"values": np.asarray(state["values"]).tolist(),
                           "initialised": state["initialised"]}).encode("utf-8")

    @staticmethod
    def _fmu_state_from_bytes(data):
        state = json.loads(data.decode("utf-8"))
        return {"values": np.array(state["values"]), "initialised": state["initialised"]}

    def to_xml(self, model_options=dict()):
        xml = super().to_xml(model_options)
        # Python writes NaN as "nan"; xs:double spells it "NaN".
        for element in xml.iter("Real"):
            if element.get("start") == "nan":
                element.set("start", "NaN")
        return xml


def _input_description(name):
    if name == "T_out":
        return "outdoor air temperature [degC]"
    if name == "T_sky":
        return "sky temperature [degC]"
    if name.startswith("I_"):
        return f"solar irradiance on the outside face of {name[2:]} [W/m2]"
    return f"measured input column {name}"

