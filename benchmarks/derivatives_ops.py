"""Operation counts of the generated derivative programs (issue 25): Panda (fingers locked), UR5
and PUMA 560.

For each robot, each derivative function of the generated CasADi module is counted as
``casadi.Function.n_instructions()`` (SX instructions, what CasADi executes), beside the same
count of CasADi's own automatic differentiation of the generated τ
(``casadi.jacobian(inverse_dynamics(q, qd, qdd), [q; qd])``; also in reverse mode, one
adjoint sweep per joint, and of ∂τ/∂q alone), and eomgen's own operation count of
each program (:meth:`eomgen.Dynamics.operation_count`, SymPy ``count_ops``). Issue 25's target:
Panda ∂τ/∂(q, q̇) ≤ 0.6 × CasADi's AD of the generated τ.

Usage::

    python benchmarks/derivatives_ops.py                      # about a minute
    python benchmarks/derivatives_ops.py --markdown benchmarks/results/derivatives_ops.md
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # measure this checkout, not some installed copy
sys.path.insert(0, str(ROOT / "benchmarks"))

import casadi as ca  # noqa: E402

from codegen_speed import robots  # noqa: E402
from eomgen.codegen import loadable_backends  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.dynamics import derive  # noqa: E402

FUNCTIONS = ("inverse_dynamics", "inverse_dynamics_derivatives", "gravity_derivative",
             "forward_dynamics_aba", "forward_dynamics_derivatives", "linearize")
SYMBOLS = {"inverse_dynamics": "tau", "inverse_dynamics_derivatives": "dtau",
           "gravity_derivative": "dg_dq", "forward_dynamics_aba": "qdd_aba",
           "forward_dynamics_derivatives": "dqdd", "linearize": "AB"}


def casadi_counts(model, folder: Path) -> dict[str, int]:
    for f in render_files(model, ["casadi"], functions=FUNCTIONS):
        (folder / f.name).write_text(f.content, encoding="utf-8")
    module = loadable_backends()["casadi"].load(folder, folder.name).namespace
    counts = {name: module[name].n_instructions() for name in FUNCTIONS}
    n = model.dof
    q, qd, qdd = (ca.SX.sym(s, n) for s in ("q", "qd", "qdd"))
    tau = module["inverse_dynamics"](q, qd, qdd)  # parameters at their defaults
    x = ca.vertcat(q, qd)
    counts["AD"] = ca.Function("J", [q, qd, qdd], [ca.jacobian(tau, x)]).n_instructions()
    # the same Jacobian in reverse mode: one adjoint sweep per row of τ (a row each)
    rows = [ca.jtimes(tau, x, ca.DM.eye(n)[:, i], True).T for i in range(n)]
    counts["AD reverse"] = ca.Function("R", [q, qd, qdd], [ca.vertcat(*rows)]).n_instructions()
    counts["AD q"] = ca.Function("Jq", [q, qd, qdd], [ca.jacobian(tau, q)]).n_instructions()
    return counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", type=Path, help="also write the table to this file")
    args = parser.parse_args()
    lines = ["| robot | n | τ | ∂τ/∂(q, q̇) | CasADi AD of τ | ours / AD | AD, reverse mode | "
             "AD of ∂τ/∂q alone | ∂g/∂q | q̈ (ABA) | "
             "∂q̈/∂(q, q̇, τ) | linearize (A, B) | ops ∂τ (SymPy) | ops ∂q̈ (SymPy) | derive s |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    print(lines[0], flush=True)
    for robot in robots():
        model = robot.load()
        start = time.perf_counter()
        dyn = derive(model, tuple(SYMBOLS.values()))
        seconds = time.perf_counter() - start
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp) / robot.label
            folder.mkdir()
            c = casadi_counts(model, folder)
        ratio = c["inverse_dynamics_derivatives"] / c["AD"]
        line = (f"| {robot.label} | {model.dof} | {c['inverse_dynamics']:,} | "
                f"{c['inverse_dynamics_derivatives']:,} | {c['AD']:,} | {ratio:.2f} | "
                f"{c['AD reverse']:,} | {c['AD q']:,} | "
                f"{c['gravity_derivative']:,} | {c['forward_dynamics_aba']:,} | "
                f"{c['forward_dynamics_derivatives']:,} | {c['linearize']:,} | "
                f"{dyn.operation_count(['dtau']):,} | {dyn.operation_count(['dqdd']):,} | "
                f"{seconds:.1f} |")
        print(line, flush=True)
        lines.append(line)
    lines.append("")
    lines.append("SX instructions (casadi.Function.n_instructions) unless marked SymPy; Panda "
                 "target ∂τ/∂(q, q̇) ≤ 0.6 × CasADi AD.")
    if args.markdown:
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
