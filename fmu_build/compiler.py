"""Compiling the FMUs' C code (c/) at export: the standalone FMU's binary and the guard in front
of the Python FMU's. The importing machine needs no compiler; the exporting one does for these."""
import os
import shutil
import subprocess
from pathlib import Path

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


def compile_library(source, output, libraries=(), link_options=(), defines=()):
    """Compile c/<source> (a file name, or several) with the headers beside it into the shared
    library `output`.

    Compiled in c/ by relative name, without debug information: the bytes do not depend on
    where nodeforce is installed, so the same model gives the same FMU.

    libraries : names given to -l; link_options : options for the linker (-Wl,...), before them;
    defines : preprocessor names given to -D

    Raises RuntimeError without a C compiler or when compiling fails.
    """
    compiler = find_compiler()
    if compiler is None:
        raise RuntimeError("no C compiler found (cc, gcc or $CC): install one (e.g. apt-get install gcc)")
    command = [*compiler, "-std=c99", "-O2", "-fPIC", "-shared", "-fvisibility=hidden", *(f"-D{d}" for d in defines),
               "-o", str(output), *([source] if isinstance(source, str) else source), *RPATH, *link_options,
               *(f"-l{name}" for name in libraries)]
    done = subprocess.run(command, cwd=C_DIR, capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(f"compiling {source!r} failed: {' '.join(command)}\n{done.stderr}")
