"""Run one FMI 2.0 co-simulation FMU the same way in several importers.

Test helper, not a test module: ``from tests.importers import run_fmpy, run_libcosim, run_ecos``
(as the other tests import ``tests.conftest``; run pytest from the repository root).

Every runner has the same contract::

    run_X(fmu, parameters, inputs, outputs, dt, n_steps) -> np.ndarray  # shape (n_steps, len(outputs))

- ``parameters`` {name: value} is applied once, before initialisation ends; the Python type is
  ignored, the variable's type in modelDescription.xml decides (``force[1]`` -> Boolean,
  ``T_start[1]`` -> Real), so ``{"force[1]": 1, "T_start[1]": 20}`` works everywhere.
- ``inputs`` {name: array}: ``inputs[name][k]`` is set before step k (k = 0..n_steps-1), step k
  goes from k*dt to (k+1)*dt. Inputs not given keep their start value. NaN is passed through.
- row k of the result holds ``outputs`` read after step k.

How each importer is driven (and what was found on a pythonfmu 0.7.0 toy FMU shaped like ours:
Boolean fixed parameters ``force[i]``, Real inputs ``T_forced[i]`` with start="NaN", outputs
``T[i]`` with initial="exact", canGetAndSetFMUstate, run for 200 steps with NaN gaps in
``T_forced[1]``: the three runners gave bit-identical outputs):

FMPy (``fmpy.fmi2.FMU2Slave``, the low-level API, not ``simulate_fmu``, so that no input
interpolation or output grid is involved): instantiate, setupExperiment(0), set parameters,
enter/exitInitializationMode, then per step set inputs, doStep(k*dt, dt), getReal.

libcosim (libcosimpy 0.0.6): ``CosimExecution.from_step_size`` takes the step in *integer
nanoseconds*. Parameters go through ``*_initial_value`` (Boolean parameters are accepted with
``boolean_initial_value``). A different input value at every step goes through an *override
manipulator* (``CosimManipulator.create_override()`` + ``slave_real_values`` before every
``execution.step()``): the override is applied at the start of the next step, so it is what that
doStep sees (checked against FMPy, bit-identical). Outputs come from a ``last_value`` observer.
NaN start values ("NaN", and even pythonfmu's invalid "nan") and NaN overrides are accepted.
libcosim logs every FMI call at debug level to stderr by default; we lower it to WARNING
(a process-wide setting of libcosimc). libcosim calls the FMU from a worker thread, which
pythonfmu's wrapper handles (it takes the GIL itself). dt is rounded to a whole number of ns.

ecos (ecospy 0.7.2): needs libtbb12 from Debian (``make system-deps``) or importing ecospy fails
with ``OSError: libtbb.so.12``. Variables are named ``"<instance>::<variable>"``, brackets are
fine (``m::T_forced[1]``). Parameters go through a parameter set given to ``init``; we build an
``EcosParameterSet`` typed from modelDescription.xml because ecospy's dict shortcut types values
by their Python type and refuses numpy scalars ("Illegal value type" for ``np.bool_``). ``EcosParameterSet`` is not exported by ``ecospy/__init__``: import it from
``ecospy.EcosParameterSet``. Per-step inputs: ``sim.set_real(id, v)`` before each
``sim.step()`` reaches the FMU before that step's doStep (checked against FMPy,
bit-identical); ecospy's ``add_scenario`` is not usable for this (its Integer/Boolean/String
actions call the Real C function, and a scenario file path is passed as the bytes "utf-8").
Boolean parameters and NaN start values are accepted. The FMU runs in-process (no proxyfmu).

All three run a pythonfmu FMU inside the calling Python process (the interpreter is already
initialised; pythonfmu's wrapper reuses it), also one after the other and interleaved in one
process, with no crash at exit. The slave module is imported into *this* interpreter's
``sys.modules`` under its module name (``resources/slavemodule.txt``) and stays there, and every
instance's ``resources`` folder is prepended to ``sys.path`` and never removed. Consequences:
two *different* pythonfmu FMUs whose slave modules share a name cannot both run in one process:
with the same class name the second one silently runs the first one's code (in all three
importers); with another class name it fails to instantiate ("[ctor] findClass AttributeError").
Distinct module names coexist. Two instances of one FMU (interleaved, or in threads) are
independent. fmi2Reset re-creates the Python object: parameters must be set again after it,
as the standard says, and the re-run is then identical. getFMUstate/setFMUstate work through
FMPy when the slave overrides ``_get_fmu_state``/``_set_fmu_state``.

OMSimulator is not a runner here: the ``omsimulator`` package on PyPI has no wheel (every version
is a source package whose build downloads OMSimulator's binaries from the OpenModelica build
server, which CI cannot reach) and no Debian package carries it. Its source says why it cannot
record our FMU's results: ``ComponentFMUCS::getReal`` fails on any NaN it reads ("getReal returned
NAN"), and ``updateSignals`` reads every input and output to record it, so an unset or missing
``T_forced[i]`` (NaN: no measurement) stops the recording. ``oms_removeSignalsFromResults(model,
".*T_forced.*")`` before simulating leaves those signals out.

The Python FMU's ``binaries/linux64/<id>.so`` is nodeforce's guard (fmu_build/c/guard.c) in front of
pythonfmu's binary: forbidden calls get fmi2Error in every importer, and a host without Python
(the C host, the checkers' own simulators) needs no LD_PRELOAD.

Checkers: ``fmpy_validate`` (``fmpy.validation.validate_fmu``: XSD + names + ModelStructure +
start values) and ``fmutool_check`` (fmu-manipulation-toolbox ``fmutool -input X.fmu -check``:
XSD + semantic rules; exit status 0 and "seems to be compliant with FMI-2.0" / "No semantic
error" on success, exit status 7 and "-check: N error(s) found." on failure). Both reject
pythonfmu 0.7.0's own spelling of a NaN start value, start="nan" (it formats floats with
``f"{v:.16g}"``): the xs:double spelling is "NaN", so the slave's ``to_xml`` must rewrite it.
Both also reject outputs left at the default initial="calculated" (pythonfmu writes no
<InitialUnknowns>); initial="exact" passes both. The importers themselves accept both defects
(libcosim only logs FMI Library errors), so only the checkers catch them.
"""
from __future__ import annotations

