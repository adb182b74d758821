"""Build the FMU of a building file: `nodeforce fmu BUILDING [--standalone] -o MODEL.fmu`.

Two kinds of FMU, with the same variables and the same numbers:

- "python" (the default, the one the search drives): pythonfmu runs `slave.py` with the physics
  modules of `model/` and the building description it carries, behind the guard of `guard.py`
  (fmi2Error for forbidden calls; libpython for a host without Python). Its slave module is named after
  a hash of that content, so two different FMUs in one process never share Python modules
  (pythonfmu imports the slave by name), while the same FMU loaded twice does, harmlessly.
- "standalone" (`standalone.py`): the assembled network as data, stepped by generic C code; no
  Python at run time.

Both carry the model description of `description.py`, with a GUID that hashes their content.
"""
import json
import sys
import tempfile
import zipfile
from pathlib import Path

from nodeforce import model
from nodeforce.model.effects import EFFECTS
from nodeforce.model.network import input_names

from . import description
from .guard import guarded
from .variables import Layout

SLAVE = Path(__file__).with_name("slave.py")
VARIABLES = Path(__file__).with_name("variables.py")
MODEL_DIR = Path(model.__file__).parent
# The modules the FMU imports; weather and solar stay outside (their results are inputs).
PHYSICS_MODULES = ("__init__", "errors", "building", "discretise", "effects", "network", "integrate")


def build_fmu(building, destination, effect=None, kind="python"):
    """Write the FMU of a building.

    Parameters
    ----------
    building : Building
    destination : path of the .fmu to write
    effect : (effect id, target) of `model.effects` whose parameters the FMU exposes as
        `<effect>.<name>` (start: the values the building declares), or None
    kind : "python" (pythonfmu) or "standalone" (C, no Python at run time)

    Returns
    -------
    Path of the FMU written
    """
    if kind not in KINDS:
        raise ValueError(f"unknown FMU kind {kind!r}: one of {', '.join(KINDS)}")
    if effect is not None and not EFFECTS[effect[0]].applies(building, effect[1]):
        raise ValueError(f"effect {effect[0]} does not apply to {effect[1]!r}")
    if effect is not None:  # declared at its present values, so the FMU has every input the effect uses
        building = EFFECTS[effect[0]].apply(building, effect[1], {})
    destination = Path(destination).resolve()
    destination.parent.mkdir(parents=True, exist_ok=True)
    return KINDS[kind](building, destination, effect)


def model_interface(building, effect):
    """(Layout, effect for `description.model_description`) of a building with its effect."""
    start = EFFECTS[effect[0]].read(building, effect[1]) if effect else {}
    layout = Layout(building.n_nodes, input_names(building), [f"{effect[0]}.{n}" for n in start])
    return layout, ((*effect, start) if effect else None)


def _build_python(building, destination, effect):
    from pythonfmu.builder import FmuBuilder
    from pythonfmu.osutil import get_platform

    building_text = json.dumps(building.to_json(), indent=1)
    effect_text = json.dumps({"effect": effect[0], "target": effect[1]}) if effect else ""
    sources = {f"{name}.py": (MODEL_DIR / f"{name}.py").read_text() for name in PHYSICS_MODULES}
    sources["variables.py"] = VARIABLES.read_text()
    slave_text = SLAVE.read_text()
    module = "nodeforce_" + description.content_hash(building_text, effect_text, slave_text,
                                                     *sources.values())[:16]

    with tempfile.TemporaryDirectory(prefix="nodeforce_fmu_") as tmp:
        tmp = Path(tmp)
        script = tmp / f"{module}.py"
        script.write_text(slave_text)
        package = tmp / f"{module}_model"
        package.mkdir()
        for name, text in sources.items():
            (package / name).write_text(text)
        (tmp / "building.json").write_text(building_text)
        resources = [package, tmp / "building.json"]
        if effect:
            (tmp / "effect.json").write_text(effect_text)
            resources.append(tmp / "effect.json")
        built = tmp / "pythonfmu.fmu"
        try:
            FmuBuilder.build_FMU(script, dest=built, project_files=resources)
        finally:
            # pythonfmu leaves the build folder on sys.path; the module cache entries it made are
            # the same code as the FMU's, under the FMU's unique name, and may stay.
            while str(tmp) in sys.path:
                sys.path.remove(str(tmp))
        with zipfile.ZipFile(built) as fmu:
            files = {name: fmu.read(name) for name in fmu.namelist()
                     if name != "modelDescription.xml" and "__pycache__" not in name}
    if not any(name.startswith(f"binaries/{get_platform()}/") for name in files):
        raise RuntimeError(f"pythonfmu has no binary for {get_platform()}: the pythonfmu imported "
                           f"from {FmuBuilder.build_FMU.__code__.co_filename} is a copy without one")
    # pythonfmu names the binaries after the slave class, and finds the module in slavemodule.txt
    identifier = Path(next(name for name in files if name.startswith("binaries/"))).stem
    files, is_guarded = guarded(files, identifier, model_interface(building, effect)[0])
    return _write(destination, files, building, effect, identifier, standalone=False, guarded=is_guarded)


def _write(destination, files, building, effect, identifier, standalone, source_files=(), guarded=True):
    """Add the documentation and the model description (GUID: hash of every file) and write."""
    name = building.name or identifier
    files = {**files, "documentation/index.html": description.documentation(name, standalone, guarded)}
    guid = description.content_guid(*(part for item in sorted(files.items()) for part in item))
    layout, effect_spec = model_interface(building, effect)
    files["modelDescription.xml"] = description.model_description(
        layout, building, guid, identifier, name, effect_spec, standalone, source_files)
    return description.write_fmu(destination, files)


def _build_standalone(building, destination, effect):
    from .standalone import standalone_files

    files, identifier, source_files = standalone_files(building, effect)
    return _write(destination, files, building, effect, identifier, True, source_files)


KINDS = {"python": _build_python, "standalone": _build_standalone}
