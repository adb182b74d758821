"""The nodal building model as an FMI 2.0 co-simulation slave (pythonfmu).

This file is copied into each FMU as `<module>.py`, with the physics package beside it as
`<module>_model` and the building description as `resources/building.json`; `<module>` is unique
to the FMU's content, because pythonfmu imports the slave by module name and Python's module
cache would otherwise run the first FMU's code for the second.

Variables: `<module>_model/variables.py` (the layout the standalone FMU shares). The inputs set
before doStep(t, h) are those at t, and their first derivatives (set through the guard from
fmi2SetRealInputDerivatives, zero when not given) make them linear over the step: doStep takes
k = ceil(h / max_step) backward-Euler steps of h / k, each with the inputs and the imposed
temperatures at its end, u(t) + u'(t) tau. The derivatives hold for that one step. A node with
`force[i]` is imposed over the step where T_forced[i] at t is not NaN. The state at the start is
`T_start[i]`, with the model of the parameters set before initialisation ends (the building's
properties and an added effect's: `model.effects.fmu_parameters`). Calls the standard forbids,
and a value set that is not finite (but a measurement's NaN), are refused with a logged reason,
and change nothing.

The step needs numpy only: an FMU that imports scipy corrupts memory when the host ends.
"""
import sys

if sys.version_info < (3, 10):
    raise ImportError(f"this FMU's model code needs Python 3.10 or newer; the host runs Python "
                      f"{sys.version.split()[0]} (see documentation/index.html in the FMU)")

import functools
import importlib
import json
import os
from collections import OrderedDict

import numpy as np
from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Status

_physics = {name: importlib.import_module(f"{__name__}_model.{name}")
            for name in ("building_file", "effects", "integrate", "network", "variables")}
_variables = _physics["variables"]


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


# Reset re-constructs the slave: keep per process what depends only on the model's description,
# for the few sets of parameter values last used (a calibration tries many, in turn).
@functools.lru_cache(maxsize=8)
def _model(resources, values=()):
    """(building, network, steppers by dt) of the FMU's building with the parameters of `values`
    ((name, value) pairs, those that differ from the declared ones) set."""
    data, effect = _read(resources)
    building = _physics["building_file"].parse_checked(data, source="building.json")
    if not values:
        return building, _physics["network"].assemble(building), {}
    # the FMU's inputs are those of the building as declared, in its order: the effect's network
    # takes its columns in that order (a bridge to a column moves the column in the building's own)
    inputs = _model(resources)[1].input_names
    building = _physics["effects"].with_fmu_parameters(building, effect, dict(values))
    return building, _physics["network"].assemble(building, inputs), {}


@functools.lru_cache(maxsize=8)
def _parameter_start(resources):
    """{name: declared value} of the FMU's parameters but forcing and start values."""
    return _physics["effects"].fmu_parameters(_model(resources)[0], _read(resources)[1])


