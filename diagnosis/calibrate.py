"""Calibrate an effect's parameters on the direct model, with their uncertainty and identifiability.

Bounded least squares on the air-temperature residual of the calibration window (scipy's
`least_squares`, trust region reflective), simulated by the direct model (`model.integrate`):
the FMUs carry the same equations and are tested equal to it (tests/test_fmu3.py), and a
diagnosis calibrates tens of candidates, each once on the whole calibration window and once per
cross-validation block left out (`diagnosis.selection`, each fold one Gauss-Newton step from the
whole window's optimum), so a simulation without an FMU's per-step calls is what makes that
affordable. Least squares' Jacobian is exact: the temperatures' derivatives propagated with each
run through its own factors (forward sensitivities, `Candidate.jacobian`), one run a point for
every parameter, not a run a parameter. The chosen effect's FMU is built and written all
the same (`diagnosis.loop`). The covariance of the estimate is the linearised sandwich of
`model.significance`, which allows for the residual's correlation in time (the textbook
s^2 (J^T J)^-1 assumes independent residuals and, on real records, is several times too tight).
A parameter is called identifiable from the data when that estimate is tight enough to act on
(`diagnosis.policy.Policy.identifiable`) and it did not end on a bound. A parameter with a
physical prior (`model.effects.Prior`) is fitted with it weighed against the data, a maximum a
posteriori fit (`Penalised`, `calibrate`).
"""
import logging
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
from scipy.linalg import block_diag
from scipy.optimize import least_squares

from nodeforce.diagnosis.candidates import calibration_start
from nodeforce.diagnosis.policy import Policy
from nodeforce.diagnosis.selection import on_block
from nodeforce.model.case import as_cases
from nodeforce.model.significance import bandwidth, parameter_covariance
from nodeforce.model.effects import EFFECTS
from nodeforce.model.hlc import heat_loss_coefficient
from nodeforce.model.network import assemble, derivative, moved
from nodeforce.model.numerical import share, share_slope
from nodeforce.model.start import fitted_start, free_response, residual_sd

log = logging.getLogger("nodeforce.diagnosis")

# The step of a derived quantity's differences (`gradient`), as a fraction of a parameter's range:
# the HLC and a ground coupling's flux are smooth in every parameter (a conductance in series, a
# linear network solved exactly), so a small step is exact to many digits.
STEP = 1e-6
# Simulations a candidate keeps, by parameter values and window: the runs the report needs at the
# calibrated values are then simulations already made.
KEPT_RUNS = 64
# Halvings of a fold's step before it falls back on the whole window's optimum (`fold`).
FOLD_HALVINGS = 6
# The network's derivative with respect to a parameter is the difference of two assemblies this
# fraction of the parameter's range apart, divided by it: exact, whatever the fraction, for a
# network affine in the parameter, which a third assembly a step further checks (`AFFINE`). A
# large step keeps the difference's rounding far below the entries it measures.
NETWORK_STEP = 1e-2
# How far apart the two steps' differences may be, relative to the largest entry, for the network
# to be affine in the parameter; a parameter it is not affine in keeps finite differences of its
# runs (`Candidate.jacobian`).
AFFINE = 1e-9
# Least squares stops once a step lowers its cost (half the sum of squared residuals) by less
# than this fraction of it (scipy's ftol). At a fit near the noise the cost is n sigma^2 / 2 for n
# residuals, so the fraction is n / 2e6 of one residual's variance: a thousandth of sigma^2 on
# a record of 2,000 scored steps, a twentieth on one of 100,000, where the choice reads
# differences of J of the order of its spread over the blocks, some sigma^2 sqrt(2 n). scipy's
# default, 1e-8, walked a ground coupling's valley (the data fix U (T_ground - T_floor), not U
# and T_ground apart) for 190 iterations and 0.03 % of J: most of a test-cell round's time.
FIT_TOLERANCE = 1e-6


