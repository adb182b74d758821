"""The direct model's runs of steps compiled (c/steps.c), where a C compiler is found (the
compiler is `runtime.compiler`'s, which the FMUs' export uses too: `fmu_build.compiler`).

A run of backward-Euler steps under one step matrix (`integrate.ImplicitEuler.run`) is, in
numpy, one product with the dense inverse of M a step: O(N^2), some 15 us on the Twin House's
267 nodes, and as much again in Python's own work per step. In C, M is factorised once per run,
without pivoting, on the pattern its links fill in a minimum-degree order (`Pattern`, made once
per pattern: SuperLU's order, scipy's), and a step is two sparse triangular solves. A
building's walls are chains of nodes hung on a few air and radiant nodes, which that order
eliminates last, so L and U hold about as many entries as M (459 each off the diagonal on the
Twin House, whose M has 974 nonzeros; its profile in reverse Cuthill-McKee order, within which
the standalone FMU factorises, model/c/profile.h, holds 5,257). Each step's sources are formed
there too, from the inputs and B's few nonzeros (100 of the Twin House's 267 x 20): formed in
numpy, an (L, N) array of them cost a run as much as its steps. The library is compiled once per
process at its first run, for this machine's processor (it is never shipped), and loaded from a
temporary folder removed at once; without a C compiler, or with one that fails on it, `steps`
says so (None) and the caller steps in numpy: the same arithmetic, rounded otherwise
(tests/test_compiled.py).

Only the direct model loads it: the Python FMU steps in numpy alone (`fmu_build.slave`).
"""
import ctypes
import functools
import logging
import threading
from pathlib import Path

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu

from nodeforce.runtime.compiler import compiled_function

from .network import FLOW_FIELDS

log = logging.getLogger("nodeforce.model")
_LOCK = threading.Lock()
_DOUBLE, _INT = np.ctypeslib.ndpointer(np.float64, flags="C"), np.ctypeslib.ndpointer(np.int32, flags="C")


C_DIR = Path(__file__).with_name("c")


@functools.lru_cache(maxsize=None)
def _library():
    """The loaded library, or None where it cannot be compiled (no C compiler, or one that fails
    on it: said once in the log)."""
    # for this machine's processor: the library is never shipped
    function = compiled_function(C_DIR, "steps.c", "nodeforce_steps", "the runs of steps are stepped in numpy", log,
                                 options=("-O3", "-march=native"))
    if function is None:
        return None
    function.restype = ctypes.c_int
    function.argtypes = [ctypes.c_int, _INT, _INT, _INT, _INT, _INT, ctypes.c_long, _INT, _DOUBLE, _DOUBLE,
                         ctypes.c_long, ctypes.c_int, _DOUBLE, _INT, _INT, _DOUBLE, _DOUBLE, ctypes.c_int, _INT, _DOUBLE,
                         _DOUBLE, ctypes.c_int, _INT, _DOUBLE, ctypes.c_int, _INT, _DOUBLE, ctypes.c_int, _INT, _DOUBLE,
                         ctypes.c_int, _INT, _DOUBLE, _INT, ctypes.c_int, _INT, _DOUBLE, ctypes.c_int, _INT, _DOUBLE,
                         ctypes.c_int, _INT, _DOUBLE, ctypes.c_int, _INT, _DOUBLE, ctypes.c_int, _INT, _DOUBLE]
    return function


def available():
    """Whether the compiled steps load here (a C compiler is found)."""
    with _LOCK:
        return _library() is not None


class Pattern:
    """M's pattern of links eliminated in a minimum-degree order (SuperLU's, scipy's, on M + M^T):
    the order, the pattern L and U fill in (the elimination of each node makes its later
    neighbours a clique), and where each of M's nonzeros goes in the factors' storage
    ([diagonal | L | U], as c/steps.c reads it). Made once per pattern (`pattern`): every mask
    and switched conductance of a network, and every value of an effect's parameters, share it.

    Parameters
    ----------
    starts, rows : int32 arrays of M's nonzeros column after column
        (`integrate.ImplicitEuler.matrix`), the diagonal among them
    n : M's order
    """

    def __init__(self, starts, rows, n):
        cols = np.repeat(np.arange(n), np.diff(starts))
        diagonal = rows == cols
        # the order reads the pattern alone: ones on it, made dominant on the diagonal
        ones = sparse.csc_matrix((np.where(diagonal, float(n), -1.0 / n), rows, starts), shape=(n, n))
        position = splu(ones, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                        options={"SymmetricMode": True}).perm_c
        neighbours = [set() for _ in range(n)]
        for i, j in zip(position[rows[~diagonal]], position[cols[~diagonal]]):
            neighbours[i].add(j)
            neighbours[j].add(i)
        for i in range(n):
            later = [j for j in neighbours[i] if j > i]
            for j in later:
                neighbours[j].update(later)
                neighbours[j].discard(j)
        lower = [sorted(j for j in neighbours[i] if j < i) for i in range(n)]
        upper = [sorted(j for j in neighbours[i] if j > i) for i in range(n)]
        self.order = np.argsort(position).astype(np.int32)
        self.lower_ptr, self.lower_col = _rows(lower)
        self.upper_ptr, self.upper_col = _rows(upper)
        at = {}
        for i in range(n):
            at[(i, i)] = i
            at.update(((i, j), n + self.lower_ptr[i] + k) for k, j in enumerate(lower[i]))
            at.update(((i, j), n + self.lower_ptr[n] + self.upper_ptr[i] + k) for k, j in enumerate(upper[i]))
        self.slot = np.array([at[(i, j)] for i, j in zip(position[rows], position[cols])], dtype=np.int32)
        self.n = n


