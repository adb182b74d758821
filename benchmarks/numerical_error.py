"""The building file's own numerical error on benchmark records: the objective air simulated from
the file as written and from the file with every stretch between two of its nodes or layer
boundaries cut into 2 and 4 cells (`records.refined`), over the record's calibration window (its
first 60 % after the burn-in), with the history the diagnosis reads.

The refined files converge on what the file's walls discretise; their difference from the file
is a lower bound of the error no correction of the building's physics should be fitted to, to set
beside the sensors' noise (docs/benchmark_diagnosis.md, "What is left").

    python benchmarks/numerical_error.py sdp-jul/none mia-jun/none
"""
import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.catalogue import CALIBRATION_FRACTION, SPECS_BY_NAME  # noqa: E402
from benchmarks.records import record  # noqa: E402
from nodeforce.model.numerical import refined  # noqa: E402

CELLS = (2, 4)


def air_on_calibration(building, r, air):
    """(n,) the air node's temperature (C) simulated from `building` on record `r`'s calibration window."""
    case = r.case(building=building)
    T = case.run(building, [air - 1])[case.burn_in_steps:, 0]
    return T[:int(round(CALIBRATION_FRACTION * len(T)))]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("records", nargs="+", help="record names, e.g. sdp-jul/none (see bench_diagnosis.py --list)")
    args = p.parse_args(argv)
    unknown = [name for name in args.records if name not in SPECS_BY_NAME]
    if unknown:
        p.error(f"no such record: {', '.join(unknown)}")
    print("| record | noise (C) | " + " | ".join(f"file x{c} - file, RMS (C)" for c in CELLS)
          + f" | (noise^2 + RMS x{CELLS[-1]}^2) / noise^2 |")
    print("|---|---|" + "---|" * (len(CELLS) + 1))
    for name in args.records:
        r = record(name, 0)
        zone = r.building.zone(r.spec.objective) if r.spec.objective else r.building.zones[0]
        file = air_on_calibration(r.building, r, zone.air_node)
        rms = [float(np.sqrt(np.mean((air_on_calibration(refined(r.building, c), r, zone.air_node) - file) ** 2)))
               for c in CELLS]
        ratio = (r.spec.noise ** 2 + rms[-1] ** 2) / r.spec.noise ** 2
        print(f"| {name} | {r.spec.noise:g} | " + " | ".join(f"{x:.3f}" for x in rms) + f" | {ratio:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
