"""The data flow one way (docs/index.md, Layout of the code): read from each module's own source,
no import goes against it."""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
# Each folder and the packages of the stages after it, which it must not import: the physics
# knows nothing of files, FMUs, the search or the diagnosis; the diagnosis calls the search
# (`ga.locate`) and nothing else of it.
FORBIDDEN = {"model": ("iotools", "fmu_build", "cosim", "ga", "diagnosis", "nodeforce"),
             "iotools": ("fmu_build", "cosim", "ga", "diagnosis", "nodeforce"),
             "diagnosis": ("nodeforce",)}
ALLOWED = {"diagnosis": ("ga.locate",)}
PACKAGES = ("model", "iotools", "fmu_build", "cosim", "ga", "diagnosis", "nodeforce")


def imported(path, text=None):
    """The nodeforce modules a file (its `text`, default read) imports, as "ga.locate",
    "model.case", ... (relative imports resolved against the file's own package)."""
    package = path.relative_to(ROOT).parent.parts
    names = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8") if text is None else text)):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package[:len(package) - node.level + 1] + ((base,) if base else ()))
            names += [base] + [f"{base}.{alias.name}" for alias in node.names]
    return {name.removeprefix("nodeforce.") for name in names
            if name.startswith("nodeforce.") or name.split(".")[0] in PACKAGES}


def against(path, text=None):
    """The imports of a file against the flow."""
    folder = path.relative_to(ROOT).parts[0]
    allowed = ALLOWED.get(folder, ())
    return sorted(name for name in imported(path, text)
                  if name.split(".")[0] in FORBIDDEN.get(folder, ()) and name != "nodeforce"
                  or (folder == "diagnosis" and name.split(".")[0] == "ga"
                      and not any(name == a or name.startswith(a + ".") for a in allowed)))


@pytest.mark.parametrize("path", sorted(p for folder in FORBIDDEN for p in (ROOT / folder).rglob("*.py")),
                         ids=lambda p: p.relative_to(ROOT).as_posix())
def test_no_import_goes_against_the_flow(path):
    assert not against(path), f"{path.relative_to(ROOT)} imports {against(path)}"


def test_the_walk_sees_an_import_against_the_flow():
    """The check can fail: a module of model/ reading a file through iotools, or of diagnosis/
    reaching into the search's parsimony, is caught, relative imports included."""
    for probe, text in (("model/probe.py", "from nodeforce.iotools.timetable import check_celsius\n"),
                        ("model/probe.py", "from ..iotools import weather\n"),
                        ("model/probe.py", "import nodeforce.diagnosis.loop\n"),
                        ("diagnosis/probe.py", "from nodeforce.ga.parsimony import tolerance\n"),
                        ("diagnosis/report/probe.py", "from ...ga import parsimony\n")):
        assert against(ROOT / probe, text), text
    assert not against(ROOT / "diagnosis" / "probe.py", "from nodeforce.ga.locate import locate\n")
    assert not against(ROOT / "model" / "probe.py", "from .effects import EFFECTS\n")
