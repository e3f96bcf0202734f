"""Closed chains: the Delta robot's generation time and compiled speed (issue 26 loop targets).

    python benchmarks/loops_speed.py            # 3 generations, 15 interleaved timing batches
    python benchmarks/loops_speed.py --quick    # 1 generation, 5 batches

Prints, for the Delta robot of examples/robots/delta.yaml closed by examples/loops/
delta_loops.yaml (12 coordinates, 3 actuated joints, 3 point loops of 3 rows):

* the wall-clock time of ``eomgen generate`` (a fresh process, no cache) of the fast module
  with ``constrained_forward_dynamics``, ``loop_jacobian``, ``loop_constraint``,
  ``inverse_dynamics``: median and spread of the runs (target ≤ 30 s);
* the agreement of the fast module's ``constrained_forward_dynamics`` with Pinocchio's
  ``constraintDynamics`` on the same loops (three ``CONTACT_3D`` ``RigidConstraintModel`` between
  the platform joint and each forearm joint, ``LOCAL``, proximal ``mu = 0``): q̈ and the loop
  forces (``λ = −R_a λ_pin``, docs/loops.md);
* the time of one state, interleaved in the same run: the fast module's Python call
  ``constrained_forward_dynamics(q, qd, tau)`` (it allocates its result arrays) against
  ``pin.constraintDynamics(model, data, q, v, tau, models, datas, settings)`` from Python on
  Pinocchio's own arrays; medians and quartiles of the batches and the ratio of the medians
  (target ≤ 0.5);
* the fast module's ``parallel_inverse_dynamics(q, qd, qdd)`` (τ zero on the passive joints,
  and λ; solved in C), checked to give back the efforts and loop forces of the constrained
  motion and timed alike against the same Pinocchio call (Pinocchio has no parallel inverse
  dynamics; its constrained forward dynamics is the reference cost the target names); and,
  for comparison, the same composed in Python from the fast ``inverse_dynamics`` and
  ``loop_jacobian`` and one ``numpy.linalg.solve`` of ``[Sᵀ J_lᵀ]``.

Exit status 2 when a target is missed.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import subprocess
import sys
import tempfile
import time
import timeit
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import eomgen  # noqa: E402
from eomgen.numeric.loops import LoopDynamics  # noqa: E402
from eomgen.numeric.loops import pinocchio_loops  # noqa: E402
from eomgen.numeric.pinocchio import to_pinocchio  # noqa: E402
from eomgen.reduction import apply_scene  # noqa: E402
from eomgen.scene import load_scene  # noqa: E402

ROBOT = ROOT / "examples/robots/delta.yaml"
SCENE = ROOT / "examples/loops/delta_loops.yaml"
OUTPUTS = ("constrained_forward_dynamics,parallel_inverse_dynamics,loop_jacobian,loop_constraint,"
           "inverse_dynamics")
HOME = [0.3, 2.13, 0.0] * 3 + [0.0, 0.0, -0.35]


def rel(a, b) -> float:
    return float(np.abs(np.asarray(a) - b).max() / np.abs(b).max())


def summary(x) -> str:
    q1, med, q3 = np.percentile(x, [25, 50, 75])
    return f"median {med:.2f} µs (quartiles {q1:.2f}–{q3:.2f})"


def per_call(function, number: int = 2000) -> float:
    """Microseconds per call over one batch of ``number`` calls."""
    return timeit.Timer(function).timeit(number) / number * 1e6


def generate(out: str) -> float:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "eomgen.cli", "generate", str(ROBOT), "--scene",
                    str(SCENE), "--backend", "fast", "--outputs", OUTPUTS, "-o", out,
                    "--no-cache", "--quiet"], check=True, env=env, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    import pinocchio as pin

    runs, batches = (1, 5) if args.quick else (3, 15)
    with tempfile.TemporaryDirectory() as out:
        seconds = [generate(out) for _ in range(runs)]
        print(f"eomgen generate Delta (12 joints, 3 point loops), fast module ({OUTPUTS}): "
              f"median {np.median(seconds):.1f} s over {runs} runs (min {min(seconds):.1f}, "
              f"max {max(seconds):.1f}; target ≤ 30 s)")
        library = next(Path(out).glob("delta_fast.*.so"))
        spec = importlib.util.spec_from_file_location("delta_fast", library)
        fast = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(fast)

    model = apply_scene(eomgen.load(ROBOT), load_scene(SCENE)).model
    dyn = LoopDynamics(model)
    q = dyn.assemble(HOME)
    J = dyn.loop_jacobian(q)
    rng = np.random.default_rng(4)
    qd = np.linalg.svd(J)[2][9:].T @ rng.uniform(-1, 1, 3)
    tau = np.zeros(12)
    tau[dyn.actuated] = rng.uniform(-2, 2, 3)

    pm = to_pinocchio(model)
    p = pm.perm
    models = pinocchio_loops(model, pm)
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm.model, pm.data, models, datas)
    settings = pin.ProximalSettings(1e-14, 0.0, 1)
    q_pin, v_pin, tau_pin = q[p].copy(), qd[p].copy(), tau[p].copy()
    a = pin.constraintDynamics(pm.model, pm.data, q_pin, v_pin, tau_pin, models, datas, settings)
    qdd_pin = np.empty(12)
    qdd_pin[p] = a
    lam_pin = np.concatenate([-d.oMc1.rotation @ pm.data.lambda_c[3 * k:3 * k + 3]
                              for k, d in enumerate(datas)])
    qdd, lam = fast.constrained_forward_dynamics(q, qd, tau)
    agree = max(rel(qdd, qdd_pin), rel(lam, lam_pin))
    print(f"fast constrained_forward_dynamics vs Pinocchio constraintDynamics: {agree:.1e} "
          "(largest relative difference of q̈, λ)")

    act = dyn.actuated
    S_T = np.eye(12)[:, act]

    def parallel_inverse(q=q, qd=qd, qdd=qdd):
        A = np.hstack([S_T, fast.loop_jacobian(q).T])
        return np.linalg.solve(A, fast.inverse_dynamics(q, qd, qdd))

    x = parallel_inverse()
    tau_c, lam_c = fast.parallel_inverse_dynamics(q, qd, qdd)
    agree_id = max(rel(x[:3], tau[act]), rel(x[3:], lam_pin), rel(tau_c, tau), rel(lam_c, lam_pin))
    print(f"parallel inverse dynamics (compiled, and composed in Python) gives back τ_a and λ: "
          f"{agree_id:.1e}")

    ours, compiled, inverse, theirs = [], [], [], []
    for _ in range(batches):  # interleaved
        ours.append(per_call(lambda: fast.constrained_forward_dynamics(q, qd, tau)))
        compiled.append(per_call(lambda: fast.parallel_inverse_dynamics(q, qd, qdd)))
        inverse.append(per_call(parallel_inverse))
        theirs.append(per_call(lambda: pin.constraintDynamics(
            pm.model, pm.data, q_pin, v_pin, tau_pin, models, datas, settings)))
    ours, compiled, inverse, theirs = map(np.array, (ours, compiled, inverse, theirs))
    ratio = np.median(ours) / np.median(theirs)
    print(f"one state, {batches} batches of 2000 calls: eomgen fast constrained_forward_dynamics "
          f"{summary(ours)}; Pinocchio constraintDynamics {summary(theirs)}; ratio "
          f"{ratio:.2f} (target ≤ 0.5)")
    ratio_id = np.median(compiled) / np.median(theirs)
    print(f"one state: fast parallel_inverse_dynamics {summary(compiled)}; ratio to Pinocchio "
          f"constraintDynamics {ratio_id:.2f} (target ≤ 0.5)")
    print(f"one state: parallel inverse dynamics (fast kernels + NumPy solve, from Python) "
          f"{summary(inverse)}; ratio to Pinocchio constraintDynamics "
          f"{np.median(inverse) / np.median(theirs):.2f}")
    ok = (np.median(seconds) <= 30 and agree <= 1e-8 and agree_id <= 1e-8 and ratio <= 0.5
          and ratio_id <= 0.5)
    return 0 if ok else 2


if __name__ == "__main__":
    sys.exit(main())
