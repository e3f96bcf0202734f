"""CasADi's Opti with eomgen's forward dynamics, three ways (issue 42): a reach with torque
limits (multiple shooting, RK4, IPOPT) solved with

* ``sx-ad``: the CasADi module's ``forward_dynamics`` generated without derivative outputs,
  which CasADi differentiates itself (AD of the SX graph);
* ``sx-eomgen``: the module generated with ``forward_dynamics_derivatives``, whose Jacobian in
  the MX graph is eomgen's derivative program (``custom_jacobian``);
* ``external``: the C backend's library (with ``jac_forward_dynamics``) loaded by
  ``casadi.external``, compiled ``-O3``;
* ``external-ad``: the C library of the module without derivative outputs, its
  ``jac_forward_dynamics`` written from the SX function's CasADi AD instead (what a library
  would export if eomgen differentiated nothing), for comparison.

* ``sx-eomgen2``: the module generated with ``forward_dynamics_second_derivatives`` too, whose
  Jacobian's Jacobian (``jac_jac_forward_dynamics``) is eomgen's second derivatives of the
  forward dynamics, composed from those of the inverse dynamics;
* ``external2``: that module's C library (``jac_forward_dynamics`` and
  ``jac_jac_forward_dynamics``) loaded by ``casadi.external``.

Each with IPOPT's limited-memory Hessian and, with ``--exact``, the exact Hessian (``external``
and ``external-ad`` have no second derivatives: exact runs skip them). The table gives the
solve time (wall clock of ``opti.solve()``, the median of ``--repeats``), IPOPT's iterations,
the optimum, which must agree across ways, and the load average (``os.getloadavg()``, 1 min)
when the row was measured: the machine is shared.

Usage::

    python benchmarks/casadi_opti.py [--robot panda|puma560|planar_2link] [--steps 30] [--repeats 3]
        [--exact] [--ways sx-ad,sx-eomgen2,...] [--hessians limited-memory,exact]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # measure this checkout, not some installed copy
sys.path.insert(0, str(ROOT / "benchmarks"))

import casadi as ca  # noqa: E402
import numpy as np  # noqa: E402

import eomgen  # noqa: E402
from eomgen.codegen.backends.casadi_backend import library_name, load_casadi  # noqa: E402
from eomgen.codegen.functions import module_name, select_functions  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.common.compiler import c_compiler  # noqa: E402

DEFAULT = ["M", "C", "g", "tau", "forward_dynamics"]


def model_of(robot: str):
    if robot == "panda":
        from codegen_speed import erd_robots_dir
        from eomgen.model import lock_joints

        model = eomgen.load(erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf")
        return lock_joints(model, {n: 0 for n in model.joint_names if "finger" in n})
    return eomgen.load(eomgen.example_path(robot))


def write(model, functions, folder: Path, backends) -> dict:
    for f in render_files(model, backends, functions=select_functions(functions)):
        path = folder / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    return load_casadi(folder, module_name(model.name)).namespace


def ad_library(f, folder: Path):
    """``f`` and a ``jac_<name>`` of CasADi's AD of its SX graph, compiled like the C
    backend's library, loaded by ``casadi.external``."""
    inputs = [ca.SX.sym(f.name_in(i), f.sparsity_in(i)) for i in range(f.n_in())]
    value = f(*inputs)
    options = {"allow_duplicate_io_names": True,
               "default_in": [f.default_in(i) for i in range(f.n_in())]}
    plain = ca.Function(f.name(), inputs, [value], f.name_in(), f.name_out(), options)
    jac = ca.Function("jac_" + f.name(), inputs + [ca.SX.sym("out", value.sparsity())],
                      [ca.jacobian(value, x) for x in inputs], options | {
                          "default_in": options["default_in"] + [0.0]})
    generator = ca.CodeGenerator("ad.c", {"with_header": False})
    generator.add(plain)
    generator.add(jac)
    generator.generate(str(folder) + "/")
    subprocess.run([c_compiler(), "-O3", "-fPIC", "-shared", str(folder / "ad.c"), "-o",
                    str(folder / "libad.so")], check=True)
    return ca.external(f.name(), str(folder / "libad.so"))


