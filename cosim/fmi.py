"""The one place where nodeforce talks FMI, through FMPy.

An `FmuInstance` extracts and instantiates an FMU once; each `run` resets it, so a search can
simulate thousands of forcing masks without unzipping or instantiating again. A run's steps
(`Steps`) call the FMU's set, doStep and get functions as FMPy bound them from its library,
checking their status as FMPy does: in a loop compiled once per process (c/master.c), where a
C compiler is found, else in Python, the same calls with the same values. A step of the test
cell's standalone FMU costs some 5 us in C, 16 us in Python (docs/performance.md).

The calls follow the model description's fmiVersion, as FMPy's own `simulate_fmu` does: one class
per version (`Fmi2`, `Fmi3`) sets, steps and gets, and both speak in scalar names (`force[i]`,
`T_forced[i]`, `T[i]`), which FMI 3.0 FMUs hold as elements of arrays; this layer knows nothing
of how an FMU was made. Extracted FMUs live in temporary folders named
`nodeforce_fmu_*`, removed when the instance closes, when instantiation fails, and at the latest
when the interpreter exits: instances still open then are freed first, while Python still runs
(a library's own exit handlers must not meet live instances after the interpreter has gone).
"""
import atexit
import functools
import logging
import weakref
from ctypes import POINTER, Structure, byref, c_double, c_int, c_int64, c_size_t, c_uint32, c_void_p, cast
from functools import partial
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2Boolean, fmi2True, fmi2Warning
from fmpy.fmi3 import FMU3Slave, fmi3Boolean, fmi3Float64

from nodeforce.runtime import tempdirs
from nodeforce.runtime.compiler import compiled_function

log = logging.getLogger("nodeforce.cosim")

_OPEN = weakref.WeakSet()


def raw(fmu, name):
    """The FMI function `name` of `fmu`'s library as FMPy declared it (its argument and result
    types), called in the step loop without FMPy's per-call wrapper (its call logger, unused
    here: a tenth of a standalone FMU's run); its status is checked with `check`."""
    return getattr(fmu.dll, name)


def check(status, name):
    """FMPy's FMICallException where an FMI call's status is above warning (1 in FMI 2.0 and
    3.0 alike), as FMPy raises it."""
    if status > fmi2Warning:
        raise FMICallException(function=name, status=status)


@functools.lru_cache(maxsize=None)
def _master():
    """The step loop compiled (c/master.c), loaded once per process; None where it cannot be
    compiled (no C compiler, or one that fails on it: said once in the log): the loop runs in
    Python."""
    function = compiled_function(Path(__file__).with_name("c"), "master.c", "nodeforce_master_steps",
                                 "the FMUs' steps are looped in Python", log)
    if function is None:
        return None
    double = np.ctypeslib.ndpointer(np.float64, flags="C")
    function.restype = c_int64
    function.argtypes = [c_int, c_void_p, c_void_p, c_int, c_void_p, c_int, c_void_p, c_void_p,
                         POINTER(_TransferStruct), POINTER(_TransferStruct), POINTER(_TransferStruct), c_int64,
                         double, double, double, double, double, c_int64, np.ctypeslib.ndpointer(np.intc, flags="C"),
                         POINTER(c_int)]
    return function


class Transfer:
    """One set or get of a step (c/master.c): the value references it names, a buffer of every
    value of their variables (an FMI 3.0 array whole, at its start values: FMI 3.0 sets whole
    arrays) and where column j of a row goes in that buffer."""

    def __init__(self, refs, values, positions):
        self.refs = np.ascontiguousarray(refs, dtype=np.uint32)
        self.values = np.ascontiguousarray(values, dtype=float)
        self.positions = np.ascontiguousarray(positions, dtype=np.int64)
        self.n = len(self.positions)
        self.refs_pointer = self.refs.ctypes.data_as(POINTER(c_uint32))
        self.values_pointer = self.values.ctypes.data_as(POINTER(c_double))
        self.struct = _TransferStruct(self.refs_pointer, len(self.refs), self.values_pointer, len(self.values),
                                      self.positions.ctypes.data_as(POINTER(c_int64)), self.n)

    @classmethod
    def scalars(cls, refs):
        """Of scalar variables, one column each (FMI 2.0)."""
        return cls(refs, np.zeros(len(refs)), np.arange(len(refs)))


class _TransferStruct(Structure):
    _fields_ = [("refs", POINTER(c_uint32)), ("n_refs", c_size_t), ("values", POINTER(c_double)),
                ("n_values", c_size_t), ("positions", POINTER(c_int64)), ("n", c_int64)]