class Candidate:
    """The model with one added effect, simulated by the direct model at any parameter values.

    `protocols` ({id(case): Building}) gives, for a case of a record run under another protocol
    (its own supply flows, its own blinds), that record's building as the model stands; the effect
    is added to it there. Other cases run `building`.

    An effect that acts on the model's inputs alone, affinely in its parameters
    (`model.effects.Effect.on_inputs`: a gain, an absorptance, a transmittance, a split of the
    heat input), leaves the step matrix as it was, and the temperatures are affine in its
    parameters: T(x) = T(a) + sum_i (x_i - a_i) S_i, every term linear in the sources. Such a
    candidate is simulated 1 + k times per case and nodes (at a, and at each parameter moved to
    its far bound: `Superposition`), and every other value of its parameters, the least
    squares' iterations, their differences and the folds, is that sum: the same temperatures to
    rounding. Whether the matrix is indeed left as it was is checked on the buildings themselves
    (a heat input's split changes the links of a heater node, where the zone has one).

    `beside`: effects the building already holds ((effect, target) pairs) refitted together with
    the candidate, their parameters after its own (`names`: theirs as "effect@target/name"), each
    starting from its value in `building`; those named in `held` ({label: names}) stay there
    (a parameter that rests on its physical prior: `diagnosis.loop.resting_on_priors`). A model's effects refitted
    together is the fair test of one of them against another (`diagnosis.loop.revisit`)."""

    def __init__(self, building, effect, target, protocols=None, beside=(), held=None):
        self.building, self.effect, self.target = building, effect, target
        self.protocols = protocols or {}
        self.parts = ((effect, target), *beside)
        self.own = len(EFFECTS[effect].parameters)  # the candidate's own parameters come first
        # (label of the effect beside it, or None for its own, parameter), in `parameters` order
        entries = [(f"{e}@{t}" if j else None, p) for j, (e, t) in enumerate(self.parts) for p in EFFECTS[e].parameters]
        self.parameters = tuple(p for _, p in entries)
        self.names = tuple(p.name if label is None else f"{label}/{p.name}" for label, p in entries)
        # [(low, high)] a calibration explores
        self.bounds = [b for e, t in self.parts for b in EFFECTS[e].bounds(building, t)]
        self.held = tuple(i for i, (label, p) in enumerate(entries)
                          if label is not None and p.name in (held or {}).get(label, ()))
        self._beside = [(label, p.name) for label, p in entries[self.own:]]
        self._runs, self._inputs, self._superposed, self._jacobians = {}, {}, {}, {}
        self._derivatives, self._affine_alone, self._affines = {}, {}, {}
        self.simulations = 0  # simulations run (kept ones not counted again): a round's cost

    @property
    def label(self):
        return f"{self.effect}@{self.target}"

    def by_effect(self, fitted):
        """A calibration's result ({name: ...}, `names`) split: the candidate's own parameters by
        name, and those of the effects beside it by label ({label: {name: ...}})."""
        beside = {}
        for (label, name), key in zip(self._beside, self.names[self.own:]):
            beside.setdefault(label, {})[name] = fitted[key]
        return {name: fitted[name] for name in self.names[:self.own]}, beside

    def start(self):
        """Where its calibration starts (`calibration_start` of each part, in `parameters` order):
        every value strictly inside its range."""
        values = []
        for effect, target in self.parts:
            start = calibration_start(self.building, effect, target)
            values += [start[p.name] for p in EFFECTS[effect].parameters]
        return np.array(values)

    def built(self, values, base=None):
        """The building (`base`, default the candidate's) with the effect, and those `beside` it, at
        `values` (sequence, in `parameters` order)."""
        building, values = self.building if base is None else base, list(values)
        for effect, target in self.parts:
            parameters = EFFECTS[effect].parameters
            building = EFFECTS[effect].apply(building, target, {p.name: float(v) for p, v in
                                                                zip(parameters, values[:len(parameters)])})
            values = values[len(parameters):]
        return building

    def base(self, case):
        """The building `case` runs before the effect is added (its record's protocol's, or
        `building`)."""
        return self.protocols.get(id(case), self.building)

    def nodes(self, case, node_ids, values):
        """Simulated temperatures (C) of nodes at t_1..t_N, (N_t, len(node_ids)), with the effect
        at `values` (sequence)."""
        key = (id(case), tuple(node_ids), tuple(float(v) for v in values))
        if key in self._runs:
            return self._runs[key]
        superposed = self._superposition(case, key[1])
        run = superposed(values) if superposed is not None else \
            self._simulated(case, node_ids, *self.network(values, self.base(case)))
        keep_run(self._runs, key, run)
        return run

    def jacobian(self, case, node_ids, values):
        """(N_t, len(node_ids), k): the derivatives of `nodes` at `values` with respect to each
        parameter (C per unit of it). A superposed candidate's are its slopes; any other's are
        propagated through the run's own factors beside its temperatures (forward
        sensitivities: `integrate.simulate`, docs/model.md section 5.9), from the network's
        derivative with respect to each parameter (`_derivative`), at the cost of one run. A
        parameter the network is not affine in has none: its column is a forward difference of
        runs, least squares' own step (`step_forward`)."""
        values = np.asarray(values, dtype=float)
        key = (id(case), tuple(node_ids), tuple(values))
        if key in self._jacobians:
            return self._jacobians[key]
        superposed = self._superposition(case, key[1])
        if superposed is not None:
            jacobian = np.stack(superposed.slopes, axis=-1)
        else:
            base = self.base(case)
            building, network = self.network(values, base)
            affine = self.affine(base)
            derivatives = affine.derivatives if affine is not None else \
                [self._derivative(base, network, values, i) for i in range(len(values))]
            exact = [i for i, d in enumerate(derivatives) if d is not None]
            self.simulations += 1
            run = self._inputs_of(case).run(building, np.asarray(node_ids) - 1, network,
                                            [derivatives[i] for i in exact])
            run, moved = run if exact else (run, None)
            keep_run(self._runs, key, run)
            jacobian = np.empty(run.shape + (len(values),))
            if exact:
                jacobian[..., exact] = moved
            for i in sorted(set(range(len(values))) - set(exact)):
                h = step_forward(values[i], *self.bounds[i])
                stepped = values.copy()
                stepped[i] += h
                jacobian[..., i] = (self.nodes(case, node_ids, stepped) - run) / h
        keep_run(self._jacobians, key, jacobian)
        return jacobian

    def _derivative(self, base, network, values, i):
        """The `network.Derivative` of `network`, the candidate's on `base` at `values`, with
        respect to parameter i: the difference of the assemblies at values and one step
        (`NETWORK_STEP`) of i's range away, or None where the network is not affine in the
        parameter (a difference one step further is not the same, to `AFFINE`, or the
        network's shape moves with it). Kept for the values of the others: the network's
        terms in one parameter may scale with another (a ground coupling's U T_ground)."""
        key = (id(base), i, tuple(np.delete(values, i)))
        if key in self._derivatives:
            return self._derivatives[key]
        one, h = self._stepped(base, values, i, 1)
        found = derivative(network, one, h)
        if found is not None and (id(base), i) not in self._affine_alone:
            further = derivative(one, self._stepped(base, values, i, 2)[0], h)
            self._affine_alone[(id(base), i)] = further is not None and found.close_to(further, AFFINE)
            if not self._affine_alone[(id(base), i)]:
                log.info("%s: the network is not affine in %s: its derivatives by differences of runs",
                         self.label, self.names[i])
        if not self._affine_alone.get((id(base), i), False):
            found = None
        self._derivatives[key] = found
        return found

    def _stepped(self, base, values, i, steps):
        """The network of the candidate on `base` at `values` with parameter i moved `steps` steps
        of `NETWORK_STEP` of its range (towards the side with room for two), assembled; and the
        step (the parameter's unit)."""
        low, high = self.bounds[i]
        h = NETWORK_STEP * (high - low)
        h = h if values[i] + 2 * h <= high else -h
        moved = values.copy()
        moved[i] += steps * h
        return assemble(self.built(moved, base)), h

    def _inputs_of(self, case):
        """The case with the inputs the candidate's buildings read: the effect may read inputs the
        building as declared does not (a daily gain, the clock)."""
        if id(case) not in self._inputs:
            declared = self.base(case)
            for effect, target in self.parts:
                declared = EFFECTS[effect].apply(declared, target, {})
            self._inputs[id(case)] = (case, case.with_inputs(declared))
        return self._inputs[id(case)][1]

    def _simulated(self, case, node_ids, building, network=None):
        """The nodes of `building`, the case's base with the effect at some values, simulated
        (`network`: its network, where the caller has it)."""
        self.simulations += 1
        return self._inputs_of(case).run(building, np.asarray(node_ids) - 1, network)

    def network(self, values, base=None):
        """The building and the network of the candidate on `base` (default its building) at
        `values`: where the network is affine in the parameters together (`affine`), the one
        assembled at the start moved along its derivatives, and the building at the start (its
        layout, which is all a run or the HLC reads of it besides the network, does not move
        with them); else the building edited and assembled."""
        base = self.building if base is None else base
        affine = self.affine(base)
        if affine is None:
            building = self.built(values, base)
            return building, assemble(building)
        return affine.building, affine.network_at(values)

    def affine(self, base):
        """The candidate's `Affine` network on `base`, or None where the network is not affine in
        its parameters together. Its derivatives are differences of one step (`NETWORK_STEP`)
        of each parameter's range from the start; at the far corner of the ranges, every
        parameter moved to the farther of its bounds, the network moved along them from the
        start must be the one assembled there to `AFFINE` of the move: a network curved in a
        parameter over its range fails it, as one whose terms in a parameter scale with another
        does (a ground coupling's U T_ground, affine in each alone)."""
        if id(base) in self._affines:
            return self._affines[id(base)]
        start = self.start()
        building = self.built(start, base)
        network = assemble(building)
        derivatives = [derivative(network, *self._stepped(base, start, i, 1)) for i in range(len(start))]
        affine = None
        if all(d is not None for d in derivatives):
            far = farther_bounds(start, self.bounds)
            assembled = derivative(network, assemble(self.built(far, base)), 1.0)
            predicted = derivative(network, moved(network, derivatives, far - start), 1.0)
            if assembled is not None and predicted.close_to(assembled, AFFINE):
                affine = Affine(start, building, network, derivatives)
            else:
                log.info("%s: the network is not affine in its parameters together: assembled at each of "
                         "their values", self.label)
        self._affines[id(base)] = affine
        return affine

    def _superposition(self, case, node_ids):
        """The `Superposition` of these nodes on `case`, or None where the effect is not on the
        inputs alone or its building's matrices move with its parameters."""
        if not EFFECTS[self.effect].on_inputs or len(self.parts) > 1:
            return None
        key = (id(case), node_ids)
        if key not in self._superposed:
            reference, far = superposition_points(self.building, self.effect, self.target, self.bounds)
            buildings = [self.built(x, self.base(case)) for x in [reference, *far]]
            networks = [assemble(b) for b in buildings]
            kept = all(np.array_equal(n.C, networks[0].C) and np.array_equal(n.A, networks[0].A)
                       and n.switched == networks[0].switched for n in networks[1:])
            self._superposed[key] = Superposition(
                reference, far, [self._simulated(case, node_ids, b) for b in buildings]) if kept else None
        return self._superposed[key]


