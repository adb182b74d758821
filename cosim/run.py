"""Simulate a measured case through the FMU, warm-up included (docs/model.md section 5).

The FMU knows one step; the warm-up, the initial measurements and the forcing mask are the
driver's, and follow the same rules as `model.integrate.simulate`, so both give the same numbers.
The driver speaks FMI's co-simulation semantics: before the step from t it sets the inputs at t
and, through the input derivatives, their slope over the step (the direct model's inputs are
linear between samples, a heat input held at the power of the interval); the FMU's `max_step`
makes one doStep the direct model's k sub-steps of a sample, or its one long step over a history.
"""
import numpy as np
import pandas as pd

from nodeforce.model.integrate import (STEADY_STEP, forcing_schedule, held_inputs, history_block, history_inputs,
                                       steady_inputs, step_start, warmup_rows)


def node_names(prefix, ids):
    return [f"{prefix}[{i}]" for i in ids]


def input_table(case, force=None, T_default=20.0):
    """The FMU's inputs over a case, as an importer sets them, and its start values.

    Row n holds what is set before the step from t_n (FMI's co-simulation semantics), in time
    from t_0 (s): the weather and every other sampled input at t_n (linear between rows: give
    FMPy `set_input_derivatives=True`); a zone's heat input, held over each step, the power of the
    interval that starts at t_n, which the record logs at t_n+1 (`integrate.held_inputs`), NaN in
    the last row (no step starts there); `T_forced[i]` of every node: for a node forced over the
    step from t_n (a node of the `force` mask, and every node over the case's burn-in) its
    measurement at t_n (NaN where missing), NaN elsewhere; a discrete input, held over the step,
    never interpolated.

    Parameters
    ----------
    case : model.case.Case without a history (`history_steps` 0): an importer starts at t_0
    force : (N,) bool, nodes forced to their measurements for the whole record; None: none
    T_default : C, the start of a node nothing informs

    Returns
    -------
    (DataFrame indexed by `time` (s from t_0), one column per FMU input variable;
     {name: value} of the start values: `T_start[i]` of every node, `force[i]` true for the forced)
    """
    if case.history_steps:
        raise ValueError("an input table starts at the first measurement: make the case without a history")
    measured = case.measured
    n_rows, n = measured.shape
    # the nodes forced over the step from each row: the mask's, and over the burn-in's steps (to
    # rows 1..B) every node; each at its sample, which the importer holds (NaN: computed)
    member = np.zeros((n_rows, n), dtype=bool) if force is None else np.tile(np.asarray(force, dtype=bool), (n_rows, 1))
    member[:case.burn_in_steps] = True
    T_forced = np.where(member, measured, np.nan)
    forced_ids = [int(i) + 1 for i in np.flatnonzero(np.isfinite(T_forced[:-1]).any(axis=0))]
    held = held_inputs(case.building, case.input_names)
    U = np.where(held, np.vstack([case.U[1:], np.full((1, len(held)), np.nan)]), case.U)
    columns = {**dict(zip(case.input_names, U.T)), **{f"T_forced[{i}]": T_forced[:, i - 1] for i in range(1, n + 1)}}
    seconds = (case.times - case.times[0]).total_seconds().to_numpy()
    table = pd.DataFrame(columns, index=pd.Index(seconds, name="time"))
    start = case.start_state(T_default)
    values = {**{f"T_start[{i}]": float(start[i - 1]) for i in range(1, len(start) + 1)},
              **{f"force[{i}]": True for i in forced_ids}}
    return table, values


def simulate_fmu(instance, case, force=None, warmup_days=2, output_ids=None, T_default=20.0,
                 parameters=None):
    """Node temperatures (C) at t_1..t_N, simulated by an `FmuInstance` of the case's building.

    Parameters
    ----------
    instance : cosim.fmi.FmuInstance
    case : model.case.Case (inputs and measurements on the simulation grid) of the FMU's building
    force : (N,) bool, nodes forced to their measurements; None: no forcing (the case's burn-in
        forces every measured node over its first steps all the same)
    warmup_days : passes over the first day before the run
    output_ids : node ids to return (default: all)
    T_default : C, the initial temperature of a node nothing informs
    parameters : {name: value} of other FMU parameters (an added effect's `<effect>.<name>`)

    Returns
    -------
    (N_t, len(output_ids)) ndarray
    """
    return CaseRuns(case, warmup_days, T_default).simulate(instance, force, output_ids, parameters)


