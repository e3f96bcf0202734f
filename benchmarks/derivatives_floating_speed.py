"""Generated derivatives of a quaternion free flyer and of its contact-constrained dynamics
against Pinocchio's, from Python (issue 25; the solo12, quaternion base, four feet held).

Each side is timed through its plain public call on data in its own layout (Pinocchio reads the
same URDF with ``JointModelFreeFlyer``; q = (x, y, z, quaternion x, y, z, w, legs), v the body
twist and the legs' rates, identical in both, so nothing is converted):

* ``fast.inverse_dynamics_derivatives(q, v, a)`` → (∂τ/∂q along the tangent, ∂τ/∂v) against
  ``pin.computeRNEADerivatives``;
* ``fast.forward_dynamics_derivatives(q, v, tau)`` → (∂q̈/∂q, ∂q̈/∂v, M⁻¹) against
  ``pin.computeABADerivatives``;
* ``constrained_forward_dynamics_derivatives(q, v, tau)`` (the KKT solve for q̈ and F_c, the
  partials, the solve for the six derivatives with the same factors), of the fast module (in
  C) and of the NumPy module (composed in Python), against ``pin.constraintDynamics`` followed
  by ``pin.computeConstraintDynamicsDerivatives`` (``CONTACT_3D``, ``LOCAL_WORLD_ALIGNED``);
  and the fast module's printed partials alone (``constrained_dynamics_partials``) against the
  same pair.

Both sides first agree (≤ 1e-8 relative to the largest entry: Pinocchio's proximal solver for
the contacts). Times are medians over the repeats with the spread (min–max); ratios are medians
of per-repeat ratios, both sides timed in turns in one process; CPU clock unless
``--clock wall``. Nothing asserts on a time. Generating the modules takes minutes (the
derivation of the 18-joint derivatives, then the C compile).

Usage::

    python benchmarks/derivatives_floating_speed.py
    python benchmarks/derivatives_floating_speed.py --quick --markdown benchmarks/results/derivatives_floating_speed.md
"""

from __future__ import annotations

import argparse
import platform
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # measure this checkout, not some installed copy
sys.path.insert(0, str(ROOT / "benchmarks"))

import eomgen  # noqa: E402
from codegen_speed import erd_robots_dir  # noqa: E402
from eomgen.codegen import loadable_backends  # noqa: E402
from eomgen.codegen.functions import module_name  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.reduction import apply_scene  # noqa: E402
from eomgen.scene import load_scene  # noqa: E402
from fair_speed import CLOCK, spread, timed  # noqa: E402

AGREEMENT = 1e-8
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
FAST = ("inverse_dynamics_derivatives", "forward_dynamics_derivatives",
        "constrained_dynamics_partials", "constrained_forward_dynamics_derivatives")
NUMPY = ("constrained_forward_dynamics_derivatives",)


def solo_modules(folder: Path):
    """The solo12 with a quaternion base and its feet held: (URDF path, model, fast module,
    NumPy module namespace, seconds to generate)."""
    path = erd_robots_dir() / "solo_description" / "robots" / "solo12.urdf"
    scene = "version: 1\nfloating_base: quaternion\ncontacts:\n" + "".join(
        f"  - {{frame: {f}}}\n" for f in FEET)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = apply_scene(eomgen.load(path), load_scene("s.yaml", text=scene)).model
    start, stem = time.perf_counter(), module_name(model.name)
    if not list(folder.glob(f"{stem}_fast.*.so")):  # --build: modules made by an earlier run
        for backend, functions in (("fast", FAST), ("numpy", NUMPY)):
            for f in render_files(model, [backend], functions=functions):
                (folder / f.name).write_bytes(f.content if isinstance(f.content, bytes)
                                              else f.content.encode("utf-8"))
    seconds = time.perf_counter() - start
    fast = SimpleNamespace(**loadable_backends()["fast"].load(folder, stem).namespace)
    numpy_module = loadable_backends()["numpy"].load(folder, stem).namespace
    return path, model, fast, numpy_module, seconds


def pinocchio_solo(path: Path):
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    constraints = pin.StdVec_RigidConstraintModel()
    for foot in FEET:
        frame = model.frames[model.getFrameId(foot)]
        constraints.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model,
                                                    frame.parentJoint, frame.placement,
                                                    pin.LOCAL_WORLD_ALIGNED))
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in constraints])
    pin.initConstraintDynamics(model, data, constraints, datas)
    return pin, model, data, constraints, datas