@dataclass
class Affine:
    """A candidate's network on one base where it is affine in the parameters together: the
    building and its network assembled at the values `at`, and the network's `Derivative` with
    respect to each parameter."""
    at: np.ndarray
    building: object
    network: object
    derivatives: list

    def network_at(self, values):
        """The network at `values`: the one assembled moved along its derivatives
        (`network.moved`), exactly it at `at`."""
        return moved(self.network, self.derivatives, np.asarray(values, dtype=float) - self.at)


def keep_run(store, key, value):
    """Keep a run or its derivatives in `store` by its (case, nodes, values), the oldest dropped
    past `KEPT_RUNS`."""
    if len(store) >= KEPT_RUNS:
        store.pop(next(iter(store)))
    store[key] = value


def superposition_points(building, effect, target, bounds):
    """Where a `Superposition` simulates an effect: its calibration's start a (strictly inside
    the range), and a with each parameter in turn moved to the farther of its bounds, the
    longest difference, whose rounding is the least."""
    start = calibration_start(building, effect, target)
    a = np.array([start[p.name] for p in EFFECTS[effect].parameters])
    corner = farther_bounds(a, bounds)
    far = []
    for i in range(len(bounds)):
        x = a.copy()
        x[i] = corner[i]
        far.append(x)
    return a, far


def farther_bounds(values, bounds):
    """(k,) each parameter's bound the farther from its value: the longest move within its range."""
    return np.array([high if high - x >= x - low else low for x, (low, high) in zip(values, bounds)])


class Superposition:
    """Temperatures affine in an effect's parameters, from runs at a point a and at a with each
    parameter moved alone (`far`): T(x) = T(a) + sum_i (x_i - a_i) (T(far_i) - T(a)) /
    (far_i - a_i)."""

    def __init__(self, reference, far, runs):
        self.reference = np.asarray(reference, dtype=float)
        self.at = runs[0]
        self.slopes = [(run - self.at) / (x[i] - self.reference[i]) for i, (x, run) in enumerate(zip(far, runs[1:]))]

    def __call__(self, values):
        out = self.at.copy()
        for value, a, slope in zip(values, self.reference, self.slopes):
            out += (float(value) - a) * slope
        return out


@dataclass
class Own:
    """A component's own measured nodes, read by its candidate's fit beside the objective air:
    per case their ids (besides the air's) and the file's numerical error there (C, (N_t,
    len(ids)), or None), the sd (C) of a reading's noise, and the component's memory of its
    start (s: `Policy.start_memory` of its slowest time constant)."""
    ids: list
    numerical: list
    sd: float
    memory: float

    def measured(self, case, ids):
        """(N_t, len(ids)) the readings of the nodes `ids` on `case` the fit reads: from `memory`
        after the burn-in, NaN before."""
        readings = case.scored([n - 1 for n in ids])
        readings[:case.burn_in_steps + int(np.ceil(self.memory / case.dt))] = np.nan
        return readings


