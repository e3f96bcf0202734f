"""``eomgen bench``: time per evaluation against the largest error, for every route.

For a robot, every route of :mod:`eomgen.analysis.routes` evaluates inverse dynamics τ(q, q̇, q̈)
and the mass matrix M(q) on the same sampled states; each result is compared with the
high-precision reference of :mod:`eomgen.analysis.precision` (40 digits, cross-checked by an
mpmath Newton–Euler recursion).

What is measured
----------------
* **Error**: for each state, the normwise relative error ``max|x − x_ref| / max|x_ref|``
  (entries of τ, or of M), the difference taken exactly in mpmath; the table gives the largest
  over the states (and the CSV the median too). A correctly rounded float64 result has error
  ≤ 1.1e-16, float32 ≤ 6e-8.
* **Time per evaluation**: a route is run ``repeats`` times over a set of states (one-state
  routes: the first ``timing_states`` sample states, called one by one; batch routes: the
  samples tiled to ``batch_size`` states, one call); the time of one repeat divided by the number
  of states is one measurement. The table gives the median over repeats and the spread
  (25th–75th percentile). Times include the call overhead (argument checks, conversion of
  results to NumPy arrays) a user pays.
* **Pareto front**: the routes no other route beats in both time and error (errors
  within a factor of :data:`PARETO_TIE` = 2 count as equal: rounding noise).

States: ``q`` uniform in [−π, π], ``q̇`` and ``q̈`` standard normal (seeded). With quaternion
joints (a free flyer, ball joints) ``q`` is the configuration (NQ entries) and each quaternion is
uniform on the unit sphere (:func:`eomgen.model.configuration.random_configuration`); ``q̇``,
``q̈``, τ and M have NV entries.
"""

from __future__ import annotations

import statistics
import tempfile
import time
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable, Protocol

import numpy as np

from ..common.compiler import c_compiler
from ..model import RobotModel
from ..common.progress import plural
from ..model.configuration import random_configuration
from .precision import Reference, relative_error
from .report import csv_text, fmt, markdown_table, pareto_front, pyplot
from .routes import Route, build_routes, numeric_only

#: Largest acceptable disagreement between the two high-precision references.
CROSS_CHECK_LIMIT = 1e-25
#: Errors within this factor count as equal on the Pareto front (see
#: :func:`~eomgen.analysis.report.pareto_front`).
PARETO_TIE = 2.0
QUANTITIES = (("tau", "inverse dynamics τ(q, q̇, q̈)"), ("M", "mass matrix M(q)"))


class Progress(Protocol):
    def update(self, n_steps: int) -> None: ...


class _NoProgress:
    def update(self, n_steps: int) -> None:
        pass


@dataclass(frozen=True)
class Measurement:
    """One route on one quantity."""

    route: str
    dtype: str
    batch: bool
    quantity: str                 # "tau" or "M"
    time_median: float            # seconds per evaluation
    time_q1: float
    time_q3: float
    error_max: float              # normwise relative error, largest over the states
    error_median: float
    note: str = ""
    pareto: bool = False


