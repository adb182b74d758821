"""Compiling the FMUs' C code (c/) at export: the standalone FMU's binary and the guard in front
of the Python FMU's. The importing machine needs no compiler; the exporting one does for these.
The compiler is the direct model's (`model.compiled`), as is the profile LU the standalone FMU
includes (model/c/profile.h).

No library depends on the building (a building is its FMU's data, in resources/): each is
compiled at a process's first export that needs it, and every later export copies its bytes."""
import functools
from pathlib import Path

from nodeforce.model.compiled import C_DIR as MODEL_C_DIR
from nodeforce.runtime.compiler import compile_library

C_DIR = Path(__file__).with_name("c")

# The libraries an FMU's binary loads beside it are found in its own folder (the FMU's
# binaries/<platform>), whatever the host's working directory: DT_RPATH $ORIGIN.
RPATH = ("-Wl,--disable-new-dtags", "-Wl,-rpath,$ORIGIN")


@functools.lru_cache(maxsize=None)
def library(source, libraries=(), link_options=(), defines=()):
    """The shared library (bytes) of c/<source> (a file name, or a tuple of several) with the
    headers beside it and the direct model's (model/c/), compiled once per process
    (`runtime.compiler.compile_library`, -O2: the binary is shipped to other machines).

    libraries : names given to -l; link_options : options for the linker (-Wl,...), before them;
    defines : preprocessor names given to -D

    Raises RuntimeError without a C compiler or when compiling fails.
    """
    return compile_library(C_DIR, source, libraries=libraries, link_options=(*RPATH, *link_options),
                           defines=defines, includes=(MODEL_C_DIR,))