class Residuals:
    """A fit's residuals at parameter values x, and their Jacobian: the measured less the
    simulated (`raw`, and its derivatives `raw_jacobian`, (rows, k)), less the share of the file's
    numerical error `error` found on the rows that count (`model.numerical.share`), each row times
    its `scale` (the square root of its weight; a row of weight 0 does not count)."""

    def __init__(self, raw, raw_jacobian, error, scale):
        self.raw, self.raw_jacobian, self.error, self.scale = raw, raw_jacobian, error, scale
        self.counted = scale > 0

    def __call__(self, x, rows=None):
        """The residuals at x, the share read on the `rows` (bool) that count, or all of them."""
        r = self.raw(x)
        counted = self.counted if rows is None else self.counted & rows
        return (r + share(r, self.error, counted) * self.error) * self.scale

    def fitting(self, x):
        """The residuals at x with their Jacobian there worked out beside them (the candidate keeps
        both): least squares asks for the Jacobian at every point it moves to, and a run that
        carries the derivatives costs less than a run and then another for them."""
        self.raw_jacobian(x)
        return self(x)

    def jacobian(self, x):
        r, slopes = self.raw(x), self.raw_jacobian(x)
        return (slopes + np.outer(self.error, share_slope(r, self.error, self.counted, slopes))) * self.scale[:, None]


class Started:
    """`Residuals` with each record's slow modes' start profiled out (`model.start`, variable
    projection): the data's rows are r - F c, F the free responses of the start's amplitudes on
    the rows (`free`, (rows, m), each record's own columns), weighted as the rows are, and c
    their Gaussian-prior least squares at the same parameters (`fitted_start`); a row per
    amplitude after the data's, sigma c_j / sd_j, makes the squares' sum the J of
    `model.start`. F does not move with the parameters, so the Jacobian is the data's projected:
    (I - F Q) J_r and sigma diag(sd^-1) Q J_r, Q = (F'F + sigma^2 diag(sd^-2))^-1 F'."""

    def __init__(self, residuals, free, sd, sigma):
        self.residuals = residuals
        self.F = free * residuals.scale[:, None]
        self.sd, self.sigma = np.asarray(sd, dtype=float), sigma
        self.data = len(residuals.counted)
        self.counted = np.r_[residuals.counted, np.ones(len(self.sd), dtype=bool)]

    def amplitudes(self, r, rows=None):
        """c (m,) K of the weighted data rows' residual `r`, on the `rows` (bool) alone where given."""
        F = self.F if rows is None else self.F * rows[:, None]
        return fitted_start(F, r if rows is None else np.where(rows, r, 0.0), self.sd, self.sigma)[0]

    def at(self, x, rows=None):
        """c at parameters x, fitted on the data's `rows` (bool, data rows) where given."""
        return self.amplitudes(self.residuals(x, rows), rows)

    def _started(self, r, rows=None):
        c = self.amplitudes(r, rows)
        return np.r_[r - self.F @ c, self.sigma * c / self.sd]

    def __call__(self, x, rows=None):
        rows = None if rows is None else rows[:self.data]
        return self._started(self.residuals(x, rows), rows)

    def fitting(self, x):
        return self._started(self.residuals.fitting(x))

    def jacobian(self, x):
        J = self.residuals.jacobian(x)
        QJ = self.amplitudes(J)
        return np.vstack([J - self.F @ QJ, (self.sigma / self.sd)[:, None] * QJ])


class Penalised:
    """`Residuals` with a row per Gaussian prior (`model.effects.Prior`) after the data's: sigma (x_i
    - value) / sd for parameter i, sigma the noise's sd (C). Their squares' sum is J (C2) plus
    sigma^2 sum ((x_i - value) / sd)^2, which is -2 sigma^2 times the log-posterior of the
    parameters under white noise of sd sigma and the priors (to a constant): least squares on
    them is the maximum a posteriori fit. The data's rows come first (`data`: how many)."""

    def __init__(self, residuals, priors, sigma):
        self.residuals = residuals
        self.indices = np.array(list(priors), dtype=int)
        self.values = np.array([p.value for p in priors.values()])
        self.weights = sigma / np.array([p.sd for p in priors.values()])
        self.data = len(residuals.counted)
        self.counted = np.r_[residuals.counted, np.ones(len(priors), dtype=bool)]

    def _prior_rows(self, x):
        return self.weights * (np.asarray(x, dtype=float)[self.indices] - self.values)

    def __call__(self, x, rows=None):
        return np.r_[self.residuals(x, None if rows is None else rows[:self.data]), self._prior_rows(x)]

    def fitting(self, x):
        return np.r_[self.residuals.fitting(x), self._prior_rows(x)]

    def jacobian(self, x):
        rows = np.zeros((len(self.indices), len(x)))
        rows[np.arange(len(self.indices)), self.indices] = self.weights
        return np.vstack([self.residuals.jacobian(x), rows])


def with_priors(cov, priors):
    """The posterior covariance of the parameters: the data's `cov` (k, k, units squared)
    combined with the Gaussian `priors` ({index: Prior}), (cov^+ + P)^+ with P diagonal, 1 / sd^2
    at a prior's index and 0 elsewhere: the inverse of the log-posterior's Hessian, the priors'
    terms added to the data's. A direction the data say nothing of (a T_ground whose coupling U
    is 0, its Jacobian column zero and its data variance 0) has no data precision, and the
    prior's sd is the posterior's; a parameter held (variance 0, no prior) keeps variance 0.
    Computed on the correlations (each parameter in units of its data sd), whose inverse's
    relative cutoff then drops a direction the data leave undetermined, never a parameter whose
    unit makes its variance small. `cov` itself where there is no prior."""
    if not priors:
        return cov
    d = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    d = np.where(d > 0, d, 1.0)
    precision = np.zeros(len(cov))
    for i, prior in priors.items():
        precision[i] = (d[i] / prior.sd) ** 2
    posterior = np.linalg.pinv(np.linalg.pinv(cov / np.outer(d, d), hermitian=True) + np.diag(precision),
                               hermitian=True)
    return posterior * np.outer(d, d)


