"""Runs of backward-Euler steps under one step matrix, solved for all their steps at once
(docs/model.md section 5.1, "Runs of steps").

Over steps that share a forcing mask and switched conductances, the step of
`integrate.ImplicitEuler` is

    T^n+1 = S (c T^n + e^n),

S the inverse of M = C/dt - A with the forced rows made unit rows, c the capacities over dt with
the forced nodes' zeroed, e^n the step's sources B u + q (with the products of inputs,
`Network.source_terms`), the forced nodes' entries replaced by their imposed temperatures. Only
the nodes with c > 0 (capacitive and free: the state x) carry anything from one step to the
next; every other node follows from them and the step's inputs. So

    x^n+1 = G x^n + f^n,    G = S_xx diag(c_x),    f^n = (S e^n)_x,

a linear recurrence with constant coefficients. In the eigenbasis of G (G = V diag(lam) V^-1) it
is one scalar recurrence per mode, z^n+1 = lam z^n + w^n, which `scan` solves for every step at
once; the inputs enter through S B, projected on the modes once per run, and only the nodes and
steps asked for are formed. The arithmetic is the step's in another order: the temperatures agree
to rounding (tests/test_modal.py), and a run of thousands of steps costs a few dozen numpy calls
and, on a house of 267 nodes, a fraction of the step's N^2 products.

Where every conductance is symmetric (walls, films, air exchanged between zones), G is similar
to the symmetric diag(c)^1/2 S_xx diag(c)^1/2: its modes are real and orthogonal in the
capacities' inner product, and the temperatures come back to within some 1e-13 of the steps'.
Air carried one way (a supply from one zone to the next) makes G non-symmetric: its
eigenvectors, from a general eigen-solver, gave the Twin House's temperatures to only 2e-10
to 4e-12 of the steps', with complex modes, and its runs in no less time than its steps (0.17
s against 0.16 s for a record of the living room). `Modes.of` says so (None), and the caller
steps such a run one step at a time.

The direct model solves runs in their modes only where its steps are not compiled
(`integrate.MODAL_FROM`): a compiled step of a building's sparse network costs less than the
modes' projections. numpy alone, as `integrate` (whose FMU must not load scipy).
"""
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Modes:
    """The modes of one step matrix: the state nodes (`state`, indices), their capacities over
    the step c_x (W/K), the eigenvalues lam (each mode's factor per step) and the eigenvectors
    V and V^-1 of G = S_xx diag(c_x)."""
    state: np.ndarray
    c_x: np.ndarray
    lam: np.ndarray
    V: np.ndarray
    V_inv: np.ndarray

    @classmethod
    def of(cls, inverse, c, forced):
        """The modes of the step with `inverse` S (N, N), capacities over the step `c` (N,) and
        the `forced` nodes (bool, (N,)) imposed; None where G is not similar to a symmetric
        matrix (air carried one way: module docstring)."""
        state = np.flatnonzero((c > 0) & ~forced)
        c_x = c[state]
        root = np.sqrt(c_x)
        K = root[:, None] * inverse[np.ix_(state, state)] * root[None, :]
        if len(state) and np.abs(K - K.T).max() > 1e-12 * np.abs(K).max():
            return None
        lam, Q = np.linalg.eigh((K + K.T) / 2.0)
        return cls(state, c_x, lam, Q / root[:, None], Q.T * root[None, :])


def scan(lam, z0, W):
    """z^1..z^L of z^n+1 = lam z^n + w^n, per mode: (L, m), from z^0 (m,) and W (L, m) = w^0..w^L-1.

    z^0 enters as part of the first step's w (lam z^0 + w^0). A doubling scan: after the pass of
    span s, row k holds sum over k - 2s < j <= k of lam^(k-j) w^j; after ceil(log2 L) passes,
    every j <= k. Each pass is one vector operation on all the steps."""
    y = np.array(W, dtype=float)
    y[0] += lam * z0
    factor, span = lam.copy(), 1
    while span < len(y):
        y[span:] = y[span:] + factor * y[:-span]
        factor, span = factor * factor, 2 * span
    return y


def run(inverse, c, forced, modes, T0, inputs, B, q, imposed, kept, outputs):
    """The temperatures of the `outputs` nodes after the `kept` steps of a run of L steps under
    one step matrix from T0, and every node's after the last step.

    Parameters
    ----------
    inverse : (N, N) S, the inverse of M with the forced rows made unit rows (`integrate.DenseSolve`)
    c : (N,) C/dt (W/K)
    forced : (N,) bool, the nodes imposed at every step of the run
    modes : `Modes.of` this S, c and mask (not None)
    T0 : (N,) the temperatures before the first step (C)
    inputs, B, q : each step's input terms (L, n) and their coefficients (N, n), and the constant
        sources (N,) (W): the sources are inputs B' + q (`Network.source_terms`)
    imposed : (L, N) each step's imposed temperatures (C), read at the forced nodes only
    kept : indices of the steps whose temperatures are returned, increasing
    outputs : indices of the nodes returned

    Returns
    -------
    (len(kept), len(outputs)) C, and (N,) C after the last step
    """
    free = np.flatnonzero(~forced)
    index = np.flatnonzero(forced)
    state, c_x, lam, V, V_inv = modes.state, modes.c_x, modes.lam, modes.V, modes.V_inv
    # S e^n = S_:free (B u^n + q)_free + S_:forced T_imposed^n, on the rows asked for
    SB, Sq = inverse[:, free] @ B[free], inverse[:, free] @ q[free]
    S_forced = inverse[:, index]

    def driven(rows, steps):
        """(S e^n)_rows at the `steps` (slice or indices)."""
        return inputs[steps] @ SB[rows].T + Sq[rows] + imposed[steps][:, index] @ S_forced[rows].T

    W = inputs @ (V_inv @ SB[state]).T + V_inv @ Sq[state] + imposed[:, index] @ (V_inv @ S_forced[state]).T
    z = scan(lam, V_inv @ T0[state], W)  # z^1..z^L: the state after each step
    kept = np.asarray(kept, dtype=int)
    # T^n+1 = S_:x c_x x^n + S e^n, x^n the state before step n: z^n, T0's for the first step
    before = np.vstack([(V_inv @ T0[state])[None, :], z[:-1]])

    def after(rows, steps):
        return before[steps] @ (inverse[np.ix_(rows, state)] * c_x[None, :] @ V).T + driven(rows, steps)

    outputs = np.asarray(outputs, dtype=int)
    T = after(outputs, kept)
    at = np.flatnonzero(forced[outputs])
    T[:, at] = imposed[kept][:, outputs[at]]  # a Dirichlet node is exact, as in the step
    last = after(np.arange(len(T0)), [len(W) - 1])[0]
    last[index] = imposed[-1, index]
    return T, last
