"""The direct model's runs of steps compiled (c/steps.c), where a C compiler is found; and the
project's C compiler itself, which the FMUs' export uses too (`fmu_build.compiler`).

A run of backward-Euler steps under one step matrix (`integrate.ImplicitEuler.run`) is, in
numpy, one product with the dense inverse of M a step: O(N^2), some 15 us on the Twin House's
267 nodes, and as much again in Python's own work per step. In C, with M factorised once by
SuperLU (`factorise`: scipy's, in a minimum-degree order of M + M^T, pivots on the diagonal),
a step is two sparse triangular solves: a building's walls are chains of nodes hung on a few
air and radiant nodes, which that order eliminates last, so L and U hold about as many entries
as M (459 each off the diagonal on the Twin House, whose M has 974). The library is compiled
once per process at its first run, for this machine's processor (it is never shipped), and
loaded from a temporary folder removed at once; without a C compiler, or with one that fails
on it, `steps` says so (None) and the caller steps in numpy: the same arithmetic, rounded
otherwise (tests/test_compiled.py).

Only the direct model loads it: the Python FMU steps in numpy alone (`fmu_build.slave`), and
the standalone FMU factorises within M's profile in its own C (model/c/profile.h).
"""
import ctypes
import functools
import logging
import os
import shutil
import subprocess
import threading
from pathlib import Path

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu

from nodeforce import tempdirs

log = logging.getLogger("nodeforce.model")
_LOCK = threading.Lock()
_DOUBLE, _INT = np.ctypeslib.ndpointer(np.float64, flags="C"), np.ctypeslib.ndpointer(np.int32, flags="C")


C_DIR = Path(__file__).with_name("c")


def find_compiler():
    """The C compiler command ($CC, else cc or gcc) as a list, or None when there is none."""
    command = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not command or not shutil.which(command.split()[0]):
        return None
    return command.split()


def compile_library(directory, source, libraries=(), link_options=(), defines=(), options=("-O2",), includes=()):
    """The shared library (bytes) of `directory`/<source> (a file name, or a tuple of several)
    with the headers beside it and in `includes` (folders).

    Compiled in `directory` by relative name, without debug information: the bytes do not depend
    on where nodeforce is installed, so the same model gives the same FMU.

    libraries : names given to -l; link_options : options for the linker (-Wl,...), before them;
    defines : preprocessor names given to -D; options : the compiler's (optimisation)

    Raises RuntimeError without a C compiler or when compiling fails.
    """
    compiler = find_compiler()
    if compiler is None:
        raise RuntimeError("no C compiler found (cc, gcc or $CC): install one (e.g. apt-get install gcc)")
    with tempdirs.folder("c") as tmp:
        output = Path(tmp) / "library.so"
        command = [*compiler, "-std=c99", *options, "-fPIC", "-shared", "-fvisibility=hidden",
                   *(f"-I{folder}" for folder in includes), *(f"-D{d}" for d in defines), "-o", str(output),
                   *([source] if isinstance(source, str) else source), *link_options,
                   *(f"-l{name}" for name in libraries)]
        done = subprocess.run(command, cwd=directory, capture_output=True, text=True)
        if done.returncode:
            raise RuntimeError(f"compiling {source!r} failed: {' '.join(command)}\n{done.stderr}")
        return output.read_bytes()


@functools.lru_cache(maxsize=None)
def _library():
    """The loaded library, or None where it cannot be compiled (no C compiler, or one that fails
    on it: said once in the log)."""
    if find_compiler() is None:
        return None
    try:  # for this machine's processor: the library is never shipped
        data = compile_library(C_DIR, "steps.c", options=("-O3", "-march=native"))
    except RuntimeError as error:
        log.warning("the runs of steps are stepped in numpy: %s", str(error).splitlines()[0])
        return None
    with tempdirs.folder("steps") as tmp:
        path = Path(tmp) / "steps.so"
        path.write_bytes(data)
        loaded = ctypes.CDLL(str(path))
    function = loaded.nodeforce_steps
    function.restype = ctypes.c_int
    function.argtypes = [ctypes.c_int, _INT, _INT, _INT, _INT, _DOUBLE, _INT, _INT, _DOUBLE, _DOUBLE,
                         ctypes.c_long, _DOUBLE, _DOUBLE, ctypes.c_int, _INT, _DOUBLE]
    return function


def available():
    """Whether the compiled steps load here (a C compiler is found)."""
    with _LOCK:
        return _library() is not None


class Factors:
    """M = P_r^T L U P_c^T factorised by SuperLU in a minimum-degree order of M + M^T with its
    pivots on the diagonal (M is diagonally dominant: a node's capacity over the step and its
    conductances against those to its neighbours; a forced node's row a unit row), L and U by
    columns as SuperLU gives them, which the kernel reads.

    Parameters
    ----------
    pattern : (rows, cols) int32 arrays of M's nonzeros; values : their values (W/K)
    n : M's order

    ValueError where M is singular."""

    def __init__(self, pattern, values, n):
        M = sparse.csc_matrix((np.asarray(values, dtype=float), pattern), shape=(n, n))
        try:
            lu = splu(M, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        except RuntimeError as error:  # SuperLU's "Factor is exactly singular"
            raise ValueError(f"the step matrix is singular: {error}") from None
        L, U = lu.L, lu.U
        self.arrays = tuple(np.ascontiguousarray(a, dtype=t) for a, t in (
            (lu.perm_r, np.int32), (lu.perm_c, np.int32), (L.indptr, np.int32), (L.indices, np.int32),
            (L.data, float), (U.indptr, np.int32), (U.indices, np.int32), (U.data, float)))
        self.n = n


def steps(factors, c, v, T, rows):
    """The temperatures after each of L steps M T^k+1 = c T^k + v^k, or None where the library
    cannot be compiled.

    Parameters
    ----------
    factors : M's `Factors`, the forced nodes' rows unit rows
    c : (N,) C/dt, zero at the forced nodes (W/K)
    v : (L, N) each step's sources (W), the forced nodes' imposed temperatures (C) in their place
    T : (N,) C before the first step
    rows : indices of the nodes returned

    Returns
    -------
    (L, len(rows)) C after each step, and (N,) C after the last
    """
    if not available():
        return None
    T = np.array(T, dtype=float)
    v = np.ascontiguousarray(v, dtype=float)
    rows = np.ascontiguousarray(rows, dtype=np.int32)
    path = np.empty((len(v), len(rows)))
    if not _library()(factors.n, *factors.arrays, np.ascontiguousarray(c, dtype=float), len(v), v, T, len(rows),
                      rows, path):
        raise ValueError("the step matrix is singular, or the compiled steps ran out of memory")
    return path, T