def calibrate(candidate, cases, objective, blocks=(), numerical=None, own=None, policy=None, sigma=None,
              start=False):
    """Least-squares values of the candidate's parameters on the calibration windows of one or
    several records of the building (`cases`), on the residuals of every objective zone of every
    record together (the sum of each window's J), and the same fit with each block of steps left out.

    Where the file's own numerical error is given (`numerical`), the residual is taken less the
    share of it least squares finds there (`model.numerical.share`, on the rows a fit reads): a
    wall's conductivity or absorptance, slow and weather-driven, would otherwise be fitted to what
    the file's coarse walls make, and chosen for it over the fault the record holds.

    A parameter physics has a prior for (`model.effects.Prior`: a ground coupling's T_ground, the
    site's deep ground) is fitted with the prior weighed against the data, a maximum a posteriori
    fit (`Penalised`): where the data fix a combination of the parameters only (the ground's flux
    U (T_ground - T_face)), the prior sets where along that valley the fit ends, not wherever
    least squares stopped (a ground at 0.2 C under a cell in Miami, its U a tenth of the
    truth's); where the data fix the parameter, they move it, the prior's pull some (sd_data /
    sd_prior)^2 of the way back. No test chooses between a held and a free fit: the posterior is
    both at once. Its covariance is the data's with the priors' precision added (`with_priors`).

    Parameters
    ----------
    candidate : Candidate
    cases : Case, or a sequence of Cases: each record's calibration window
    objective : model.score.Objective
    blocks : (record index, (N_t,) bool mask of the steps of that record's window) of each
        cross-validation block (`diagnosis.selection`); a bare mask is a block of the first record
    numerical : per case, the file's numerical error at the objective air (C, (N_t, zones):
        `model.numerical.discretisation_error`), or None
    own : the candidate's component's own measured nodes (`Own`), or None. The air alone fits a
        component's value wrongly where another fault shares the air's error (a door's
        conductivity taking part of a window's transmittance); its own surface says which value
        is the component's. The fit to the air alone weighs each own node (`own_weights`), and
        the fit is made again with them beside the air, read once the component has forgotten
        the start the burn-in could not set (`Own.measured`)
    policy : the `diagnosis.policy.Policy` that says what is identifiable and how a sensor weighs
        (default: `Policy()`)
    sigma : the noise's sd (C), which puts a prior's penalty in J's units (`Penalised`); None:
        the rms residual of the fit without the priors
    start : whether each record's slow modes' start its history leaves unknown is fitted with
        the parameters (`Started`): once a round of the diagnosis has chosen the start
        (`diagnosis.selection.decide`), every later fit estimates it

    Returns
    -------
    dict {name: {"value", "std", "identifiable", "on_bound"}, and "prior": its prior, stated
    (`stated`), where it has one; "std" the posterior's, "identifiable" whether the data alone
    fix it}; the quantities the data determine
    even where the parameters are not (see `derived`); and per block the parameter values fitted
    without it (`fold`), the residuals (C, (N_t, zones) of its record, NaN off the block) they
    leave on it, and what they predict there of the own nodes ("own", C, (N_t, len(own ids)))
    """
    cases = as_cases(cases)
    policy = Policy() if policy is None else policy
    blocks = [b if isinstance(b, tuple) else (0, b) for b in blocks]
    zones = len(objective.air_nodes)
    extra = own.ids if own is not None else [[] for _ in cases]
    ids = [list(objective.air_nodes) + list(e) for e in extra]
    # the air's columns, then the component's own nodes'
    measured = [np.hstack([objective.measured(case), own.measured(case, e) if own is not None else case.scored([])])
                for case, e in zip(cases, extra)]
    have = [np.isfinite(m) for m in measured]
    lows, highs = np.array(candidate.bounds).T
    x0 = candidate.start()  # inside the bounds: `calibration_start`
    kept = {i: x0[i] for i in candidate.held}  # the effects beside it keep what their own round held

    numerical = [np.hstack([air if air is not None else np.zeros((len(m), zones)),
                            at if at is not None else np.zeros((len(m), len(e)))])
                 for m, e, air, at in zip(measured, extra, numerical or [None] * len(cases),
                                          (own.numerical if own is not None else None) or [None] * len(cases))]
    error = np.concatenate([e[h] for e, h in zip(numerical, have)])

    def raw(x):
        return np.concatenate([(m - candidate.nodes(case, i, x))[h] for case, i, m, h in zip(cases, ids, measured, have)])

    def raw_jacobian(x):
        return -np.concatenate([candidate.jacobian(case, i, x)[h] for case, i, h in zip(cases, ids, have)])

    # each record's slow modes' start, where `start`, fitted at every value of the parameters
    # (`Started`), on the model as it stands: its free response is the model's, a candidate's effect aside
    starts = [free_response(case, candidate.base(case), i) for case, i in zip(cases, ids)] if start else []
    free = block_diag(*[F[h] for (F, _), h in zip(starts, have)]) if start else None
    start_sd = np.concatenate([modes.sd for _, modes in starts] or [np.zeros(0)])
    sigma_start = (residual_sd(free, raw(x0)) if sigma is None else sigma) if len(start_sd) else None

    def weighted(weights):
        """The `Residuals` with each own node's column times the square root of its weight (one
        (len(ids),) per case; the air's columns weigh 1), the start profiled out (`Started`)
        where a record has a slow mode its history leaves unknown."""
        scale = np.sqrt(np.concatenate([np.broadcast_to(np.r_[np.ones(zones), w], h.shape)[h]
                                        for w, h in zip(weights, have)]))
        residuals = Residuals(raw, raw_jacobian, error, scale)
        return Started(residuals, free, start_sd, sigma_start) if len(start_sd) else residuals

    # each record's steps numbered apart from the others' by more than the HAC's lags: residuals
    # of two records are not correlated
    lags = bandwidth(cases[0].dt)
    steps, offset = [], 0
    for h in have:
        steps.append(np.nonzero(h)[0] + offset)
        offset += len(h) + lags + 1
    steps = np.concatenate(steps)
    priors = wanted_priors(candidate, cases)
    residuals = weighted([np.zeros(len(e)) for e in extra])
    started = residuals
    fit = solve(residuals, x0, lows, highs, kept)
    if priors:
        # the MAP fit starts from the free fit's end of a valley: from the prior's side a coupling
        # the data want the other way ends on U = 0, where T_ground acts not at all and its prior
        # holds it at a point that fits nothing. The noise unknown, the free fit's rms residual.
        sigma = float(np.sqrt(np.mean(np.square(fit.fun)))) if sigma is None else sigma
        residuals = Penalised(residuals, priors, sigma)
        fit = solve(residuals, fit.x, lows, highs, kept)
    if any(h[:, zones:].any() for h in have):
        weights = own_weights(candidate, cases, ids, measured, numerical, fit.x, own, policy)
        log.info("%s: its own nodes read beside the air, weighing %s", candidate.label,
                 "; ".join(", ".join(f"{n}: {w:.2g}" for n, w in zip(e, ws)) for e, ws in zip(extra, weights)))
        residuals = started = weighted(weights)
        residuals = Penalised(residuals, priors, sigma) if priors else residuals
        fit = solve(residuals, fit.x, lows, highs, kept)
    data = len(steps)  # the data's rows, the priors' after them
    data_cov = parameter_covariance(fit.jac[:data], fit.fun[:data], steps, lags)
    cov = with_priors(data_cov, priors)
    if priors:
        log.info("%s: %s, each weighed with its prior", candidate.label,
                 ", ".join(f"{candidate.parameters[i].name} = {fit.x[i]:.4g} {candidate.parameters[i].unit} "
                           f"(prior {prior.value:.4g} +- {prior.sd:.2g}: {prior.source})" for i, prior in priors.items()))
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    result = {}
    for i, (p, name, value, sd, bound, fixed) in enumerate(zip(candidate.parameters, candidate.names, fit.x, std,
                                                               fit.active_mask,
                                                               identified(candidate, fit, data_cov, policy))):
        if not fixed and i not in priors:
            log.info("%s: %s = %.4g +- %.2g %s is not identifiable from these data%s", candidate.label,
                     name, value, sd, p.unit, " (it ended on a bound)" if bound else "")
        result[name] = {"value": float(value), "std": float(sd), "identifiable": bool(fixed),
                        "on_bound": bool(bound != 0), **({"prior": stated(priors[i], p.unit)} if i in priors else {})}
    folds = []
    for record, block in blocks:
        train = ~np.concatenate([rows[h] for rows, h in zip(on_block([h.shape for h in have], record, block), have)])
        train = np.r_[train, np.ones(len(fit.fun) - data, dtype=bool)]  # every fold weighs the priors
        x = fold(fit, train, lows, highs, lambda x: residuals(x, train))
        case, m, h = cases[record], measured[record], have[record]
        s = share(raw(x), error, train[:data] & residuals.counted[:data])
        T = candidate.nodes(case, ids[record], x)
        if len(start_sd):  # the start fitted without the block
            T = T + start_of(starts, record, started.at(x, train[:data]))
        left = np.where(h & block[:, None], m - T + s * numerical[record], np.nan)
        folds.append({"values": [float(v) for v in x], "residuals": left[:, :zones],
                      "own": np.where(block[:, None], T[:, zones:], np.nan)})
    determined = derived(candidate, cases[0], fit.x, cov)
    if len(start_sd):
        determined.update(stated_start(starts, started, fit.x, sigma_start))
    return result, determined, folds