import functools
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

__all__ = ["run_fmpy", "run_libcosim", "run_ecos", "fmpy_validate", "fmutool_check"]

# --------------------------------------------------------------------------- common checks
def _restores_sys_path(run):
    """pythonfmu prepends each instance's resources folder to sys.path for good; its copy of
    pythonfmu (no binaries) would shadow the installed package here and in spawned workers."""
    @functools.wraps(run)
    def wrapper(*args, **kwargs):
        saved = list(sys.path)
        try:
            return run(*args, **kwargs)
        finally:
            sys.path[:] = saved
    return wrapper


def _variables(fmu):
    """{name: fmpy ScalarVariable} and the model description of ``fmu``."""
    from fmpy import read_model_description

    # validate=False: the runners exercise the importers, the checkers below do the validating
    # (read_model_description validates by default and would refuse e.g. start="nan" first).
    md = read_model_description(str(fmu), validate=False)
    return {v.name: v for v in md.modelVariables}, md


def _check_request(variables, parameters, inputs, outputs, dt, n_steps):
    """Fail early with a clear message, the same for every runner; return inputs as float arrays."""
    if n_steps < 0 or int(n_steps) != n_steps:
        raise ValueError(f"n_steps must be a non-negative integer, got {n_steps!r}")
    if not dt > 0:
        raise ValueError(f"dt must be > 0, got {dt!r}")
    for name in parameters:
        if name not in variables:
            raise KeyError(f"no variable {name!r} in the FMU")
        if variables[name].causality not in ("parameter", "input"):
            raise ValueError(f"{name!r} is a {variables[name].causality}, not a parameter")
    series = {}
    for name, values in inputs.items():
        if name not in variables:
            raise KeyError(f"no variable {name!r} in the FMU")
        if variables[name].causality != "input" or variables[name].type != "Real":
            raise ValueError(f"{name!r} is not a Real input")
        values = np.asarray(values, dtype=float).reshape(-1)
        if len(values) < n_steps:
            raise ValueError(f"input {name!r} has {len(values)} values for {n_steps} steps")
        series[name] = values
    for name in outputs:
        if name not in variables:
            raise KeyError(f"no variable {name!r} in the FMU")
        if variables[name].type != "Real":
            raise ValueError(f"output {name!r} is not Real")
    return series


