"""Forward dynamics of the Panda by the generated Articulated-Body Algorithm against the
generated Cholesky route, and the nonlinear effects h = C q̇ + g against C q̇ + g: operation
counts and time per state, measured in one run.

Usage::

    python benchmarks/aba_speed.py            # 7 repeats
    python benchmarks/aba_speed.py --quick    # 3 repeats

The Panda is example-robot-data's ``panda.urdf`` with the fingers locked (7 joints). Operations are
counted by :mod:`eomgen.symbolic.opcount` from the generated NumPy code. Both routes
come from the same generated modules (``--outputs forward_dynamics,qdd_aba,h,C,g``):

* ``forward_dynamics``: M(q) and τ(q, q̇, 0) printed, then a Cholesky solve (NumPy or C);
* ``forward_dynamics_aba``: the ABA printed as one straight-line program (no factorisation).

Times are CPU µs per state (``time.process_time``), medians over the repeats with the range in
brackets, for one state (the fast C module, whose per-call cost is what a one-state user pays)
and for a batch of 1000 states (the NumPy module). Ratios are taken per repeat. Pinocchio's
``aba`` on the same state is shown for scale (its plain public call, data in its layout).
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import eomgen  # noqa: E402
from eomgen.codegen.functions import select_functions  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402
from eomgen.symbolic.opcount import module_operation_counts  # noqa: E402
from fair_speed import LOCKED, erd_robots_dir, pinocchio_panda, spread, timed  # noqa: E402

FUNCTIONS = select_functions(["forward_dynamics", "qdd_aba", "h", "C", "g"])


def modules(folder: Path):
    path = erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = lock_joints(eomgen.load(path), LOCKED)
    files = render_files(model, ["numpy", "fast"], functions=FUNCTIONS)
    loaded = {}
    for f in files:
        (folder / f.name).write_bytes(f.content if isinstance(f.content, bytes)
                                      else f.content.encode("utf-8"))
    for suffix in ("_numpy", "_fast"):
        target = next(folder / f.name for f in files if f.name.startswith("panda" + suffix + ".")
                      and not f.name.endswith(".c"))
        spec = importlib.util.spec_from_file_location("panda" + suffix, target)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        loaded[suffix[1:]] = module
    source = next(f.content for f in files if f.name.endswith("_numpy.py"))
    return path, model, loaded, module_operation_counts(source)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    repeats = 3 if args.quick else 7
    with tempfile.TemporaryDirectory() as tmp:
        path, model, mods, counts = modules(Path(tmp))
        fast, numpy_module = mods["fast"], mods["numpy"]
        pin, pmodel, data = pinocchio_panda(path, model.joint_names)
        rng = np.random.default_rng(0)
        q, qd, tau = (rng.uniform(-1, 1, 7) for _ in range(3))
        Q, QD, TAU = (rng.uniform(-1, 1, (1000, 7)) for _ in range(3))
        ours = fast.forward_dynamics_aba(q, qd, tau)
        err = np.abs(ours - pin.aba(pmodel, data, q, qd, tau)).max() / np.abs(ours).max()
        chol = counts["mass_matrix"] + counts["inverse_dynamics"]
        print(f"Panda, 7 joints. Operation counts of the generated functions: "
              f"forward_dynamics_aba {counts['forward_dynamics_aba']}; Cholesky route "
              f"M {counts['mass_matrix']} + tau {counts['inverse_dynamics']} = {chol} "
              f"before the 7x7 solve (~{7**3 // 3 + 2 * 49} more); nonlinear_effects "
              f"{counts['nonlinear_effects']}; C {counts['coriolis_matrix']} + g "
              f"{counts['gravity_vector']} (then C qd).")
        print(f"ABA vs Pinocchio aba: max relative difference {err:.1e}")
        namespace = dict(np=np, fast=fast, np_mod=numpy_module, pin=pin, pmodel=pmodel, data=data,
                         q=q, qd=qd, tau=tau, Q=Q, QD=QD, TAU=TAU)
        single = {
            "fast forward_dynamics_aba": "fast.forward_dynamics_aba(q, qd, tau)",
            "Pinocchio aba": "pin.aba(pmodel, data, q, qd, tau)",
            "fast forward_dynamics (Cholesky)": "fast.forward_dynamics(q, qd, tau)",
        }
        samples, ratios = timed(single, namespace, 20000, repeats)
        print("\nOne state, fast C module (CPU µs per call; ratio to the Cholesky route):")
        for k in single:
            print(f"  {k:34s} {spread(samples[k], '.2f')} µs   ratio {spread(ratios[k], '.2f')}")
        batch = {
            "numpy forward_dynamics_aba": "np_mod.forward_dynamics_aba(Q, QD, TAU)",
            "numpy h = nonlinear_effects": "np_mod.nonlinear_effects(Q, QD)",
            "numpy C qd + g": "np.einsum('nij,nj->ni', np_mod.coriolis_matrix(Q, QD), QD)"
                              " + np_mod.gravity_vector(Q)",
            "numpy forward_dynamics (Cholesky)": "np_mod.forward_dynamics(Q, QD, TAU)",
        }
        samples, ratios = timed(batch, namespace, 20, repeats, units=1000)
        print("\nBatch of 1000 states, NumPy module (CPU µs per state; ratio to the Cholesky "
              "route):")
        for k in batch:
            print(f"  {k:34s} {spread(samples[k], '.2f')} µs   ratio {spread(ratios[k], '.2f')}")
        print(f"\n(h vs C qd + g, batch: "
              f"{statistics.median(samples['numpy h = nonlinear_effects']) / statistics.median(samples['numpy C qd + g']):.2f}x)")


if __name__ == "__main__":
    main()