def start_of(starts, record, c):
    """(N_t, nodes) C: what the start's amplitudes `c` (every record's, in order) add to
    `record`'s run, from its free responses (`starts`: `free_response` of each record)."""
    offset = sum(len(modes.tau) for _, modes in starts[:record])
    F, modes = starts[record]
    return F @ c[offset:offset + len(modes.tau)]


def stated_start(starts, started, x, sigma):
    """What the fit at `x` found of each record's start, as report.json carries what the data
    determine: each slow mode's amplitude at the first measurement (K) and its posterior sd,
    keyed by the record's number and the mode's time constant; and the share of the
    calibration window's J (the data's rows) the fitted start takes out of it. The sd is the
    amplitudes' and the parameters' together: sigma^2 (A'A)^-1 with A the data's Jacobian in
    both, [J_r F], over the amplitudes' prior rows [0 sigma diag(sd^-1)], its amplitudes' block;
    a parameter that trades off against the start (a gain against a warm floor) widens it."""
    r = started.residuals(x)
    c = fitted_start(started.F, r, started.sd, sigma)[0]
    slopes = started.residuals.jacobian(x)
    k = slopes.shape[1]
    A = np.vstack([np.hstack([slopes, started.F]), np.hstack([np.zeros((len(c), k)), np.diag(sigma / started.sd)])])
    sds = np.sqrt(np.clip(np.diag(sigma ** 2 * np.linalg.pinv(A.T @ A, hermitian=True))[k:], 0.0, None))
    out, j = {}, 0
    for number, (_, modes) in enumerate(starts, 1):
        for tau in modes.tau:
            out[f"start_of_record_{number}_{tau / 86400:.3g}_day_mode"] = {"value": float(c[j]), "std": float(sds[j]),
                                                                          "unit": "K"}
            j += 1
    J = float(r @ r)
    left = r - started.F @ c
    out["start_share_of_J"] = {"value": float(1.0 - (left @ left) / J) if J > 0 else 0.0, "std": 0.0, "unit": ""}
    return out


