"""Generated derivatives against Pinocchio's from Python (issue 25; Franka Panda, fingers locked).

Each side is timed through its plain public call on data already in its own layout:
``pin.computeRNEADerivatives(model, data, q, qd, qdd)`` and
``pin.computeABADerivatives(model, data, q, qd, tau)`` on Pinocchio's own reduced model of the
URDF (joint order equal to eomgen's, so nothing is converted or timed), against the fast module's
``inverse_dynamics_derivatives(q, qd, qdd)`` → (∂τ/∂q, ∂τ/∂q̇) and
``forward_dynamics_derivatives(q, qd, tau)`` → (∂q̈/∂q, ∂q̈/∂q̇, M⁻¹), and
``gravity_derivative`` against ``pin.computeGeneralizedGravityDerivatives``.

Differences that favour neither side much, stated: Pinocchio's RNEA derivatives also return
∂τ/∂q̈ = M (upper triangle), its ABA derivatives fill only the upper triangle of M⁻¹ (ours is
full); each of our calls allocates its NumPy results.

1. One state from Python: target fast / Pinocchio ≤ 0.5.
2. A batch of 1,000 states: the fast module on the (N, 7) arrays (loop in C) against a Python
   loop of the plain Pinocchio calls storing into preallocated arrays; target ≤ 1/5.

Both sides first agree (≤ 1e-10 relative to the largest entry). Times are medians over the
repeats with the spread (min–max); ratios are medians of per-repeat ratios, both sides timed in
turns in one process; CPU clock (``time.process_time``) unless ``--clock wall``. Nothing asserts
on a time.

Usage::

    python benchmarks/derivatives_speed.py            # about a minute
    python benchmarks/derivatives_speed.py --quick
    python benchmarks/derivatives_speed.py --markdown benchmarks/results/derivatives_speed.md
"""

from __future__ import annotations

import argparse
import importlib.util
import platform
import statistics
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # measure this checkout, not some installed copy
sys.path.insert(0, str(ROOT / "benchmarks"))

import eomgen  # noqa: E402
from codegen_speed import erd_robots_dir  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402
from fair_speed import CLOCK, LOCKED, pinocchio_panda, spread, timed  # noqa: E402

AGREEMENT = 1e-10
FUNCTIONS = ("inverse_dynamics_derivatives", "forward_dynamics_derivatives",
             "gravity_derivative")
#: (label, our call, Pinocchio's call, number of results compared)
PAIRS = (
    ("∂τ/∂(q, q̇)", "fast.inverse_dynamics_derivatives(q, qd, qdd)",
     "pin.computeRNEADerivatives(model, data, q, qd, qdd)", 2),
    ("∂q̈/∂(q, q̇, τ)", "fast.forward_dynamics_derivatives(q, qd, tau)",
     "pin.computeABADerivatives(model, data, q, qd, tau)", 3),
    ("∂g/∂q", "fast.gravity_derivative(q)",
     "pin.computeGeneralizedGravityDerivatives(model, data, q)", 1),
)


def panda_fast_module(folder: Path):
    """Generate the Panda's fast module with the derivative functions and import it; also the
    URDF's path."""
    path = erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = lock_joints(eomgen.load(path), LOCKED)
    files = render_files(model, ["fast"], functions=FUNCTIONS)
    for f in files:
        (folder / f.name).write_bytes(f.content if isinstance(f.content, bytes)
                                      else f.content.encode("utf-8"))
    built = [folder / f.name for f in files if f.name.startswith("panda_fast.")
             and not f.name.endswith(".c")]
    if not built:
        sys.exit("derivatives_speed: the fast module was not compiled (no C compiler?)")
    spec = importlib.util.spec_from_file_location("panda_fast", built[0])
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return path, module


def _parts(result, count):
    parts = result if isinstance(result, tuple) else (result,)
    return [np.asarray(p) for p in parts[:count]]


