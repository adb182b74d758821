"""The docs' benchmark pages, made from the latest results (`benchmarks.results`):

    python benchmarks/pages.py

docs/benchmark_diagnosis.md is made whole from the latest `diagnosis` run (`bench_diagnosis.page`).
docs/performance.md is written by hand but for its figures: each block between
`<!-- results BENCHMARK PART -->` and `<!-- /results -->` is the latest BENCHMARK run's PART tables,
or its run line for PART `run`.
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks import results  # noqa: E402

DOCS = ROOT / "docs"
BLOCK = re.compile(r"(<!-- results (\w+) (\w+) -->\n)(.*?)(<!-- /results -->)", re.S)


def filled(text, folder=results.RESULTS):
    """`text` with each results block made from the latest run it names."""
    def block(match):
        run = results.latest(match.group(2), folder)
        if run is None:
            raise SystemExit(f"benchmarks/results: no {match.group(2)} run to make the docs from")
        lines = [results.run_line(run)] if match.group(3) == "run" else run[match.group(3)]["tables"]
        return match.group(1) + "\n".join(lines) + "\n" + match.group(5)
    return BLOCK.sub(block, text)


def pages(folder=results.RESULTS):
    """{path: the page's text} of every page made from results."""
    from benchmarks.bench_diagnosis import page
    performance = DOCS / "performance.md"
    return {DOCS / "benchmark_diagnosis.md": page(results.latest("diagnosis", folder)),
            performance: filled(performance.read_text(), folder)}


def main():
    for path, text in pages().items():
        path.write_text(text)
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