def _typed(variable, value):
    """``value`` converted to the Python type of the FMI variable's type."""
    kind = variable.type
    if kind == "Real":
        return float(value)
    if kind in ("Integer", "Enumeration"):
        return int(value)
    if kind == "Boolean":
        return bool(value)
    if kind == "String":
        return str(value)
    raise TypeError(f"unsupported type {kind} of {variable.name!r}")


# --------------------------------------------------------------------------- FMPy
@_restores_sys_path
def run_fmpy(fmu: str | os.PathLike, parameters: dict[str, float | bool], inputs: dict[str, np.ndarray],
             outputs: list[str], dt: float, n_steps: int) -> np.ndarray:
    """Run ``fmu`` in FMPy for ``n_steps`` steps of ``dt`` s; row k = ``outputs`` after step k."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave

    variables, md = _variables(fmu)
    series = _check_request(variables, parameters, inputs, outputs, dt, n_steps)
    unzipdir = extract(str(fmu))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="m")
    result = np.empty((n_steps, len(outputs)))
    try:
        slave.instantiate()
        try:
            slave.setupExperiment(startTime=0.0)
            for name, value in parameters.items():
                _fmpy_set(slave, variables[name], value)
            slave.enterInitializationMode()
            slave.exitInitializationMode()
            in_vrs = [variables[name].valueReference for name in series]
            in_cols = list(series.values())
            out_vrs = [variables[name].valueReference for name in outputs]
            for k in range(n_steps):
                if in_vrs:
                    slave.setReal(in_vrs, [float(col[k]) for col in in_cols])
                slave.doStep(currentCommunicationPoint=k * dt, communicationStepSize=dt)
                result[k] = slave.getReal(out_vrs)
            slave.terminate()
        finally:
            slave.freeInstance()
    finally:
        shutil.rmtree(unzipdir, ignore_errors=True)
    return result


def _fmpy_set(slave, variable, value):
    value = _typed(variable, value)
    vr = [variable.valueReference]
    if variable.type == "Real":
        slave.setReal(vr, [value])
    elif variable.type == "Boolean":
        slave.setBoolean(vr, [value])
    elif variable.type == "String":
        slave.setString(vr, [value])
    else:
        slave.setInteger(vr, [value])


# --------------------------------------------------------------------------- libcosim
@_restores_sys_path
def run_libcosim(fmu: str | os.PathLike, parameters: dict[str, float | bool], inputs: dict[str, np.ndarray],
                 outputs: list[str], dt: float, n_steps: int) -> np.ndarray:
    """Run ``fmu`` in libcosim (libcosimpy) for ``n_steps`` steps of ``dt`` s; row k = after step k."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave
    from libcosimpy._internal import get_last_error_message

    variables, _ = _variables(fmu)
    series = _check_request(variables, parameters, inputs, outputs, dt, n_steps)
    log_output_level(CosimLogLevel.WARNING)

    def fail(what):
        raise RuntimeError(f"libcosim: {what}: {get_last_error_message()}")

    step_ns = int(round(dt * 1e9))
    execution = CosimExecution.from_step_size(step_ns)
    slave = CosimLocalSlave(fmu_path=str(Path(fmu).resolve()), instance_name="m")
    index = execution.add_local_slave(slave)
    if index < 0:
        fail(f"cannot load {fmu}")
    for name, value in parameters.items():
        var = variables[name]
        value = _typed(var, value)
        setter = {"Real": execution.real_initial_value, "Boolean": execution.boolean_initial_value,
                  "String": execution.string_initial_value}.get(var.type, execution.integer_initial_value)
        if not setter(index, var.valueReference, value):
            fail(f"initial value of {name}")
    override = CosimManipulator.create_override()
    execution.add_manipulator(override)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)

    in_vrs = [variables[name].valueReference for name in series]
    in_cols = list(series.values())
    out_vrs = [variables[name].valueReference for name in outputs]
    result = np.empty((n_steps, len(outputs)))
    for k in range(n_steps):
        if in_vrs and not override.slave_real_values(index, in_vrs, [float(col[k]) for col in in_cols]):
            fail(f"override of the inputs before step {k}")
        if not execution.step():
            fail(f"step {k}")
        result[k] = observer.last_real_values(index, out_vrs)
    # Destroy now (terminate + free the FMU) rather than whenever the GC gets to it.
    del observer, override, execution, slave
    return result


