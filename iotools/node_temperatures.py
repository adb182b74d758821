"""Writing a simulation's node temperatures (`nodeforce simulate`): the time table and the names
of its nodes."""
from pathlib import Path

import pandas as pd

from .timetable import write_time_table


def write_node_temperatures(path, times, T):
    """CSV time table (`iotools.timetable.write_time_table`) of `T1..TN` (C), one row per time."""
    write_time_table(pd.DataFrame(T, index=times, columns=[f"T{i}" for i in range(1, T.shape[1] + 1)]), path)


def write_node_names(path, building):
    """Beside the table `path`, `<stem>.nodes.csv`: each column `T<id>` with its node's readable
    name ("W9 at 0.340 m", "living air") and the sensors that name it. Returns its path."""
    sensors = {}
    for name, node in building.sensors.items():
        sensors.setdefault(node, []).append(name)
    rows = [{"column": f"T{i}", "node": i, "name": name, "sensors": " ".join(sensors.get(i, []))}
            for i, name in building.node_names().items()]
    out = Path(path).with_suffix(".nodes.csv")
    pd.DataFrame(rows).to_csv(out, index=False)
    return out