@dataclass(frozen=True)
class BenchResult:
    robot: str
    dof: int
    samples: int
    batch_size: int
    repeats: int
    cross_check: float
    measurements: tuple[Measurement, ...]
    skipped: tuple[str, ...] = field(default=())

    def rows(self, quantity: str) -> list[Measurement]:
        return sorted((m for m in self.measurements if m.quantity == quantity),
                      key=lambda m: m.time_median)

    # -- output -------------------------------------------------------------------------------

    CSV_HEADERS = ("robot", "quantity", "route", "dtype", "batch", "time_median_s", "time_q1_s",
                   "time_q3_s", "error_max", "error_median", "pareto", "note")

    def csv(self) -> str:
        rows = []
        for quantity, _ in QUANTITIES:
            for m in self.rows(quantity):
                rows.append((self.robot, quantity, m.route, m.dtype, int(m.batch),
                             f"{m.time_median:.4e}", f"{m.time_q1:.4e}", f"{m.time_q3:.4e}",
                             f"{m.error_max:.3e}", f"{m.error_median:.3e}", int(m.pareto),
                             m.note))
        return csv_text(self.CSV_HEADERS, rows)

    def markdown(self, image: str | None = None) -> str:
        lines = [f"# Speed against error: {self.robot} ({plural(self.dof, 'joint')})", "",
                 f"{self.samples} sampled states; batch routes on {self.batch_size} states per "
                 f"call; {self.repeats} repeats. Error: largest normwise relative error against "
                 f"the 40-digit reference (program and mpmath Newton–Euler agree to "
                 f"{fmt(self.cross_check)}). Time: median per evaluation [25th–75th "
                 "percentile]. ★: on the Pareto front (no route both faster and more accurate).",
                 ""]
        for quantity, title in QUANTITIES:
            rows = [(("★ " if m.pareto else "") + m.route, m.dtype, _time(m.time_median),
                     f"{_time(m.time_q1)}–{_time(m.time_q3)}", fmt(m.error_max),
                     fmt(m.error_median)) for m in self.rows(quantity)]
            lines += [f"## {title}", "",
                      markdown_table(["route", "dtype", "time", "spread", "max error",
                                      "median error"], rows, "llrrrr"), ""]
        if self.skipped:
            lines += ["Not measured: " + "; ".join(self.skipped) + ".", ""]
        if image:
            lines += [f"![speed against error]({image})", ""]
        return "\n".join(lines)

    def plot(self, path: Path) -> None:
        """Speed against error, one panel per quantity, Pareto front marked (PNG)."""
        plt = pyplot()
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
        markers = "osD^v<>phX*P"
        names = sorted({m.route for m in self.measurements})
        for ax, (quantity, title) in zip(axes, QUANTITIES):
            rows = self.rows(quantity)
            for m in rows:
                k = names.index(m.route)
                floor = max(m.error_max, 1e-18)
                ax.errorbar([m.time_median * 1e6], [floor],
                            xerr=[[max(m.time_median - m.time_q1, 0) * 1e6],
                                  [max(m.time_q3 - m.time_median, 0) * 1e6]],
                            fmt=markers[k % len(markers)], color=f"C{k % 10}", ms=7,
                            capsize=2, label=m.route,
                            markeredgecolor="black" if m.pareto else f"C{k % 10}",
                            markeredgewidth=1.8 if m.pareto else 0.5)
            front = [m for m in rows if m.pareto]
            if front:
                xs = [m.time_median * 1e6 for m in front]
                ys = [max(m.error_max, 1e-18) for m in front]
                ax.step(xs, ys, where="post", color="black", lw=1, ls="--",
                        label="Pareto front")
            for eps, label in ((np.finfo(np.float64).eps, "float64 ε"),
                               (np.finfo(np.float32).eps, "float32 ε")):
                ax.axhline(eps, color="grey", lw=0.6, ls=":")
                ax.annotate(label, (1, eps), xycoords=("axes fraction", "data"),
                            ha="right", va="bottom", fontsize=7, color="grey")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("time per evaluation [µs] (median, 25–75 % bars)")
            ax.set_ylabel("largest relative error")
            ax.set_title(f"{self.robot}: {title}", fontsize=10)
            ax.grid(True, which="major", lw=0.3)
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=7, frameon=False)
        fig.tight_layout(rect=(0, 0.14, 1, 1))
        fig.savefig(path, dpi=90)
        plt.close(fig)


def _time(seconds: float) -> str:
    us = seconds * 1e6
    return f"{us:.3g} µs" if us < 1000 else f"{us / 1000:.3g} ms"


def sample_states(n: int, samples: int, seed: int, model: RobotModel | None = None):
    """(q, qd, qdd), each (samples, n): q uniform in [−π, π], qd and qdd standard normal.
    With a ``model`` holding quaternion joints, q is (samples, model.nq): each quaternion
    uniform on the unit sphere."""
    rng = np.random.default_rng(seed)
    q, qd, qdd = (rng.uniform(-np.pi, np.pi, (samples, n)), rng.normal(size=(samples, n)),
                  rng.normal(size=(samples, n)))
    if model is not None and model.nq > model.dof:
        q = np.array([random_configuration(model, x, rng) for x in q])
    return q, qd, qdd


