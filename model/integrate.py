"""Backward-Euler integration with forcing (PHYSICS.md section 5, paper eqs. 6 and 7).

One step from t_n to t_n+1 solves `M T^n+1 = V`, with `M = C/dt - A` and
`V = (C/dt) T^n + B u^n+1 + q`. Forcing node i replaces row i of M by the unit row and v_i by
the node's measured temperature: a Dirichlet condition. M is inverted once per forcing mask, so
a step is one matrix-vector product.

The FMU's `doStep` and the direct model's `simulate` both call `ImplicitEuler.step`: one
arithmetic for every path through the code.
"""
from collections import OrderedDict

import numpy as np

DAY = 86400.0  # s


class ImplicitEuler:
    """The step of a `Network` for a step size dt (s), with the step matrix kept per forcing mask.

    M (with its forced rows made unit rows) is inverted once per mask, so that a step is one
    matrix-vector product: numpy alone, no scipy (the Python FMU imports this class, and an FMU
    that loads scipy corrupts memory when pythonfmu's host ends the interpreter). The most
    recently used `CACHED_MASKS` inverses are kept: a search tries thousands of masks.
    """

    CACHED_MASKS = 64

    def __init__(self, network, dt):
        self.network = network
        self.dt = float(dt)
        self.c_dt = network.C / self.dt
        self._M = np.diag(self.c_dt) - network.A
        self._inverses = OrderedDict()

    def inverse(self, forced):
        """The inverse of M with the rows of the `forced` nodes (bool mask) replaced by unit
        rows, and the indices of those nodes."""
        key = forced.tobytes()
        found = self._inverses.get(key)
        if found is None:
            M = self._M.copy()
            M[forced] = 0.0
            M[forced, forced] = 1.0
            found = self._inverses[key] = (np.linalg.inv(M), np.flatnonzero(forced))
            if len(self._inverses) > self.CACHED_MASKS:
                self._inverses.popitem(last=False)
        else:
            self._inverses.move_to_end(key)
        return found

    def step(self, T, source, forced, T_forced):
        """Temperatures (C) at t_n+1 from T at t_n.

        Parameters
        ----------
        T : (N,) node temperatures at t_n (C)
        source : (N,) `B u^n+1 + q` (W)
        forced : (N,) bool, nodes imposed this step (their measurement exists at t_n+1)
        T_forced : (N,) imposed temperatures (C); read only where `forced`
        """
        v = self.c_dt * T
        v += source
        inverse, index = self.inverse(forced)
        if not len(index):
            return inverse @ v
        T_imposed = T_forced[index]
        v[index] = T_imposed
        T_next = inverse @ v
        # The product returns the unit rows' values to rounding only; a Dirichlet node is exact.
        T_next[index] = T_imposed
        return T_next


def imposed(force, measured):
    """The nodes forced at a step (or at every step, row by row): those of the forcing mask whose
    measurement exists there. A missing one (NaN) leaves its node computed, never invented."""
    return force & np.isfinite(measured)


def forcing_schedule(force, measured, burn_in_steps=0):
    """(N_t+1, N) bool: the nodes imposed at each input row t_0..t_N (PHYSICS.md section 5).

    Over the burn-in, rows 1..B, every node measured there is forced (a state observer: the
    record, not a guess, sets the walls' state); from row B+1 on, the mask's nodes whose
    measurement exists. The warm-up replays rows 1..M with their own forcing.

    Parameters
    ----------
    force : (N,) bool, the forcing mask
    measured : (N_t+1, N) measured temperatures (C), NaN where missing
    burn_in_steps : B, steps of the burn-in
    """
    forced = imposed(np.asarray(force, dtype=bool), measured)
    forced[1:burn_in_steps + 1] = np.isfinite(measured[1:burn_in_steps + 1])
    return forced


