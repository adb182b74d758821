"""`nodeforce locate`: which nodes, forced to their measurements, best explain the indoor air.

Chooses the chromosome (every measured node but the objective's air nodes and, by default, the
algebraic radiant nodes, which are no sub-model), builds the FMU, and runs the search with the
sensors' noise given by the user or estimated from the measured air. A record that measures
only the objective's air (a thermostat's) has nothing to force: its locate.json says so, with
`best_nodes` [], and the diagnosis goes on to the air's own equation.
"""
import time
from dataclasses import dataclass

import numpy as np
from scipy.sparse.csgraph import shortest_path

from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga.checkpoint import NAME as CHECKPOINT
from nodeforce.runtime.compiler import find_compiler
from nodeforce.runtime.jsonfile import JsonFile
from nodeforce.ga.fitness import FmuFitness, RecordsFitness
from nodeforce.ga.parsimony import EXPLAINED
from nodeforce.ga.search import Execution, SearchSettings, search as run_search
from nodeforce.model.case import as_cases
from nodeforce.model.errors import InputError
from nodeforce.model.network import assemble
from nodeforce.model.score import Noise, removed


def evaluator_kind(kind, buildings):
    """`kind` as `build_fmu` takes it: "auto" (or "auto-fmi3") is the standalone FMU where a C
    compiler is at hand (it is compiled at export) and every one of `buildings` has a constant
    matrix, else the Python FMU; any other kind is itself. Measured (benchmarks/bench_scale.py,
    docs/performance.md): a simulation of a new mask costs at least 1.7 times less through the
    standalone FMU than through the Python FMU, from the test cell's 23 nodes to 2,922. The
    standalone steps coefficients that follow the state (docs/model.md 3.6) as the direct model
    does; a building with a scheduled air flow or a scheduled gain that follows the air's
    temperature runs the Python FMU: the standalone steps one constant matrix."""
    base, _, version = kind.partition("-fmi")
    if base != "auto":
        return kind
    scheduled = any(b.switched for b in buildings)
    return ("python" if scheduled or not find_compiler() else "standalone") + (f"-fmi{version}" if version else "")


def check_measured(objective, case, source):
    """Every objective zone's air must be measured: J is computed on it."""
    for zone, air in zip(objective.zones, objective.air_nodes):
        if air not in case.measured_ids:
            raise InputError(source, f"T{air}", f"the air of zone {zone} (node {air}) is not measured; "
                                                "J is computed on it")


def links_to(network, nodes):
    """Number of conductances between each node and the nearest of `nodes` (ids)."""
    coupled = (network.A != 0) & ~np.eye(network.n_nodes, dtype=bool)
    return shortest_path(coupled, unweighted=True, indices=np.asarray(nodes) - 1).min(axis=0)


def chromosome_nodes(building, case, objective, source, nodes=None, include_algebraic=False):
    """The nodes the search may force (ids), nearest the objective's air first, then by id.

    `case` is a Case or the Cases of several records of the building: a node any of them
    measures may be forced (where a record does not measure it, it stays computed there).
    The order is the search's preference between nodes whose scores the noise cannot separate:
    forcing a node nearer the zone cuts off more of the sub-model behind it (the inside surface
    isolates the whole component, a node deeper in cuts only the layers beyond).
    """
    cases = as_cases(case)
    for c in cases:
        check_measured(objective, c, source)
    network = assemble(building)
    measured = set().union(*(c.measured_ids for c in cases)) - set(objective.air_nodes)
    # a node no other node reads (a zone's mean radiant temperature under longwave "scriptf")
    # cuts off nothing when forced
    read = np.any((network.A != 0.0) & ~np.eye(network.n_nodes, dtype=bool), axis=0)
    unread = set(np.flatnonzero(~read) + 1)
    if nodes is None:
        algebraic = set(np.flatnonzero(network.algebraic) + 1)
        chosen = (measured if include_algebraic else measured - algebraic) - unread
    else:
        for i in nodes:
            if i in objective.air_nodes:
                raise InputError("--nodes", str(i), f"node {i} is an output (objective air), not a forcing candidate")
            if i in unread:
                raise InputError("--nodes", str(i), f"node {i} is read by no other node (a zone's mean radiant "
                                                    "temperature): forcing it changes nothing")
            if i not in measured:
                raise InputError(source, f"T{i}", f"node {i} is asked for in --nodes but has no measurement column")
        chosen = set(nodes)
    distance = links_to(network, objective.air_nodes)
    return sorted(chosen, key=lambda i: (distance[i - 1], i))