# how c/master.c calls a set: fmi2SetReal, fmi2SetRealInputDerivatives, fmi3SetFloat64
SET_REAL2, SET_DERIVATIVES2, SET_FLOAT3 = 0, 1, 2


def _bound(form, function, component, t, orders):
    """The set (or get) of transfer `t` by FMI function `function` as c/master.c calls it in
    `form`, with nothing left to give: a get has the arguments of the set of its version."""
    tail = {SET_REAL2: (t.values_pointer,), SET_DERIVATIVES2: (orders, t.values_pointer),
            SET_FLOAT3: (t.values_pointer, len(t.values))}[form]
    return partial(function, component, t.refs_pointer, len(t.refs), *tail)


class Steps:
    """A run's calls at every step, bound to an instance: set the inputs (the `Transfer`
    `inputs`), set their slopes (`slopes`), step, get the outputs (`outputs`), through the FMI
    functions `calls` names; `forms` says how the two sets are called (SET_REAL2, ...). The loop
    in C (c/master.c) and the one in Python read these alike."""

    def __init__(self, version, fmu, inputs, slopes, outputs, calls, forms):
        self.version, self.component = version, fmu.component
        self.inputs, self.slopes, self.outputs = inputs, slopes, outputs
        self.calls, self.forms = calls, forms
        self.orders = np.ones(max(slopes.n, 1), dtype=np.intc)
        self.functions = [raw(fmu, name) for name in calls]
        self.addresses = [cast(f, c_void_p).value for f in self.functions]

    def run(self, times, steps, inputs, slopes, outputs, skip):
        """Step k from times[k] by steps[k] with row k of `inputs` and of `slopes` set before it,
        its outputs into row k - skip of `outputs` for k >= skip; in C (c/master.c) where the
        loop compiles, else in Python: the same calls with the same values."""
        master = _master()
        if master is None:
            self._run_in_python(times, steps, inputs, slopes, outputs, skip)
            return
        status = c_int()
        set_inputs, set_slopes, do_step, get_outputs = self.addresses
        failed = master(self.version, self.component, set_inputs, self.forms[0], set_slopes, self.forms[1], do_step,
                        get_outputs, byref(self.inputs.struct), byref(self.slopes.struct), byref(self.outputs.struct),
                        len(times), times, steps, inputs, slopes, outputs, skip, self.orders, byref(status))
        if failed >= 0:
            check(status.value, self.calls[failed % 4])

    def _run_in_python(self, times, steps, inputs, slopes, outputs, skip):
        orders = self.orders.ctypes.data_as(POINTER(c_int))
        set_inputs, set_slopes = (_bound(form, f, self.component, t, orders) for form, f, t in
                                  zip(self.forms, self.functions, (self.inputs, self.slopes)))
        get_outputs = _bound(SET_REAL2 if self.version == 2 else SET_FLOAT3, self.functions[3], self.component,
                             self.outputs, orders)
        if self.version == 2:
            flags = (fmi2Boolean(fmi2True),)
        else:
            event, terminate, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()
            flags = fmi3Boolean(True), byref(event), byref(terminate), byref(early), byref(last)
        do_step = self.functions[2]
        for k in range(len(times)):
            if self.inputs.n:
                self.inputs.values[self.inputs.positions] = inputs[k]
                check(set_inputs(), self.calls[0])
            if self.slopes.n:
                self.slopes.values[self.slopes.positions] = slopes[k]
                check(set_slopes(), self.calls[1])
            check(do_step(self.component, times[k], steps[k], *flags), self.calls[2])
            if k >= skip:
                check(get_outputs(), self.calls[3])
                outputs[k - skip] = self.outputs.values[self.outputs.positions]


