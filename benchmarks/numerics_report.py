"""Regenerate the tables and plots of docs/numerics.md and the README's accuracy section.

    python benchmarks/numerics_report.py                 # everything (about 10 minutes)
    python benchmarks/numerics_report.py --only bench    # speed against error only
    python benchmarks/numerics_report.py --only simulate --duration 5 --panda-duration 1
    python benchmarks/numerics_report.py --quick         # 10 samples, 2 s and 0.5 s simulated

``--quick`` checks that the report runs; it overwrites the recorded tables and plots with
numbers from fewer samples and shorter runs, so do not commit what it writes.

Writes ``docs/img/bench_<robot>.png``, ``docs/img/simulate.png`` and
``benchmarks/results/{bench_<robot>,simulate,hard_cases,forms}.{md,csv}``. Robots: the bundled planar
2-link arm and PUMA 560 and, when example-robot-data is installed (as in tests/support/__init__.py),
the UR5, the Panda (fingers locked at 0) and the double pendulum.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import eomgen  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402
from support import erd_robots_dir  # noqa: E402

IMAGES = ROOT / "docs" / "img"
RESULTS = ROOT / "benchmarks" / "results"


def load(path: Path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # PUMA 560's inertias, the Panda's mimic finger
        model = eomgen.load(path)
    fingers = {j: 0.0 for j in model.joint_names if "finger" in j}
    return lock_joints(model, fingers) if fingers else model


def robots() -> dict[str, Path]:
    found = {"planar_2link": eomgen.example_path("planar_2link"),
             "puma560": eomgen.example_path("puma560_dh")}
    erd = erd_robots_dir()
    if erd is not None:
        found["ur5"] = erd / "ur_description/urdf/ur5_robot.urdf"
        found["panda"] = erd / "panda_description/urdf/panda.urdf"
    return found


def bench(samples: int, names: list[str] | None = None) -> None:
    from eomgen.analysis.bench import prepare_bench

    for name, path in robots().items():
        if names and name not in names:
            continue
        start = time.perf_counter()
        plan = prepare_bench(load(path), samples=samples)
        result = plan.run()
        result.plot(IMAGES / f"bench_{name}.png")
        (RESULTS / f"bench_{name}.md").write_text(
            result.markdown(f"../../docs/img/bench_{name}.png"), encoding="utf-8")
        (RESULTS / f"bench_{name}.csv").write_text(result.csv(), encoding="utf-8")
        print(f"bench {name}: {time.perf_counter() - start:.0f} s", flush=True)


def simulate(duration: float, panda_duration: float) -> None:
    from eomgen.analysis.simulate import default_integrators, plot, run_study

    erd = erd_robots_dir()
    cases = [("double pendulum", erd / "double_pendulum_description/urdf/double_pendulum.urdf"
              if erd else eomgen.example_path("planar_2link"), [2.0, 2.5], None, duration)]
    if erd:  # a 7-link chain falling freely is chaotic within seconds: a shorter horizon
        cases.append(("panda", erd / "panda_description/urdf/panda.urdf",
                      [0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8], None, panda_duration))
    studies = []
    for label, path, q0, qd0, seconds in cases:
        start = time.perf_counter()
        studies.append(run_study(load(path), default_integrators(), seconds, q0, qd0))
        print(f"simulate {label}: {time.perf_counter() - start:.0f} s", flush=True)
    plot(studies, IMAGES / "simulate.png")
    lines = []
    for study in studies:
        lines += [f"## {study.robot}", "", study.describe(), "", study.markdown_table(), ""]
    (RESULTS / "simulate.md").write_text("\n".join(lines), encoding="utf-8")
    from eomgen.analysis.report import csv_text
    from eomgen.analysis.simulate import Study

    rows = [row for study in studies for row in study.csv_rows()]
    (RESULTS / "simulate.csv").write_text(csv_text(Study.CSV_HEADERS, rows), encoding="utf-8")


def hard_cases() -> None:
    """The hard cases of tests/dynamics/test_hard_cases.py: cond(M) and the largest errors."""
    import test_hard_cases as hc
    from eomgen.analysis.precision import relative_error
    from eomgen.analysis.report import csv_text, fmt, markdown_table
    from eomgen.numeric import rnea

    folder = RESULTS / ".hard_cases"
    folder.mkdir(exist_ok=True)
    rows = []
    for name in ("mass_ratio", "light_tip", "prismatic_near_singular", "zero_gravity", "arm",
                 "chain30"):
        case = hc.Case(name, folder)
        states = case.states(2 if name == "chain30" else 5, seed=1)
        if name == "arm":
            rng = np.random.default_rng(7)
            states = [hc.HARD_STATES[k](case.n, rng) for k in hc.HARD_STATES]
        worst = dict(cond=0.0, M=0.0, tau=0.0, rnea=0.0, fd=0.0, bound=0.0)
        for q, qd, qdd in states:
            tau_ref = case.reference.tau(q, qd, qdd)
            tau = hc.tau_ref_float(tau_ref)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                qdd_fd = case.module.forward_dynamics(q, qd, tau)
            bound, qdd_ref = hc.fd_bound(case, q, qd, tau)
            worst["cond"] = max(worst["cond"], case.reference.condition(q))
            worst["M"] = max(worst["M"], relative_error(case.module.mass_matrix(q),
                                                        case.reference.M(q)))
            worst["tau"] = max(worst["tau"], relative_error(
                case.module.inverse_dynamics(q, qd, qdd), tau_ref))
            worst["rnea"] = max(worst["rnea"], relative_error(rnea(case.nm, q, qd, qdd), tau_ref))
            worst["fd"] = max(worst["fd"], relative_error(qdd_fd, qdd_ref))
            worst["bound"] = max(worst["bound"], bound)
        label = name if name != "arm" else "arm at ±π, 1e3 rad, 1e6 rad, 1e3 rad/s"
        rows.append((label, case.n, fmt(worst["cond"]), fmt(worst["M"]), fmt(worst["tau"]),
                     fmt(worst["rnea"]), fmt(worst["fd"]), fmt(worst["bound"])))
        print(f"hard case {name} done", flush=True)
    headers = ["case", "n", "cond(M)", "M (generated)", "τ (generated)", "τ (RNEA)",
               "q̈ (generated)", "q̈ bound"]
    (RESULTS / "hard_cases.md").write_text(markdown_table(headers, rows) + "\n", encoding="utf-8")
    (RESULTS / "hard_cases.csv").write_text(csv_text(headers, rows), encoding="utf-8")
    for f in folder.iterdir():
        f.unlink()
    folder.rmdir()


def forms() -> None:
    """Which form of M keeps its digits: the straight-line program, the same arithmetic
    expanded, the trig-simplified dyn.M and the fully expanded polynomial, at 20 random q."""
    import sympy as sp

    import test_hard_cases as hc
    from eomgen.analysis.precision import Reference, relative_error
    from eomgen.analysis.report import csv_text, fmt, markdown_table
    from eomgen.analysis.routes import compile_scalar
    from eomgen.dynamics import derive
    from eomgen.symbolic.program import Program

    R = sp.Rational
    cases = {
        "2 links of 1 m, first joint 10 m from the root origin":
            hc.chain("far10", [1, 1], [1, 1], base=(10, 0, 0)),
        "2 links of 1 m, first joint 1 km from the root origin":
            hc.chain("far1000", [1, 1], [1, 1], base=(1000, 0, 0)),
        "3 links of 1 m, first joint 1 km from the root origin":
            hc.chain("far1000_3", [1, 1, 1], [1, 1, 1], base=(1000, 0, 0)),
        "link 1 of 1 km, link 2 of 0.1 m": hc.chain("long", [1, 1], [1000, R(1, 10)]),
        "masses 1000, 1, 0.001 kg": hc.chain("ratio", [1000, 1, R(1, 1000)], [1, 1, 1]),
    }
    rows = []
    rng = np.random.default_rng(2)
    for label, model in cases.items():
        dyn = derive(model, outputs=("M", "tau"), simplify=True)
        reference = Reference(model, dynamics=dyn)
        n = model.dof
        full = dyn.program.expand(dyn.program.output("M"))
        variants = {
            "program": dyn.program.pruned(["M"]),
            "expanded": Program((), (("M", full),)),
            "trigsimp": Program((), (("M", dyn.M),)),
            "polynomial": Program((), (("M", full.applyfunc(
                lambda e: sp.expand(sp.expand_trig(e)))),)),
        }
        functions = {k: compile_scalar(p, dyn.q, ["M"]) for k, p in variants.items()}
        tau = compile_scalar(dyn.program, dyn.q + dyn.qd + dyn.qdd, ["tau"])
        worst = {k: [0.0, 0.0] for k in list(functions) + ["tau"]}
        for _ in range(20):
            q, qd, qdd = (rng.uniform(-np.pi, np.pi, n), rng.normal(size=n),
                          rng.normal(size=n))
            M_ref = reference.M(q)
            big = max(abs(x) for x in M_ref.ravel())
            for k, f in functions.items():
                M = np.reshape(f(*q)[0], (n, n))
                worst[k][0] = max(worst[k][0], relative_error(M, M_ref))
                worst[k][1] = max(worst[k][1], max(
                    relative_error(M[i, j], M_ref[i, j]) for i in range(n) for j in range(n)
                    if abs(M_ref[i, j]) > 1e-12 * big))
            tau_ref = reference.tau(q, qd, qdd)
            worst["tau"][0] = max(worst["tau"][0], relative_error(
                np.array(tau(*q, *qd, *qdd)[0]), tau_ref))
        rows.append((label, *(f"{fmt(a)} / {fmt(b)}" for a, b in
                              (worst[k] for k in variants)), fmt(worst["tau"][0])))
        print(f"forms: {label} done", flush=True)
    headers = ["model", "program", "program expanded", "dyn.M (trigsimp)",
               "expanded polynomial", "τ (Newton–Euler program)"]
    (RESULTS / "forms.md").write_text(markdown_table(headers, rows) + "\n", encoding="utf-8")
    (RESULTS / "forms.csv").write_text(csv_text(headers, rows), encoding="utf-8")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=("bench", "simulate", "hard", "forms"), default=None)
    parser.add_argument("--samples", type=int, default=None, help="default 50; 10 with --quick")
    parser.add_argument("--duration", type=float, default=None,
                        help="simulated seconds of the double pendulum (default 10; 2 with "
                             "--quick)")
    parser.add_argument("--panda-duration", type=float, default=None,
                        help="default 2; 0.5 with --quick")
    parser.add_argument("--quick", action="store_true",
                        help="10 samples, 2 s and 0.5 s simulated")
    parser.add_argument("--robots", default=None,
                        help="comma-separated robots for --only bench (default: all found)")
    args = parser.parse_args()
    quick = {"samples": 10, "duration": 2.0, "panda_duration": 0.5}
    full = {"samples": 50, "duration": 10.0, "panda_duration": 2.0}
    for name in full:
        if getattr(args, name) is None:
            setattr(args, name, (quick if args.quick else full)[name])
    IMAGES.mkdir(parents=True, exist_ok=True)
    RESULTS.mkdir(parents=True, exist_ok=True)
    if args.only in (None, "hard"):
        hard_cases()
    if args.only in (None, "forms"):
        forms()
    if args.only in (None, "bench"):
        bench(args.samples, args.robots.split(",") if args.robots else None)
    if args.only in (None, "simulate"):
        simulate(args.duration, args.panda_duration)


if __name__ == "__main__":
    main()
