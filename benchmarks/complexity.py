"""The complexity table, measured: operation counts and evaluation times of eomgen's generated
programs for spatial chains of n = 2…30 links, with fitted log-log slopes.

Usage::

    python benchmarks/complexity.py                 # n = 2…30 (several minutes)
    python benchmarks/complexity.py --quick         # n = 2, 4, 8, 12; C up to n = 8 (< 1 min)
    python benchmarks/complexity.py --replot        # table and plot again from the CSV
    python benchmarks/complexity.py --csv --plot    # also write benchmarks/results/complexity.csv
                                                    # and docs/img/complexity.png
    python benchmarks/complexity.py --robots        # operation counts of the Panda and PUMA 560

What is measured, for each n (a chain of n revolute joints, see :func:`spatial_chain`):

* ``tau``  — the Newton–Euler program τ(q, q̇, q̈) (:mod:`eomgen.symbolic.newton_euler`);
* ``crba`` — the mass matrix by the body-frame Composite-Rigid-Body Algorithm
  (:mod:`eomgen.symbolic.crba`);
* ``M``    — the mass matrix as M_ij = S_iᵀ I^c_j S_j with everything in world axes
  (:func:`eomgen.symbolic.composite.composite_M_program`; ``derive`` builds whichever
  of it and the CRBA is cheaper for the robot);
* ``aba``  — the Articulated-Body Algorithm program q̈(q, q̇, τ) (:mod:`eomgen.symbolic.aba`);
* ``chol`` — the Cholesky route to q̈ as one program (the CRBA's M, bias τ(q, q̇, 0),
  M = L Lᵀ, two triangular solves);
* ``C``    — the Coriolis matrix from the Christoffel symbols of the closed-form ∂M/∂q
  (:func:`eomgen.symbolic.composite.christoffel_coriolis_program`, O(n³));
* ``Crec`` — the same matrix by Echeandia and Wensing's recursion
  (:func:`eomgen.symbolic.composite.coriolis_program`, O(n²)); ``derive`` builds the cheaper;
* ``derive`` — ``eomgen.derive(model)`` (M, C, g): seconds and assignments of its program (the
  Lagrangian derivation's own cost).

``ops`` are counted by :mod:`eomgen.symbolic.opcount` from the printed NumPy code (what a
generated function executes: ``+ − * / **``, unary minus, ``np.sin``…). ``µs`` is the time of
one evaluation of the program printed as plain Python over floats
(:func:`eomgen.symbolic.evaluate.compile_program`), best of 7 timed loops of 0.03 s: Python's
cost per operation is nearly constant, so it follows the operation count; ``batch µs`` is the
time per state of the same program over NumPy arrays of 1000 states (as the generated NumPy
modules run), best of 7 timed loops. ``build s`` is the time
to build the program symbolically. Slopes are least-squares fits of log(value) against log(n)
over n ≥ 8.

Featherstone's operation counts for comparison (multiplications + additions, general
revolute-jointed chains, spatial-vector implementations), quoted as the references state them —
see docs/complexity.md for the sources and the caveats.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
import timeit
import warnings
from pathlib import Path

import numpy as np
import sympy as sp

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from eomgen.model.bodies import body_tree  # noqa: E402
from eomgen.dynamics import derive, joint_symbols  # noqa: E402
from eomgen.model import Inertial, Joint, JointType, Link, Transform, build_model, vec3  # noqa: E402
from eomgen.symbolic.aba import aba_program, cholesky_program  # noqa: E402
from eomgen.symbolic.composite import (christoffel_coriolis_program, coriolis_program,  # noqa: E402
                                       composite_M_program)
from eomgen.symbolic.crba import crba_program  # noqa: E402
from eomgen.symbolic.evaluate import compile_program  # noqa: E402
from eomgen.symbolic.newton_euler import inverse_dynamics_program  # noqa: E402
from eomgen.symbolic.opcount import program_operation_count  # noqa: E402
from eomgen.symbolic.program import Program, ProgramBuilder  # noqa: E402

FULL_NS = (2, 3, 4, 6, 8, 10, 12, 15, 20, 25, 30)
QUICK_NS = (2, 4, 8, 12)
FIT_FROM = 8
QUANTITIES = ("tau", "crba", "M", "aba", "chol", "C", "Crec")


def featherstone(name: str, n: int) -> int | None:
    """Multiplications + additions of Featherstone's algorithms for an n-joint revolute chain, as
    quoted in docs/complexity.md (Featherstone 2008, Table 10.x; Featherstone & Orin 2000)."""
    if name == "tau":  # RNEA
        return (93 * n - 69) + (81 * n - 66)
    if name in ("M", "crba"):  # CRBA
        return (10 * n * n + 22 * n - 32) + (6 * n * n + 37 * n - 43)
    if name == "aba":
        return (224 * n - 165) + (205 * n - 186)
    return None


def spatial_chain(n: int):
    """An n-link spatial chain: revolute joints about their z axes, consecutive axes turned by
    ±90° about x and offset by (0.1, 0, 0.3) m (a Panda-like modified-DH geometry), every link
    with a centre of mass off all axes and a full inertia tensor (no structural zeros there)."""
    half = sp.pi / 2
    links = [Link("base")]
    joints = []
    for k in range(1, n + 1):
        m = sp.Float(1 + (k % 5) / 10)
        com = vec3((0.03, -0.02, 0.12))
        inertia = ((0.021, 0.001, -0.002), (0.001, 0.019, 0.003), (-0.002, 0.003, 0.008))
        links.append(Link(f"link{k}", Inertial(m, com, inertia)))
        origin = Transform() if k == 1 else Transform.from_xyz_rpy(
            (0.1, 0, 0.3), ((1 if k % 2 else -1) * half, 0, 0))
        joints.append(Joint(f"joint{k}", JointType.REVOLUTE, "base" if k == 1 else f"link{k - 1}",
                            f"link{k}", origin, vec3((0, 0, 1))))
    return build_model("<benchmark>", f"chain_{n}", links, joints, gravity=(0, 0, -9.81))


def _program(build) -> tuple[Program, tuple, float]:
    start = time.perf_counter()
    program, inputs = build()
    return program, inputs, time.perf_counter() - start


def programs(model, with_C: bool) -> dict:
    """name -> (program, inputs, build seconds) for one model."""
    n = model.dof
    tree = body_tree(model)
    q, qd, qdd = joint_symbols(n)

    def tau():
        b = ProgramBuilder({s.name for s in q + qd + qdd})
        out = inverse_dynamics_program(tree, q, qd, qdd, model.gravity, b)
        return Program(tuple(b.assignments), (("tau", out),)).pruned(["tau"]), q + qd + qdd

    def lagrangian(name, make):
        def build():
            b = ProgramBuilder({s.name for s in q + qd})
            out = make(b)
            return Program(tuple(b.assignments), ((name, out),)).pruned([name]), q + qd
        return build

    def forward(make):
        def build():
            fd = make(model)
            return fd.program, fd.inputs
        return build

    def crba():
        q_sym, program = crba_program(model)
        return program, q_sym

    builders = {"tau": tau, "crba": crba,
                "M": lagrangian("M", lambda b: composite_M_program(tree, q, b)),
                "aba": forward(aba_program), "chol": forward(cholesky_program)}
    if with_C:
        builders["C"] = lagrangian("C", lambda b: christoffel_coriolis_program(tree, q, qd, b))
        builders["Crec"] = lagrangian("C", lambda b: coriolis_program(tree, q, qd, b))
    return {name: _program(build) for name, build in builders.items()}


def time_evaluation(program: Program, inputs, repeat: int = 7) -> float:
    """Seconds of one evaluation of ``program`` printed as Python over floats: the best of
    ``repeat`` timed loops of about 0.03 s (the others measure the machine's other load)."""
    f = compile_program(program, inputs)
    values = list(np.random.default_rng(0).uniform(-1, 1, len(inputs)))
    f(*values)
    number = max(1, int(0.03 / max(1e-7, min(timeit.repeat(lambda: f(*values), number=1, repeat=3)))))
    runs = timeit.repeat(lambda: f(*values), number=number, repeat=repeat)
    return float(min(runs)) / number


BATCH = 1000


def time_batch(program: Program, inputs, repeat: int = 7) -> float:
    """Seconds per state of the program over NumPy arrays of :data:`BATCH` states (as the
    generated NumPy modules run it), best of ``repeat``."""
    from eomgen.analysis.routes import compile_batch

    names = [name for name, _ in program.outputs]
    f = compile_batch(program, inputs, names)
    columns = list(np.random.default_rng(0).uniform(-1, 1, (len(inputs), BATCH)))
    f(*columns)
    number = max(1, int(0.03 / max(1e-6, min(timeit.repeat(lambda: f(*columns), number=1, repeat=3)))))
    return min(timeit.repeat(lambda: f(*columns), number=number, repeat=repeat)) / number / BATCH


def slope(ns, values) -> float:
    pairs = [(math.log(n), math.log(v)) for n, v in zip(ns, values) if n >= FIT_FROM and v]
    if len(pairs) < 2:
        return float("nan")
    x, y = zip(*pairs)
    return float(np.polyfit(x, y, 1)[0])


def measure(ns, c_max_n: int, derive_max_n: int, progress=print) -> list[dict]:
    rows = []
    for n in ns:
        model = spatial_chain(n)
        row: dict = {"n": n}
        for name, (program, inputs, build_s) in programs(model, n <= c_max_n).items():
            row[f"{name}_ops"] = program_operation_count(program)
            row[f"{name}_build_s"] = build_s
            row[f"{name}_us"] = time_evaluation(program, inputs) * 1e6
            row[f"{name}_batch_us"] = time_batch(program, inputs) * 1e6
        if n <= derive_max_n:
            start = time.perf_counter()
            dyn = derive(model, simplify=False)
            row["derive_s"] = time.perf_counter() - start
            row["derive_assignments"] = len(dyn.program.assignments)
        rows.append(row)
        progress(f"n = {n:2d}: " + ", ".join(
            f"{q} {row[f'{q}_ops']} ops" for q in QUANTITIES if f"{q}_ops" in row)
            + (f", derive {row['derive_s']:.2f} s" if "derive_s" in row else ""))
    return rows


def print_table(rows) -> None:
    print("cells: operations (µs per evaluation over Python floats; µs per state in a NumPy "
          f"batch of {BATCH})")
    head = ("| n | τ RNEA | M CRBA | M composite | q̈ ABA "
            "| q̈ CRBA + Cholesky | C Christoffel | C recursion | derive M,C,g s (assignments) "
            "| Featherstone RNEA / CRBA / ABA |")
    print(head)
    print("|" + "---|" * 10)
    for r in rows:
        cells = [str(r["n"])]
        for q in QUANTITIES:
            batch = f"; {r[f'{q}_batch_us']:.2f}" if f"{q}_batch_us" in r else ""
            cells.append(f"{r[f'{q}_ops']} ({r[f'{q}_us']:.0f}{batch})" if f"{q}_ops" in r else "–")
        cells.append(f"{r['derive_s']:.2f} ({r['derive_assignments']})" if "derive_s" in r else "–")
        cells.append(" / ".join(str(featherstone(q, r["n"])) for q in ("tau", "M", "aba")))
        print("| " + " | ".join(cells) + " |")
    print()
    print(f"log-log slopes over n ≥ {FIT_FROM} (ops; scalar time; batch time per state; build time):")
    for q in QUANTITIES:
        have = [r for r in rows if f"{q}_ops" in r]
        if len([r for r in have if r["n"] >= FIT_FROM]) < 2:
            continue
        hn = [r["n"] for r in have]
        print(f"  {q:5s} {slope(hn, [r[f'{q}_ops'] for r in have]):5.2f}; "
              f"{slope(hn, [r[f'{q}_us'] for r in have]):5.2f}; "
              f"{slope(hn, [r.get(f'{q}_batch_us', 0) for r in have]):5.2f}; "
              f"{slope(hn, [r[f'{q}_build_s'] for r in have]):5.2f}")
    dn = [r for r in rows if "derive_s" in r]
    if len([r for r in dn if r["n"] >= FIT_FROM]) >= 2:
        print(f"  derive time {slope([r['n'] for r in dn], [r['derive_s'] for r in dn]):.2f}, "
              f"size {slope([r['n'] for r in dn], [r['derive_assignments'] for r in dn]):.2f}")
    crossing = [r["n"] for r in rows if r["aba_ops"] < r["chol_ops"]]
    faster = [r["n"] for r in rows if r["aba_us"] < r["chol_us"]]
    faster_batch = [r["n"] for r in rows if r.get("aba_batch_us", 1) < r.get("chol_batch_us", 0)]
    print(f"ABA fewer operations than the Cholesky route from n = {min(crossing) if crossing else '–'}"
          f" (n = {crossing}); faster per evaluation for n = {faster} (scalar), "
          f"{faster_batch} (batch)")


def write_csv(rows, path: Path) -> None:
    keys = sorted({k for r in rows for k in r}, key=lambda k: (k != "n", k))
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=keys)
        writer.writeheader()
        for r in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})


