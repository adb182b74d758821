"""Build the FMU of a building file: `nodeforce fmu BUILDING -o MODEL.fmu`.

The FMU carries everything it runs: the slave, the physics modules of `model/` and the building
description. Its slave module is named after a hash of that content, so two different FMUs in
one process never share Python modules (pythonfmu imports the slave by name), while the same
FMU loaded twice does, harmlessly.
"""
import hashlib
import json
import sys
import tempfile
import zipfile
from pathlib import Path

from pythonfmu.builder import FmuBuilder
from pythonfmu.osutil import get_platform

from nodeforce import model
from nodeforce.model.effects import EFFECTS

SLAVE = Path(__file__).with_name("slave.py")
MODEL_DIR = Path(model.__file__).parent
# The modules the FMU imports; weather and solar stay outside (their results are inputs).
PHYSICS_MODULES = ("__init__", "errors", "building", "discretise", "effects", "network", "integrate")


def build_fmu(building, destination, effect=None):
    """Write the FMU of a building.

    Parameters
    ----------
    building : Building
    destination : path of the .fmu to write
    effect : (effect id, target) of `model.effects` whose parameters the FMU exposes as
        `<effect>.<name>` (start: the values the building declares), or None

    Returns
    -------
    Path of the FMU written
    """
    if effect is not None and not EFFECTS[effect[0]].applies(building, effect[1]):
        raise ValueError(f"effect {effect[0]} does not apply to {effect[1]!r}")
    building_text = json.dumps(building.to_json(), indent=1)
    effect_text = json.dumps({"effect": effect[0], "target": effect[1]}) if effect else ""
    sources = {name: (MODEL_DIR / f"{name}.py").read_text() for name in PHYSICS_MODULES}
    slave_text = SLAVE.read_text()
    digest = hashlib.sha256("\0".join([building_text, effect_text, slave_text, *sources.values()]).encode())
    module = f"nodeforce_{digest.hexdigest()[:16]}"

    destination = Path(destination).resolve()
    destination.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="nodeforce_fmu_") as tmp:
        tmp = Path(tmp)
        script = tmp / f"{module}.py"
        script.write_text(slave_text)
        package = tmp / f"{module}_model"
        package.mkdir()
        for name, text in sources.items():
            (package / f"{name}.py").write_text(text)
        (tmp / "building.json").write_text(building_text)
        resources = [package, tmp / "building.json"]
        if effect:
            (tmp / "effect.json").write_text(effect_text)
            resources.append(tmp / "effect.json")
        try:
            FmuBuilder.build_FMU(script, dest=destination, project_files=resources,
                                 canGetAndSetFMUstate=True, canSerializeFMUstate=True)
        finally:
            # pythonfmu leaves the build folder on sys.path; the module cache entries it made are
            # the same code as the FMU's, under the FMU's unique name, and may stay.
            while str(tmp) in sys.path:
                sys.path.remove(str(tmp))
    with zipfile.ZipFile(destination) as fmu:
        if not any(name.startswith(f"binaries/{get_platform()}/") for name in fmu.namelist()):
            raise RuntimeError(f"{destination} has no binary for {get_platform()}: the pythonfmu imported "
                               f"from {FmuBuilder.build_FMU.__code__.co_filename} is a copy without one")
    return destination
