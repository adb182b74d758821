"""The diagnosis report, split by what it produces: `summary` (the first screen of report.md and
of the terminal, and the Decision's refusals grouped by reason), `tables` (the before/after table
and report.md's tables), `figures` (the PNG plots), `markdown` (report.md).

It reads report.json's content and the simulated series and decides nothing: the loop's
decision, its reason and margins are in report["decision"]. The residual is
r = T_air,measured - T_air,simulated (docs/model.md), so a positive mean means the model
is too cold. The tables follow Lauret et al.: Table 4 (J with each node forced alone) for the
localisation, Table 5 (mean and standard deviation of the residual, before and after the
correction) for the result, with RMSE and n added, per zone of the objective.
"""
from __future__ import annotations

from pathlib import Path

from .figures import draw
from .markdown import write_markdown
from .summary import terminal_summary
from .tables import before_after_table

__all__ = ["before_after_table", "terminal_summary", "write_report"]


def write_report(out_dir, report: dict, series: dict) -> list[Path]:
    """Write report.md and its PNG plots in out_dir; return the plot paths (also to be listed by the caller in report['artifacts']['plots'])."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    plots, notes = draw(out_dir, report or {}, series or {})
    write_markdown(out_dir, report or {}, plots, notes)
    return list(plots.values())
