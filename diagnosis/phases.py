"""Each model's error phase by phase (heated at a set point, heat pulses, free float...).

A record mixes regimes that test different parts of a model: where the air is held at a set
point the information is in the heat input, where it floats the air is a real model output. A
candidate's total can improve while one phase gets worse, which the total hides; the report
shows every phase and flags an added effect that makes one worse.
"""
import numpy as np

from nodeforce.model.score import metrics

# A phase is made worse when its RMSE rises by this fraction or more.
WORSE = 0.05


def phase_errors(phases, times, measured, runs, zones=(), apart=("before", "after")):
    """The RMSE (C) of every run on every phase, over the scored steps the phase holds, and of
    the runs `apart` in each zone where the objective has several (`zones`, the columns' names):
    a house's total can hide a room made worse.

    Parameters
    ----------
    phases : iotools.phases.Phase records
    times : DatetimeIndex of the rows of `measured` and of each run
    measured : (N_t, n_zones) measured air of the objective (C), NaN where not scored
    runs : {label: (N_t, n_zones) simulated air (C)}

    zones : names of the columns of `measured`; apart : the labels of `runs` given per zone

    Returns
    -------
    [{"phase", "start", "end", "n", "rmse": {label: C, or None where the phase holds no scored
    step}, and with several zones "zones": {zone: {label of `apart`: C or None}}}]
    """
    rows = []
    for phase in phases:
        inside = np.asarray(phase.mask(times))
        n = int(np.isfinite(measured[inside]).sum())
        rows.append({"phase": phase.name, "start": phase.start.isoformat(),
                     "end": phase.end.isoformat() if phase.end is not None else None, "n": n,
                     "rmse": {label: metrics(measured[inside], run[inside])["rmse"] if n else None
                              for label, run in runs.items()}})
        if len(zones) > 1:
            rows[-1]["zones"] = {
                zone: {label: metrics(measured[inside, j:j + 1], runs[label][inside, j:j + 1])["rmse"]
                       if np.isfinite(measured[inside, j]).any() else None for label in apart if label in runs}
                for j, zone in enumerate(zones)}
    return rows


def is_worse(before, after):
    """Whether an RMSE (C) went from `before` to `after` by a rise of WORSE or more; False where
    either is unknown (a phase without a scored step)."""
    return before is not None and after is not None and after >= (1 + WORSE) * before


def worsened(rows, before, after):
    """The phases whose RMSE rises by WORSE or more from run `before` to run `after`."""
    return [{"phase": row["phase"], "before": row["rmse"][before], "after": row["rmse"][after]}
            for row in rows if is_worse(row["rmse"][before], row["rmse"][after])]
