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

from nodeforce.runtime.compiler import find_compiler

from .compiler import library

PLATFORM = "linux64"  # the guard's platform; pythonfmu's other binaries (win64) stay unguarded
GUARD_FILE = "resources/guard.txt"
LIBPYTHON_VARIABLE = "NODEFORCE_LIBPYTHON"  # the guard's override of the recorded libpython
# The newest glibc symbol version each linux64 binary of the Python FMU needs (objdump -T): the
# guard's, and pythonfmu 0.7.0's, which also needs the C++ runtime of GCC 12 (GLIBCXX_3.4.30)
GUARD_GLIBC = "2.2.5"
PYTHONFMU_GLIBC = "2.32"


@functools.lru_cache(maxsize=2)
def guard_binary(fmi=2):
    """The guard library (bytes), compiled once per process; None without a C compiler. With
    fmi=3, the FMI 3.0 interface (c/fmi3.c) over it, in one library whose own calls to its
    fmi2* functions stay inside it (-Bsymbolic)."""
    if find_compiler() is None:
        print("nodeforce: warning: no C compiler (cc, gcc or $CC): the Python FMU is written without its "
              "guard, so forbidden calls get fmi2Discard or fmi2Fatal instead of fmi2Error and a C host "
              "must preload libpython", file=sys.stderr)
        return None
    # libdl.so.2 by name and kept: where glibc is older than 2.34 the dl* functions the guard
    # asks for (c/guard.c) are there; since, it is an empty compatibility library
    return library(("guard.c", "fmi3.c") if fmi == 3 else "guard.c", libraries=(":libdl.so.2",),
                   link_options=("-Wl,--no-as-needed",), defines=("NODEFORCE_FMI3",) if fmi == 3 else ())


def libpython():
    """Path of the shared libpython of this Python: its run-time name (sysconfig INSTSONAME,
    e.g. libpython3.11.so.1.0, which a machine without Python's development files has too, and
    the name the guard gives the dynamic linker where this path does not exist), else LDLIBRARY."""
    folder = Path(sysconfig.get_config_var("LIBDIR"))
    runtime = folder / (sysconfig.get_config_var("INSTSONAME") or "")
    return str(runtime if runtime.is_file() else folder / sysconfig.get_config_var("LDLIBRARY"))


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