def agree(ours, theirs, what: str) -> None:
    for k, (a, b) in enumerate(zip(ours, theirs)):
        a, b = np.asarray(a), np.asarray(b)
        if what.startswith("∂q̈") and k == 2:  # Pinocchio fills the upper triangle of M⁻¹
            a, b = np.triu(a), np.triu(b)
        error = np.abs(a - b).max() / max(1.0, np.abs(b).max())
        if error > AGREEMENT:
            sys.exit(f"derivatives_floating_speed: {what} result {k} differs by {error:.1e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--clock", choices=sorted(CLOCK), default="cpu")
    parser.add_argument("--markdown", type=Path, help="also write the tables to this file")
    parser.add_argument("--build", type=Path, help="keep the generated modules in this folder "
                        "(and reuse them when it holds them already)")
    args = parser.parse_args()
    calls, repeats = (1_000, 5) if args.quick else (10_000, 9)
    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    with tempfile.TemporaryDirectory() as tmp:
        folder = args.build or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        path, model, fast, np_module, seconds = solo_modules(folder)
        pin, pm, data, constraints, datas = pinocchio_solo(path)
        assert list(pm.names[2:]) == list(model.joint_names[6:])
        say(f"solo12, quaternion base (NQ {model.nq}, NV {model.dof}), four feet held (m = 12). "
            f"Python {platform.python_version()}, NumPy {np.__version__}, Pinocchio "
            f"{pin.__version__}, eomgen {eomgen.__version__}, {platform.machine()}; "
            f"{args.clock} clock; modules generated (or loaded) in {seconds:.0f} s.")
        rng = np.random.default_rng(0)
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        v, a = rng.normal(size=pm.nv), rng.normal(size=pm.nv)
        tau = pin.rnea(pm, data, q, v, a)
        settings = pin.ProximalSettings(1e-14, 1e-12, 1)

        def pin_constrained():
            pin.constraintDynamics(pm, data, q, v, tau, constraints, datas, settings)
            pin.computeConstraintDynamicsDerivatives(pm, data, constraints, datas)
            return (data.ddq_dq, data.ddq_dv, data.ddq_dtau, data.dlambda_dq, data.dlambda_dv,
                    data.dlambda_dtau)

        ddq, F = np_module["constrained_forward_dynamics"](q, v, tau)
        partials = fast.constrained_dynamics_partials
        namespace = dict(fast=fast, np_module=np_module, pin=pin, model=pm, data=data, q=q,
                         v=v, a=a, tau=tau, ddq=ddq, F=F, partials=partials,
                         pin_constrained=pin_constrained,
                         ours_constrained=np_module["constrained_forward_dynamics_derivatives"])
        pairs = (
            ("∂τ/∂(q, v)", "fast.inverse_dynamics_derivatives(q, v, a)",
             "pin.computeRNEADerivatives(model, data, q, v, a)", 2),
            ("∂q̈/∂(q, v, τ)", "fast.forward_dynamics_derivatives(q, v, tau)",
             "pin.computeABADerivatives(model, data, q, v, tau)", 3),
            ("∂(q̈, F_c)/∂(q, v, τ)", "fast.constrained_forward_dynamics_derivatives(q, v, tau)",
             "pin_constrained()", 6),
            ("∂(q̈, F_c)/∂(q, v, τ), NumPy", "ours_constrained(q, v, tau)", "pin_constrained()",
             6),
            ("KKT partials only (fast)", "partials(q, v, ddq, F)", "pin_constrained()", 0),
        )
        for label, ours, theirs, count in pairs:
            if count:
                result = eval(theirs, namespace)  # noqa: S307
                reference = [np.array(x) for x in result][:count]
                agree(list(eval(ours, namespace))[:count], reference, label)  # noqa: S307
        say()
        say(f"One state from Python, µs per call: median (min–max) over {repeats} repeats of "
            f"{calls} calls ({calls // 100} for the NumPy module); ratio = median of per-repeat "
            "ratios (min–max).")
        say()
        say("| output | eomgen | Pinocchio | eomgen / Pinocchio |")
        say("|---|---:|---:|---:|")
        for label, ours, theirs, _ in pairs:  # the NumPy module: ms per call, fewer calls
            number = calls // 100 if "NumPy" in label else calls
            samples, ratios = timed({"ours": ours, "pin": theirs}, namespace, number, repeats,
                                    clock=CLOCK[args.clock])
            say(f"| {label} | {spread(samples['ours'], '.1f')} (`{ours.split('(')[0]}`) | "
                f"{spread(samples['pin'], '.1f')} | {statistics.median(ratios['ours']):.2f} "
                f"({min(ratios['ours']):.2f}–{max(ratios['ours']):.2f}) |")
    if args.markdown:
        args.markdown.parent.mkdir(parents=True, exist_ok=True)
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
