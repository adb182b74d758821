"""The one place where nodeforce talks FMI, through FMPy.

An `FmuInstance` extracts and instantiates an FMU once; each `run` resets it, so a search can
simulate thousands of forcing masks without unzipping or instantiating again. The step loop
writes the inputs into preallocated ctypes arrays through numpy views and calls FMPy's
`fmi2SetReal`, `fmi2DoStep` and `fmi2GetReal`, so a step allocates nothing in Python.

The slave class follows the model description's fmiVersion, as FMPy's own `simulate_fmu` does;
this layer knows nothing of how an FMU was made. Extracted FMUs live in temporary folders named
`nodeforce_fmu_*`, removed when the instance closes, when instantiation fails, and at the latest
when the interpreter exits: instances still open then are freed first, while Python still runs
(a library's own exit handlers must not meet live instances after the interpreter has gone).
"""
import atexit
import weakref

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2Boolean, fmi2Real, fmi2True, fmi2ValueReference

from nodeforce import tempdirs

SLAVES = {"2.0": FMU2Slave}
_OPEN = weakref.WeakSet()


def content_id(fmu_path):
    """The FMU's identity: its GUID, which nodeforce's FMUs make a hash of their content."""
    return read_model_description(str(fmu_path), validate=False).guid


class FmuInstance:
    """An instantiated co-simulation FMU, reused across runs."""

    def __init__(self, fmu_path, instance_name="nodeforce"):
        self.path = str(fmu_path)
        self.description = read_model_description(self.path)
        slave_class = SLAVES.get(self.description.fmiVersion)
        if slave_class is None:
            raise ValueError(f"{self.path} is an FMI {self.description.fmiVersion} FMU; "
                             f"nodeforce runs FMI {', '.join(SLAVES)}")
        if self.description.coSimulation is None:
            raise ValueError(f"{self.path} is not a co-simulation FMU")
        self.variables = {v.name: v for v in self.description.modelVariables}
        self._unzipdir = extract(self.path, unzipdir=tempdirs.make("fmu"))
        self.fmu = None
        try:
            self.fmu = slave_class(guid=self.description.guid, unzipDirectory=self._unzipdir,
                                   modelIdentifier=self.description.coSimulation.modelIdentifier,
                                   instanceName=instance_name)
            self.fmu.instantiate()
        except BaseException:
            self.close()
            raise
        _OPEN.add(self)
        self._used = False

    def names(self, causality):
        """Names of the variables of a causality ("parameter", "input", "output")."""
        return [v.name for v in self.description.modelVariables if v.causality == causality]

    def _refs(self, names):
        try:
            return [self.variables[n].valueReference for n in names]
        except KeyError as e:
            raise KeyError(f"{self.path} has no variable {e.args[0]}") from None

    def run(self, dt, parameters, start_inputs, input_names, inputs, output_names, start_time=0.0,
            skip=0):
        """Simulate from a fresh state; return the outputs after each step but the first `skip`.

        Parameters
        ----------
        dt : communication step (s)
        parameters : {name: value} for Boolean and Real parameters
        start_inputs : {name: value} inputs set during initialisation
        input_names : the inputs set before every step
        inputs : (n_steps, len(input_names)) values, row k applied before step k
        output_names : the outputs read after every step
        skip : steps whose outputs are not needed (a warm-up): not read at all

        Returns
        -------
        (n_steps - skip, len(output_names)) ndarray
        """
        fmu = self.fmu
        if self._used:
            fmu.reset()
        self._used = True
        fmu.setupExperiment(startTime=start_time)
        fmu.enterInitializationMode()
        booleans = {n: v for n, v in parameters.items() if self.variables[n].type == "Boolean"}
        reals = {n: v for n, v in {**parameters, **start_inputs}.items() if n not in booleans}
        if booleans:
            fmu.setBoolean(self._refs(booleans), [bool(v) for v in booleans.values()])
        if reals:
            fmu.setReal(self._refs(reals), [float(v) for v in reals.values()])
        fmu.exitInitializationMode()

        inputs = np.asarray(inputs, dtype=float)
        n_in, n_out = len(input_names), len(output_names)
        in_refs = (fmi2ValueReference * n_in)(*self._refs(input_names))
        in_values = (fmi2Real * n_in)()
        in_view = np.ctypeslib.as_array(in_values)
        out_refs = (fmi2ValueReference * n_out)(*self._refs(output_names))
        out_values = (fmi2Real * n_out)()
        out_view = np.ctypeslib.as_array(out_values)
        component = fmu.component
        set_real, do_step, get_real = fmu.fmi2SetReal, fmu.fmi2DoStep, fmu.fmi2GetReal
        outputs = np.empty((len(inputs) - skip, n_out))
        time = start_time
        for k, row in enumerate(inputs):
            if n_in:
                in_view[:] = row
                set_real(component, in_refs, n_in, in_values)
            do_step(component, time, dt, fmi2Boolean(fmi2True))
            if k >= skip:
                get_real(component, out_refs, n_out, out_values)
                outputs[k - skip] = out_view
            time = start_time + (k + 1) * dt
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
