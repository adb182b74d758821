"""The data flow one way (docs/index.md, Layout of the code): read from each module's own source,
no import goes against it. Every import is compared as its whole module path
(`nodeforce.model.network`), relative ones resolved, so that the top package (`nodeforce.api`,
`nodeforce.cli`, `nodeforce` itself) is a layer like the others."""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
# The folders that install as nodeforce's subpackages (pyproject.toml), bottom first; any other
# module of nodeforce (`nodeforce.api`, `nodeforce.cli`, `nodeforce` itself) is the top package.
SUBPACKAGES = ("runtime", "model", "iotools", "fmu_build", "cosim", "ga", "diagnosis")
TOP = "top"
# Each folder and the layers it must not import: the runtime plumbing (temporary folders, worker
# processes, the Dask cluster, the C compiler) nothing of nodeforce; the physics knows nothing of
# files, FMUs, the search or the diagnosis; no layer reaches up into the top package (the API and
# the command line), and the diagnosis calls the search (`ga.locate`) and nothing else of it.
FORBIDDEN = {"runtime": ("model", "iotools", "fmu_build", "cosim", "ga", "diagnosis", TOP),
             "model": ("iotools", "fmu_build", "cosim", "ga", "diagnosis", TOP),
             "iotools": ("fmu_build", "cosim", "ga", "diagnosis", TOP),
             "fmu_build": ("ga", "diagnosis", TOP),
             "cosim": ("ga", "diagnosis", TOP),
             "ga": ("diagnosis", TOP),
             "diagnosis": ("ga", TOP)}
# ... except these modules (and what is inside them): the diagnosis runs the search through its
# entry point; the plumbing raises the error type of bad input, which the Python FMU carries with
# the physics (`model.errors`).
ALLOWED = {"diagnosis": ("nodeforce.ga.locate",), "runtime": ("nodeforce.model.errors",)}


def package_of(path):
    """The dotted package a file of the repository is in: nodeforce/api.py is in `nodeforce`,
    model/network.py in `nodeforce.model`, diagnosis/report/plots.py in `nodeforce.diagnosis.report`."""
    parts = path.relative_to(ROOT).parent.parts
    return ".".join(parts if parts[0] == "nodeforce" else ("nodeforce", *parts))


def imported(path, text=None):
    """The whole module paths of nodeforce a file (its `text`, default read) imports:
    "nodeforce.ga.locate", "nodeforce.api", "nodeforce", ... (relative imports resolved against
    the file's own package; `from nodeforce import x` imports `nodeforce.x`)."""
    package = package_of(path).split(".")
    names = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8") if text is None else text)):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package[:len(package) - node.level + 1] + ([base] if base else []))
            names += ([] if base == "nodeforce" else [base]) + [f"{base}.{alias.name}" for alias in node.names]
    return {name for name in names if name == "nodeforce" or name.startswith("nodeforce.")}


def layer(name):
    """The layer of a whole module path: its subpackage, or the top package."""
    first = name.split(".")[1] if "." in name else ""
    return first if first in SUBPACKAGES else TOP


def against(path, text=None):
    """The imports of a file against the flow."""
    folder = path.relative_to(ROOT).parts[0]
    allowed = ALLOWED.get(folder, ())
    return sorted(name for name in imported(path, text)
                  if layer(name) in FORBIDDEN.get(folder, ())
                  and not any(name == a or name.startswith(a + ".") for a in allowed))


@pytest.mark.parametrize("path", sorted(p for folder in FORBIDDEN for p in (ROOT / folder).rglob("*.py")),
                         ids=lambda p: p.relative_to(ROOT).as_posix())
def test_no_import_goes_against_the_flow(path):
    assert not against(path), f"{path.relative_to(ROOT)} imports {against(path)}"


def test_the_walk_sees_an_import_against_the_flow():
    """The check can fail: a module of model/ reading a file through iotools or reaching into the
    top package, of diagnosis/ reaching into the search's parsimony, of the plumbing into the
    physics, is caught, relative imports included."""
    for probe, text in (("model/probe.py", "from nodeforce.iotools.timetable import check_celsius\n"),
                        ("model/probe.py", "from ..iotools import weather\n"),
                        ("model/probe.py", "import nodeforce.diagnosis.loop\n"),
                        ("model/probe.py", "from nodeforce.api import diagnose\n"),
                        ("model/probe.py", "from nodeforce import diagnose\n"),
                        ("model/probe.py", "import nodeforce\n"),
                        ("model/probe.py", "from .. import api\n"),
                        ("ga/probe.py", "from nodeforce.cli import main\n"),
                        ("runtime/probe.py", "from nodeforce.model.network import assemble\n"),
                        ("diagnosis/probe.py", "from nodeforce.ga.parsimony import tolerance\n"),
                        ("diagnosis/report/probe.py", "from ...ga import parsimony\n")):
        assert against(ROOT / probe, text), text
    for probe, text in (("diagnosis/probe.py", "from nodeforce.ga.locate import locate\n"),
                        ("model/probe.py", "from .effects import EFFECTS\n"),
                        ("model/probe.py", "from nodeforce.runtime import tempdirs\n"),
                        ("model/probe.py", "from nodeforce import model\n"),
                        ("runtime/probe.py", "from nodeforce.model.errors import InputError\n")):
        assert not against(ROOT / probe, text), text