class NodalBuilding(Fmi2Slave):

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        # pythonfmu's binary puts the resources folder first on sys.path and leaves it there; its
        # copy of pythonfmu (no binaries) would shadow the host's own. The model is imported by
        # now. (pythonfmu's builder, which instantiates "dummyInstance", removes the entry itself.)
        while self.instance_name != "dummyInstance" and self.resources in sys.path:
            sys.path.remove(self.resources)
        _, self._effect = _read(self.resources)
        self.building, self.network, self._steppers = _model(self.resources)
        start = _parameter_start(self.resources)
        self._parameter_start = np.array(list(start.values()), dtype=float)
        layout = self.layout = _variables.Layout(self.network.n_nodes, self.network.input_names, start)
        self._values = np.zeros(layout.derivatives.stop)
        self._values[layout.max_step] = _physics["integrate"].MAX_STEP
        self._values[layout.T_start] = 20.0
        self._values[layout.T_forced] = np.nan
        self._values[layout.T] = 20.0
        self._values[layout.parameters] = self._parameter_start
        self._time = 0.0
        self._force = np.zeros(layout.n_nodes, dtype=bool)
        self._any_forced = False
        self._checked = OrderedDict()
        self._state = _variables.INSTANTIATED

    def _refuse(self, reason):
        self.log(reason, Fmi2Status.error)
        return False

    def _index(self, vrs, real, setting):
        """Index array of value references, or the reason the call is refused; kept for the
        lists an importer sets and gets at every step."""
        key = (tuple(vrs), real, setting, self._state)
        found = self._checked.get(key)
        if found is None:
            reasons = [self.layout.refusal(vr, real, setting, self._state) for vr in key[0]]
            reason = next((r for r in reasons if r), None)
            found = reason if reason else np.array(key[0], dtype=np.intp)
            self._checked[key] = found
            if len(self._checked) > 64:
                self._checked.popitem(last=False)
        return found

    def _get(self, vrs, real):
        index = self._index(vrs, real, False)
        if isinstance(index, str):
            raise ValueError(index)
        values = self._values[index]
        return (values if real else values != 0.0).tolist()

    def _set(self, vrs, values, real):
        index = self._index(vrs, real, True)
        if isinstance(index, str):
            raise ValueError(index)
        values = np.asarray(values, dtype=float)
        if real and not np.isfinite(values).all():  # a NaN is refused but in a measurement (layout)
            # `_index` allowed every reference: only a value that is not finite may be refused
            bad = ~np.isfinite(values) & ~self.layout.takes_nan(index)
            for vr, value in zip(index[bad].tolist(), values[bad].tolist()):
                reason = self.layout.refusal(vr, real, True, self._state, value, self._time)
                if reason:
                    raise ValueError(reason)
        self._values[index] = values

    def get_real(self, vrs):
        return self._get(vrs, True)

    def get_boolean(self, vrs):
        return self._get(vrs, False)

    def set_real(self, vrs, values):
        self._set(vrs, values, True)

    def set_boolean(self, vrs, values):
        self._set(vrs, values, False)

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self._time = float(start_time)

    def enter_initialization_mode(self):
        self._state = _variables.INITIALISATION

    def _fix_parameters(self):
        """force[i] and the other parameters are fixed once initialised: read them once; the
        model is the building with those that differ from the declared values set."""
        layout = self.layout
        self._force = self._values[layout.force] != 0.0
        self._any_forced = bool(self._force.any())
        values = self._values[layout.parameters]
        changed = np.flatnonzero(values != self._parameter_start)
        self.building, self.network, self._steppers = _model(
            self.resources, tuple((layout.parameter_names[k], float(values[k])) for k in changed))

    def exit_initialization_mode(self):
        # the start values alone set the state: what an importer applies as inputs at t_0 does not
        self._fix_parameters()
        self._values[self.layout.T] = self._values[self.layout.T_start]
        self._state = _variables.STEPPING

    def do_step(self, current_time, step_size):
        if self._state != _variables.STEPPING:
            return self._refuse("doStep before initialisation ended, or after terminate")
        if not step_size > 0.0:
            return self._refuse(f"doStep with communicationStepSize {step_size} s: it must be > 0")
        values, layout = self._values, self.layout
        if not values[layout.max_step] > 0.0:
            return self._refuse(f"value reference {layout.max_step} (max_step) is {values[layout.max_step]} s: "
                                "it must be > 0")
        if step_size / values[layout.max_step] > _variables.MAX_SUBSTEPS:
            return self._refuse(f"doStep of {step_size} s is more than {_variables.MAX_SUBSTEPS} steps of max_step = "
                                f"{values[layout.max_step]} s: set max_step larger")
        k = max(1, int(np.ceil(step_size / values[layout.max_step] - 1e-9)))
        tau = step_size / k
        n_in = len(layout.input_names)
        u, T_forced = values[layout.inputs], values[layout.T_forced]
        du, dT_forced = values[layout.derivatives][:n_in], values[layout.derivatives][n_in:]
        forced = _physics["integrate"].imposed(self._force, T_forced) if self._any_forced else self._force
        stepper = self._steppers.get(tau)
        if stepper is None:
            stepper = self._steppers[tau] = _physics["integrate"].ImplicitEuler(self.network, tau)
        T = values[layout.T]
        # each sub-step's inputs and imposed temperatures at its end, their sources at once; inputs
        # held over the step give one row for every sub-step
        s = tau * np.arange(1, k + 1)[:, None]
        held = not du.any()
        u_s = u[None] if held else u + du * s
        sources, switched = self.network.sources(u_s), self.network.switched_diagonal(u_s)
        T_s = T_forced + dT_forced * s
        for j in range(k):
            i = 0 if held else j
            T = stepper.step(T, sources[i], forced, T_s[j], None if switched is None else switched[i], u_s[i])
        values[layout.T] = T
        values[layout.derivatives] = 0.0  # the next step's are set before it, or it holds its inputs
        self._time = current_time + step_size
        return True

    def terminate(self):
        self._state = _variables.TERMINATED

    def _get_fmu_state(self):
        return {"values": self._values.copy(), "state": self._state}

    def _set_fmu_state(self, state):
        self._values[:] = state["values"]
        self._state = state["state"]
        if self._state == _variables.STEPPING:
            self._fix_parameters()

    @staticmethod
    def _fmu_state_to_bytes(state):
        # json writes NaN as a bare token, which json reads back: no value is lost.
        return json.dumps({"values": np.asarray(state["values"]).tolist(),
                           "state": state["state"]}).encode("utf-8")

    @staticmethod
    def _fmu_state_from_bytes(data):
        state = json.loads(data.decode("utf-8"))
        return {"values": np.array(state["values"]), "state": state["state"]}