class Fmi2:
    """FMI 2.0 calls: every value is a variable of its own."""

    slave_class = FMU2Slave

    def __init__(self, description):
        self.variables = {v.name: v for v in description.modelVariables}
        # nodeforce's Python FMU written without a C compiler has no guard, and pythonfmu refuses
        # fmi2SetRealInputDerivatives (canInterpolateInputs="false"): its slave keeps the inputs'
        # derivatives as the values after the declared ones, in the inputs' order
        # (fmu_build/variables.py, `derivatives`), which fmi2SetReal sets
        self.derivatives_as_values = not description.coSimulation.canInterpolateInputs
        inputs = [v.valueReference for v in description.modelVariables if v.causality == "input"]
        self._derivative_offset = len(description.modelVariables) - min(inputs, default=0)

    def names(self, causality):
        return [name for name, v in self.variables.items() if v.causality == causality]

    def refs(self, names):
        try:
            return [self.variables[n].valueReference for n in names]
        except KeyError as e:
            raise KeyError(f"no variable {e.args[0]}") from None

    def is_boolean(self, name):
        return self.variables[name].type == "Boolean"

    def initialise(self, fmu, start_time, booleans, reals):
        """Set up, set the parameters and start values ({name: value}), end initialisation."""
        fmu.setupExperiment(startTime=start_time)
        fmu.enterInitializationMode()
        if booleans:
            fmu.setBoolean(self.refs(booleans), [bool(v) for v in booleans.values()])
        if reals:
            fmu.setReal(self.refs(reals), [float(v) for v in reals.values()])
        fmu.exitInitializationMode()

    def steps(self, fmu, input_names, output_names, n_slopes=0):
        """The `Steps` that set the inputs and the first derivatives of the first `n_slopes` of
        them, step, and get the outputs."""
        refs = self.refs(input_names[:n_slopes])
        if self.derivatives_as_values:
            refs = [r + self._derivative_offset for r in refs]
        inputs, slopes = Transfer.scalars(self.refs(input_names)), Transfer.scalars(refs)
        outputs = Transfer.scalars(self.refs(output_names))
        slope_call, slope_form = (("fmi2SetReal", SET_REAL2) if self.derivatives_as_values
                                  else ("fmi2SetRealInputDerivatives", SET_DERIVATIVES2))
        return Steps(2, fmu, inputs, slopes, outputs, ("fmi2SetReal", slope_call, "fmi2DoStep", "fmi2GetReal"),
                     (SET_REAL2, slope_form))


class Fmi3(Fmi2):
    """FMI 3.0 calls: `force`, `T_forced` and `T` are arrays of N, whose element i-1 is the
    scalar `name[i]`; a set or get names whole arrays, the elements not given at their start."""

    slave_class = FMU3Slave

    def __init__(self, description):
        super().__init__(description)
        self.elements = {}  # scalar name: (variable, index in its array or None)
        for v in description.modelVariables:
            if v.dimensions:
                self.elements.update({f"{v.name}[{i + 1}]": (v, i) for i in range(int(v.dimensions[0].start))})
            else:
                self.elements[v.name] = (v, None)

    def names(self, causality):
        return [name for name, (v, _) in self.elements.items() if v.causality == causality]

    def is_boolean(self, name):
        return self.elements[name][0].type == "Boolean"

    def layout(self, names):
        """(value references, buffer of every value of their variables at the start values,
        the position of each of `names` in the buffer)."""
        try:
            chosen = [self.elements[n] for n in names]
        except KeyError as e:
            raise KeyError(f"no variable {e.args[0]}") from None
        variables = list({id(v): v for v, _ in chosen}.values())
        size = lambda v: int(np.prod(v.shape or (1,)))
        starts = [np.array([text.lower() in ("true", "1") if v.type == "Boolean" else float(text)
                            for text in v.start.split()] if v.start else np.zeros(size(v)), dtype=float)
                  for v in variables]
        offsets = dict(zip((id(v) for v in variables), np.cumsum([0] + [len(x) for x in starts])))
        buffer = np.concatenate(starts) if starts else np.empty(0)
        positions = np.array([offsets[id(v)] + (i or 0) for v, i in chosen], dtype=np.intp)
        return [v.valueReference for v in variables], buffer, positions

    def _set(self, fmu, values, boolean):
        if values:
            refs, buffer, positions = self.layout(list(values))
            buffer[positions] = [float(x) for x in values.values()]
            if boolean:
                fmu.setBoolean(refs, [bool(x) for x in buffer])
            else:
                fmu.setFloat64(refs, list(buffer))

    def initialise(self, fmu, start_time, booleans, reals):
        fmu.enterInitializationMode(startTime=start_time)
        self._set(fmu, booleans, True)
        self._set(fmu, reals, False)
        fmu.exitInitializationMode()

    @staticmethod
    def derivative_name(name):
        """The FMI 3.0 input that is the derivative of input `name` (`der(T_out)`, `der(T_forced)[3]`)."""
        array, _, index = name.partition("[")
        return f"der({array})" + (f"[{index}" if index else "")

    def steps(self, fmu, input_names, output_names, n_slopes=0):
        """As `Fmi2.steps`; FMI 3.0 has no call for input derivatives, so the slopes are set as
        the FMU's derivative inputs (`derivative_name`)."""
        inputs, slopes, outputs = (Transfer(*self.layout(names)) for names in
                                   (input_names, [self.derivative_name(n) for n in input_names[:n_slopes]],
                                    output_names))
        return Steps(3, fmu, inputs, slopes, outputs, ("fmi3SetFloat64", "fmi3SetFloat64", "fmi3DoStep", "fmi3GetFloat64"),
                     (SET_FLOAT3, SET_FLOAT3))


