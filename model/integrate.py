"""Backward-Euler integration with forcing (docs/model.md section 5, paper eqs. 6 and 7).

One step from t_n to t_n+1 solves `M T^n+1 = V`, with `M = C/dt - A` and
`V = (C/dt) T^n + B u^n+1 + q`. Forcing node i replaces row i of M by the unit row and v_i by
the node's measured temperature: a Dirichlet condition. M is factorised once per forcing mask
(`ImplicitEuler`: inverted whole below a few hundred nodes, by blocks and a Schur complement on
the zones' nodes above). A record sampled every dt is integrated in `substeps(dt)` steps per
sample, its inputs and imposed temperatures in between from `within_steps`.

The FMU's `doStep` calls `ImplicitEuler.step`; the direct model's `simulate` calls it too, or,
over a long run of steps under one step matrix, solves the same steps in their modes (`modal`):
the same temperatures to rounding.
"""
import math
from collections import OrderedDict

import numpy as np

from .modal import Modes, run as modal_run

DAY = 86400.0  # s
# The longest step (s) the integration takes: a record sampled more coarsely is integrated in
# `substeps` equal steps per sample, its inputs linear between samples (a zone's heat input held:
# `held_inputs`). Backward Euler's error is of first order in the step: on the test cell, the
# file's air against the same file at 1 min differs by some 0.005 C per minute of step (0.05 C
# at 10 min, 0.17 at 30, 0.27 at 60), while halving its walls' cells moves it by 0.03 to 0.05 C
# (benchmarks/records.py's truth). At 5 min the step's error is about that of the walls' cells
# and below the noise of air sensors: a fault, not the step, is then what the residual shows.
MAX_STEP = 300.0
# The steady start's one backward-Euler step: a mode of time constant tau keeps 1 / (1 + STEADY_STEP
# / tau) of its start (1e-4 for the 12 days of the test cell's floor over its air), and C / dt is
# still far above rounding next to the conductances (an infinite step would be the steady state
# itself, but no FMU takes one).
STEADY_STEP = 1e10  # s
# The longest step (s) over a history, the weather before the first measurement (`history_block`):
# a history sets the slow modes' state at the record's start (days to weeks), which backward Euler
# follows at hours' steps as well as at minutes, for a fraction of the steps; what the steps miss
# of the faster modes the record's first hours and its burn-in set again. On the test cell's air
# after a 90-day past, 60 days of history in steps of 1, 3 and 6 h left the record, after its
# burn-in day, within 0.004 to 0.011 C of the truth alike; 3 h keeps the day's swing in the steps.
HISTORY_STEP = 10800.0  # s
# Steps per state node from which a run of steps under one step matrix is solved in its modes
# (`modal`) rather than stepped in numpy: a shorter run costs less stepped than decomposed. The
# test cell's 22 state nodes decompose in 0.1 ms against 3 us a step (some 1.5 steps a node); a
# decomposition grows as the cube of the nodes, a step as their square, so larger networks
# break even later. Where the steps are compiled (`model.compiled`) every run is stepped: a
# compiled step costs a fraction of a microsecond on the test cell, and a run of the test
# cell's record in C a half to two thirds of one in its modes, its derivatives a fifth.
MODAL_FROM = 8


class DenseSolve:
    """M (forced rows made unit rows) inverted: a step is one matrix-vector product, O(N^2)."""

    def __init__(self, M):
        self.inverse = np.linalg.inv(M)

    def __call__(self, v):
        return self.inverse @ v


def blocks_apart(n, rows, cols, hub):
    """Label (n,) of the connected component of each node in the graph of the links
    (rows[k], cols[k]) once the `hub` nodes (bool, (n,)) are removed; -1 on hubs."""
    parent = list(range(n))

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i, j in zip(rows.tolist(), cols.tolist()):
        if not (hub[i] or hub[j]):
            a, b = root(i), root(j)
            if a != b:
                parent[max(a, b)] = min(a, b)
    return np.array([-1 if hub[i] else root(i) for i in range(n)])


