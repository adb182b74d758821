"""Compiling the FMUs' C code (c/) at export: the standalone FMU's binary and the guard in front
of the Python FMU's. The importing machine needs no compiler; the exporting one does for these.

No library depends on the building (a building is its FMU's data, in resources/): each is
compiled at a process's first export that needs it, and every later export copies its bytes."""
import functools
import os
import shutil
import subprocess
from pathlib import Path

from nodeforce import tempdirs

C_DIR = Path(__file__).with_name("c")


def find_compiler():
    """The C compiler command ($CC, else cc or gcc) as a list, or None when there is none."""
    command = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not command or not shutil.which(command.split()[0]):
        return None
    return command.split()


# The libraries an FMU's binary loads beside it are found in its own folder (the FMU's
# binaries/<platform>), whatever the host's working directory: DT_RPATH $ORIGIN.
RPATH = ("-Wl,--disable-new-dtags", "-Wl,-rpath,$ORIGIN")


@functools.lru_cache(maxsize=None)
def library(source, libraries=(), link_options=(), defines=(), options=("-O2",)):
    """The shared library (bytes) of c/<source> (a file name, or a tuple of several) with the
    headers beside it, compiled once per process.

    Compiled in c/ by relative name, without debug information: the bytes do not depend on
    where nodeforce is installed, so the same model gives the same FMU.

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
                   *(f"-D{d}" for d in defines), "-o", str(output), *([source] if isinstance(source, str) else source),
                   *RPATH, *link_options, *(f"-l{name}" for name in libraries)]
        done = subprocess.run(command, cwd=C_DIR, capture_output=True, text=True)
        if done.returncode:
            raise RuntimeError(f"compiling {source!r} failed: {' '.join(command)}\n{done.stderr}")
        return output.read_bytes()