VERSIONS = {"2.0": Fmi2, "3.0": Fmi3}


def content_id(fmu_path):
    """The FMU's identity: its GUID, which nodeforce's FMUs make a hash of their content."""
    return read_model_description(str(fmu_path), validate=False).guid


class FmuInstance:
    """An instantiated co-simulation FMU, reused across runs."""

    def __init__(self, fmu_path, instance_name="nodeforce"):
        self.path = str(fmu_path)
        self.description = read_model_description(self.path)
        version = VERSIONS.get(self.description.fmiVersion)
        if version is None:
            raise ValueError(f"{self.path} is an FMI {self.description.fmiVersion} FMU; "
                             f"nodeforce runs FMI {', '.join(VERSIONS)}")
        if self.description.coSimulation is None:
            raise ValueError(f"{self.path} is not a co-simulation FMU")
        self.calls = version(self.description)
        self.variables = self.calls.variables
        self._unzipdir = extract(self.path, unzipdir=tempdirs.make("fmu"))
        self.fmu = None
        try:
            self.fmu = version.slave_class(guid=self.description.guid, unzipDirectory=self._unzipdir,
                                   modelIdentifier=self.description.coSimulation.modelIdentifier,
                                   instanceName=instance_name)
            self.fmu.instantiate()
        except BaseException:
            self.close()
            raise
        _OPEN.add(self)
        self._used = False

    def names(self, causality):
        """Names of the variables of a causality ("parameter", "input", "output"), array
        elements by their scalar names (`T[3]`)."""
        return self.calls.names(causality)

    def run(self, dt, parameters, start_inputs, input_names, inputs, output_names, start_time=0.0,
            skip=0, slopes=None):
        """Simulate from a fresh state; return the outputs after each step but the first `skip`.

        Parameters
        ----------
        dt : communication step (s), or one per step (n_steps,)
        parameters : {name: value} for Boolean and Real parameters
        start_inputs : {name: value} inputs set during initialisation
        input_names : the inputs set before every step
        inputs : (n_steps, len(input_names)) values, row k applied before step k
        output_names : the outputs read after every step
        skip : steps whose outputs are not needed (a warm-up): not read at all
        slopes : (n_steps, n) first time derivatives (per s) of the first n inputs over each step
            (FMI 2.0 fmi2SetRealInputDerivatives, FMI 3.0 the `der(...)` inputs), or None: the
            inputs held over each step

        Returns
        -------
        (n_steps - skip, len(output_names)) ndarray
        """
        fmu = self.fmu
        if self._used:
            fmu.reset()
        self._used = True
        calls = self.calls
        booleans = {n: v for n, v in parameters.items() if calls.is_boolean(n)}
        reals = {n: v for n, v in {**parameters, **start_inputs}.items() if n not in booleans}
        calls.initialise(fmu, start_time, booleans, reals)
        inputs = np.ascontiguousarray(inputs, dtype=float)
        n_slopes = 0 if slopes is None else np.shape(slopes)[1]
        steps = np.ascontiguousarray(np.broadcast_to(np.asarray(dt, dtype=float), (len(inputs),)))
        times = (start_time + np.concatenate([[0.0], np.cumsum(steps)]))[:-1]
        slopes = np.ascontiguousarray(slopes, dtype=float) if n_slopes else np.zeros((len(inputs), 0))
        outputs = np.empty((len(inputs) - skip, len(output_names)))
        calls.steps(fmu, list(input_names), list(output_names), n_slopes).run(times, steps, inputs, slopes, outputs, skip)
        fmu.terminate()
        return outputs

    def close(self):
        """Free the instance and remove the extracted files (again: nothing happens)."""
        fmu, self.fmu = self.fmu, None
        if fmu is not None:
            # FMPy's freeInstance unloads the library too: unloading it twice is undefined
            # behaviour in glibc's dlclose.
            if getattr(fmu, "component", None) is not None:
                fmu.freeInstance()
            else:
                fmu.freeLibrary()
        tempdirs.remove(self._unzipdir)
        _OPEN.discard(self)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


@atexit.register
def _close_all():
    for instance in list(_OPEN):
        instance.close()
