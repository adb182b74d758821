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

Either as FMI 2.0 (the default) or FMI 3.0 (kind "python-fmi3", "standalone-fmi3"; `fmu_kind`):
the same model, its FMI 3.0 interface (c/fmi3.c) compiled into the FMU's binary over its FMI
2.0 one, with `force`, `T_forced` and `T` as arrays of N.
"""
import json
import sys
import zipfile
from pathlib import Path

from nodeforce import model

from nodeforce.runtime import tempdirs
from nodeforce.model.effects import EFFECTS, fmu_parameters
from nodeforce.model.network import input_names

from . import description
from .compiler import C_DIR, library
from .guard import PLATFORM, guard_binary, guarded
from .variables import Layout

SLAVE = Path(__file__).with_name("slave.py")
VARIABLES = Path(__file__).with_name("variables.py")
MODEL_DIR = Path(model.__file__).parent
# The modules the FMU imports; weather and solar stay outside (their results are inputs).
PHYSICS_MODULES = ("__init__", "errors", "building", "building_file", "convection", "geometry", "discretise", "schedule",
                   "effects", "gains", "glazing", "interior_sun", "longwave", "network", "modal", "integrate")
SCHEMA = "data/nodal-building.schema.json"


FMI3_PLATFORM = "x86_64-linux"  # FMI 3.0's name of FMI 2.0's linux64
FMI3_SOURCES = ("fmi3.c", "fmi3.h", "glibc.h")
# The FMI 3.0 standalone binary: (C files, libraries, preprocessor definitions), which
# sources/buildDescription.xml says too, so that an importer builds the same library
FMI3_BUILD = (("nodeforce_fmu.c", "fmi3.c"), ("m",), ("NODEFORCE_FMI3",))


def fmu_kind(kind, fmi):
    """The `build_fmu` kind of an FMU kind ("python", "standalone") at an FMI version (2, 3)."""
    return kind if int(fmi) == 2 else f"{kind}-fmi3"


def build_fmu(building, destination, effect=None, kind="python"):
    """Write the FMU of a building.

    Parameters
    ----------
    building : Building
    destination : path of the .fmu to write
    effect : (effect id, target) of `model.effects` whose parameters the FMU exposes as
        `<effect>.<name>` (start: the values the building declares), or None
    kind : "python" (pythonfmu) or "standalone" (C, no Python at run time), FMI 2.0; with
        "-fmi3", the same as FMI 3.0 (`fmu_kind`)

    Returns
    -------
    Path of the FMU written
    """
    kind, _, version = kind.partition("-fmi")
    if kind not in KINDS or version not in ("", "3"):
        raise ValueError(f"unknown FMU kind {kind!r}: one of {', '.join(KINDS)}, each optionally -fmi3")
    if effect is not None and not EFFECTS[effect[0]].applies(building, effect[1]):
        raise ValueError(f"effect {effect[0]} does not apply to {effect[1]!r}")
    if effect is not None and kind.startswith("standalone") and EFFECTS[effect[0]].not_standalone:
        raise ValueError(f"effect {effect[0]}: {EFFECTS[effect[0]].not_standalone}, which a standalone FMU's form "
                         "cannot hold: use the Python FMU")
    if effect is not None:  # declared at its present values, so the FMU has every input the effect uses
        building = EFFECTS[effect[0]].apply(building, effect[1], {})
    destination = Path(destination).resolve()
    destination.parent.mkdir(parents=True, exist_ok=True)
    return KINDS[kind](building, destination, effect, int(version or 2))


def model_interface(building, effect):
    """The `Layout` of the FMU of a building with its effect ((id, target) or None)."""
    return Layout(building.n_nodes, input_names(building), fmu_parameters(building, effect))


def _build_python(building, destination, effect, fmi):
    from pythonfmu.builder import FmuBuilder
    from pythonfmu.osutil import get_platform

    building_text = json.dumps(building.to_json(), indent=1)
    effect_text = json.dumps({"effect": effect[0], "target": effect[1]}) if effect else ""
    sources = {f"{name}.py": (MODEL_DIR / f"{name}.py").read_text() for name in PHYSICS_MODULES}
    sources["variables.py"] = VARIABLES.read_text()
    sources[SCHEMA] = (MODEL_DIR / SCHEMA).read_text()  # an importer's parameters edit the building: checked by it
    slave_text = SLAVE.read_text()
    module = "nodeforce_" + description.content_hash(building_text, effect_text, slave_text,
                                                     *sources.values())[:16]

    with tempdirs.folder("fmu") as tmp:
        tmp = Path(tmp)
        script = tmp / f"{module}.py"
        script.write_text(slave_text)
        package = tmp / f"{module}_model"
        package.mkdir()
        for name, text in sources.items():
            (package / name).parent.mkdir(exist_ok=True)
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
    layout = model_interface(building, effect)
    files, is_guarded = guarded(files, identifier, layout)
    if is_guarded:
        files["resources/names.txt"] = layout.names_file().encode()
    if fmi == 3:
        if not is_guarded:
            raise RuntimeError("the FMI 3.0 Python FMU's binary is its FMI 3.0 interface over the guard, compiled at "
                               "export: it needs a C compiler (cc, gcc or $CC)")
        files = _as_fmi3(files, identifier, layout, guard_binary(fmi=3))
    return _write(destination, files, building, effect, identifier, standalone=False, guarded=is_guarded, fmi=fmi)


def _as_fmi3(files, identifier, layout, binary):
    """The files of an FMU as FMI 3.0: its linux64 binaries under FMI 3.0's platform name, the
    model's `binary` (FMI 3.0 over FMI 2.0) for its own, no other platform (pythonfmu's win64
    binary is FMI 2.0 only), and the sizes c/fmi3.c reads."""
    moved = {name.replace(f"binaries/{PLATFORM}/", f"binaries/{FMI3_PLATFORM}/"): data
             for name, data in files.items() if not name.startswith("binaries/") or f"/{PLATFORM}/" in name}
    moved[f"binaries/{FMI3_PLATFORM}/{identifier}.so"] = binary
    moved["resources/fmi3.txt"] = (f"nodeforce-fmi3/1\nsizes {layout.n_nodes} {len(layout.input_names)} "
                                   f"{len(layout.parameter_names)}\n").encode()
    return moved


def _write(destination, files, building, effect, identifier, standalone, source_files=(), guarded=True, fmi=2):
    """Add the documentation and the model description (GUID: hash of every file) and write."""
    name = building.name or identifier
    files = {**files, "documentation/index.html": description.documentation(name, standalone, guarded, fmi=fmi)}
    guid = description.content_guid(*(part for item in sorted(files.items()) for part in item))
    files["modelDescription.xml"] = description.model_description(
        model_interface(building, effect), building, guid, identifier, name, effect, standalone, source_files,
        fmi=fmi, interpolates=standalone or guarded)
    return description.write_fmu(destination, files)


def _build_standalone(building, destination, effect, fmi):
    from .standalone import standalone_files

    files, identifier, source_files = standalone_files(building, effect, model_interface(building, effect))
    if fmi == 3:
        binary = library(FMI3_BUILD[0], libraries=FMI3_BUILD[1], defines=FMI3_BUILD[2])
        files = _as_fmi3(files, identifier, model_interface(building, effect), binary)
        files.update({f"sources/{name}": (C_DIR / name).read_bytes() for name in FMI3_SOURCES})
        files["sources/buildDescription.xml"] = description.build_description(identifier, *FMI3_BUILD)
    return _write(destination, files, building, effect, identifier, True, source_files, fmi=fmi)


KINDS = {"python": _build_python, "standalone": _build_standalone}