@dataclass(frozen=True)
class Localization(JsonFile):
    """What the forcing search found (`locate`), the content of locate.json: the nodes measured
    and those it may force (`chromosome_nodes`), the objective's air (`output_node`, `objective`
    its zones, `output_nodes`), J unforced and with `best_nodes` forced (`J_best`, None: the
    simulation failed), each node's score forced alone (`node_scores`, by str(id)), the nodes
    that lower J alone (`ranked_nodes`, lowest first) and the groups the noise cannot separate
    (`tied_nodes`), how the search ran (`search`), the noise it judged by, the evidence per
    component (`components`, `evidence`) and the `finding` in words. `to_json()` is locate.json,
    `read(path)` reads one back, `summary()` is what `nodeforce locate` prints."""
    measured_nodes: list
    output_node: int
    objective: list
    output_nodes: list
    chromosome_nodes: list
    J_unforced: float | None
    best_nodes: list
    J_best: float | None
    node_scores: dict
    ranked_nodes: list
    tied_nodes: list
    search: dict
    noise: dict
    components: list
    finding: str

    def summary(self):
        """A short table of the single-node scores (the paper's Table 4) and the answer."""
        lines = [f"J unforced: {self.J_unforced:.3f} C2 on the air of {', '.join(self.objective)}"]
        # every node scored, most helpful first (the ranked ones, then those that lower nothing)
        scores = self.node_scores
        order = [str(n) for n in self.ranked_nodes]
        order += sorted((n for n in scores if n not in order), key=lambda n: (scores[n] is None, scores[n]))
        # nodes the noise cannot separate share a tie mark (a, b, ...): ranked by J, not reordered
        tied = {str(n): chr(ord("a") + k) for k, group in enumerate(self.tied_nodes or []) for n in group}
        if order:
            lines.append(f"{'node':>6}{'J forced alone':>16}  tie")
            lines += [f"{node:>6}{'failed' if scores[node] is None else format(scores[node], '.3f'):>16}  "
                      f"{tied.get(node, '')}".rstrip() for node in order[:8]]
        found = ", ".join(map(str, self.best_nodes)) or "none"
        search = self.search
        how = ("nothing to force" if search["method"] == "none" else
               f"{search['method']} search, {search['unique_evaluations']} simulations in {search['seconds']:.1f} s")
        lines.append(f"best nodes: {found} (J = {self.J_best:.3f}); {how}")
        lines.append(self.finding)
        return "\n".join(lines)


def locate(building, case, workdir, objective, *, search=SearchSettings(), execution=Execution(),
           source="measurements", protocols=None):
    """Run the forcing search on a case; return its `Localization` (locate.json's content).

    `case` may be the Cases of several records of the building: J is then the sum of each
    record's J, a forcing applied to every record (`ga.fitness.RecordsFitness`), and `protocols`
    gives, per record, the building it runs under when that is not `building` (another
    protocol's flows and blinds; None: `building`), each with its own FMU.
    The FMUs (`model.fmu` of `building` where a record runs it, `model_<k>.fmu` of the k-th
    record's own building) and the search's
    checkpoint (`locate.checkpoint.json`) are written in
    `workdir`, so a run stopped midway and started again resumes. `search`
    (`ga.search.SearchSettings`): the GA's settings (its defaults stop at convergence;
    `SearchSettings.paper()` gives the paper's search), the nodes it may force
    (`chromosome_nodes`), the FMUs it drives (`fmu_kind`: "python", "standalone", or "auto",
    `evaluator_kind`, the command line's default and this one's, each with "-fmi3" for FMI 3.0),
    the warm-up days and `noise`, the air sensors' noise sd (C) if the user knows it, else it is
    estimated (`model.score.Noise`) from every record's air. `execution` (`ga.search.Execution`):
    where the search runs (`workers`, `scheduler`) and its `progress`, called after every
    generation with (generation, total, best J, unique evaluations); its `fmu_kind` is not read.
    `source`: what an error about the measurements names.
    """
    cases = as_cases(case)
    protocols = list(protocols) if protocols is not None else [None] * len(cases)
    candidates = chromosome_nodes(building, cases, objective, source,
                                  None if search.nodes is None else list(search.nodes), search.include_algebraic)
    kind = evaluator_kind(search.fmu_kind, [building, *filter(None, protocols)])
    # one FMU per building a record runs under: `building`'s only where a record runs it
    names = ["model.fmu" if own is None else f"model_{k + 1}.fmu" for k, own in enumerate(protocols)]
    built = {}
    for name, own in zip(names, protocols):
        if name not in built:
            built[name] = build_fmu(own or building, workdir / name, kind=kind)
    fmus = [built[name] for name in names]
    parts = [FmuFitness(path, c, candidates, objective, search.warmup_days) for path, c in zip(fmus, cases)]
    fitness = parts[0] if len(parts) == 1 else RecordsFitness(parts)
    measured = [objective.measured(c) for c in cases]
    noise = Noise.of_records(measured, search.noise)
    measured_ids = sorted(set().union(*(c.measured_ids for c in cases)))
    if not candidates:
        return Localization.of(nothing_to_force(building, measured_ids, objective, fitness, noise))
    result = run_search(fitness, candidates, search, execution, checkpoint=workdir / CHECKPOINT,
                        noise_sigma=noise.sigma, n_residuals=int(sum(np.isfinite(m).sum() for m in measured)))
    result = {"measured_nodes": measured_ids, "output_node": objective.air_nodes[0],
              "objective": list(objective.zones), "output_nodes": list(objective.air_nodes), **result,
              "noise": noise.to_json()}
    result["components"] = evidence(building, result)
    return Localization.of({**result, "finding": finding(building, result)})


