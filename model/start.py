"""The start as an unknown: the slow modes' state at a record's first measurement, fitted with
every fit's parameters (docs/model.md section 5.10).

A run starts from the steady state of its history's first day, and the history (section 5.7)
then carries the building to the first measurement. What that start got wrong, e0 (K per node),
falls with the network's free response: every input held, C dT/dt = -K T has the modes
K v_j = (1 / tau_j) C v_j, and an error along v_j is a_j exp(-t / tau_j) v_j. A history of H
seconds leaves exp(-H / tau_j) of it at the first measurement; the burn-in's forcing sets the
modes of hours again. The modes slower than `START_FROM` that the history has not run for
`FORGOTTEN` of their time constants (`slow_modes`) are what a short history leaves unknown.

The response of the measured nodes to the amplitudes c (K, each mode's at the first
measurement, along its shape scaled to 1 K at its largest node) is linear in them, F c, F
(N_t, nodes, m) from one extra run per mode (`free_response`: the run started c_j = 1 K off
along v_j, less the run as started). For any values of a fit's parameters the residual r
(measured less simulated) is then r - F c, and c its Gaussian-prior least squares
(`fitted_start`): the prior's mean 0 is the start the history gives, its sd
sd_j = `START_SD` exp(-H / tau_j) what a history of H leaves of an error of the start's size.
A fit minimises, over its parameters only,

    J_start = min over c of |r - F c|^2 + sigma^2 sum_j (c_j / sd_j)^2,

variable projection: no search over c, and one run per mode.
"""
from dataclasses import dataclass

import numpy as np

from .network import assemble

# The modes whose start is fitted are those slower than a day (s): the burn-in's day of forcing,
# and the record's first hours, set the faster ones (the test cell's next after its floor's 14.7
# days is 0.49 days), and those of days outlast them. At most `START_MODES`, the slowest.
START_FROM = 86400.0
START_MODES = 3
# What the steady start at one day's mean conditions gets wrong of a slow mode (K, one sd): the
# mean outdoor air of the weeks before a record differs from one day's by the weather's swing
# from day to day and the season's drift over a mode of two weeks, some 3 to 5 K in spring
# and autumn in the benchmark's climates.
START_SD = 5.0
# A history of this many time constants of a mode leaves e^-3 (5 %) of its start's error: the
# mode is taken as set by it, and its start is not fitted (the fit is then the one before).
FORGOTTEN = 3.0


@dataclass(frozen=True)
class SlowModes:
    """The slow modes whose start a record's fit estimates: their time constants `tau` (m,) s,
    their shapes (N, m), K per K of amplitude (each 1 at its largest node), and the prior sd
    (m,) K of each amplitude at the first measurement, after a history of `history` s."""
    tau: np.ndarray
    shapes: np.ndarray
    sd: np.ndarray
    history: float

    @property
    def decay(self):
        """(m,) exp(-history / tau): what the history leaves of a start's error along each mode."""
        return np.exp(-self.history / self.tau)


def slow_modes(network, history):
    """`SlowModes` of `network` after a history of `history` s: its modes slower than
    `START_FROM`, every node free and every input held, that the history has not run for
    `FORGOTTEN` time constants, the `START_MODES` slowest of them (none: m = 0).

    The modes are those of C dT/dt = -K T on the nodes with capacity, the nodes without it
    eliminated (K_cc - K_ca K_aa^-1 K_ac, as `network.slowest_time_constant`), which those follow
    at once: T_a = -K_aa^-1 K_ac T_c."""
    has = network.C > 0.0
    c, a = np.flatnonzero(has), np.flatnonzero(~has)
    K = -network.A[np.ix_(c, c)]
    follow = -np.linalg.solve(network.A[np.ix_(a, a)], network.A[np.ix_(a, c)]) if len(a) else np.zeros((0, len(c)))
    K = K - network.A[np.ix_(c, a)] @ follow
    root = np.sqrt(network.C[c])
    scaled = K / np.outer(root, root)
    if np.allclose(scaled, scaled.T):
        rates, vectors = np.linalg.eigh((scaled + scaled.T) / 2.0)
        vectors = vectors / root[:, None]
    else:  # air carried one way: the modes of C^-1 K, real parts
        rates, vectors = np.linalg.eig(K / network.C[c][:, None])
        rates, vectors = rates.real, vectors.real
    tau = 1.0 / rates
    slow = [j for j in np.argsort(-tau) if tau[j] >= START_FROM and history < FORGOTTEN * tau[j]][:START_MODES]
    shapes = np.zeros((network.n_nodes, len(slow)))
    shapes[c] = vectors[:, slow]
    shapes[a] = follow @ vectors[:, slow]
    largest = shapes[np.abs(shapes).argmax(axis=0), np.arange(len(slow))] if slow else np.ones(0)
    tau = tau[slow]
    return SlowModes(tau, shapes / largest, START_SD * np.exp(-history / tau), float(history))


def free_response(case, building, nodes, network=None):
    """The response of the nodes `nodes` (ids) of `building` on `case` (`Case.run`: its history,
    steady start, burn-in and sub-steps) to the amplitude of each slow mode at the first
    measurement: (N_t, len(nodes), m), K per K, from one run per mode started 1 K off along its
    shape before the history, less the run as started, over the history's decay of the mode
    (`SlowModes.decay`); and the `SlowModes`. m = 0 (no run) where the history has set every
    slow mode."""
    network = assemble(building) if network is None else network
    modes = slow_modes(network, case.history_steps * case.dt)
    rows = np.asarray(nodes, dtype=int) - 1
    if not len(modes.tau):
        return np.zeros((len(case.times) - 1, len(rows), 0)), modes
    case = case.with_inputs(building)
    started = case.run(building, rows, network)
    F = np.stack([case.run(building, rows, network, start_offset=modes.shapes[:, j]) - started
                  for j in range(len(modes.tau))], axis=-1)
    return F / modes.decay, modes


def fitted_start(F, r, sd, sigma):
    """The amplitudes c (m,) K, and their posterior covariance (m, m) K2, of the least squares
    of the residual `r` (n,) C on the free responses `F` (n, m) with the Gaussian prior
    N(0, sd^2) on each: c = (F'F + sigma^2 diag(sd^-2))^-1 F' r, covariance
    sigma^2 (F'F + sigma^2 diag(sd^-2))^-1, sigma (C) the noise's sd. `r` may be (n, k): each
    column's amplitudes (k of them, (m, k)), as a fit's Jacobian is projected."""
    G = F.T @ F + np.diag((sigma / np.asarray(sd, dtype=float)) ** 2)
    return np.linalg.solve(G, F.T @ r), sigma ** 2 * np.linalg.inv(G)


def residual_sd(F, r):
    """The rms residual (C) of `r` (n,) once the free responses `F` (n, m) are fitted without a
    prior: the noise's sd where a fit is not told it."""
    c = np.linalg.lstsq(F, r, rcond=None)[0]
    return float(np.sqrt(np.mean(np.square(r - F @ c))))
