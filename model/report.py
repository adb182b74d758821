"""Writing results: node temperature tables and the names of their nodes."""
from pathlib import Path

import pandas as pd


def write_node_temperatures(path, times, T):
    """CSV with `time` (ISO 8601 with offset) and `T1..TN` (C), one row per time; its folder is
    made if absent, as the other commands make their output folders."""
    frame = pd.DataFrame(T, columns=[f"T{i}" for i in range(1, T.shape[1] + 1)])
    frame.insert(0, "time", [t.isoformat() for t in times])
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    frame.to_csv(path, index=False)


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
