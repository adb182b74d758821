"""The FMU's input table and start values as files another tool reads (docs/fmu.md).

The table is a CSV whose first column, `time`, is in seconds from the first row and whose other
columns are named after the FMU's input variables: the form FMPy's `simulate_fmu(input=...)`
takes (`fmpy.util.read_csv` reads it). The start values go beside it as JSON, {variable name: value}:
FMPy's `start_values`.
"""
import json
from pathlib import Path


def start_values_path(path):
    """`<stem>.start.json` beside the table `path`."""
    return Path(path).with_suffix(".start.json")


def write_fmu_inputs(path, table, start):
    """Write the table (DataFrame indexed by `time`, s) to `path` and the start values ({name:
    value}) to `start_values_path(path)`; return that path. Numbers are written to the digit
    (repr), NaN as `nan`, which `fmpy.util.read_csv` reads (an empty cell it cannot)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(path, na_rep="nan")
    out = start_values_path(path)
    out.write_text(json.dumps(start, indent=1) + "\n")
    return out


def read_fmu_inputs(path):
    """(table, start values) as `write_fmu_inputs` wrote them."""
    import pandas as pd
    return pd.read_csv(path, index_col="time"), json.loads(start_values_path(path).read_text())
