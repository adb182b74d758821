"""The FMU's variables, their value references and which calls may change them.

One layout serves both FMUs (the Python slave reads it at run time, the standalone C code gets
the same counts) and the model description: every value lives in one array indexed by value
reference, in this order:

    force[1..N]      Boolean parameter, fixed      node i is forced to T_forced[i]
    T_start[1..N]    Real parameters, fixed (C)    node i's temperature at the start
    <inputs>         Real inputs                   network.input_names, in order
    T_forced[1..N]   Real inputs (C)               measurement of node i, NaN where none
    T[1..N]          Real outputs (C)              node temperatures
    <parameters>     Real parameters, fixed        the building's properties and an added effect's
                                                   parameters (model.effects.fmu_parameters)
    max_step         Real parameter, tunable (s)   the longest internal step of a doStep

A Real set must be finite, but T_forced's NaN ("not measured"). Beyond the declared variables, the
Python FMU keeps the first time derivatives of the inputs and of T_forced[1..N] (`derivatives`,
in their order), which its guard sets from fmi2SetRealInputDerivatives (pythonfmu forwards no
input derivatives): never declared, settable like the inputs.

This file is copied into the Python FMU: standard library only, syntax of Python 3.6.
"""

# The internal steps one doStep may take (h / max_step), at most: beyond, doStep is refused
# (c/nodeforce_fmu.c's MAX_SUBSTEPS).
MAX_SUBSTEPS = 10_000_000

# What a call may do to a variable, by the slave's state (FMI 2.0 section 4.2.4, table 2).
INSTANTIATED, INITIALISATION, STEPPING, TERMINATED = range(4)


class Layout:
    """Value references of a model with `n_nodes` nodes, its input names and its other
    parameters' names (`<component>.<property>`, `<effect>.<name>`)."""

    def __init__(self, n_nodes, input_names, parameter_names=()):
        n = int(n_nodes)
        self.n_nodes = n
        self.input_names = tuple(input_names)
        self.parameter_names = tuple(parameter_names)
        self.force = slice(0, n)
        self.T_start = slice(n, 2 * n)
        self.inputs = slice(2 * n, 2 * n + len(self.input_names))
        self.T_forced = slice(self.inputs.stop, self.inputs.stop + n)
        self.T = slice(self.T_forced.stop, self.T_forced.stop + n)
        self.parameters = slice(self.T.stop, self.T.stop + len(self.parameter_names))
        self.max_step = self.parameters.stop
        self.size = self.max_step + 1  # the declared variables
        # undeclared: d/dt of the inputs and of T_forced, in value-reference order
        self.derivatives = slice(self.size, self.size + self.T_forced.stop - self.inputs.start)

    def names(self):
        """Variable names in value-reference order."""
        n = range(1, self.n_nodes + 1)
        return ([f"force[{i}]" for i in n] + [f"T_start[{i}]" for i in n] + list(self.input_names)
                + [f"T_forced[{i}]" for i in n] + [f"T[{i}]" for i in n] + list(self.parameter_names)
                + ["max_step"])

    def names_file(self):
        """resources/names.txt: the inputs' and parameters' names, one a line, which the C code
        names them by in its messages (c/variables.h)."""
        return "".join(f"{name}\n" for name in (*self.input_names, *self.parameter_names))

    def is_boolean(self, vr):
        return vr < self.n_nodes

    def is_output(self, vr):
        return self.T.start <= vr < self.T.stop

    def is_fixed(self, vr):
        """A parameter: settable only before initialisation ends."""
        return vr < self.T_start.stop or self.parameters.start <= vr < self.max_step

    def takes_nan(self, vr):
        """Whether a Real set to NaN is allowed: on T_forced, a measurement's gap (vr: a value
        reference or an array of them)."""
        return (self.T_forced.start <= vr) & (vr < self.T_forced.stop)

    def derivative_of(self, vr):
        """The value reference whose time derivative `vr` holds (`derivatives`), or None."""
        if self.derivatives.start <= vr < self.derivatives.stop:
            return self.inputs.start + vr - self.derivatives.start
        return None

    def refusal(self, vr, real, setting, state, value=0.0, time=0.0):
        """Why the standard forbids this get or set (None when it is allowed), or why the
        value set is refused (a Real that is not finite, but a measurement's NaN): the messages
        of c/variables.h.

        vr : value reference; real : a Real call (else Boolean); setting : a set call;
        state : INSTANTIATED, INITIALISATION, STEPPING or TERMINATED; value : the value set;
        time : the communication point (s)
        """
        of = self.derivative_of(vr)
        if of is not None:  # as the input it belongs to, but finite even for T_forced's
            reason = self.refusal(of, real, setting, state)
            if reason is None and real and setting and value - value != 0.0:
                reason = f"value reference {of} ({self.names()[of]}): its derivative set to {value} at t = {time:.17g} s: it must be finite"
            return reason
        if not 0 <= vr < self.size:
            return f"value reference {vr} (none) does not exist (0..{self.size - 1})"
        reason = None
        if self.is_boolean(vr) == real:
            reason = f"is {'Boolean' if real else 'Real'}, not {'Real' if real else 'Boolean'}"
        elif not setting:
            return None
        elif self.is_output(vr):
            reason = "is an output, which cannot be set"
        elif self.is_fixed(vr) and state not in (INSTANTIATED, INITIALISATION):
            reason = "is a fixed parameter, which cannot change after initialisation"
        elif state == TERMINATED:
            reason = "cannot be set: the slave is terminated"
        elif real and value - value != 0.0 and not self.takes_nan(vr):
            reason = f"set to {value} at t = {time:.17g} s: it must be finite (NaN means \"not measured\" on T_forced only)"
        return reason and f"value reference {vr} ({self.names()[vr]}) {reason}"