def own_weights(candidate, cases, ids, measured, numerical, x, own, policy):
    """Per case, each own node's weight beside the air in a component candidate's fit
    (`policy.sensor_weight`): sd_j^2 over its mean squared residual at `x`, the fit to the air
    alone, sd_j the noise (`own.sd`, C) and the file's numerical error there; 0 where it has no
    reading. `ids`, `measured`, `numerical`: per case, the objective air's columns then the own
    nodes' (`own.ids`).

    A sensor is weighted as a measurement whose error is what the model leaves there: a surface
    the component's correction brings to the noise counts as the air does, and fixes the
    component's value where another fault shares the air's error; one the model cannot follow
    whatever the value (a real wall behind a simplified one) counts as little as its misfit says,
    and does not pull the fit of the air towards it."""
    out = []
    for case, i, m, e, o in zip(cases, ids, measured, numerical, own.ids):
        zones = len(i) - len(o)
        r, e = m[:, zones:] - candidate.nodes(case, i, x)[:, zones:], e[:, zones:]
        finite = np.isfinite(r)
        n = finite.sum(axis=0)
        mean_square = np.where(finite, np.square(r), 0.0).sum(axis=0) / np.maximum(n, 1)
        floor = np.hypot(own.sd, np.sqrt(np.where(finite, np.square(e), 0.0).sum(axis=0) / np.maximum(n, 1)))
        out.append(np.where(n > 0, policy.sensor_weight(floor, np.maximum(mean_square, np.finfo(float).tiny)), 0.0))
    return out


def solve(residuals, x0, lows, highs, held=None):
    """Bounded least squares of `residuals(x)` from x0 over the parameters not `held` ({index:
    value}, those fixed at their value): its x, fun, jac and active_mask as scipy's, of every
    parameter (a held one's Jacobian column zero, its active_mask 0). The Jacobian is
    `residuals.jacobian(x)` where the residuals carry one (`Residuals`), else least squares'
    differences."""
    held = held or {}
    free = np.array([i not in held for i in range(len(x0))])
    x = np.array(x0, dtype=float)
    x[list(held)] = list(held.values())

    def full(z):
        out = x.copy()
        out[free] = z
        return out
    exact = getattr(residuals, "jacobian", None)
    fun = residuals if exact is None else residuals.fitting
    fit = least_squares(lambda z: fun(full(z)), x[free], bounds=(lows[free], highs[free]), x_scale="jac",
                        method="trf", ftol=FIT_TOLERANCE,
                        jac="2-point" if exact is None else (lambda z: exact(full(z))[:, free]))
    jac = np.zeros((len(fit.fun), len(x)))
    jac[:, free] = fit.jac
    active = np.zeros(len(x), dtype=int)
    active[free] = fit.active_mask
    return SimpleNamespace(x=full(fit.x), fun=fit.fun, jac=jac, active_mask=active)


def identified(candidate, fit, cov, policy):
    """Per parameter, whether the data fix it: its estimate tight enough to act on
    (`policy.identifiable`, sd from `cov`) and not on a bound."""
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return [bool(policy.identifiable(value, sd, p.unit) and bound == 0)
            for p, value, sd, bound in zip(candidate.parameters, fit.x, std, fit.active_mask)]


def wanted_priors(candidate, cases):
    """{index: model.effects.Prior} of the candidate's own parameters that physics has a prior for
    inside their range: a ground coupling's T_ground. The prior reads the outdoor air of the
    weather the `cases` hold, their history included, and the annual mean air of the weather
    they were prepared from (`Case.annual_air`, the first case's that has one)."""
    effect = EFFECTS[candidate.effect]
    if effect.priors is None:
        return {}
    outdoor = np.concatenate([case.U[:, case.input_names.index("T_out")] for case in cases])
    annual = next((case.annual_air for case in cases if case.annual_air is not None), None)
    priors = effect.priors(candidate.building, candidate.target, outdoor, annual)
    return {i: priors[p.name] for i, (p, (low, high)) in
            enumerate(zip(candidate.parameters[:candidate.own], candidate.bounds))
            if p.name in priors and low <= priors[p.name].value <= high}


def stated(prior, unit):
    """A prior as report.json carries it: its value, sd and source in one sentence."""
    return f"{prior.value:.4g} +- {prior.sd:.2g} {unit}, {prior.source}"


def fold(fit, train, lows, highs, residuals):
    """The parameters fitted without a block: one Gauss-Newton step from the whole window's
    optimum on the `train` rows of its residuals and Jacobian, shortened along its direction
    where it would leave the bounds, and halved while it fits its own rows worse than the whole
    window's optimum does (`residuals(x)`: every row's residual at x).

    Leaving one day out of several moves the optimum by little, and the step from the optimum
    is exact to first order in that move (for a model linear in its parameters, exact): a fold
    costs the one simulation that scores its left-out day, where a fit of its own would cost
    tens; on the Twin House's eighteen days a candidate's fifteen folds would otherwise be most
    of a diagnosis's time. Where two parameters trade off (a ground coupling's U and T_ground, a
    mass's C and H), the linearised valley is nearly flat and the step runs far along it, where
    the model no longer is linear: such a fold, worse on its own days than the optimum it started
    from, would score the left-out day with a fit that is no fit, and a candidate would lose the
    cross-validation to its own linearisation. The optimum is a fit of the training rows too, so
    a fold never does worse on them; the halvings cost a simulation each, and only where the
    step overshoots."""
    # a parameter the whole window's fit left on a bound stays there: its step would leave the
    # range. Nor is a step that leaves the range clipped parameter by parameter: where two
    # parameters trade off, the step runs along their valley, and clipping one alone (U to 0)
    # would leave the valley, and the fit, altogether
    # (a parameter held beside the candidate has a Jacobian column of zeros: least squares'
    # minimum-norm step leaves it where it is)
    free = fit.active_mask == 0
    if not free.any():
        return fit.x.copy()
    step = np.zeros_like(fit.x)
    step[free] = np.linalg.lstsq(fit.jac[train][:, free], -fit.fun[train], rcond=None)[0]
    room = np.where(step > 0, highs - fit.x, lows - fit.x)
    moving = step != 0
    step *= min(1.0, np.min(room[moving] / step[moving])) if moving.any() else 0.0
    at_optimum = float(np.sum(np.square(fit.fun[train])))
    for _ in range(FOLD_HALVINGS):
        x = np.clip(fit.x + step, lows, highs)  # rounding only
        if float(np.sum(np.square(residuals(x)[train]))) <= at_optimum:
            return x
        step /= 2.0
    return fit.x.copy()