class CaseRuns:
    """What every run of a case through an FMU sets whatever it forces (`simulate_fmu`): the
    start state, the input row of every step (warm-up, history), the inputs' starts and slopes,
    the measured nodes' starts; made once where a case is run under many forcings (the search's
    evaluator)."""

    def __init__(self, case, warmup_days=2, T_default=20.0):
        self.case = case
        n_rows = len(case.measured)
        # the state at t_0 is the FMU's T_start: the measured nodes at their value, the others by
        # the rule of the direct model (model.integrate.initial_state)
        self.start = case.start_state(T_default)
        H = case.history_steps  # a history stands in for the warm-up, in steps of its own (integrate.simulate)
        self.rows = H + warmup_rows(n_rows - H, case.dt, 0 if H else warmup_days)
        # the step to each row r starts from step_start's row r with the slope to row r (the
        # direct model's within_steps)
        u_start = step_start(case.U, held_inputs(case.building, case.input_names))
        self.u_inputs, self.u_slopes = u_start[self.rows], (case.U[self.rows] - u_start[self.rows]) / case.dt
        self.m_start = step_start(case.measured)
        self.sub_step = np.full((len(self.rows), 1), case.dt / case.substeps)
        self.block = history_block(case.dt)
        self.coarse = history_inputs(case.U, H, case.dt) if H else None
        self.returned = n_rows - 1 - H  # the steps after the history and the warm-up: their outputs are read

    def simulate(self, instance, force=None, output_ids=None, parameters=None):
        """`simulate_fmu` of the case with `force`, `output_ids` and `parameters`."""
        case, rows = self.case, self.rows
        measured = case.measured
        n = measured.shape[1]
        # The FMU forces node i where force[i] is set and T_forced[i] is a number: the schedule's
        # nodes get force[i], and T_forced[i] is NaN at the steps the schedule leaves them computed.
        schedule = forcing_schedule(np.zeros(n, dtype=bool) if force is None else force, measured,
                                    case.burn_in_steps)
        forced_ids = [i + 1 for i in np.flatnonzero(schedule[1:].any(axis=0))]
        output_ids = list(range(1, n + 1)) if output_ids is None else list(output_ids)
        parameters = {**dict(zip(node_names("T_start", range(1, len(self.start) + 1)), self.start.tolist())),
                      **{name: True for name in node_names("force", forced_ids)}, **(parameters or {})}
        columns = np.array(forced_ids, dtype=int) - 1
        # T_forced NaN (slope 0) where the schedule leaves a node computed
        imposed = schedule[:, columns]
        m_start = np.where(imposed, self.m_start[:, columns], np.nan)
        m_slope = np.where(imposed, measured[:, columns] - m_start, 0.0)
        inputs = np.hstack([self.u_inputs, m_start[rows], self.sub_step])
        slopes = np.hstack([self.u_slopes, m_slope[rows] / case.dt])
        steps = np.full(len(inputs), case.dt)
        if self.coarse is not None:
            coarse = self.coarse
            inputs = np.vstack([np.hstack([coarse, np.full((len(coarse), len(columns)), np.nan),
                                           np.full((len(coarse), 1), self.block * case.dt)]), inputs])
            slopes = np.vstack([np.zeros((len(coarse), slopes.shape[1])), slopes])
            steps = np.concatenate([np.full(len(coarse), self.block * case.dt), steps])
        if case.steady_start:
            u, held_nodes, values = steady_inputs(case.U, measured, schedule, case.dt)
            inputs = np.vstack([np.concatenate([u, np.where(held_nodes[columns], values[columns], np.nan),
                                                [STEADY_STEP]]), inputs])
            slopes = np.vstack([np.zeros((1, slopes.shape[1])), slopes])
            steps = np.concatenate([[STEADY_STEP], steps])
        history = case.history_steps // self.block
        names = list(case.input_names) + node_names("T_forced", forced_ids)
        out = instance.run(steps, parameters, {}, names + ["max_step"], inputs, node_names("T", output_ids),
                           skip=len(inputs) - self.returned - history,
                           slopes=np.nan_to_num(slopes, nan=0.0))
        # a history's rows hold each of its steps' end state, as the direct model's do
        return np.vstack([np.repeat(out[:history], self.block, axis=0), out[history:]])