class Partition:
    """The nodes split into hubs H (zone air and radiant nodes: those linked to more than three
    others) and blocks of the rest, no two blocks linked except through H: a component's chain
    of nodes (its surfaces' links go to hubs) is a block. The step matrix then factorises per
    block (small dense inverses, applied in batches of blocks of equal size) and a dense Schur
    complement on H: O(N) per step rather than O(N^2).

    A block larger than `largest` nodes (a network that is not chains between zones) loses its
    most linked node to the hubs, until none is.
    """

    def __init__(self, M, largest=64):
        n = len(M)
        rows, cols = np.nonzero(M)
        off = rows != cols
        r, c = rows[off], cols[off]
        degree = np.bincount(np.concatenate([r, c]), minlength=n) // 2
        hub = degree > 3
        while True:
            label = blocks_apart(n, r, c, hub)
            sizes = np.bincount(label[~hub], minlength=n)
            big = int(np.argmax(sizes))
            if sizes[big] <= largest:
                break
            members = np.flatnonzero(label == big)
            hub[members[np.argmax(degree[members])]] = True
        self.n = n
        self.hubs = np.flatnonzero(hub)
        # the other nodes, ordered so that blocks of one size are contiguous
        nodes = np.flatnonzero(~hub)
        labels = label[nodes]
        order = np.lexsort((nodes, labels, sizes[labels]))
        self.block_nodes = nodes[order]
        block_size = sizes[labels[order]]
        self.groups = []  # (start in block_nodes, number of blocks, block size)
        start = 0
        while start < len(nodes):
            size = int(block_size[start])
            count = int(np.sum(block_size == size)) // size
            self.groups.append((start, count, size))
            start += count * size


class CondensedSolve:
    """M (the `forced` rows made unit rows) solved by blocks and a Schur complement on the hubs of
    a `Partition`: M_II x_I + M_IH x_H = v_I and M_HI x_I + M_HH x_H = v_H, with M_II block
    diagonal, give S x_H = v_H - M_HI M_II^-1 v_I, S = M_HH - M_HI M_II^-1 M_IH, then
    x_I = M_II^-1 (v_I - M_IH x_H). Every sparse product is one gather and one `np.bincount`.
    Only the blocks and the couplings are read from the unforced M (left unchanged): O(N) per
    mask, not a copy of M.
    """

    def __init__(self, M, partition, forced):
        p = self.partition = partition
        I, H = p.block_nodes, p.hubs
        rows, cols, values = [], [], []
        for start, count, size in p.groups:
            idx = I[start:start + count * size].reshape(count, size)
            blocks = unit_rows(M[idx[:, :, None], idx[:, None, :]], forced[idx])
            inverse = np.linalg.inv(blocks)
            local = start + size * np.arange(count)[:, None, None]
            rows.append(np.broadcast_to(local + np.arange(size)[None, :, None], inverse.shape).ravel())
            cols.append(np.broadcast_to(local + np.arange(size)[None, None, :], inverse.shape).ravel())
            values.append(inverse.ravel())
        self.II = tuple(np.concatenate(x) for x in (rows, cols, values))  # M_II^-1, I-local indices
        M_IH, M_HI = M[np.ix_(I, H)], M[np.ix_(H, I)]
        M_IH[forced[I]] = 0.0
        M_HI[forced[H]] = 0.0
        self.IH, self.HI = sparse(M_IH), sparse(M_HI)
        X = np.stack([self._product(self.II, column, len(I)) for column in M_IH.T], axis=1) \
            if len(H) else np.zeros((len(I), 0))
        self.schur_inverse = np.linalg.inv(unit_rows(M[np.ix_(H, H)], forced[H]) - M_HI @ X)

    @staticmethod
    def _product(matrix, x, size):
        r, c, g = matrix
        return np.bincount(r, g * x[c], minlength=size)

    def __call__(self, v):
        p = self.partition
        n_I, n_H = len(p.block_nodes), len(p.hubs)
        v_I = v[p.block_nodes]
        y = self._product(self.II, v_I, n_I)
        x_H = self.schur_inverse @ (v[p.hubs] - self._product(self.HI, y, n_H))
        x_I = self._product(self.II, v_I - self._product(self.IH, x_H, n_I), n_I)
        T = np.empty(p.n)
        T[p.block_nodes] = x_I
        T[p.hubs] = x_H
        return T


def unit_rows(blocks, forced):
    """Square matrices (..., n, n) with the rows flagged in `forced` (..., n) made unit rows."""
    where = np.nonzero(forced)
    blocks[where] = 0.0
    blocks[where + (where[-1],)] = 1.0
    return blocks


def sparse(matrix):
    """(rows, columns, values) of a matrix's nonzeros."""
    r, c = np.nonzero(matrix)
    return r, c, matrix[r, c]