class Derivation:
    """What an effect's derived quantities read (`model.effects.Effect.derived`): the building and
    target of the candidate, its fitted values `x` and their `bounds`, the heat loss coefficient at
    `x` (`hlc`, W/K) and its gradient (`hlc_slope`); `nodes` and `hlc_at` simulate at other values,
    `of` and `with_sd` give a quantity with its standard deviation by the delta method."""

    def __init__(self, candidate, case, x, cov):
        self.building, self.target, self.x, self.bounds = candidate.building, candidate.target, x, candidate.bounds
        self._candidate, self._case = candidate, case
        self.within = within_ranges(cov, candidate.bounds)
        self.hlc, self.hlc_slope = gradient(self.hlc_at, x, candidate.bounds)

    def hlc_at(self, values):
        """The heat loss coefficient (W/K) of the model at `values`."""
        return heat_loss_coefficient(*self._candidate.network(values))

    def nodes(self, ids, values):
        """The temperatures (C) of nodes `ids` simulated at `values` over the calibration window."""
        return self._candidate.nodes(self._case, ids, values)

    def with_sd(self, value, gradient, unit, cov=None):
        """{"value", "std", "unit"}: sd^2 = g' cov g, cov the parameters' covariance combined with
        their ranges (`within_ranges`) unless given."""
        cov = self.within if cov is None else cov
        return {"value": float(value), "std": float(np.sqrt(max(gradient @ cov @ gradient, 0.0))), "unit": unit}

    def of(self, f, unit):
        """`with_sd` of f(values) at `x`, its gradient by differences (`gradient`)."""
        return self.with_sd(*gradient(f, self.x, self.bounds), unit)


def derived(candidate, case, x, cov):
    """What the data fix when the parameters trade off against each other, each with its
    standard deviation by the delta method, sd^2 = g' cov g for its gradient g.

    - The heat loss coefficient of the model with the effect (docs/model.md section 8), W/K: what a
      record of the air and the heating power fixes well even where the effect's parameters, or
      the split of the loss among effects, it does not (`gradient`).
    - What its record derives (`Effect.derived`, on a `Derivation`): a ground coupling's heat flux
      density q = U (T_ground - T_face) (W/m2), g its gradient with the face simulated at each
      parameter moved, since where U is large beside the component's own conductance the face
      follows T_ground, and holding it fixed would make a well-fixed flux look unknown; a zone's
      internal mass or heater node's time constant tau = C / H (s), which a short record of the
      air fixes far better than C and H apart, g = (1 / H, -C / H^2); a component's conductivity
      factor's heat loss (W/K): the HLC with the factor less the HLC with the factor at its lower
      bound, where the layers pass almost nothing. In series with the surface coefficients that
      loss saturates as the layers conduct more, so a door twice as conductive as its wood and one
      ten times are told apart by little, while the loss the data see is fixed; g is the HLC's.

    What the parameters trade off along (the flux, a time constant, a component's loss) reads
    their covariance combined with their ranges (`within_ranges`): the valley leaves it unchanged,
    and only the linearisation's share of the valley's spread is bounded. The HLC reads the data's
    covariance alone: with a ground coupling it changes along the valley (U = q / (T_ground -
    T_face), a hyperbola the range's linear extrapolation does not follow), and so is not fixed.
    """
    d = Derivation(candidate, case, x, cov)
    out = {"heat_loss_coefficient": d.with_sd(d.hlc, d.hlc_slope, "W/K", cov)}
    effect = EFFECTS[candidate.effect]
    return {**out, **(effect.derived(d) if effect.derived else {})}


def within_ranges(cov, bounds):
    """The parameters' covariance with what their search ranges add: (cov^-1 + P)^-1, P the
    precision of a uniform distribution over each range, 12 / (high - low)^2. Computed in the
    ranges' units, C' = S^-1 cov S^-1 with S the ranges' standard deviations, as
    S V diag(l / (1 + l)) V' S from C' = V diag(l) V', which holds where cov is singular or
    spans many orders of magnitude.

    Where two parameters trade off, the linearised covariance runs along their valley far
    beyond the ranges the calibration searched (a ground coupling's T_ground +- 1.7e4 K on a
    range of 50 K), and a derived quantity's gradient, never exactly across the linearised
    valley, picks up a share of that: a flux the folds fit to within a few per cent came out
    +- 30 %. The range is known besides the data; combined with them, it bounds the valley's
    spread, and leaves a direction the data fix far more tightly than the range as it was.

    Parameters
    ----------
    cov : (k, k) covariance of the parameters (units squared)
    bounds : [(low, high)] of each parameter, finite
    """
    scale = np.array([high - low for low, high in bounds], dtype=float) / np.sqrt(12.0)
    values, vectors = np.linalg.eigh(cov / np.outer(scale, scale))
    values = np.clip(values, 0.0, None)
    return np.outer(scale, scale) * ((vectors * (values / (1.0 + values))) @ vectors.T)


def step_forward(value, low, high):
    """The forward difference step of least squares' own Jacobian (scipy's "2-point": sqrt of the
    machine epsilon times max(1, |value|)), turned back where it would leave the range."""
    h = np.sqrt(np.finfo(float).eps) * max(1.0, abs(value))
    return h if value + h <= high else -h


def step_inside(value, low, high):
    """A difference step of `STEP` of the range (low, high), away from `value` into the range."""
    h = STEP * (high - low)
    return h if value + h <= high else -h


def gradient(f, x, bounds):
    """f(x) and its gradient over the parameters (units of f per unit of each), by differences of
    STEP of each parameter's range, taken inside the `bounds`."""
    x = np.asarray(x, dtype=float)
    at = f(x)
    slope = np.zeros(len(x))
    for j, (low, high) in enumerate(bounds):
        h = step_inside(x[j], low, high)
        moved = x.copy()
        moved[j] += h
        change = f(moved) - at
        # a parameter f does not depend on (a capacity in the HLC, a gain) moves it by rounding only
        slope[j] = change / h if abs(change) > 1e-12 * max(abs(at), 1.0) else 0.0
    return at, slope
