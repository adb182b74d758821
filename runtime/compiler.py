"""The project's C compiler: found once ($CC, else cc or gcc), a library built in a temporary
folder removed at once, its bytes for an FMU's binaries, or a function of it loaded here. The
direct model's compiled steps (`model.compiled`), the FMI master loop (`cosim.fmi`) and the FMUs'
export (`fmu_build.compiler`) compile through it."""
import ctypes
import os
import shutil
import subprocess
from contextlib import contextmanager
from pathlib import Path

from nodeforce.runtime import tempdirs


def find_compiler():
    """The C compiler command ($CC, else cc or gcc) as a list, or None when there is none."""
    command = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not command or not shutil.which(command.split()[0]):
        return None
    return command.split()


@contextmanager
def built_library(directory, source, libraries=(), link_options=(), defines=(), options=("-O2",), includes=()):
    """The path of the shared library of `directory`/<source> (a file name, or a tuple of several)
    with the headers beside it and in `includes` (folders), in a temporary folder removed at the
    block's end.

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
        yield output


def compile_library(directory, source, **options):
    """The shared library (bytes) `built_library` compiles, for an FMU's binaries."""
    with built_library(directory, source, **options) as path:
        return path.read_bytes()


def compiled_function(directory, source, symbol, fallback, logger, options=("-O2",)):
    """The function `symbol` of `directory`/`source` compiled here (`built_library`) and loaded
    from its temporary folder, removed at once; None where it cannot be compiled (no C compiler,
    or one that fails on it: `fallback`, what is done instead, said in `logger`'s log with the
    compiler's first line). The caller declares its argument and result types."""
    if find_compiler() is None:
        return None
    try:
        with built_library(directory, source, options=options) as path:
            return getattr(ctypes.CDLL(str(path)), symbol)
    except RuntimeError as error:
        logger.warning("%s: %s", fallback, str(error).splitlines()[0])
        return None
