"""The direct model's runs of steps compiled (c/steps.c), where a C compiler is found; and the
project's C compiler itself, which the FMUs' export uses too (`fmu_build.compiler`).

A run of backward-Euler steps under one step matrix (`integrate.ImplicitEuler.run`) is, in
numpy, one product with the dense inverse of M a step: O(N^2), some 15 us on the Twin House's
267 nodes, and as much again in Python's own work per step. In C, M factorised within its
profile (c/profile.h, the standalone FMU's LU too) makes a step two triangular solves of
O(N). The library is compiled once per process at its first run, for this machine's processor
(it is never shipped), and loaded from a temporary folder removed at once; without a C
compiler, or with one that fails on it, `steps` says so (None) and the caller steps in numpy:
the same arithmetic, rounded otherwise (tests/test_compiled.py).

Only the direct model loads it: the Python FMU steps in numpy alone (`fmu_build.slave`).
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
    function.argtypes = [ctypes.c_int, ctypes.c_long, _INT, _INT, _DOUBLE, _DOUBLE, ctypes.c_long, _DOUBLE,
                         _DOUBLE, ctypes.c_int, _INT, _DOUBLE]
    return function


def available():
    """Whether the compiled steps load here (a C compiler is found)."""
    with _LOCK:
        return _library() is not None


def steps(pattern, values, c, v, T, rows):
    """The temperatures after each of L steps M T^k+1 = c T^k + v^k, or None where the library
    cannot be compiled.

    Parameters
    ----------
    pattern : (rows, cols) int32 arrays of M's nonzeros; values : their values (W/K), the forced
        nodes' rows unit rows
    c : (N,) C/dt, zero at the forced nodes (W/K)
    v : (L, N) each step's sources (W), the forced nodes' imposed temperatures (C) in their place
    T : (N,) C before the first step
    rows : indices of the nodes returned

    Returns
    -------
    (L, len(rows)) C after each step, and (N,) C after the last; ValueError where M is singular
    """
    if not available():
        return None
    T = np.array(T, dtype=float)
    v = np.ascontiguousarray(v, dtype=float)
    rows = np.ascontiguousarray(rows, dtype=np.int32)
    path = np.empty((len(v), len(rows)))
    if not _library()(len(T), len(values), pattern[0], pattern[1], np.ascontiguousarray(values, dtype=float),
                      np.ascontiguousarray(c, dtype=float), len(v), v, T, len(rows), rows, path):
        raise ValueError("the step matrix is singular")
    return path, T
