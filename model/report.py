"""Writing results: node temperature tables."""
import pandas as pd


def write_node_temperatures(path, times, T):
    """CSV with `time` (ISO 8601 with offset) and `T1..TN` (C), one row per time."""
    frame = pd.DataFrame(T, columns=[f"T{i}" for i in range(1, T.shape[1] + 1)])
    frame.insert(0, "time", [t.isoformat() for t in times])
    frame.to_csv(path, index=False)