@dataclass
class BenchPlan:
    """A prepared benchmark: routes built, states drawn; :meth:`run` measures.

    ``steps`` is the number of progress steps :meth:`run` reports (one per reference state,
    one per route and quantity).
    """

    model: RobotModel
    routes: list[Route]
    states: tuple[np.ndarray, np.ndarray, np.ndarray]
    batch_size: int
    repeats: int
    timing_states: int
    workdir: tempfile.TemporaryDirectory
    skipped: tuple[str, ...] = ()

    @property
    def steps(self) -> int:
        return len(self.states[0]) + 2 * len(self.routes)

    def run(self, progress: Progress | None = None) -> BenchResult:
        progress = progress or _NoProgress()
        q, qd, qdd = self.states
        samples = len(q)
        try:
            reference = Reference(self.model)
            tau_ref, M_ref = [], []
            for k in range(samples):
                tau_ref.append(reference.tau(q[k], qd[k], qdd[k]))
                M_ref.append(reference.M(q[k]))
                progress.update(1)
            check = reference.cross_check([(q[k], qd[k], qdd[k]) for k in range(min(3, samples))])
            if check > CROSS_CHECK_LIMIT:
                warnings.warn(f"the two high-precision references of {self.model.name} disagree "
                              f"by {check:.1e} (> {CROSS_CHECK_LIMIT:.0e}): the errors below are "
                              "not trustworthy", RuntimeWarning, stacklevel=2)
            measured = []
            for route in self.routes:
                for quantity, _ in QUANTITIES:
                    measured.append(self._measure(route, quantity, tau_ref, M_ref))
                    progress.update(1)
        finally:
            self.workdir.cleanup()
        marked = []
        for quantity, _ in QUANTITIES:
            rows = [m for m in measured if m.quantity == quantity]
            front = set(pareto_front([(m.time_median, m.error_max) for m in rows], PARETO_TIE))
            marked += [_with_pareto(m, i in front) for i, m in enumerate(rows)]
        return BenchResult(self.model.name, self.model.dof, samples, self.batch_size,
                           self.repeats, check, tuple(marked), self.skipped)

    def _measure(self, route: Route, quantity: str, tau_ref, M_ref) -> Measurement:
        q, qd, qdd = self.states
        if quantity == "tau":
            def call(a, b, c):
                return route.tau(a, b, c)
            values = call(q, qd, qdd)
            errors = [relative_error(values[k], tau_ref[k]) for k in range(len(q))]
        else:
            def call(a, b, c):
                return route.M(a)
            values = call(q, qd, qdd)
            errors = [relative_error(values[k], M_ref[k]) for k in range(len(q))]
        if route.batch:
            reps = -(-self.batch_size // len(q))
            args = tuple(np.ascontiguousarray(np.tile(x, (reps, 1))[:self.batch_size])
                         for x in (q, qd, qdd))
        else:
            args = tuple(x[:self.timing_states] for x in (q, qd, qdd))
        call(*args)  # warm-up (CasADi builds its maps on the first call)
        times = []
        for _ in range(self.repeats):
            start = time.perf_counter()
            call(*args)
            times.append((time.perf_counter() - start) / len(args[0]))
        quartiles = statistics.quantiles(times, n=4) if len(times) > 1 else [times[0]] * 3
        return Measurement(route.name, route.dtype, route.batch, quantity,
                           statistics.median(times), quartiles[0], quartiles[2],
                           max(errors), statistics.median(errors), route.note)


def _with_pareto(m: Measurement, pareto: bool) -> Measurement:
    return replace(m, pareto=pareto)


def prepare_bench(model: RobotModel, samples: int = 50, seed: int = 0, batch_size: int = 1000,
                  repeats: int = 7, timing_states: int = 20,
                  log: Callable[[str], None] = lambda _: None) -> BenchPlan:
    """Derive, generate and load every route of ``model``, draw the states (see the module
    docstring); nothing is measured yet."""
    if samples < 1 or repeats < 1 or batch_size < 1 or timing_states < 1:
        raise ValueError("samples, repeats, batch size and timing states must be positive")
    model = numeric_only(model)
    workdir = tempfile.TemporaryDirectory(prefix="eomgen-bench-")
    try:
        routes = build_routes(model, Path(workdir.name), progress=log)
    except BaseException:
        workdir.cleanup()
        raise
    skipped = []
    if c_compiler() is None:
        skipped.append("C (CasADi): no C compiler found")
    if not any(r.name == "Pinocchio" for r in routes):
        skipped.append("Pinocchio: not installed")
    return BenchPlan(model, routes, sample_states(model.dof, samples, seed, model), batch_size,
                     repeats,
                     min(timing_states, samples), workdir, tuple(skipped))


def write_outputs(result: BenchResult, outdir: Path, stem: str) -> list[Path]:
    """``bench_<stem>.md``, ``.csv`` and ``.png`` in ``outdir``; returns their paths."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    png = outdir / f"bench_{stem}.png"
    result.plot(png)
    md = outdir / f"bench_{stem}.md"
    md.write_text(result.markdown(png.name), encoding="utf-8")
    csv_path = outdir / f"bench_{stem}.csv"
    csv_path.write_text(result.csv(), encoding="utf-8")
    return [md, csv_path, png]


__all__ = ["BenchPlan", "BenchResult", "Measurement", "prepare_bench", "sample_states",
           "write_outputs"]
