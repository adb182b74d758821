"""`make bestest`: the ASHRAE 140 free-float cases converted by `nodeforce convert`, simulated by
`nodeforce simulate` over the standard's Denver year at 10-min steps (`STEP`), their hourly zone
air (each hour the mean of its six steps, as EnergyPlus reports an hour) its minimum, maximum
and mean beside the reference programs' range (ASHRAE 140-2020, Tables B8-5a, b, c).

    python examples/bestest/run.py OUT [WEATHER]    writes OUT/results.csv, OUT/bestest.png

WEATHER is the standard's Denver weather, by default the copy the repository carries
(examples/bestest/data/725650TYCST.epw, NREL's, with its README and licence), read as EnergyPlus
reads a typical year: its months in one calendar year, 2017 (`--year`).
"""
import subprocess
import sys
from pathlib import Path

import matplotlib
import pandas as pd

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
import cases  # noqa: E402

BIN = Path(sys.executable).parent
WEATHER = Path(__file__).parent / "data" / "725650TYCST.epw"
YEAR = 2017
STEP = 600  # s: the steps an hour's mean is taken of; on a 30-min grid 650FF's mean was 0.1 K warmer
# ASHRAE 140-2020 Tables B8-5a, b, c: the range of the six reference programs, C, given to 0.1 K:
# a figure is in it where it rounds into it (`in_range`)
REFERENCE = {
    "600FF": {"min": (-13.8, -9.9), "max": (62.4, 68.4), "mean": (24.3, 26.1)},
    "900FF": {"min": (0.6, 2.2), "max": (43.3, 46.0), "mean": (24.5, 25.7)},
    "650FF": {"min": (-17.8, -16.7), "max": (61.1, 66.8), "mean": (17.6, 18.9)},
    "950FF": {"min": (-13.4, -12.5), "max": (36.1, 37.1), "mean": (14.3, 15.0)},
    "680FF": {"min": (-8.1, -5.7), "max": (69.8, 78.5), "mean": (30.2, 33.3)},
    "980FF": {"min": (7.3, 12.5), "max": (48.5, 52.8), "mean": (30.5, 33.3)},
}
WEEKS = {"winter week": ("2017-01-02", "2017-01-09"), "summer week": ("2017-07-10", "2017-07-17")}


def in_range(value, low, high):
    """Whether `value` (C) is within the reference range at the tables' precision (0.1 K)."""
    return low <= round(value, 1) <= high


def run(*args):
    subprocess.run([str(BIN / "nodeforce"), *map(str, args)], check=True, stdout=subprocess.DEVNULL)


def zone_air(sim):
    """The hourly air temperature (C) of the zone of a one-zone simulation (its `<zone> air` node):
    each hour the mean of the steps that end in it."""
    names = pd.read_csv(sim.with_suffix(".nodes.csv"))
    column = names[names.iloc[:, 2].str.endswith(" air")].iloc[0, 0]
    return hourly(pd.read_csv(sim, index_col=0, parse_dates=True)[column])


def hourly(T):
    """Each hour's mean of the states `T` at the ends of the steps in it (the hour ending 01:00
    holds those after 00:00 up to 01:00)."""
    return T.groupby(T.index.ceil("h")).mean()


def main(out, weather=WEATHER):
    out = Path(out)
    cases.main(out)
    air, rows = {}, []
    for k, name in enumerate(cases.CASES, start=1):
        print(f"[{k}/{len(cases.CASES)}] {name}: nodeforce convert, nodeforce simulate over the year", flush=True)
        run("convert", out / f"{name}.idf", "-o", out / f"{name}.json")
        run("simulate", out / f"{name}.json", "--weather", weather, "--year", YEAR, "--step", STEP,
            "-o", out / f"{name}_sim.csv")
        air[name] = zone_air(out / f"{name}_sim.csv")
        rows.append({"case": name, "min": air[name].min(), "max": air[name].max(), "mean": air[name].mean()})
    results = pd.DataFrame(rows)
    results.to_csv(out / "results.csv", index=False, float_format="%.2f")
    print(f"{'case':6} {'min':>7} {'range':>15} {'max':>7} {'range':>13} {'mean':>7} {'range':>13}")
    for r in rows:
        ref = REFERENCE[r["case"]]
        cells = []
        for key in ("min", "max", "mean"):
            low, high = ref[key]
            mark = " " if in_range(r[key], low, high) else "*"
            cells.append(f"{r[key]:7.2f}{mark} {low:6.1f}..{high:<6.1f}")
        print(f"{r['case']:6} " + " ".join(cells))
    print("* outside the reference range at its precision, 0.1 K")
    plot(air, out / "bestest.png")
    print(f"wrote {out / 'results.csv'}, {out / 'bestest.png'}")


def plot(air, path):
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    for ax, (title, (start, end)) in zip(axes, WEEKS.items()):
        for name, T in air.items():
            T[start:end].plot(ax=ax, label=name)
        ax.set_title(f"{title} (hourly zone air)")
        ax.set_ylabel("C")
        ax.legend()
    for name, T in air.items():
        axes[2].hist(T, bins=60, histtype="step", label=name)
    axes[2].set_title("annual distribution of the hourly zone air")
    axes[2].set_xlabel("C")
    axes[2].set_ylabel("hours")
    axes[2].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit(print("usage: python examples/bestest/run.py OUT [WEATHER]", file=sys.stderr) or 2)
    weather = Path(sys.argv[2]) if len(sys.argv) == 3 and sys.argv[2] else WEATHER
    if not weather.is_file():
        sys.exit(print(f"{weather}: file: no such weather file (ASHRAE 140's 725650TYCST.epw)", file=sys.stderr) or 2)
    main(sys.argv[1], weather)
