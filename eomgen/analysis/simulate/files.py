"""The files ``eomgen simulate`` writes: a Markdown report, a CSV of every run and the plot of
wall time against energy drift and trajectory error."""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

from ..report import csv_text, pyplot
from .study import Study


def plot(studies: Sequence[Study], path) -> None:
    """Time against energy drift and against trajectory error, one row per robot (PNG)."""
    plt = pyplot()
    fig, axes = plt.subplots(len(studies), 2, figsize=(11, 3.9 * len(studies)), squeeze=False)
    for row, study in zip(axes, studies):
        families = list(dict.fromkeys(r.integrator for r in study.runs))
        for k, family in enumerate(families):
            runs = [r for r in study.runs if r.integrator == family and r.status == "ok"]
            runs.sort(key=lambda r: r.seconds)
            for ax, value in ((row[0], "relative_energy_drift"), (row[1], "trajectory_error")):
                ys = [max(getattr(r, value), 1e-17) for r in runs]
                ax.plot([r.seconds for r in runs], ys, marker="osD^v<>"[k % 7], color=f"C{k}",
                        label=family, lw=1)
        for ax, title in ((row[0], "energy drift max|E − E0| / energy scale"),
                          (row[1], "trajectory error max‖q − q_ref‖∞ [rad]")):
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("wall time [s]")
            ax.set_title(f"{study.robot}: {title}", fontsize=10)
            ax.grid(True, lw=0.3)
        row[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def write_outputs(studies: Sequence[Study], outdir, stem: str = "simulate") -> list:
    """``<stem>.md``, ``<stem>.csv`` and ``<stem>.png`` in ``outdir``; returns their paths."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    png = outdir / f"{stem}.png"
    plot(studies, png)
    lines = ["# Simulation: time against energy drift and trajectory error", ""]
    for study in studies:
        lines += [f"## {study.robot}", "", study.describe(), "", study.markdown_table(), ""]
    lines += [f"![time against error]({png.name})", ""]
    md = outdir / f"{stem}.md"
    md.write_text("\n".join(lines), encoding="utf-8")
    rows = [row for study in studies for row in study.csv_rows()]
    csv_path = outdir / f"{stem}.csv"
    csv_path.write_text(csv_text(Study.CSV_HEADERS, rows), encoding="utf-8")
    return [md, csv_path, png]


__all__ = ["plot", "write_outputs"]