class Sources:
    """Each step's sources B t^k + q (W) of a run of L steps, as their terms t^k (L, m: the inputs
    and their products, `Network.source_terms`), coefficients B (N, m) and constant q (N,): the
    compiled steps form each step's from B's few nonzeros, never the (L, N) array."""

    def __init__(self, terms, B, q, found=None):
        self.terms, self.B, self.q = terms, B, q
        self._found = {} if found is None else found  # B's nonzeros, shared with the slices

    def __len__(self):
        return len(self.terms)

    def __getitem__(self, steps):
        return Sources(self.terms[steps], self.B, self.q, self._found)

    @property
    def nonzeros(self):
        """(nodes, columns, values) of B's nonzeros, row after row (`sparse`), found once and
        shared with every slice: a year's run is sliced wherever its switched conductances change,
        hundreds of times, and B has a column an input, thousands where the direct sun is traced."""
        if "B" not in self._found:
            self._found["B"] = sparse(self.B)
        return self._found["B"]

    def dense(self):
        """(L, N) W."""
        return self.terms @ self.B.T + self.q


class ImplicitEuler:
    """The step of a `Network` for a step size dt (s), with the step matrix kept per forcing mask.

    M (with its forced rows made unit rows) is factorised once per mask, with numpy alone, no
    scipy (the Python FMU imports this class, and an FMU that loads scipy corrupts memory when
    pythonfmu's host ends the interpreter): inverted whole below `CONDENSED_FROM` nodes
    (`DenseSolve`, a step is one O(N^2) product), by blocks and a Schur complement on the zones'
    nodes from there on (`CondensedSolve`, O(N) per step; the threshold is where it gets faster,
    benchmarks/bench_scale.py). The most recently used `CACHED_MASKS` factors are kept: a search
    tries thousands of masks.
    """

    CACHED_MASKS = 64
    CONDENSED_FROM = 300  # nodes

    def __init__(self, network, dt, condensed=None):
        self.network = network
        self.dt = float(dt)
        self.c_dt = network.C / self.dt
        self._M = np.diag(self.c_dt) - network.A
        self.condensed = network.n_nodes >= self.CONDENSED_FROM if condensed is None else condensed
        self._partition = None
        self._solvers = OrderedDict()
        self._modes = {}
        self._pattern = None
        self._one_way = None

    def solver(self, forced, switched=None):
        """The solve of M with the rows of the `forced` nodes (bool mask) replaced by unit rows
        (a callable v -> T), and the indices of those nodes; `switched` (N,) adds the switched
        conductances of the step to M's diagonal (W/K; one factorisation per distinct value)."""
        key = forced.tobytes() + (b"" if switched is None else switched.tobytes())
        found = self._solvers.get(key)
        if found is None:
            M = self._M if switched is None else self._M + np.diag(switched)
            if self.condensed:
                if self._partition is None:  # from the unforced pattern, which every mask shares
                    self._partition = Partition(self._M)
                solve = CondensedSolve(M, self._partition, forced)
            else:
                solve = DenseSolve(unit_rows(M.copy(), forced))
            found = self._solvers[key] = (solve, np.flatnonzero(forced))
            if len(self._solvers) > self.CACHED_MASKS:
                self._modes.pop(self._solvers.popitem(last=False)[0], None)
        else:
            self._solvers.move_to_end(key)
        return found

    def modes(self, forced, switched=None):
        """The `modal.Modes` of the step with this mask and switched conductances (kept with its
        factors), None where M is solved by blocks (`CondensedSolve`: its inverse is never formed)
        or the modes are not well enough conditioned for a run. Air carried one way between two
        free nodes (a supply from one zone to the next) makes the step non-symmetric, which
        `Modes.of` would find only after M's inverse is formed: such a mask has None at once."""
        if self._one_way is None:  # M's non-symmetric pairs, the same for every mask
            asymmetric = np.abs(self._M - self._M.T) > 1e-12 * np.abs(self._M).max(initial=0.0)
            # a row no other node reads (a zone's mean radiant temperature, docs/model.md 3.5)
            # leaves the other nodes' step symmetric
            read = np.any((self._M != 0.0) & ~np.eye(len(self._M), dtype=bool), axis=0)
            self._one_way = np.nonzero(asymmetric & read[:, None] & read[None, :])
        rows, cols = self._one_way
        if np.any(~forced[rows] & ~forced[cols]):
            return None
        solve, _ = self.solver(forced, switched)
        key = forced.tobytes() + (b"" if switched is None else switched.tobytes())
        if key not in self._modes:
            self._modes[key] = (Modes.of(solve.inverse, self.c_dt, forced) if isinstance(solve, DenseSolve)
                                else None)
        return self._modes[key]

    def matrix(self, forced, switched=None):
        """M with the switched conductances `switched` (N,) added to its diagonal and the rows of
        the `forced` nodes unit rows, by columns: ((column starts (N + 1,), rows) int32, values)
        of its nonzeros, column after column."""
        if self._pattern is None:  # M's pattern, the diagonal included: every mask's
            cols, rows = np.nonzero(((self._M != 0) | np.eye(len(self._M), dtype=bool)).T)
            starts = np.concatenate([[0], np.cumsum(np.bincount(cols, minlength=len(self._M)))])
            self._pattern = (starts.astype(np.int32), rows.astype(np.int32)), cols, self._M[rows, cols]
        (starts, rows), cols, values = self._pattern
        values, diagonal = values.copy(), rows == cols
        if switched is not None:
            values[diagonal] += switched[rows[diagonal]]
        at = forced[rows]
        values[at] = diagonal[at]
        return (starts, rows), values

    def run(self, T, sources, forced, imposed=None, switched=None, rows=None, inputs=None):
        """The temperatures of the nodes `rows` (indices, default every node) after each of L steps
        under one mask and switched conductances, (L, len(rows)), and every node's after the last
        (N,): compiled (`model.compiled`) where a C compiler is found, else step by step (`step`).

        Parameters
        ----------
        T : (N,) C before the first step
        sources : `Sources` of the L steps
        forced : (N,) bool, the nodes imposed at every step
        imposed : (L, N) each step's imposed temperatures (C), read where forced; None: zero (the
            temperatures' derivatives, which no parameter moves at a forced node)
        switched : (N,) the steps' switched conductances (`Network.switched_diagonal`), or None
        inputs : (L, n_inputs) each step's inputs, from which and the temperatures before it the
            network's `convection` adds its lagged source; None: no such source (the derivatives,
            along which it is held frozen)
        """
        from . import compiled  # not in the Python FMU, which steps one doStep at a time
        rows = np.arange(len(T)) if rows is None else np.asarray(rows, dtype=int)
        index = np.flatnonzero(forced)
        convection = None if inputs is None else self.network.convection
        if compiled.available():
            return compiled.steps(self.matrix(forced, switched), self.c_dt, sources, index,
                                  None if imposed is None else imposed[:, index], T, rows, convection)
        zero = np.zeros(len(T))
        out = np.empty((len(sources), len(rows)))
        for k, source in enumerate(sources.dense()):
            T = self.step(T, source, forced, zero if imposed is None else imposed[k], switched,
                          None if convection is None else inputs[k])
            out[k] = T[rows]
        return out, T

    def step(self, T, source, forced, T_forced, switched=None, inputs=None):
        """Temperatures (C) at t_n+1 from T at t_n.

        Parameters
        ----------
        T : (N,) node temperatures at t_n (C)
        source : (N,) `B u^n+1 + q` (W)
        forced : (N,) bool, nodes imposed this step (their measurement exists at t_n+1)
        T_forced : (N,) imposed temperatures (C); read only where `forced`
        switched : (N,) the switched conductances at t_n+1 (`Network.switched_diagonal`), or None
        inputs : (n_inputs,) the inputs at t_n+1, from which and T the network's `convection`, if
            any, adds its lagged source (docs/model.md section 3.6); None: no such source
        """
        v = self.c_dt * T
        v += source
        if inputs is not None and self.network.convection is not None:
            v += self.network.convection.source(T, inputs, self.c_dt)
        solve, index = self.solver(forced, switched)
        if not len(index):
            return solve(v)
        T_imposed = T_forced[index]
        v[index] = T_imposed
        T_next = solve(v)
        # The product returns the unit rows' values to rounding only; a Dirichlet node is exact.
        T_next[index] = T_imposed
        return T_next


