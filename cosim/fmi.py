"""The one place where nodeforce talks FMI, through FMPy.

An `FmuInstance` extracts and instantiates an FMU once; each `run` resets it, so a search can
simulate thousands of forcing masks without unzipping or instantiating again. The step loop
writes the inputs into preallocated ctypes arrays through numpy views and calls the FMU's set,
doStep and get functions as FMPy bound them from its library, checking their status as FMPy
does, so a step allocates nothing in Python.

The calls follow the model description's fmiVersion, as FMPy's own `simulate_fmu` does: one class
per version (`Fmi2`, `Fmi3`) sets, steps and gets, and both speak in scalar names (`force[i]`,
`T_forced[i]`, `T[i]`), which FMI 3.0 FMUs hold as elements of arrays; this layer knows nothing
of how an FMU was made. Extracted FMUs live in temporary folders named
`nodeforce_fmu_*`, removed when the instance closes, when instantiation fails, and at the latest
when the interpreter exits: instances still open then are freed first, while Python still runs
(a library's own exit handlers must not meet live instances after the interpreter has gone).
"""
import atexit
import weakref
from ctypes import byref

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2Boolean, fmi2Integer, fmi2Real, fmi2True, fmi2ValueReference, fmi2Warning
from fmpy.fmi3 import FMU3Slave, fmi3Boolean, fmi3Float64, fmi3ValueReference

from nodeforce import tempdirs

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

    def stepper(self, fmu, input_names, output_names, n_slopes=0):
        """step(time, dt, inputs row, outputs row or None, slopes row): set the inputs and the
        first derivatives of the first `n_slopes` of them, step, get the outputs, through
        preallocated ctypes arrays (a step allocates nothing in Python)."""
        n_in, n_out = len(input_names), len(output_names)
        refs = self.refs(input_names[:n_slopes])
        if self.derivatives_as_values:
            refs = [r + self._derivative_offset for r in refs]
        d_refs = (fmi2ValueReference * n_slopes)(*refs)
        d_orders = (fmi2Integer * n_slopes)(*([1] * n_slopes))
        d_values = (fmi2Real * n_slopes)()
        d_view = np.ctypeslib.as_array(d_values) if n_slopes else None
        d_name = "fmi2SetReal" if self.derivatives_as_values else "fmi2SetRealInputDerivatives"
        d_set = raw(fmu, d_name)
        d_args = (d_refs, n_slopes, d_values) if self.derivatives_as_values else (d_refs, n_slopes, d_orders, d_values)
        in_refs = (fmi2ValueReference * n_in)(*self.refs(input_names))
        in_values = (fmi2Real * n_in)()
        in_view = np.ctypeslib.as_array(in_values) if n_in else None
        out_refs = (fmi2ValueReference * n_out)(*self.refs(output_names))
        out_values = (fmi2Real * n_out)()
        out_view = np.ctypeslib.as_array(out_values) if n_out else None
        component, no_rollback = fmu.component, fmi2Boolean(fmi2True)
        set_real, do_step, get_real = (raw(fmu, name) for name in ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal"))

        def step(time, dt, row, out, slopes=None):
            if n_in:
                in_view[:] = row
                check(set_real(component, in_refs, n_in, in_values), "fmi2SetReal")
            if n_slopes:
                d_view[:] = slopes
                check(d_set(component, *d_args), d_name)
            check(do_step(component, time, dt, no_rollback), "fmi2DoStep")
            if out is not None:
                check(get_real(component, out_refs, n_out, out_values), "fmi2GetReal")
                out[:] = out_view
        return step


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

    def stepper(self, fmu, input_names, output_names, n_slopes=0):
        """As `Fmi2.stepper`; FMI 3.0 has no call for input derivatives, so the slopes are set as
        the FMU's derivative inputs (`derivative_name`)."""
        d_refs, d_buffer, d_positions = self.layout([self.derivative_name(n) for n in input_names[:n_slopes]])
        d_refs = (fmi3ValueReference * len(d_refs))(*d_refs)
        d_values = (fmi3Float64 * len(d_buffer))(*d_buffer)
        d_view = np.ctypeslib.as_array(d_values) if n_slopes else None
        in_refs, in_buffer, in_positions = self.layout(input_names)
        out_refs, out_buffer, out_positions = self.layout(output_names)
        n_in, n_out = len(in_buffer), len(out_buffer)
        in_refs = (fmi3ValueReference * len(in_refs))(*in_refs)
        in_values = (fmi3Float64 * n_in)(*in_buffer)
        in_view = np.ctypeslib.as_array(in_values) if n_in else None
        out_refs = (fmi3ValueReference * len(out_refs))(*out_refs)
        out_values = (fmi3Float64 * n_out)()
        out_view = np.ctypeslib.as_array(out_values) if n_out else None
        component = fmu.component
        set_float, do_step, get_float = (raw(fmu, name) for name in ("fmi3SetFloat64", "fmi3DoStep", "fmi3GetFloat64"))
        event, terminate, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()
        flags = fmi3Boolean(True), byref(event), byref(terminate), byref(early), byref(last)

        def step(time, dt, row, out, slopes=None):
            if n_in:
                in_view[in_positions] = row
                check(set_float(component, in_refs, len(in_refs), in_values, n_in), "fmi3SetFloat64")
            if n_slopes:
                d_view[d_positions] = slopes
                check(set_float(component, d_refs, len(d_refs), d_values, len(d_view)), "fmi3SetFloat64")
            check(do_step(component, time, dt, *flags), "fmi3DoStep")
            if out is not None:
                check(get_float(component, out_refs, len(out_refs), out_values, n_out), "fmi3GetFloat64")
                out[:] = out_view[out_positions]
        return step


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
        inputs = np.asarray(inputs, dtype=float)
        n_slopes = 0 if slopes is None else np.shape(slopes)[1]
        step = calls.stepper(fmu, list(input_names), list(output_names), n_slopes)
        outputs = np.empty((len(inputs) - skip, len(output_names)))
        steps = np.broadcast_to(np.asarray(dt, dtype=float), (len(inputs),))
        times = start_time + np.concatenate([[0.0], np.cumsum(steps)])
        slopes = np.asarray(slopes, dtype=float) if n_slopes else [None] * len(inputs)
        for k, row in enumerate(inputs):
            step(times[k], steps[k], row, outputs[k - skip] if k >= skip else None, slopes[k])
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
