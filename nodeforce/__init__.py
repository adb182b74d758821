"""nodeforce: locate the defective sub-models of a nodal building model by forcing its nodes.

The Python API (`nodeforce.api`, docs/api.md) is available here: `nodeforce.read_building`,
`nodeforce.locate`, ... It is loaded on first use, so that importing a part of the package
(`nodeforce.model`, as the FMU's worker processes do) does not load all of it.
"""


import importlib
import importlib.util


def __getattr__(name):
    if not name.startswith("__"):
        # `from nodeforce import model` asks for the attribute before importing the subpackage:
        # a submodule is imported as such, not looked for in the API (which may be importing it).
        if importlib.util.find_spec(f"{__name__}.{name}") is not None:
            return importlib.import_module(f"{__name__}.{name}")
        api = importlib.import_module("nodeforce.api")
        if name in api.__all__:
            return getattr(api, name)
    raise AttributeError(f"module 'nodeforce' has no attribute {name!r}")