def agree(ours, theirs, count, what):
    for k, (a, b) in enumerate(zip(_parts(ours, count), _parts(theirs, count))):
        if what.startswith("∂q̈") and k == 2:  # Pinocchio fills the upper triangle of M⁻¹
            a, b = np.triu(a), np.triu(b)
        error = np.abs(a - b).max() / np.abs(b).max()
        if error > AGREEMENT:
            sys.exit(f"derivatives_speed: {what} result {k} differs by {error:.1e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--clock", choices=sorted(CLOCK), default="cpu")
    parser.add_argument("--markdown", type=Path, help="also write the tables to this file")
    args = parser.parse_args()
    calls, repeats, batch_repeats = (2_000, 5, 3) if args.quick else (20_000, 9, 7)
    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    with tempfile.TemporaryDirectory() as tmp:
        path, fast = panda_fast_module(Path(tmp))
        pin, model, data = pinocchio_panda(path, fast.JOINT_NAMES)
        say(f"Panda, 7 joints (fingers locked). Python {platform.python_version()}, NumPy "
            f"{np.__version__}, Pinocchio {pin.__version__}, eomgen {eomgen.__version__}, "
            f"{platform.machine()}; {args.clock} clock.")
        rng = np.random.default_rng(0)
        q, qd, qdd = (rng.uniform(-1.5, 1.5, 7) for _ in range(3))
        tau = pin.rnea(model, data, q, qd, qdd)
        namespace = dict(fast=fast, pin=pin, model=model, data=data, q=q, qd=qd, qdd=qdd,
                         tau=tau)
        for label, ours, theirs, count in PAIRS:
            agree(eval(ours, namespace), eval(theirs, namespace), count, label)  # noqa: S307
        say()
        say(f"One state from Python, µs per call: median (min–max) over {repeats} repeats of "
            f"{calls} calls; ratio = median of per-repeat ratios.")
        say()
        say("| output | fast module | plain Pinocchio call | fast / Pinocchio | target | met |")
        say("|---|---:|---:|---:|---:|---|")
        for label, ours, theirs, count in PAIRS:
            samples, ratios = timed({"ours": ours, "pin": theirs}, namespace, calls, repeats,
                                    clock=CLOCK[args.clock])
            ratio = statistics.median(ratios["ours"])
            name = theirs.split("(")[0]
            say(f"| {label} | {spread(samples['ours'], '.2f')} | "
                f"{spread(samples['pin'], '.2f')} (`{name}`) | {ratio:.2f} | ≤ 0.50 | "
                f"{'yes' if ratio <= 0.5 else 'NO'} |")

        N = 1_000
        Q, QD, QDD = (rng.uniform(-1.5, 1.5, (N, 7)) for _ in range(3))
        TAU = np.array([pin.rnea(model, data, Q[k], QD[k], QDD[k]) for k in range(N)])
        namespace.update(Q=Q, QD=QD, QDD=QDD, TAU=TAU, N=N, np=np)
        exec("def loop_rnea():\n"  # noqa: S102 - our own loop
             "    a, b = np.empty((N, 7, 7)), np.empty((N, 7, 7))\n"
             "    for k in range(N):\n"
             "        a[k], b[k], _ = pin.computeRNEADerivatives(model, data, Q[k], QD[k], QDD[k])\n"
             "    return a, b\n"
             "def loop_aba():\n"
             "    a, b, c = np.empty((N, 7, 7)), np.empty((N, 7, 7)), np.empty((N, 7, 7))\n"
             "    for k in range(N):\n"
             "        a[k], b[k], c[k] = pin.computeABADerivatives(model, data, Q[k], QD[k], TAU[k])\n"
             "    return a, b, c\n"
             "def loop_gravity():\n"
             "    a = np.empty((N, 7, 7))\n"
             "    for k in range(N):\n"
             "        a[k] = pin.computeGeneralizedGravityDerivatives(model, data, Q[k])\n"
             "    return a\n", namespace)
        batch = (("∂τ/∂(q, q̇)", "fast.inverse_dynamics_derivatives(Q, QD, QDD)", "loop_rnea()", 2),
                 ("∂q̈/∂(q, q̇, τ)", "fast.forward_dynamics_derivatives(Q, QD, TAU)",
                  "loop_aba()", 3),
                 ("∂g/∂q", "fast.gravity_derivative(Q)", "loop_gravity()", 1))
        say()
        say(f"Batch of {N:,} states, µs per state: median (min–max) over {batch_repeats} "
            "repeats; Pinocchio: a Python loop of plain calls storing into arrays.")
        say()
        say("| output | fast module (loop in C) | Pinocchio loop | fast / Pinocchio | target | "
            "met |")
        say("|---|---:|---:|---:|---:|---|")
        for label, ours, theirs, count in batch:
            agree(eval(ours, namespace), eval(theirs, namespace), count, label)  # noqa: S307
            samples, ratios = timed({"ours": ours, "pin": theirs}, namespace, 1, batch_repeats,
                                    units=N, clock=CLOCK[args.clock])
            ratio = statistics.median(ratios["ours"])
            say(f"| {label} | {spread(samples['ours'], '.3f')} | {spread(samples['pin'], '.2f')} "
                f"| {ratio:.3f} | ≤ 0.200 | {'yes' if ratio <= 0.2 else 'NO'} |")
    if args.markdown:
        args.markdown.parent.mkdir(parents=True, exist_ok=True)
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