def imposed(force, measured):
    """The nodes forced at a step (or at every step, row by row): those of the forcing mask whose
    measurement exists there. A missing one (NaN) leaves its node computed, never invented."""
    return force & np.isfinite(measured)


def forcing_schedule(force, measured, burn_in_steps=0):
    """(N_t+1, N) bool: the nodes imposed at each input row t_0..t_N (docs/model.md section 5).

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


def steady_inputs(U, measured, forced, dt):
    """The steady start's step: the mean inputs of the first day, or of the history where the
    first measurement comes later (the weather before it, `model.case.prepare_case`), and the
    nodes imposed over those rows held at the mean of their imposed values.

    Before the replay warm-up (docs/model.md section 5), a diagnosis may take one backward-Euler
    step of `STEADY_STEP` with these: every mode faster than centuries reaches the steady state of
    those mean conditions, so a heavy, unmeasured component starts with the gradient the
    conditions give it rather than at the air's temperature, a guess its slow time constant
    would carry through a whole record (the replay alone needs some three time constants of
    days: weeks for a heavy floor). Over a history, the mean of all of it: a slow mode's state
    is the conditions averaged over its time constant, of which one day's mean is a poor sample
    (after a fortnight's history, on 30 weeks of the test cell's air alone: 0.20 C RMS on average
    and 0.70 at worst from the first day's steady state, 0.17 and 0.66 from the whole mean's).

    Parameters
    ----------
    U : (N_t+1, n_inputs) inputs at t_0..t_N
    measured : (N_t+1, N) measured temperatures (C), NaN where missing
    forced : (N_t+1, N) bool, the nodes imposed at each row (`forcing_schedule`)
    dt : step (s)

    Returns
    -------
    u : (n_inputs,) mean inputs of rows 1..M, M a day's rows or the history's, the more
    imposed : (N,) bool, nodes imposed at some of those rows
    values : (N,) C, their mean imposed temperature (NaN elsewhere)
    """
    first = np.flatnonzero(np.isfinite(measured).any(axis=1))
    day = slice(1, max(int(first[0]) if len(first) else 0, steps_per_day(dt)) + 1)
    imposed = forced[day].any(axis=0)
    held = np.where(forced[day], measured[day], 0.0)
    counts = forced[day].sum(axis=0)
    values = np.full(measured.shape[1], np.nan)
    values[imposed] = held[:, imposed].sum(axis=0) / counts[imposed]
    return U[day].mean(axis=0), imposed, values


def substeps(dt):
    """Steps the integration takes per sample of dt (s): the fewest equal ones of at most MAX_STEP."""
    return max(1, math.ceil(dt / MAX_STEP - 1e-9))


def held_inputs(building, input_names):
    """(n_inputs,) bool: the inputs held over each step, the zones' heat inputs: a power logged at
    t_n+1 is the heat delivered over the step that ends there (energy / dt), the value the
    backward Euler step reads; and the schedules, whose input at t_n+1 is their mean over that
    step (`model.case.schedule_inputs`). Every other input (temperatures, irradiances, shading,
    the clock) is a sample of a quantity that varies in between, linear between samples within a
    step."""
    held = {name for z in building.zones for name in z.heat_input} | set(building.schedule_inputs)
    return np.array([name in held for name in input_names], dtype=bool)


def step_start(values, held=None):
    """(N_t+1, m): the value each step t_n -> t_n+1 starts from, in row n+1: v_n, or v_n+1 where a
    column is `held` or either sample is missing (NaN: a forced node is imposed only where its
    end sample exists). Row 0 is v_0 (no step ends there). Over the step the value goes linearly
    from its start to v_n+1: `within_steps`; an FMU is given the start and the slope.

    Parameters
    ----------
    values : (N_t+1, m) samples at t_0..t_N
    held : (m,) bool, columns held at the step's end value (default none)
    """
    values = np.asarray(values, dtype=float)
    start = values.copy()
    apart = np.isfinite(values[:-1]) & np.isfinite(values[1:])
    if held is not None:
        apart &= ~np.asarray(held, dtype=bool)
    start[1:] = np.where(apart, values[:-1], values[1:])
    return start


def within_steps(values, k, held=None):
    """The values at the end of each of the k sub-steps of every step t_n -> t_n+1: row n+1 of
    the j-th array (j = 1..k) is (1 - j/k) s_n + (j/k) v_n+1, s_n the step's start (`step_start`).

    Parameters
    ----------
    values : (N_t+1, m) samples at t_0..t_N
    k : sub-steps per step
    held : (m,) bool, columns held at the step's end value (default none)

    Returns
    -------
    list of k (N_t+1, m) arrays, the last equal to `values`
    """
    values = np.asarray(values, dtype=float)
    if k == 1:  # one step per sample: nothing in between
        return [values]
    start = step_start(values, held)
    return [start + (j / k) * (values - start) for j in range(1, k)] + [values]


def history_block(dt):
    """Samples of dt (s) in one step over a history: the most whose span is within `HISTORY_STEP`."""
    return max(1, int(HISTORY_STEP // dt + 1e-9))


def simulate(building, network, U, dt, measured=None, force=None, warmup_days=2, T_default=20.0,
             include_start=False, burn_in_steps=0, stepper=None, steady_start=False, steady_stepper=None,
             substeps=1, history_steps=0, history_stepper=None, outputs=None, derivatives=()):
    """Simulate the network over input samples t_0..t_N; return temperatures at t_1..t_N, and with
    `derivatives` their derivatives with respect to the network's parameters.

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
    stepper : the network's `ImplicitEuler` for dt, if one is kept between runs (its factors
        per mask are then reused)
    steady_start : before the warm-up, one step of `STEADY_STEP` at the first day's mean
        conditions (`steady_inputs`)
    steady_stepper : the network's `ImplicitEuler` for `STEADY_STEP`, if one is kept between runs
    substeps : k, steps of dt / k per sample, the inputs and imposed temperatures in between from
        `within_steps` (`stepper`, if given, is for dt / k)
    history_steps : H, samples t_1..t_H of a history, the weather before the first measurement
        (`model.case.prepare_case`): run instead of the warm-up, in steps of `history_block`
        samples, each with their mean inputs (a held heat input's energy over the step); its
        rows hold each step's end state. H must be a whole number of those steps.
    history_stepper : the network's `ImplicitEuler` for those steps, if one is kept between runs
    outputs : indices of the nodes returned (default every node): a run in modes (`modal`) forms
        only those
    derivatives : the `network.Derivative` of the network with respect to each of k parameters:
        the temperatures' derivatives are propagated beside them, through the same factors
        (forward sensitivities, docs/model.md section 5.9; `sensitivity_steps`). The start is
        the measurements' and a forced node's temperature is imposed: neither moves with a
        parameter.

    Returns
    -------
    (N_t, N) node temperatures (C) at t_1..t_N, or (N_t+1, N) at t_0..t_N with `include_start`;
    N the nodes of `outputs` where given. With `derivatives`, also their derivatives, (N_t, N, k)
    or (N_t+1, N, k), C per unit of each parameter.
    """
    plan = Plan(network, held_inputs(building, network.input_names), U, dt, measured, force, warmup_days, T_default,
                burn_in_steps, steady_start, substeps, history_steps)
    return plan.run(building, network, outputs, derivatives, include_start, stepper, steady_stepper, history_stepper)


class Plan:
    """What a run reads of its record whatever the values of its network (`simulate`'s arguments
    but the building and the network, of which it reads their layout: the nodes, the inputs and
    which are `held`): the measurements at the start, the steady start's mean inputs and held
    nodes, the history's inputs, each step's input row, inputs, forced nodes and imposed
    temperatures. A calibration runs the same record hundreds of times at other values of its
    parameters: `model.case.Case.run` keeps the plan of each layout it runs."""

    def __init__(self, network, held, U, dt, measured=None, force=None, warmup_days=2, T_default=20.0,
                 burn_in_steps=0, steady_start=False, substeps=1, history_steps=0):
        n_rows, n = U.shape[0], network.n_nodes
        self.layout = (n, tuple(network.input_names))
        if measured is None:
            measured = np.full((n_rows, n), np.nan)
        elif measured.shape[1] < n:  # a case of the building as declared: the nodes its effects add are never measured
            measured = np.hstack([measured, np.full((n_rows, n - measured.shape[1]), np.nan)])
        if force is None:
            force = np.zeros(n, dtype=bool)
        forced = forcing_schedule(force, measured, burn_in_steps)
        self.n_rows, self.dt, self.substeps, H = n_rows, dt, substeps, history_steps
        self.history_steps = H
        self.measured0, self.T_default = measured[0], T_default
        self.steady = steady_inputs(U, measured, forced, dt) if steady_start else None
        self.history = history_inputs(U, H, dt) if H else None
        # the record's steps from t_H, the warm-up's replay standing in for a history the record
        # lacks: each step's input row (from t_H) and sub-step
        rows = warmup_rows(n_rows - H, dt, 0 if H else warmup_days)
        start = len(rows) - (n_rows - 1 - H)  # the step that reaches t_H+1
        row_of, sub_of = np.repeat(rows, substeps), np.tile(np.arange(substeps), len(rows))
        self.inputs = np.stack(within_steps(U[H:], substeps, held), axis=1)[row_of, sub_of]
        self.forced = forced[H:][row_of]
        # imposed where measured: within_steps is column by column, and a column never measured is NaN
        read = np.flatnonzero(np.isfinite(measured[H:]).any(axis=0))
        self.imposed = np.full((len(row_of), n), np.nan)
        self.imposed[:, read] = np.stack(within_steps(measured[H:, read], substeps), axis=1)[row_of, sub_of]
        # the rows from t_H on, each after its last sub-step
        ks = np.arange(max(start - 1, 0), len(rows))
        self.rows, self.kept = H + ks - start + 1, (ks + 1) * substeps - 1

    def run(self, building, network, outputs=None, derivatives=(), include_start=False, stepper=None,
            steady_stepper=None, history_stepper=None, start_offset=None):
        """`simulate` of `building`'s `network`, of the layout the plan was made for (its nodes and
        inputs); `start_offset` (N,) K, where given, is added to the state after the steady start,
        before the history (or the warm-up): the start the record's fit finds (`model.start`)."""
        if (network.n_nodes, tuple(network.input_names)) != self.layout:
            raise ValueError("a network of another layout than its plan's")
        n, dt, H = network.n_nodes, self.dt, self.history_steps
        outputs = np.arange(n) if outputs is None else np.asarray(outputs, dtype=int)
        stepper = ImplicitEuler(network, dt / self.substeps) if stepper is None else stepper
        T = initial_state(building, self.measured0, self.T_default)
        S = np.zeros((n, len(derivatives)))  # the temperatures' derivatives, none at the start
        if self.steady is not None:
            u, held, values = self.steady
            steady_stepper = ImplicitEuler(network, STEADY_STEP) if steady_stepper is None else steady_stepper
            switched, sources = network.switched_diagonal(u), Sources(*network.source_terms(u[None]))
            before, (_, T) = T, steady_stepper.run(T, sources, held, values[None], switched, inputs=u[None])
            if derivatives:
                _, S = sensitivity_steps(steady_stepper, network, derivatives, S, before[None], T[None], u[None],
                                         sources.terms, held, switched, [], [])
        if start_offset is not None:
            T = T + start_offset
        out = np.empty((self.n_rows, len(outputs)))
        out[0] = T[outputs]
        d_out = np.empty((self.n_rows, len(outputs), len(derivatives)))
        d_out[0] = S[outputs]
        if H:  # nothing forced: a run of steps under one matrix, in its modes where it has them
            block = history_block(dt)
            history_stepper = ImplicitEuler(network, block * dt) if history_stepper is None else history_stepper
            L = len(self.history)
            path, d_path, T, S = steps(history_stepper, network, T, self.history, np.zeros((L, n), dtype=bool),
                                       np.full((L, n), np.nan), np.arange(L), outputs, derivatives, S)
            out[1:H + 1] = np.repeat(path, block, axis=0)
            d_out[1:H + 1] = np.repeat(d_path, block, axis=0)
        out[self.rows], d_out[self.rows], _, _ = steps(stepper, network, T, self.inputs, self.forced, self.imposed,
                                                       self.kept, outputs, derivatives, S)
        first = 0 if include_start else 1
        return (out[first:], d_out[first:]) if derivatives else out[first:]