def reach(f, n, steps, horizon, limit, hessian):
    opti = ca.Opti()
    X = opti.variable(2 * n, steps + 1)
    U = opti.variable(n, steps)
    dt = horizon / steps

    # parameters kept symbolic (planar_2link): their description values
    parameters = [f.default_in(i) for i in range(3, f.n_in())]

    def xdot(x, u):
        return ca.vertcat(x[n:], f(x[:n], x[n:], u, *parameters))

    for k in range(steps):
        x, u = X[:, k], U[:, k]
        k1 = xdot(x, u)
        k2 = xdot(x + dt / 2 * k1, u)
        k3 = xdot(x + dt / 2 * k2, u)
        k4 = xdot(x + dt * k3, u)
        opti.subject_to(X[:, k + 1] == x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4))
    opti.subject_to(X[:, 0] == 0)
    opti.subject_to(X[:, steps] == ca.vertcat(0.5 * ca.DM.ones(n), ca.DM.zeros(n)))
    opti.subject_to(opti.bounded(-limit, ca.vec(U), limit))
    opti.minimize(dt * ca.sumsqr(U))
    # initial guess: the states on the straight line to the goal
    opti.set_initial(X[:n, :], 0.5 * np.tile(np.linspace(0, 1, steps + 1), (n, 1)))
    opti.solver("ipopt", {"print_time": False},
                {"print_level": 0, "sb": "yes", "tol": 1e-8, "max_iter": 1000,
                 "hessian_approximation": hessian})
    start = time.perf_counter()
    solution = opti.solve_limited()
    elapsed = time.perf_counter() - start
    stats = solution.stats()
    optimum = float(solution.value(opti.f)) if stats["success"] else float("nan")
    return elapsed, int(stats["iter_count"]), optimum


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="panda")
    parser.add_argument("--steps", type=int, default=30)
    parser.add_argument("--horizon", type=float, default=1.0)
    parser.add_argument("--limit", type=float, default=60.0)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--exact", action="store_true", help="also the exact Hessian (SX ways)")
    parser.add_argument("--repeats-limited", type=int, default=None,
                        help="repeats of the limited-memory runs (default: --repeats)")
    parser.add_argument("--alternate", action="store_true",
                        help="run the ways in turn within each repeat (fairer on a loaded "
                             "machine) instead of each way's repeats in a row")
    parser.add_argument("--ways", default="sx-ad,sx-eomgen,external,external-ad,sx-eomgen2,"
                        "external2", help="comma-separated ways to run (see above)")
    parser.add_argument("--hessians", default=None,
                        help="comma-separated: limited-memory, exact (default: limited-memory, "
                             "and exact with --exact)")
    args = parser.parse_args()
    model = model_of(args.robot)
    n = model.dof
    chosen = args.ways.split(",")
    second_order = {"sx-eomgen2", "external2"}
    with tempfile.TemporaryDirectory() as tmp:
        folders = {name: Path(tmp, name) for name in ("plain", "derivatives", "second")}
        for folder in folders.values():
            folder.mkdir()
        start = time.perf_counter()
        plain = write(model, DEFAULT, folders["plain"], ["casadi"])
        ways = {"sx-ad": lambda: plain["forward_dynamics"],
                "external-ad": lambda: ad_library(plain["forward_dynamics"], folders["plain"])}
        if {"sx-eomgen", "external"} & set(chosen):
            first = write(model, DEFAULT + ["forward_dynamics_derivatives"],
                          folders["derivatives"], ["casadi"] + (["c"] if "external" in chosen
                                                                else []))
            ways["sx-eomgen"] = lambda: first["forward_dynamics"]
            ways["external"] = lambda: ca.external("forward_dynamics", str(
                folders["derivatives"] / library_name(module_name(model.name))))
        if second_order & set(chosen):
            second = write(model, DEFAULT + ["forward_dynamics_second_derivatives"],
                           folders["second"], ["casadi"] + (["c"] if "external2" in chosen
                                                            else []))
            ways["sx-eomgen2"] = lambda: second["forward_dynamics"]
            ways["external2"] = lambda: ca.external("forward_dynamics", str(
                folders["second"] / library_name(module_name(model.name))))
        ways = {label: ways[label]() for label in chosen}
        print(f"generation and compilation: {time.perf_counter() - start:.0f} s")
        hessians = (args.hessians.split(",") if args.hessians else
                    ["limited-memory"] + (["exact"] if args.exact else []))
        print(f"{args.robot} (n = {n}), N = {args.steps}, {args.horizon} s, |tau| <= "
              f"{args.limit}, median of {args.repeats} (limited-memory: "
              f"{args.repeats_limited or args.repeats})")
        print("| way | Hessian | solve time [s] | iterations | optimum | load |")
        print("|---|---|---|---|---|---|")
        for hessian in hessians:
            labels = [label for label in ways if not (
                hessian == "exact" and label in ("external", "external-ad"))]
            repeats = (args.repeats_limited if hessian == "limited-memory"
                       and args.repeats_limited is not None else args.repeats)
            runs: dict = {label: [] for label in labels}
            loads: dict = {label: [] for label in labels}
            order = ([labels] * repeats if args.alternate
                     else [[label] * repeats for label in labels])
            for group in order:
                for label in group:
                    runs[label].append(reach(ways[label], n, args.steps, args.horizon,
                                             args.limit, hessian))
                    loads[label].append(os.getloadavg()[0])
                    if not args.alternate and len(runs[label]) == repeats:
                        report(label, hessian, runs[label], loads[label])
            if args.alternate:
                for label in labels:
                    report(label, hessian, runs[label], loads[label])


def report(label, hessian, runs, loads) -> None:
    elapsed = statistics.median(r[0] for r in runs)
    load = f"{min(loads):.1f}" + (f"-{max(loads):.1f}" if max(loads) - min(loads) >= 0.05
                                  else "")
    print(f"| {label} | {hessian} | {elapsed:.3f} | {runs[0][1]} | {runs[0][2]:.10g} | "
          f"{load} |", flush=True)


if __name__ == "__main__":
    main()