def evidence(building, result):
    """The forcing evidence per component: the share of J above the noise that forcing its
    best-scoring measured node alone removes (`model.score.removed`), most first. A diagnosis
    calibrates the effects of the components it ranks highest, whether or not a fault is
    located (`diagnosis.candidates.physical`).

    Returns [{"component", "node", "J", "share"}]; components without a node the search forced
    are absent."""
    J_unforced, J_noise = result["J_unforced"], result["search"]["J_noise"] or 0.0
    scores = {int(i): J for i, J in result["node_scores"].items() if J is not None}
    out = []
    for c in building.components:
        scored = [i for i in c.node_ids if i in scores]
        if scored:
            node = min(scored, key=lambda i: (scores[i], i))
            out.append({"component": c.name, "node": node, "J": scores[node],
                        "share": removed(J_unforced, scores[node], J_noise)})
    return sorted(out, key=lambda e: (e["J"], e["component"]))


def nothing_to_force(building, measured_ids, objective, fitness, noise):
    """locate.json of a record with no measured node but the objective's air (a thermostat's
    record): J unforced, `best_nodes` [], and a finding that says no forcing can be tested and
    which sensors would let it."""
    start = time.perf_counter()
    evaluator = fitness()
    try:
        J = evaluator.J([])
    finally:
        evaluator.close()
    facing = sorted((c for c in building.components if c.inside.zone in objective.zones), key=lambda c: -c.area)
    largest = ", ".join(f"{c.name} (node {c.node_ids[0]})" for c in facing[:3])
    said = ("No forcing can be tested: no node besides the objective's air is measured, so the search has "
            "nothing to force and every effect is left to the diagnosis of the air's own equation; a "
            "temperature measured on the inside surface of a component facing the objective's air"
            + (f" (the largest: {largest})" if largest else "")
            + ", or inside one, would let the search test that component's sub-model.")
    return {"measured_nodes": measured_ids, "chromosome_nodes": [], "output_node": objective.air_nodes[0],
            "objective": list(objective.zones), "output_nodes": list(objective.air_nodes),
            "J_unforced": J, "best_nodes": [], "J_best": J, "node_scores": {}, "ranked_nodes": [],
            "tied_nodes": [], "components": [],
            "search": {"method": "none", "evaluations": 1, "unique_evaluations": 1,
                       "seconds": time.perf_counter() - start},
            "noise": noise.to_json(), "finding": said}


def finding(building, result):
    """What the search found, in the words its numbers allow: which share of the error above the
    noise the best forcing removes, against the share needed to call it the fault, and which
    components the sensors let the search test at all (a fault elsewhere cannot be located)."""
    names = building.node_names()
    J_unforced, J_noise = result["J_unforced"], result["search"]["J_noise"]

    def forcing(nodes):
        return "forcing " + ", ".join(f"node {i} ({names[i]})" for i in nodes)

    of = "of J" if not J_noise else "of J above the noise floor"
    best, strongest = result["best_nodes"], result["search"]["min_nodes"]
    if best:
        share = removed(J_unforced, result["J_best"], J_noise)
        said = f"{forcing(best)} removes {share:.0%} {of}: the fault is in the sub-model behind it."
        # a single node that removes more, which the parsimony rule could not tell from it
        # (the nearer the zone was preferred), is named: the numbers say both
        first = (result["ranked_nodes"] or [None])[0]
        if first is not None and first not in best and result["node_scores"][str(first)] < result["J_best"]:
            more = removed(J_unforced, result["node_scores"][str(first)], J_noise)
            said = said[:-1] + (f"; {forcing([first])} alone removes more ({more:.0%}), by a margin the data "
                                "cannot tell from the noise, and the nearer the zone is preferred.")
    elif strongest and result["ranked_nodes"]:
        share = removed(J_unforced, result["search"]["J_min"], J_noise)
        first = result["ranked_nodes"][0]
        alone = removed(J_unforced, result["node_scores"][str(first)], J_noise)
        # the rule that decided: too small a share of the error (ga.parsimony.explains), or a fall
        # of J the noise could make (smallest_subset keeps no node)
        why = (f"below the {1 - EXPLAINED:.0%} needed to call it the fault" if not result["search"]["explains"]
               else f"but its fall of J, {J_unforced - result['search']['J_min']:.3g} C2, is within the "
                    f"{result['search']['tolerance']:.3g} C2 the noise could make")
        said = (f"No forcing locates the fault: the best, {forcing(strongest)}, removes {share:.0%} {of}, "
                f"{why}; {forcing([first])} alone removes {alone:.0%}.")
    else:
        said = "No forcing lowers J by more than the noise tolerance."
    tested = [c.name for c in building.components if set(c.node_ids) & set(result["chromosome_nodes"])]
    if len(tested) < len(building.components):
        said += (f" Only {len(tested)} of the {len(building.components)} components have a measured node the search "
                 f"may force ({', '.join(tested) or 'none'}): a fault in another, or in the air's own equation, "
                 "cannot be located by forcing.")
    return said