def steps(stepper, network, T, inputs, forced, imposed, kept, outputs, derivatives, S):
    """The temperatures of the `outputs` nodes (C) after the `kept` steps (increasing indices) of
    a sequence of steps from T, (len(kept), len(outputs)); the derivatives of `derivatives`
    (`simulate`'s: k of them) from theirs S (N, k) before the first step, after the same steps
    (len(kept), len(outputs), k: `sensitivity_steps` of each run); and every node's temperature
    (N,) and derivatives (N, k) after the last step. Each run of steps under one step matrix (one
    forcing mask and switched conductances) is stepped in C where the steps are compiled;
    else, long enough, solved in its modes (`modal`, `MODAL_FROM`), or stepped in numpy.

    Parameters
    ----------
    stepper : the network's `ImplicitEuler` for the steps' dt
    network : Network
    T : (N,) C before the first step
    inputs : (L, n_inputs) each step's inputs
    forced : (L, N) bool, the nodes imposed at each step
    imposed : (L, N) C, each step's imposed temperatures (read where forced)
    kept, outputs : indices of the steps and the nodes returned
    """
    from . import compiled  # not in the Python FMU, which steps one doStep at a time
    # a lagged source reads each step's start: no run of such steps is solved in its modes
    modal = not compiled.available() and network.convection is None
    lagged = None if network.convection is None else inputs
    terms, B, q = network.source_terms(inputs)
    sources = Sources(terms, B, q)
    switched = network.switched_diagonal(inputs)  # None where nothing switches
    bounds = runs(forced, switched)
    out = np.empty((len(kept), len(outputs)))
    d_out = np.empty((len(kept), len(outputs), len(derivatives)))
    reads = np.unique(np.concatenate([d.reads for d in derivatives])) if derivatives else None
    for a, b in zip(bounds[:-1], bounds[1:]):
        mask, g = forced[a], None if switched is None else switched[a]
        here = np.flatnonzero((kept >= a) & (kept < b))
        modes = (stepper.modes(mask, g) if modal and b - a >= MODAL_FROM * np.count_nonzero((network.C > 0) & ~mask)
                 else None)
        before = T
        if modes is not None:
            solve, _ = stepper.solver(mask, g)
            if derivatives:  # from the same scan, every step of the nodes the derivatives' sources read too
                nodes = np.union1d(outputs, reads)
                path = np.zeros((b - a, network.n_nodes))
                path[:, nodes], T = modal_run(solve.inverse, stepper.c_dt, mask, modes, T, terms[a:b], B, q,
                                              imposed[a:b], np.arange(b - a), nodes)
                out[here] = path[kept[here] - a][:, outputs]
            else:
                out[here], T = modal_run(solve.inverse, stepper.c_dt, mask, modes, T, terms[a:b], B, q, imposed[a:b],
                                         kept[here] - a, outputs)
        else:  # every node's path where the derivatives' sources read it
            path, T = stepper.run(T, sources[a:b], mask, imposed[a:b], g,
                                  None if derivatives else outputs, None if lagged is None else lagged[a:b])
            out[here] = path[kept[here] - a][:, outputs] if derivatives else path[kept[here] - a]
        if derivatives:
            d_out[here], S = sensitivity_steps(stepper, network, derivatives, S, np.vstack([before[None], path[:-1]]),
                                               path, inputs[a:b], terms[a:b], mask, g, kept[here] - a, outputs, modes)
    return out, d_out, T, S


