"""Flexible joints (Spong's model): build time, integrators on a stiff system, the K → ∞ limit.

Usage::

    python benchmarks/flexible_joints.py [--md benchmarks/results/flexible_joints.md]
                                         [--plot docs/img/flexible_step.png] [--duration 2]

1. **Panda, 7 flexible joints** (example-robot-data ``panda.urdf`` with the scene
   ``examples/scenes/panda_flexible.yaml``: K = 1e4 N m/rad, motor inertia 0.1 kg m², fingers
   locked): seconds to load, derive (``eomgen.derive``), compile the numeric model with the
   flatness program (:func:`eomgen.analysis.actuators.actuated_model`) and print that program on first
   use (the first :func:`~eomgen.analysis.actuators.flexible_inverse_dynamics` call). Target: ≤ 30 s.
2. **Integrators on the stiff system**: the Panda released from rest at a bent posture with the
   springs wound for gravity, no input and no friction (the URDF's damping set to 0), for
   ``--duration`` seconds with SciPy's ``solve_ivp`` (RK45, DOP853, Radau, BDF, LSODA; rtol =
   atol = 1e-8): right-hand-side calls, accepted steps, CPU seconds and the energy error
   max |E(t) − E(0)| / (max E − min E over the links' potential range), E the total energy of
   :func:`~eomgen.analysis.actuators.flexible_energy`. The highest joint frequency sqrt(K (1/B + 1/m))
   is printed to show the stiffness.
3. **K → ∞** on the 2-link flexible arm (``examples/robots/flexible_2link.yaml``): link angles
   after 0.5 s under constant torques against the rigid model with reflected inertia
   ``M + diag(B)``, for K = 1e2 … 1e6.
4. **A step in τ_m** on the 2-link arm (K = 1e3): link angle against motor angle, plotted.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import eomgen  # noqa: E402
from eomgen import actuators as A  # noqa: E402
from eomgen.reduction import apply_scene, load_for_scene  # noqa: E402
from eomgen.scene import load_scene  # noqa: E402

PANDA_Q0 = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")


def robots_dir() -> Path:
    if os.environ.get("EXAMPLE_ROBOT_DATA_ROBOTS"):
        return Path(os.environ["EXAMPLE_ROBOT_DATA_ROBOTS"])
    from support import erd_robots_dir

    found = erd_robots_dir()
    if found is None:
        sys.exit("example-robot-data is not installed")
    return found


def build_panda():
    times = {}
    start = time.process_time()
    scene = load_scene(ROOT / "examples/scenes/panda_flexible.yaml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = apply_scene(load_for_scene(robots_dir() / "panda_description/urdf/panda.urdf",
                                           scene), scene).model
    times["load + scene"] = time.process_time() - start
    start = time.process_time()
    dyn = eomgen.derive(model)
    times["derive"] = time.process_time() - start
    start = time.process_time()
    am = A.actuated_model(dyn)
    times["actuated_model"] = time.process_time() - start
    start = time.process_time()
    A.flexible_inverse_dynamics(am, PANDA_Q0, *np.zeros((4, 7)))
    times["flatness program (first call)"] = time.process_time() - start
    return am, times


def integrators(am, duration: float):
    am = replace(am, damping=np.zeros(am.n), friction=np.zeros(am.n))
    x0 = A.flexible_rest_state(am, PANDA_Q0)  # wound for gravity: no input → it falls
    E0 = A.flexible_energy(am, x0)
    rows = []
    for method in METHODS:
        calls = [0]

        def f(t, x):
            calls[0] += 1
            return A.flexible_forward_dynamics(am, x, np.zeros(am.n))

        start = time.process_time()
        result = solve_ivp(f, (0, duration), x0, method=method, rtol=1e-8, atol=1e-8)
        cpu = time.process_time() - start
        energy = np.array([A.flexible_energy(am, x) for x in result.y.T])
        steps = len(result.t) - 1
        rows.append((method, result.success, calls[0], steps, cpu,
                     float(np.abs(energy - E0).max()), float(np.ptp(result.y[:7], axis=1).max())))
    M, _, _ = am.rigid_terms(PANDA_Q0, np.zeros(am.n))
    omega = np.sqrt(am.stiffness * (1 / am.armature + 1 / np.diag(M))).max()
    return rows, E0, omega


def stiff_limit():
    arm = eomgen.load(ROOT / "examples/robots/flexible_2link.yaml")
    dyn = eomgen.derive(arm)
    rigid = A.actuated_model(dyn)
    q0, tau = np.array([0.3, 0.5]), np.array([2.0, -1.0])
    ref = solve_ivp(lambda t, x: np.concatenate(
        [x[2:], A.rigid_forward_dynamics(rigid, x[:2], x[2:], tau)]), (0, 0.5),
        np.concatenate([q0, [0, 0]]), method="DOP853", rtol=1e-11, atol=1e-11)
    rows = []
    for K in (1e2, 1e3, 1e4, 1e5, 1e6):
        am = A.actuated_model(dyn, {"K1": K, "K2": K})
        result = solve_ivp(lambda t, x: A.flexible_forward_dynamics(am, x, tau), (0, 0.5),
                           A.flexible_rest_state(am, q0), method="DOP853", rtol=1e-10,
                           atol=1e-10)
        rows.append((K, float(np.abs(result.y[:2, -1] - ref.y[:2, -1]).max())))
    return rows


def step_plot(path: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    am = A.actuated_model(eomgen.derive(eomgen.load(ROOT / "examples/robots/flexible_2link.yaml")))
    q0 = np.array([-np.pi / 2, 0.0])  # hanging down: g(q0) = 0
    x0 = A.flexible_rest_state(am, q0)
    step = np.array([5.0, 0.0])  # N m on motor 1 from t = 0
    result = solve_ivp(lambda t, x: A.flexible_forward_dynamics(am, x, step), (0, 1.0), x0,
                       method="DOP853", rtol=1e-10, atol=1e-10, dense_output=True)
    t = np.linspace(0, 1.0, 1001)
    x = result.sol(t)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    top.plot(t, x[0], label="link angle $q_1$")
    top.plot(t, x[4], "--", label=r"motor angle $\theta_1$")
    top.set_ylabel("rad")
    top.legend()
    top.set_title(r"Flexible 2-link arm, step $\tau_{m,1}$ = 5 N m (K = 1e3 N m/rad, B = 0.5 kg m²)")
    bottom.plot(t, x[4] - x[0], color="C2", label=r"spring deflection $\theta_1 - q_1$")
    bottom.set_xlabel("t [s]")
    bottom.set_ylabel("rad")
    bottom.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100, metadata={"Software": None})
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=2.0)
    parser.add_argument("--md", type=Path, help="write the tables as Markdown to this file")
    parser.add_argument("--plot", type=Path, help="write the step-response plot (PNG)")
    args = parser.parse_args()
    lines = []
    am, times = build_panda()
    total = sum(times.values())
    lines += ["## Panda, 7 flexible joints: building the model (CPU seconds)", "",
              "| stage | s |", "| --- | ---: |"]
    lines += [f"| {k} | {v:.2f} |" for k, v in times.items()]
    lines += [f"| **total** (target ≤ 30) | **{total:.2f}** |", ""]
    rows, E0, omega = integrators(am, args.duration)
    lines += [f"## Panda released for {args.duration:g} s, K = 1e4 N m/rad (stiff: highest "
              f"joint frequency {omega:.0f} rad/s), no input, no friction", "",
              f"E(0) = {E0:.6g} J; rtol = atol = 1e-8.", "",
              "| integrator | success | rhs calls | steps | CPU s | max abs energy error [J] |"
              " largest link swing [rad] |",
              "| --- | --- | ---: | ---: | ---: | ---: | ---: |"]
    lines += [f"| {m} | {ok} | {c} | {s} | {cpu:.2f} | {e:.2e} | {swing:.3f} |"
              for m, ok, c, s, cpu, e, swing in rows]
    lines += ["", "## K → ∞: 2-link flexible arm against the rigid model with M + diag(B)", "",
              "| K [N m/rad] | max link angle difference at 0.5 s [rad] |", "| ---: | ---: |"]
    lines += [f"| {K:.0e} | {e:.3e} |" for K, e in stiff_limit()]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.md:
        args.md.write_text("# Flexible joints (benchmarks/flexible_joints.py)\n\n" + text,
                           encoding="utf-8")
    if args.plot:
        step_plot(args.plot)


if __name__ == "__main__":
    main()
