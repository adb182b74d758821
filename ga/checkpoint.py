"""Checkpoints: the search state written after every generation, so a stopped run resumes.

The file is JSON (readable, no code execution on load) holding a key, the generation reached,
the population, the random generators' states, the convergence rule's state (ga.search), the
fitness cache (J per mask, as a bit string "0110...", null for a failed simulation) and the
request counter.  The key hashes everything that decides the search (the evaluator factory's
pickle, the chromosome nodes, the GA settings, patience and seeding), so a file left by a run
with other arguments is ignored, never resumed.
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
import os
from pathlib import Path

import numpy as np

from nodeforce.ga.evaluation import Mask, factory_token

log = logging.getLogger("nodeforce.ga")

FORMAT = "nodeforce-search-checkpoint/1"
NAME = "locate.checkpoint.json"  # its name in the output folder of `locate` and `diagnose`


def run_key(factory, nodes, **settings) -> str:
    """Hash of the arguments that decide the search's answer."""
    text = json.dumps({"factory": factory_token(factory), "nodes": [str(n) for n in nodes],
                       **settings}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def encode_cache(J_of: dict[Mask, float]) -> dict[str, "float | None"]:
    return {"".join("1" if b else "0" for b in mask): (J if math.isfinite(J) else None)
            for mask, J in J_of.items()}


def decode_cache(cache: dict[str, "float | None"]) -> dict[Mask, float]:
    return {tuple(c == "1" for c in bits): (math.inf if J is None else float(J))
            for bits, J in cache.items()}


def save(path, key: str, state: dict) -> None:
    """Write atomically (temp file + rename): a run killed while writing keeps the last one."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    try:
        tmp.write_text(json.dumps({"format": FORMAT, "key": key, **state}))
        os.replace(tmp, path)
    finally:  # a run stopped while writing leaves no half-written file behind
        tmp.unlink(missing_ok=True)


def load(path, key: str) -> "dict | None":
    """The saved state if `path` holds a checkpoint of this very run, else None."""
    path = Path(path)
    if not path.exists():
        return None
    try:
        state = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        log.warning("checkpoint %s unreadable (%s); starting afresh", path, exc)
        return None
    if state.get("format") != FORMAT or state.get("key") != key:
        log.warning("checkpoint %s belongs to a run with other arguments; starting afresh", path)
        return None
    return state


def resume_hint(path) -> str:
    """What running a stopped search's command again does, in a clause for the user."""
    try:
        generation = json.loads(Path(path).read_text())["generation"]
    except (OSError, ValueError, KeyError):
        return "no checkpoint was written yet: run the same command again to start over"
    return f"run the same command again to resume from {path} (generation {generation})"


def rng_states(ga) -> dict:
    """PyGAD's two seeded generators, as JSON: all the randomness the GA draws from."""
    name, keys, pos, has_gauss, cached = ga.numpy_random_generator.get_state()
    version, internal, gauss_next = ga.python_random_generator.getstate()
    return {"numpy": [name, keys.tolist(), int(pos), int(has_gauss), float(cached)],
            "python": [version, list(internal), gauss_next]}


def restore_rng_states(ga, states: dict) -> None:
    name, keys, pos, has_gauss, cached = states["numpy"]
    ga.numpy_random_generator.set_state((name, np.array(keys, dtype=np.uint32), pos, has_gauss,
                                         cached))
    version, internal, gauss_next = states["python"]
    ga.python_random_generator.setstate((version, tuple(internal), gauss_next))
