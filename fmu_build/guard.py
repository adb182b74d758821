"""The guard in front of the Python FMU's binary (c/guard.c): fmi2Error for the calls the
standard forbids and for those in which the model raises, libpython loaded when the importing
process has no Python, and the host kept out of pythonfmu's two double releases of memory (when
the model raises, and at process exit).

The Python FMU's `binaries/linux64/<identifier>.so` becomes the guard, pythonfmu's binary ships
beside it as `<identifier>.pythonfmu.so`, and `resources/guard.txt` tells the guard the layout's
sizes, that file name and the libpython of the exporting Python. The guard does not depend on the
model: it is compiled once per process. Without a C compiler the FMU is written without it,
with a one-line warning (pythonfmu then answers forbidden calls with fmi2Discard or fmi2Fatal,
a C host must preload libpython, and pythonfmu's double releases reach the host).
"""
import functools
import sys
import sysconfig
from pathlib import Path

from nodeforce import tempdirs
from .compiler import compile_library, find_compiler

PLATFORM = "linux64"  # the guard's platform; pythonfmu's other binaries (win64) stay unguarded
GUARD_FILE = "resources/guard.txt"
LIBPYTHON_VARIABLE = "NODEFORCE_LIBPYTHON"  # the guard's override of the recorded libpython


@functools.lru_cache(maxsize=1)
def guard_binary():
    """The guard library (bytes), compiled once per process; None without a C compiler."""
    if find_compiler() is None:
        print("nodeforce: warning: no C compiler (cc, gcc or $CC): the Python FMU is written without its "
              "guard, so forbidden calls get fmi2Discard or fmi2Fatal instead of fmi2Error and a C host "
              "must preload libpython", file=sys.stderr)
        return None
    with tempdirs.folder("guard") as tmp:
        library = Path(tmp) / "guard.so"
        compile_library("guard.c", library, libraries=("dl", "pthread"))
        return library.read_bytes()


def libpython():
    """Path of the shared libpython of this Python (sysconfig LIBDIR/LDLIBRARY)."""
    return str(Path(sysconfig.get_config_var("LIBDIR")) / sysconfig.get_config_var("LDLIBRARY"))


def guard_text(layout, binary):
    """resources/guard.txt: the format c/guard.c reads."""
    return (f"nodeforce-guard/1\nsizes {layout.n_nodes} {len(layout.input_names)} {len(layout.parameter_names)}\n"
            f"binary {binary}\nlibpython {libpython()}\n")


def guarded(files, identifier, layout):
    """(files, True) with the guard in front of pythonfmu's linux64 binary; (files, False)
    unchanged without a C compiler.

    files : {archive name: bytes} of the Python FMU; identifier : its model identifier;
    layout : variables.Layout of its variables
    """
    binary = guard_binary()
    if binary is None:
        return files, False
    folder = f"binaries/{PLATFORM}/"
    wrapped = f"{identifier}.pythonfmu.so"
    files = dict(files)
    files[folder + wrapped] = files.pop(f"{folder}{identifier}.so")
    files[f"{folder}{identifier}.so"] = binary
    files[GUARD_FILE] = guard_text(layout, wrapped).encode()
    return files, True