def plot(rows, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = {"tau": "τ (RNEA)", "crba": "M (CRBA, body frames)", "M": "M (composite, root frame)", "aba": "q̈ (ABA)", "chol": "q̈ (CRBA + Cholesky)",
              "C": "C (Christoffel symbols)", "Crec": "C (Echeandia–Wensing recursion)"}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for q in QUANTITIES:
        have = [r for r in rows if f"{q}_ops" in r]
        ns = [r["n"] for r in have]
        axes[0].loglog(ns, [r[f"{q}_ops"] for r in have], "o-", label=labels[q])
        axes[1].loglog(ns, [r.get(f"{q}_batch_us", r[f"{q}_us"]) for r in have], "o-",
                       label=labels[q])
    ns = [r["n"] for r in rows]
    for q, style, name in (("tau", ":", "RNEA"), ("crba", "-.", "CRBA"), ("aba", "--", "ABA")):
        axes[0].loglog(ns, [featherstone(q, n) for n in ns], "k" + style, lw=0.8,
                       label=f"Featherstone's {name} (m + a)")
    axes[0].set(xlabel="links n", ylabel="operations (printed NumPy code)",
                title="Operation count")
    axes[1].set(xlabel="links n", ylabel=f"µs per state (NumPy batch of {BATCH})",
                title="Time per evaluation")
    for ax in axes:
        ax.grid(True, which="both", lw=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def read_csv(path: Path) -> list[dict]:
    """Rows written by :func:`write_csv`, numbers parsed."""
    with path.open() as handle:
        return [{k: (int(v) if k == "n" or k.endswith(("_ops", "_assignments")) else float(v))
                 for k, v in row.items() if v != ""} for row in csv.DictReader(handle)]


def robots() -> None:
    """Operation counts of the generated functions of the Panda and the PUMA 560 (issue 18)."""
    import eomgen
    from eomgen.robots import example_path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from derive_speed import panda_model

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cases = [("PUMA 560", eomgen.load(example_path("puma560_dh"))), ("Panda", panda_model())]
    for name, model in cases:
        dyn = derive(model, outputs=("M", "C", "g", "tau"), simplify=False)
        counts = {o: program_operation_count(dyn.program, [o]) for o in ("tau", "M", "C", "g")}
        separate = {o: program_operation_count(derive(model, outputs=(o,), simplify=False).program,
                                               [o]) for o in ("M", "C", "g")}
        counts["M+C+g separately"] = sum(separate.values())
        # the several-result functions dynamics(q, qd) -> (M, C, g) and
        # mass_matrix_and_bias(q, qd) -> (M, h): one program each
        for symbol in ("MCg", "Mh"):
            counts[symbol + " in one call"] = program_operation_count(
                derive(model, outputs=(symbol,), simplify=False).program, [symbol])
        counts["crba"] = program_operation_count(crba_program(model)[1])
        counts["aba"] = program_operation_count(aba_program(model).program)
        counts["chol"] = program_operation_count(cholesky_program(model).program)
        built = programs(model, True)
        for label, quantity in (("M composite", "M"), ("C Christoffel", "C"), ("C recursion", "Crec")):
            counts[label] = program_operation_count(built[quantity][0])
        print(f"{name}: " + ", ".join(f"{k} {v}" for k, v in counts.items()))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="n = 2, 4, 8, 12; C up to n = 8 (< 1 min)")
    parser.add_argument("--csv", action="store_true", help="write benchmarks/results/complexity.csv")
    parser.add_argument("--plot", action="store_true", help="write docs/img/complexity.png")
    parser.add_argument("--robots", action="store_true", help="Panda and PUMA 560 counts only")
    parser.add_argument("--replot", action="store_true",
                        help="table and plot from benchmarks/results/complexity.csv, no measuring")
    parser.add_argument("--c-max-n", type=int, default=None, help="largest n for C (default 30; 8 with --quick)")
    args = parser.parse_args(argv)
    if args.robots:
        robots()
        return 0
    if args.replot:
        rows = read_csv(ROOT / "benchmarks" / "results" / "complexity.csv")
        print_table(rows)
        plot(rows, ROOT / "docs" / "img" / "complexity.png")
        return 0
    ns = QUICK_NS if args.quick else FULL_NS
    c_max = args.c_max_n if args.c_max_n is not None else (8 if args.quick else max(ns))
    rows = measure(ns, c_max, 8 if args.quick else max(ns))
    print()
    print_table(rows)
    if args.csv:
        write_csv(rows, ROOT / "benchmarks" / "results" / "complexity.csv")
    if args.plot:
        plot(rows, ROOT / "docs" / "img" / "complexity.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