def initial_state(building, measured0, T_default=20.0):
    """Node temperatures at t_0 (C) from the measurements at t_0.

    A measured node starts at its value; an unmeasured node of a component that has measured
    nodes starts at the linear interpolation in depth between them (the nearest measured value
    beyond them); every other node starts at the zone's measured air temperature, or at
    `T_default` where the air is not measured.

    Parameters
    ----------
    building : Building
    measured0 : (N,) measured temperatures at t_0 (C), NaN where not measured
    T_default : C, the temperature of a node nothing informs
    """
    measured0 = np.asarray(measured0, dtype=float)
    T = np.empty(len(measured0))
    for z in building.zones:
        air = measured0[z.air_node - 1]
        fallback = air if np.isfinite(air) else T_default
        # the nodes a zone effect adds (never measured) start with the zone's air
        for i in (z.air_node, z.radiant_node, z.mass_node, z.heater_node):
            if i is not None:
                T[i - 1] = fallback
        for c in building.components:
            if c.inside.zone != z.name:
                continue
            idx = np.array(c.node_ids) - 1
            values = measured0[idx]
            known = np.isfinite(values)
            if known.any():
                # np.interp holds the end values beyond the measured range: the nearest value.
                T[idx] = np.interp(np.array(c.depths), np.array(c.depths)[known], values[known])
            else:
                T[idx] = fallback
    measured = np.isfinite(measured0)
    T[measured] = measured0[measured]
    return T


def simulate(building, network, U, dt, measured=None, force=None, warmup_days=2, T_default=20.0,
             include_start=False, burn_in_steps=0):
    """Simulate the network over input samples t_0..t_N; return temperatures at t_1..t_N.

    Parameters
    ----------
    building : Building (for the initial state)
    network : Network
    U : (N_t+1, n_inputs) inputs at t_0..t_N, columns in `network.input_names`
    dt : step (s), uniform
    measured : (N_t+1, N) measured node temperatures (C), NaN where missing; None: nothing measured;
        fewer columns than N: those of the building's own nodes, the nodes its effects add unmeasured
    force : (N,) bool, nodes forced to their measurements for the whole run
    warmup_days : passes over the first day's inputs (rows 1..24h/dt) before the run
    T_default : C, the initial temperature of a node nothing informs
    include_start : also return the state at t_0 (after the warm-up) as the first row
    burn_in_steps : B, steps over which every measured node is forced (`forcing_schedule`)

    Returns
    -------
    (N_t, N) node temperatures (C) at t_1..t_N, or (N_t+1, N) at t_0..t_N with `include_start`
    """
    n_rows, n = U.shape[0], network.n_nodes
    if measured is None:
        measured = np.full((n_rows, n), np.nan)
    elif measured.shape[1] < n:  # a case of the building as declared: the nodes its effects add are never measured
        measured = np.hstack([measured, np.full((n_rows, n - measured.shape[1]), np.nan)])
    if force is None:
        force = np.zeros(n, dtype=bool)
    sources = network.sources(U)
    forced = forcing_schedule(force, measured, burn_in_steps)
    stepper = ImplicitEuler(network, dt)
    T = initial_state(building, measured[0], T_default)
    rows = warmup_rows(n_rows, dt, warmup_days)
    start = len(rows) - (n_rows - 1)  # the step that reaches t_1
    out = np.empty((n_rows, n))
    out[0] = T
    for k, row in enumerate(rows):
        T = stepper.step(T, sources[row], forced[row], measured[row])
        if k >= start - 1:
            out[k - start + 1] = T
    return out if include_start else out[1:]


def warmup_rows(n_rows, dt, warmup_days):
    """The input row of every step, warm-up included: rows 1..M `warmup_days` times, then 1..N."""
    per_day = steps_per_day(dt)
    if warmup_days and n_rows - 1 < per_day:
        raise ValueError(f"the warm-up needs one day of inputs ({per_day} steps); only {n_rows - 1} given")
    day = np.arange(1, per_day + 1)
    return np.concatenate([day] * int(warmup_days) + [np.arange(1, n_rows)])


def steps_per_day(dt):
    """M = 24 h / dt, which must be a whole number of steps."""
    per_day = DAY / dt
    if abs(per_day - round(per_day)) > 1e-9:
        raise ValueError(f"a day is not a whole number of {dt:g} s steps")
    return int(round(per_day))