# --------------------------------------------------------------------------- ecos
@_restores_sys_path
def run_ecos(fmu: str | os.PathLike, parameters: dict[str, float | bool], inputs: dict[str, np.ndarray],
             outputs: list[str], dt: float, n_steps: int) -> np.ndarray:
    """Run ``fmu`` in ecos (ecospy) for ``n_steps`` steps of ``dt`` s; row k = after step k."""
    from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure
    from ecospy.EcosParameterSet import EcosParameterSet

    variables, _ = _variables(fmu)
    series = _check_request(variables, parameters, inputs, outputs, dt, n_steps)
    EcosLib.set_log_level("warn")

    def fail(what):
        raise RuntimeError(f"ecos: {what}: {EcosLib.get_last_error()}")

    structure = EcosSimulationStructure()
    structure.add_model("m", str(Path(fmu).resolve()))
    parameter_set = None
    if parameters:
        parameter_set = "parameters"
        values = EcosParameterSet()
        for name, value in parameters.items():
            var = variables[name]
            value = _typed(var, value)
            add = {"Real": values.add_real, "Boolean": values.add_bool,
                   "String": values.add_string}.get(var.type, values.add_int)
            add(f"m::{name}", value)
        if not structure.add_parameter_set(parameter_set, values):
            fail("parameter set")
    sim = EcosSimulation(structure=structure, step_size=float(dt))
    result = np.empty((n_steps, len(outputs)))
    try:
        if not sim.init(0.0, parameter_set):
            fail("init")
        in_ids = [f"m::{name}" for name in series]
        in_cols = list(series.values())
        out_ids = [f"m::{name}" for name in outputs]
        for k in range(n_steps):
            for ident, col in zip(in_ids, in_cols):
                sim.set_real(ident, float(col[k]))
            sim.step(1)
            result[k] = [sim.get_real(ident) for ident in out_ids]
        sim.terminate()
    finally:
        sim.free()
        structure.free()
    return result


# --------------------------------------------------------------------------- checkers
def fmpy_validate(fmu: str | os.PathLike) -> list[str]:
    """Problems ``fmpy validate`` finds in ``fmu`` (empty list: valid)."""
    from fmpy.validation import validate_fmu

    # validate_fmu only checks zip entry names when given a str, not a Path.
    return list(validate_fmu(str(fmu)))


_ANSI = re.compile(r"\x1b\[[0-9;]*m")


def fmutool_check(fmu: str | os.PathLike) -> tuple[bool, str]:
    """(ok, output) of fmu-manipulation-toolbox's ``fmutool -input FMU -check``.

    ok is True when fmutool exits 0 (exit 7 = the checks found errors, 3/4 = unreadable or not an
    FMU); output is what it printed (its log goes to stdout), colour codes removed.
    """
    command = [sys.executable, "-c",
               "import sys; from fmu_manipulation_toolbox.cli.fmutool import fmutool; sys.exit(fmutool())",
               "-input", str(fmu), "-check"]
    env = dict(os.environ, NO_COLOR="1")
    done = subprocess.run(command, capture_output=True, text=True, env=env, timeout=300)
    output = _ANSI.sub("", done.stdout + done.stderr)
    return done.returncode == 0, output