def _rows(columns):
    """(row starts, columns) int32 of rows of column indices."""
    starts = np.concatenate([[0], np.cumsum([len(c) for c in columns])]).astype(np.int32)
    return starts, np.array([j for c in columns for j in c], dtype=np.int32)


@functools.lru_cache(maxsize=32)
def pattern(n, starts, rows):
    """The `Pattern` of M's nonzeros (`starts`, `rows`: the bytes of their int32 arrays)."""
    return Pattern(np.frombuffer(starts, dtype=np.int32), np.frombuffer(rows, dtype=np.int32), n)


def steps(matrix, c, sources, forced, imposed, T, rows, convection=None):
    """The temperatures after each of L steps M T^k+1 = c T^k + B t^k + q, the forced nodes' at
    their imposed temperatures, or None where the library cannot be compiled.

    Parameters
    ----------
    matrix : M's nonzeros column after column, ((column starts, rows) int32, values (W/K)), the
        forced nodes' rows unit rows (`integrate.ImplicitEuler.matrix`)
    c : (N,) C/dt (W/K)
    sources : `integrate.Sources`, each step's terms t^k (L, m) and their coefficients B (N, m),
        q (N,) (W): each step's sources are formed from B's nonzeros
    forced : indices of the nodes imposed at every step
    imposed : (L, len(forced)) their temperatures (C), or None: zero
    T : (N,) C before the first step
    rows : indices of the nodes returned
    convection : the network's `Convection`, whose lagged source each step adds from the
        temperatures before it and the step's inputs (the first columns of its terms), or None

    Returns
    -------
    (L, len(rows)) C after each step, and (N,) C after the last; ValueError where M is singular
    """
    if not available():
        return None
    (starts, nonzero_rows), values = matrix
    T = np.array(T, dtype=float)
    p = pattern(len(T), np.require(starts, np.int32).tobytes(), np.require(nonzero_rows, np.int32).tobytes())
    terms = np.ascontiguousarray(sources.terms, dtype=float)
    nodes, columns, coefficients = sources.nonzeros  # row after row: each node's terms together
    source_ptr = np.concatenate([[0], np.cumsum(np.bincount(nodes, minlength=len(T)))]).astype(np.int32)
    forced = np.ascontiguousarray(forced, dtype=np.int32)
    imposed = (np.zeros((len(terms), len(forced))) if imposed is None
               else np.ascontiguousarray(imposed, dtype=float).reshape(len(terms), len(forced)))
    rows = np.ascontiguousarray(rows, dtype=np.int32)
    path = np.empty((len(terms), len(rows)))
    lagged = _convection_arrays(convection)
    if not _library()(p.n, p.order, p.lower_ptr, p.lower_col, p.upper_ptr, p.upper_col, len(p.slot), p.slot,
                      np.ascontiguousarray(values, dtype=float), np.ascontiguousarray(c, dtype=float), len(terms),
                      terms.shape[1], terms, source_ptr, columns.astype(np.int32),
                      np.ascontiguousarray(coefficients, dtype=float),
                      np.ascontiguousarray(sources.q, dtype=float), len(forced), forced, imposed, T, len(rows), rows,
                      path, *lagged):
        raise ValueError("the step matrix is singular")
    return path, T


# A `Convection`'s kinds in the order c/followed.h reads them: (its values, their width a row; its
# nodes, their width a row)
FOLLOWED = (("inside", 3, "inside_nodes", 2), ("outside", 6, "outside_nodes", 1), ("longwave", 4, "longwave_nodes", 1),
            ("windows", 5, "window_nodes", 2), ("gaps", 15, "gap_nodes", 2), ("pairs", 2, "pair_nodes", 2),
            ("flows", len(FLOW_FIELDS), "flow_nodes", 2), ("people", 6, "people_nodes", 3))


def followed_arrays(convection):
    """([(count, nodes int32, values float) of each kind of FOLLOWED, flat], columns int32 (4,)) of a
    `Convection` as c/followed.h reads it (the standalone FMU's export too); none of each, and the
    columns -1, of None."""
    if convection is None:
        return [(0, np.zeros(0, np.int32), np.zeros(0)) for _ in FOLLOWED], np.full(4, -1, np.int32)
    array = lambda name, kind: np.ascontiguousarray(getattr(convection, name), dtype=kind).ravel()  # noqa: E731
    kinds = [(len(getattr(convection, values)), array(nodes, np.int32), array(values, float))
             for values, _, nodes, _ in FOLLOWED]
    return kinds, np.ascontiguousarray(convection.columns, dtype=np.int32)


def _convection_arrays(convection):
    """The arguments c/steps.c reads a `Convection` from: the columns after the long-wave."""
    kinds, columns = followed_arrays(convection)
    arguments = [x for kind in kinds for x in kind]
    return (*arguments[:9], columns, *arguments[9:])
