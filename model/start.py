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
(`fitted_start`): the prior's mean 0 is the start the history gives, its sd what the unknown
past's weather could have put on the mode (`drive_spread`: the spread over days of the
amplitude each day's mean drive holds the mode at, over a window of tau_j) times
exp(-H / tau_j), what a history of H leaves of it. A fit minimises, over its parameters only,

    J_start = min over c of |r - F c|^2 + sigma^2 sum_j (c_j / sd_j)^2,

variable projection: no search over c, and one run per mode. Only the combinations of the
modes the record tells apart are fitted (`START_RCOND`): two modes whose free responses are
nearly collinear are one direction of the fit, not two amplitudes of opposite signs.
"""
from dataclasses import dataclass

import numpy as np

from .network import assemble, capacity_reduced

# The modes whose start is fitted are those slower than a day (s): the burn-in's day of forcing,
# and the record's first hours, set the faster ones (the test cell's next after its floor's 14.7
# days is 0.49 days), and those of days outlast them. At most `START_MODES`, the slowest.
START_FROM = 86400.0
START_MODES = 3
# A mode whose prior sd is under this (K) is set by its history to within any sensor's
# resolution: its start is not fitted.
START_NEGLIGIBLE = 0.01
# The directions of the amplitudes (each scaled by its prior sd) a fit keeps: those whose
# singular value of the free responses is at least this fraction of the largest, and above the
# noise. Two modes of free responses correlated by rho have singular values in the ratio
# sqrt((1 - rho) / (1 + rho)): 0.1 keeps both up to rho = 0.98, one direction beyond.
START_RCOND = 0.1
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


def modes(network):
    """Every mode of `network` with every input held: the time constants (n_c,) s, slowest
    first, of C dT/dt = -K T on the nodes with capacity, the nodes without it eliminated
    (`network.capacity_reduced`, as `network.slowest_time_constant`), which follow at once,
    T_a = -K_aa^-1 K_ac T_c; and the shapes (N, n_c), K per K, each 1 at its largest node."""
    c, a, K, follow = capacity_reduced(network, np.arange(network.n_nodes))
    root = np.sqrt(network.C[c])
    scaled = K / np.outer(root, root)
    if np.allclose(scaled, scaled.T):
        rates, vectors = np.linalg.eigh((scaled + scaled.T) / 2.0)
        vectors = vectors / root[:, None]
    else:  # air carried one way: the modes of C^-1 K, real parts
        rates, vectors = np.linalg.eig(K / network.C[c][:, None])
        rates, vectors = rates.real, vectors.real
    order = np.argsort(rates)
    shapes = np.zeros((network.n_nodes, len(c)))
    shapes[c] = vectors[:, order]
    shapes[a] = follow @ vectors[:, order]
    return 1.0 / rates[order], shapes / shapes[np.abs(shapes).argmax(axis=0), np.arange(len(c))]


def drive_spread(network, shapes, U, dt, tau):
    """(m,) K: what the unknown past's drive could have put on each mode, one sd. Each day's mean
    inputs ū_d hold the network at T_d = (-A)^-1 (B ū_d + q) (W/K, W: the steady state, the
    coefficients as assembled), which holds mode j at the amplitude c_j(d) of T_d in the modes'
    basis (`shapes`, every mode's: (N, n_c), the first m the slow ones). A mode of tau_j averages
    the drive over some tau_j, so the state the past left on it is one such amplitude; the steady
    start's guess is another. Their spread is that of c_j(d) over the days of a window of
    tau_j from the weather's start (every day the rows `U` (n_rows, n_inputs) hold where they are
    fewer, at least two), dt the rows' step (s)."""
    per_day = max(1, int(round(86400.0 / dt)))
    days = max(2, len(U) // per_day)
    daily = np.stack([U[d * per_day:(d + 1) * per_day].mean(axis=0) for d in range(days)])
    steady = np.linalg.solve(-network.A, network.sources(daily).T)  # (N, days)
    c = network.C > 0.0
    amplitudes = np.linalg.solve(shapes[c], steady[c])  # (n_c, days)
    span = np.clip(np.ceil(np.asarray(tau) / 86400.0).astype(int), 2, days)
    return np.array([amplitudes[j, :span[j]].std(ddof=1) for j in range(len(tau))])


def slow_modes(network, history, U, dt):
    """`SlowModes` of `network` after a history of `history` s: its `modes` slower than
    `START_FROM` that the history has not run for `FORGOTTEN` time constants, the `START_MODES`
    slowest of them, with their prior sd `drive_spread` (of the case's inputs `U`, rows dt s
    apart) exp(-history / tau); those of sd under `START_NEGLIGIBLE` left out (none: m = 0)."""
    tau, shapes = modes(network)
    slow = [j for j in range(len(tau)) if tau[j] >= START_FROM and history < FORGOTTEN * tau[j]][:START_MODES]
    sd = drive_spread(network, shapes, U, dt, tau[slow]) * np.exp(-history / tau[slow])
    kept = [k for k, j in enumerate(slow) if sd[k] >= START_NEGLIGIBLE]
    slow = [slow[k] for k in kept]
    return SlowModes(tau[slow], shapes[:, slow], sd[kept], float(history))


def free_response(case, building, nodes, network=None):
    """The response of the nodes `nodes` (ids) of `building` on `case` (`Case.run`: its history,
    steady start, burn-in and sub-steps) to the amplitude of each slow mode at the first
    measurement: (N_t, len(nodes), m), K per K, from one run per mode started 1 K off along its
    shape before the history, less the run as started, over the history's decay of the mode
    (`SlowModes.decay`); and the `SlowModes`. m = 0 (no run) where the history has set every
    slow mode."""
    network = assemble(building) if network is None else network
    case = case.with_inputs(building)
    modes = slow_modes(network, case.history_steps * case.dt, case.U, case.dt)
    rows = np.asarray(nodes, dtype=int) - 1
    if not len(modes.tau):
        return np.zeros((len(case.times) - 1, len(rows), 0)), modes
    started = case.run(building, rows, network)
    F = np.stack([case.run(building, rows, network, start_offset=modes.shapes[:, j]) - started
                  for j in range(len(modes.tau))], axis=-1)
    return F / modes.decay, modes


def fitted_start(F, r, sd, sigma):
    """The amplitudes c (m,) K, and their posterior covariance (m, m) K2, of the least squares
    of the residual `r` (n,) C on the free responses `F` (n, m) with the Gaussian prior
    N(0, sd^2) on each, sigma (C) the noise's sd, fitted along the directions the data tell
    apart. With z = c / sd and F diag(sd) = U S V' (its singular values s_k), the directions
    kept are those of s_k >= `START_RCOND` max(s) and s_k > sigma; on them

        z = V_k diag(s_k / (s_k^2 + sigma^2)) U_k' r,    cov(z) = V_k diag(sigma^2 / (s_k^2 + sigma^2)) V_k'

    (the prior's own least squares, J_start of the module), and the others stay at the prior's
    mean 0 with its spread, cov += V_d V_d'. Where every direction is kept, c = (F'F + sigma^2
    diag(sd^-2))^-1 F' r. `r` may be (n, k): each column's amplitudes (k of them, (m, k)), as a
    fit's Jacobian is projected: c is linear in r."""
    sd = np.asarray(sd, dtype=float)
    if not len(sd):
        return np.zeros((0,) + np.shape(r)[1:]), np.zeros((0, 0))
    U, s, Vt = np.linalg.svd(F * sd, full_matrices=False)
    keep = (s >= START_RCOND * s.max()) & (s > sigma)
    V, dropped = Vt[keep].T, Vt[~keep].T
    gain = s[keep] / (s[keep] ** 2 + sigma ** 2)
    z = V @ ((U[:, keep].T @ r) * (gain if np.ndim(r) == 1 else gain[:, None]))
    cov = V @ np.diag(sigma ** 2 / (s[keep] ** 2 + sigma ** 2)) @ V.T + dropped @ dropped.T
    return z * (sd if np.ndim(r) == 1 else sd[:, None]), cov * np.outer(sd, sd)


def residual_sd(F, r):
    """The rms residual (C) of `r` (n,) once the free responses `F` (n, m) are fitted without a
    prior: the noise's sd where a fit is not told it."""
    c = np.linalg.lstsq(F, r, rcond=None)[0]
    return float(np.sqrt(np.mean(np.square(r - F @ c))))
