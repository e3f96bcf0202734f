"""Legged robots with the quaternion free flyer: solo12's fast module against Pinocchio, and the
time to derive and generate the full Talos humanoid (issue 27's targets).

1. **solo12, one state from Python.** eomgen's fast module (``floating_base: quaternion``,
   generated once with the outputs below) against Pinocchio's plain calls on its own model
   (``buildModelFromUrdf(path, JointModelFreeFlyer())``), on the same (q, v, a) arrays: no
   conversion exists or is timed, since the two layouts are one. τ (``rnea``), M (``crba``),
   q̈ (``aba``) and A_G (``computeCentroidalMap``); target ours/Pinocchio ≤ 0.5.
2. **Talos, full** (free flyer + every joint of ``talos_reduced.urdf``): wall time of derive +
   NumPy module + fast module (C compile included) with the default outputs; target ≤ 60 s;
   operation counts of M, h and A_G.

Every comparison first checks that both sides agree (≤ 1e-10 relative). Times are medians over
``--repeats`` timings with the spread (min–max); the ratio is the median of the per-repeat
ratios, both sides timed in turns in one process (CPU time, ``time.process_time``). Nothing
asserts on a time.

Usage::

    python benchmarks/legged_speed.py             # about two minutes (Talos compiles)
    python benchmarks/legged_speed.py --no-talos  # solo12 only
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # measure this checkout, not some installed copy
sys.path.insert(0, str(ROOT / "benchmarks"))

import eomgen  # noqa: E402
from codegen_speed import erd_robots_dir  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.codegen.functions import select_functions  # noqa: E402
from eomgen.model.floating import add_free_flyer  # noqa: E402
from fair_speed import spread, timed  # noqa: E402

SOLO = "solo_description/robots/solo12.urdf"
TALOS = "talos_data/robots/talos_reduced.urdf"
AGREEMENT = 1e-10

OUTPUTS = (  # (label, our function, its inputs, Pinocchio function, its inputs)
    ("τ", "inverse_dynamics", "q, v, a", "rnea", "q, v, a"),
    ("M", "mass_matrix", "q", "crba", "q"),
    ("q̈", "forward_dynamics_aba", "q, v, tau", "aba", "q, v, tau"),
    ("A_G", "centroidal_momentum_matrix", "q", "computeCentroidalMap", "q"),
)


def load(path: Path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return add_free_flyer(eomgen.load(path))


def fast_module(model, functions, folder: Path, backends=("fast",)):
    files = render_files(model, list(backends), functions=select_functions(functions))
    for f in files:
        (folder / f.name).write_bytes(f.content if isinstance(f.content, bytes)
                                      else f.content.encode("utf-8"))
    built = [folder / f.name for f in files if "_fast." in f.name and not f.name.endswith(".c")]
    if not built:
        sys.exit("legged_speed: the fast module was not compiled (no C compiler or Python.h)")
    spec = importlib.util.spec_from_file_location(built[0].name.split(".")[0], built[0])
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def solo(repeats: int, number: int) -> None:
    import pinocchio as pin

    path = erd_robots_dir() / SOLO
    model = load(path)
    with tempfile.TemporaryDirectory() as tmp:
        fast = fast_module(model, ("tau", "M", "qdd_aba", "A_G"), Path(tmp))
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = pm.createData()
    rng = np.random.default_rng(0)
    q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
    v, a = rng.normal(size=pm.nv), rng.normal(size=pm.nv)
    tau = pin.rnea(pm, data, q, v, a).copy()
    namespace = {"fast": fast, "pin": pin, "model": pm, "data": data,
                 "q": q, "v": v, "a": a, "tau": tau}
    print(f"solo12, quaternion free flyer (NQ = {pm.nq}, NV = {pm.nv}), one state from Python, "
          f"µs per call, median (min–max) of {repeats} × {number} calls, CPU time")
    print(f"{'':5} {'eomgen fast':>24} {'Pinocchio':>24} {'ratio':>22}  target ≤ 0.5")
    for label, ours, our_args, theirs, their_args in OUTPUTS:
        mine = np.asarray(eval(f"fast.{ours}({our_args})", namespace))
        reference = np.asarray(eval(f"pin.{theirs}(model, data, {their_args})", namespace))
        if theirs == "crba":
            reference = np.triu(reference) + np.triu(reference, 1).T
        error = np.abs(mine.reshape(reference.shape) - reference).max() / np.abs(reference).max()
        if error > AGREEMENT:
            sys.exit(f"legged_speed: {label} disagrees with Pinocchio ({error:.1e})")
        samples, ratios = timed({"ours": f"fast.{ours}({our_args})",
                                 "pin": f"pin.{theirs}(model, data, {their_args})"},
                                namespace, number, repeats)
        verdict = "met" if statistics.median(ratios["ours"]) <= 0.5 else "not met"
        print(f"{label:5} {spread(samples['ours'], '.2f'):>24} {spread(samples['pin'], '.2f'):>24}"
              f" {spread(ratios['ours'], '.2f'):>22}  {verdict}")


def talos() -> None:
    import resource

    path = erd_robots_dir() / TALOS
    start = time.perf_counter()
    model = load(path)
    dyn = eomgen.derive(model, outputs=("M", "C", "g", "tau", "h", "A_G"))
    derived = time.perf_counter() - start
    counts = {name: dyn.program.operation_count([name]) for name in ("M", "h", "A_G")}
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        files = render_files(model, ["numpy", "fast"])
        for f in files:
            (Path(tmp) / f.name).write_bytes(f.content if isinstance(f.content, bytes)
                                             else f.content.encode("utf-8"))
        generated = time.perf_counter() - start
        numpy_module = [Path(tmp) / f.name for f in files if f.name.endswith("_numpy.py")][0]
        spec = importlib.util.spec_from_file_location(numpy_module.stem, numpy_module)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        check_talos(path, module)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    total = derived + generated
    print(f"\nTalos full (NQ = {model.nq}, NV = {model.dof}): derive (M, C, g, tau, h, A_G) "
          f"{derived:.1f} s; NumPy + fast modules with the default outputs (derive, print, C "
          f"compile) {generated:.1f} s; total {total:.1f} s (target ≤ 60 s: "
          f"{'met' if total <= 60 else 'not met'}); peak memory {peak:.0f} MB")
    print("operations: " + ", ".join(f"{k} {v:,}" for k, v in counts.items()))


def check_talos(path: Path, module) -> None:
    """The generated Talos module against Pinocchio's free flyer on one random state, the
    same arrays on both sides: M, C, g and τ (≤ 1e-10 relative, else the benchmark stops)."""
    import pinocchio as pin

    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = pm.createData()
    q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
    rng = np.random.default_rng(1)
    v, a = rng.normal(size=pm.nv), rng.normal(size=pm.nv)
    M = pin.crba(pm, data, q)
    pairs = {"M": (module.mass_matrix(q), np.triu(M) + np.triu(M, 1).T),
             "C": (module.coriolis_matrix(q, v), pin.computeCoriolisMatrix(pm, data, q, v)),
             "g": (module.gravity_vector(q), pin.computeGeneralizedGravity(pm, data, q)),
             "tau": (module.inverse_dynamics(q, v, a), pin.rnea(pm, data, q, v, a))}
    worst = max(np.abs(ours - theirs).max() / np.abs(theirs).max()
                for ours, theirs in pairs.values())
    if worst > AGREEMENT:
        sys.exit(f"legged_speed: Talos disagrees with Pinocchio ({worst:.1e})")
    print(f"Talos: M, C, g, tau equal Pinocchio's to {worst:.1e} (relative)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--number", type=int, default=2000)
    parser.add_argument("--no-talos", action="store_true")
    args = parser.parse_args()
    solo(args.repeats, args.number)
    if not args.no_talos:
        talos()


if __name__ == "__main__":
    main()
