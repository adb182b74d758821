"""Temporary folders that name their owner, so the folders of a dead process can be removed.

Every temporary folder nodeforce makes is `nodeforce_<kind>_<pid>-<start>_<random>` in the temp
directory: <pid> is the process that made it and <start> that process's start time (clock ticks
after boot, /proc/<pid>/stat field 22), so a pid the system has since given to another process is
not mistaken for the owner. A process killed outright (SIGKILL, the out-of-memory killer) cannot
remove its folders; `sweep` (run by every `nodeforce` command as it starts) removes those whose
owner no longer runs, and never touches the folder of a live process (on a system without /proc
it removes nothing).

The folders a process made and those of its parent it reads are also listed here, so a worker
told to stop by a signal removes its own, and its parent's if that parent is gone, before it
exits (`remove_held`, runtime.lifetime).
"""
import os
import re
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

PREFIX = "nodeforce_"
_OWNED = re.compile(r"nodeforce_[a-z]+_(\d+)-(\d+)_")
_made: set = set()  # this process's folders, not removed yet
_held: set = set()  # other processes' folders this process reads (`hold`)


def start_time(pid: int) -> "int | None":
    """The start time of process `pid` in clock ticks after boot; None if it does not run."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    # the command name (field 2) is in parentheses and may hold spaces: split after its end
    fields = stat[stat.rindex(")") + 2:].split()
    if fields[0] in ("Z", "X"):  # a zombie runs no more: only its exit status is left
        return None
    return int(fields[19])


def owner_tag(pid: "int | None" = None) -> str:
    pid = os.getpid() if pid is None else pid
    return f"{pid}-{start_time(pid) or 0}"


def make(kind: str) -> str:
    """A new folder `nodeforce_<kind>_<pid>-<start>_*` in the temp directory; the caller removes
    it (`remove`), else the next run's `sweep` does once this process has ended."""
    path = tempfile.mkdtemp(prefix=f"{PREFIX}{kind}_{owner_tag()}_")
    _made.add(path)
    return path


def remove(path) -> None:
    shutil.rmtree(path, ignore_errors=True)
    _made.discard(str(path))
    _held.discard(str(path))


@contextmanager
def folder(kind: str):
    """A temporary folder for the duration of a `with` block (tempfile.TemporaryDirectory's use)."""
    path = make(kind)
    try:
        yield path
    finally:
        remove(path)


def hold(path) -> None:
    """Count a folder another process made among this process's own, removed with them if it is
    stopped (`remove_held`) once that process is gone: a pool's, which its workers read beside
    the parent that made it and remove when that parent is killed outright, but leave to a
    parent that stops them (a broken pool renewed, a run stopped) and removes it itself."""
    _held.add(str(path))


def remove_held() -> None:
    """Remove every folder this process made and has not removed yet, and those it holds whose
    owner no longer runs (a worker's last act)."""
    for path in list(_made):
        remove(path)
    for path in list(_held):
        if not owner_alive(Path(path).name):
            remove(path)


def owner_alive(name: str) -> bool:
    """Whether the process a folder name gives as its owner still runs (names without an owner,
    from other tools or earlier releases, count as alive: they are never removed)."""
    match = _OWNED.match(name)
    if match is None:
        return True
    pid, started = int(match[1]), int(match[2])
    return start_time(pid) == started


def sweep(directory=None) -> list[str]:
    """Remove the nodeforce folders of processes that no longer run; return their names.

    Only this user's folders: another user's are theirs to remove (and could not be).
    """
    if not Path("/proc/self/stat").exists():  # no start times to tell a live owner by: keep all
        return []
    directory = Path(directory or tempfile.gettempdir())
    removed = []
    for path in directory.glob(PREFIX + "*"):
        try:
            if not path.is_dir() or path.stat().st_uid != os.getuid() or owner_alive(path.name):
                continue
        except OSError:  # removed meanwhile by its owner or another sweep
            continue
        shutil.rmtree(path, ignore_errors=True)
        removed.append(path.name)
    return removed