def runs(forced, switched):
    """The bounds [0, ..., L] of the runs of steps under one step matrix: the same forced nodes
    ((L, N) bool) and switched conductances ((L, N), or None)."""
    changes = np.any(forced[1:] != forced[:-1], axis=1)
    if switched is not None:
        changes |= np.any(switched[1:] != switched[:-1], axis=1)
    return np.concatenate([[0], np.flatnonzero(changes) + 1, [len(forced)]])


def sensitivity_steps(stepper, network, derivatives, S, before, after, inputs, terms, forced, switched, kept,
                      outputs, modes=None):
    """The temperatures' derivatives through a run of L steps under one step matrix (forward
    sensitivities, docs/model.md section 5.9): for each parameter, its `network.Derivative`'s
    source from the temperatures before and after each step (C, (L, N)), the steps' inputs
    (L, n_inputs) and source terms (`Network.source_terms`), carried by the step itself with the
    forced nodes held at zero (a forced temperature is the measurement's, which no parameter
    moves). The factors are the temperatures' own (`stepper.solver`); where the run was solved
    in its `modes`, so are the derivatives (`modal.run` with the source as its inputs).

    Returns
    -------
    (len(kept), len(outputs), k) the derivatives of the `outputs` nodes after the `kept` steps
    (C per unit of each parameter), and (N, k) every node's after the last step
    """
    # the source on the nodes where it may be other than zero, as inputs to them
    n = network.n_nodes
    rows = np.unique(np.concatenate([d.rows for d in derivatives]))
    source = np.stack([d.source(before, after, terms, inputs, stepper.dt, rows) for d in derivatives], axis=-1)
    source[:, forced[rows]] = 0.0
    B, q = np.eye(n)[:, rows], np.zeros(n)
    if modes is not None:
        inverse, imposed = stepper.solver(forced, switched)[0].inverse, np.zeros((len(source), n))
    out = np.empty((len(kept), len(outputs), len(derivatives)))
    last = np.empty_like(S)
    for j in range(len(derivatives)):  # one parameter at a time, each a run of the step with its source
        on = Sources(source[:, :, j], B, q)
        if modes is not None:
            out[..., j], last[:, j] = modal_run(inverse, stepper.c_dt, forced, modes, S[:, j], on.terms, B, q,
                                                imposed, kept, outputs)
        else:
            path, last[:, j] = stepper.run(S[:, j], on, forced, None, switched, outputs)
            out[..., j] = path[kept]
    return out, last


def history_inputs(U, history_steps, dt):
    """(H / b, n_inputs): the mean inputs of each step over a history's samples t_1..t_H, b =
    `history_block(dt)` samples a step; ValueError unless H is a whole number of steps."""
    block = history_block(dt)
    if history_steps % block:
        raise ValueError(f"a history of {history_steps} samples is not a whole number of steps of {block} samples")
    return U[1:history_steps + 1].reshape(history_steps // block, block, -1).mean(axis=1)


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
