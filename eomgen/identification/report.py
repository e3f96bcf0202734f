"""The identification report: a Markdown table, the estimates as CSV, and a plot of predicted
against measured efforts (PNG, byte-identical for identical input)."""

from __future__ import annotations

import csv
import io
import warnings
from dataclasses import dataclass

import numpy as np

from ..common.output import GeneratedFile
from .fit import Estimate, PhysicalFit
from .measurements import Measurements

#: rcParams applied on top of matplotlib's defaults while drawing and saving (as
#: eomgen.teach.sketch does), so the PNG does not depend on the user's configuration.
RC = {"font.size": 8.0, "font.family": "DejaVu Sans", "savefig.dpi": 100,
      "savefig.bbox": None, "path.simplify": False}


@dataclass(frozen=True)
class IdentificationReport:
    """Everything the report shows.

    Attributes
    ----------
    robot : str
    source : str
        The data file.
    names, expressions : tuple of str, (b,)
        Base parameter names and β(π) as text.
    measurements : Measurements
    estimate : Estimate
    physical : PhysicalFit or None
    reference : (b,) array or None
        β of the description's own parameters, when they all have values.
    """

    robot: str
    source: str
    names: tuple[str, ...]
    expressions: tuple[str, ...]
    measurements: Measurements
    estimate: Estimate
    physical: PhysicalFit | None = None
    reference: np.ndarray | None = None

    def markdown(self, plot: str | None = None) -> str:
        m, e = self.measurements, self.estimate
        n = len(m.joint_names)
        lines = [f"# Identification of {self.robot} from {self.source}", "",
                 f"{m.N} samples × {n} joints = {m.N * n} equations, {len(self.names)} base "
                 "parameters; weighted least squares (Gautier: joint j's rows weighted by 1/σ_j)"
                 + (f"; q̇, q̈ by zero-phase filtered differentiation of q (cut-off "
                    f"{m.cutoff:.4g} Hz)" if m.differentiated else
                    f"; q, q̇, q̈, τ zero-phase low-pass filtered at {m.cutoff:.4g} Hz"
                    if m.cutoff is not None else "") + ".", "",
                 f"Condition number of the column-normalised observation matrix: "
                 f"{e.condition:.4g}", ""]
        head = ["#", "parameter", "β(π)", "estimate", "std", "std %"]
        if self.reference is not None:
            head += ["description", "|Δ|/std"]
        if self.physical is not None:
            head += ["physical fit"]
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for k, name in enumerate(self.names):
            row = [str(k + 1), name, f"`{self.expressions[k]}`", f"{e.beta[k]:.6g}",
                   f"{e.std[k]:.3g}", f"{e.relative_std[k]:.3g}"]
            if self.reference is not None:
                z = abs(e.beta[k] - self.reference[k]) / e.std[k] if e.std[k] > 0 else np.inf
                row += [f"{self.reference[k]:.6g}", f"{z:.2f}"]
            if self.physical is not None:
                row += [f"{self.physical.beta[k]:.6g}"]
            lines.append("| " + " | ".join(row) + " |")
        lines += ["", "| joint | σ_j | residual RMS"
                  + (" | residual RMS, physical fit | min eig of its body's pseudo-inertia J |"
                     if self.physical is not None else " |"),
                  "|---|---|---|" + ("---|---|" if self.physical is not None else "")]
        for j, joint in enumerate(m.joint_names):
            row = [joint, f"{e.sigma[j]:.3g}", f"{e.rms[j]:.3g}"]
            if self.physical is not None:
                row += [f"{self.physical.rms[j]:.3g}", f"{self.physical.min_eigenvalues[j]:.3g}"]
            lines.append("| " + " | ".join(row) + " |")
        if plot:
            lines += ["", f"![predicted against measured efforts]({plot})"]
        return "\n".join(lines) + "\n"

    def csv(self) -> str:
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\n")
        head = ["name", "expression", "estimate", "std", "relative_std_percent"]
        head += ["description"] if self.reference is not None else []
        head += ["physical"] if self.physical is not None else []
        writer.writerow(head)
        e = self.estimate
        for k, name in enumerate(self.names):
            row = [name, self.expressions[k], repr(float(e.beta[k])), repr(float(e.std[k])),
                   repr(float(e.relative_std[k]))]
            row += [repr(float(self.reference[k]))] if self.reference is not None else []
            row += [repr(float(self.physical.beta[k]))] if self.physical is not None else []
            writer.writerow(row)
        return out.getvalue()

    def png(self) -> bytes:
        """Measured and predicted effort of every joint against time (or sample index)."""
        # matplotlib: an optional dependency (eomgen[analysis]), needed only for the plot
        import matplotlib
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        m, e = self.measurements, self.estimate
        n = len(m.joint_names)
        x = m.t if m.t is not None else np.arange(m.N)
        with matplotlib.rc_context():
            matplotlib.rcdefaults()
            matplotlib.rcParams.update(RC)
            fig = Figure(figsize=(7.0, 1.4 * n + 0.8))
            FigureCanvasAgg(fig)
            axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
            for j, ax in enumerate(axes):
                ax.plot(x, m.tau[:, j], color="0.6", lw=1.2, label="measured")
                ax.plot(x, e.predicted[:, j], color="C0", lw=0.8, label="weighted LS")
                if self.physical is not None:
                    ax.plot(x, self.physical.predicted[:, j], color="C3", lw=0.8, ls="--",
                            label="physical fit")
                ax.set_ylabel(f"τ {m.joint_names[j]}")
            axes[0].legend(loc="upper right", ncol=3, fontsize=7)
            axes[-1].set_xlabel("t [s]" if m.t is not None else "sample")
            fig.suptitle(f"{self.robot}: predicted against measured efforts")
            fig.tight_layout()
            out = io.BytesIO()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                fig.savefig(out, format="png", metadata={})
        return out.getvalue()

    def files(self, stem: str) -> list[GeneratedFile]:
        """``<stem>.md``, ``<stem>.csv`` (the estimates) and ``<stem>.png``."""
        png = f"{stem}.png"
        return [GeneratedFile(f"{stem}.md", self.markdown(png)),
                GeneratedFile(f"{stem}.csv", self.csv()),
                GeneratedFile(png, self.png())]
