"""MuJoCo models whole (issue 41): gymnasium's models with their own actuators and springs,
against MuJoCo's accelerations, and the fast module's ``forward_dynamics_ctrl`` timed against
``mujoco.mj_forward`` in the same run.

Usage::

    pip install -e ".[simulators,mjcf-models]"
    python benchmarks/mjcf_whole.py                      # the nine models of the issue's target
    python benchmarks/mjcf_whole.py hopper humanoid --no-speed
    python benchmarks/mjcf_whole.py --folder dm_control/suite acrobot cartpole quadruped
                                   # dm_control's suite: `pip download --no-deps dm-control`,
                                   # unzip the wheel's dm_control/suite/ (its files include
                                   # ./common/*.xml, so keep the folder whole)

For each model (gymnasium's ``envs/mujoco/assets/<name>.xml``, or ``<folder>/<name>.xml``
with ``--folder``), contacts disabled:

* **accuracy**: eomgen reads the file (the "left out" warnings are counted and shown), derives
  ``forward_dynamics_ctrl``, ``actuator_forces`` and ``passive_forces`` and prints them as the
  NumPy module (in memory); at ``--samples`` random states (configurations on the manifold,
  velocities normal, controls uniform in [−1, 1], beyond some ``ctrlrange``) the worst relative
  error (max |ours − MuJoCo| / max |MuJoCo|) against ``qacc_smooth`` (MuJoCo's acceleration
  without constraints), ``qfrc_actuator`` and ``qfrc_passive``, mapped to eomgen's coordinates
  (a free joint: ``v̇ = T⁻¹ (qacc − Ṫ v)``, forces ``Tᵀ f``; docs/formats.md). Target: ≤ 1e-9.
  A model whose actuators have activation dynamics (dm_control's quadruped: filters) is
  checked by ``forward_dynamics_act`` at random activations, ``act_dot`` against MuJoCo's; a
  model with couplings (joint and fixed-tendon equalities) against the KKT system of MuJoCo's
  arrays with its equality rows held exactly (MuJoCo's equalities are soft), as
  tests/parsers/test_mjcf_coupled_controls.py.
* **speed** (unless ``--no-speed``): the fast module of ``forward_dynamics_ctrl`` is generated
  and compiled (its build time shown), then one-state calls from Python and ``mj_forward`` on
  the same state are timed alternately (``--repeats`` repeats of 200 calls, the order swapped
  every repeat); the medians, their 10th–90th percentile spread and the median of the
  per-repeat ratios, with the load average. Target (issue 41): ratio ≤ 0.5. ``mj_forward`` does
  more than q̈ (positions of every geom and site, sensors, energy if enabled): it is what a
  MuJoCo user calls to get ``qacc_smooth``.

Exit status 0 when every target is met, 2 otherwise.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import mujoco  # noqa: E402

import eomgen  # noqa: E402
from eomgen.codegen.backends.numpy_backend import NumPyConfig, numpy_source  # noqa: E402
from eomgen.codegen.generate import generate  # noqa: E402
from eomgen.codegen.job import make_job  # noqa: E402
from eomgen.model.configuration import integrate, neutral  # noqa: E402
from eomgen.parsers.mjcf.convert import (full_mass_matrix, layout, to_mujoco,  # noqa: E402
                                         velocity_map)
from eomgen.parsers.mjcf.tree import rotation_of_quaternion  # noqa: E402
from eomgen.symbolic.printing import NumPyModulePrinter, exec_source  # noqa: E402

MODELS = ("ant", "half_cheetah", "hopper", "walker2d", "reacher", "pusher",
          "inverted_double_pendulum", "humanoid", "humanoidstandup")
FUNCTIONS = ["forward_dynamics_ctrl", "actuator_forces", "passive_forces"]


def assets() -> Path:
    import gymnasium

    return Path(gymnasium.__file__).parent / "envs" / "mujoco" / "assets"


def activated(model) -> bool:
    """Whether some control of ``model`` has activation dynamics (then ``forward_dynamics_act``
    gives q̈, at random activations, and ``act_dot`` is compared too)."""
    return any(c.dynamics is not None for c in model.controls)


def numpy_module(model) -> dict:
    symbols, functions = ("qdd_ctrl", "tau_act", "tau_p"), FUNCTIONS
    if activated(model):
        symbols, functions = ("xd_act", "tau_p"), ["forward_dynamics_act", "passive_forces"]
    dyn = eomgen.derive(model, outputs=symbols, simplify=False)
    job = make_job(dyn, functions, count_operations=False)
    printer = NumPyModulePrinter({"fully_qualified_modules": True, "standard": "python3",
                                  "order": "none"})
    namespace: dict = {}
    exec_source(numpy_source(job, printer, NumPyConfig()), "<mjcf_whole>", namespace)
    return namespace


def state(model, m, rng):
    q = integrate(neutral(model), rng.uniform(-0.5, 0.5, model.dof), 1.0, model)
    return q, rng.normal(size=model.dof), rng.uniform(-1, 1, m.nu)


def mujoco_at(m, lay, q, v, ctrl, act=None):
    data = mujoco.MjData(m)
    qpos, data.qvel[:] = to_mujoco(lay, q, v)
    absent = np.ones(m.nq, dtype=bool)  # a dropped free body's entries: at qpos0
    absent[lay.qpos_index] = False
    qpos[absent] = m.qpos0[absent]
    data.qpos[:] = qpos
    data.ctrl[:] = ctrl
    if act is not None:
        data.act[:] = act
    mujoco.mj_forward(m, data)
    return data


def constrained(m, data) -> np.ndarray:
    """The accelerations of MuJoCo's tree under its equality rows held exactly: the KKT system
    ``[[M, Jᵀ], [J, 0]] (q̈, λ) = (qfrc_smooth, 0)`` of MuJoCo's arrays (``mj_fullM`` with the
    armature, ``efc_J``; ``J̇ = 0`` for joint and fixed-tendon equalities), what eomgen's
    couplings give (MuJoCo's own equalities are soft: its ``qacc_smooth`` is without them)."""
    full = full_mass_matrix(m, data)
    rows = np.asarray(data.efc_type) == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    J = np.asarray(data.efc_J).reshape(data.nefc, m.nv)[rows]
    K = np.block([[full, J.T], [J, np.zeros((len(J), len(J)))]])
    return np.linalg.solve(K, np.r_[data.qfrc_smooth, np.zeros(len(J))])[:m.nv]


def accuracy(model, m, namespace, samples: int) -> dict[str, float]:
    lay, rng = layout(m, model), np.random.default_rng(0)
    reference = "qacc (KKT)" if model.couplings else "qacc_smooth"
    worst = {reference: 0.0, "qfrc_actuator": 0.0, "qfrc_passive": 0.0}
    if activated(model):
        worst = {reference: 0.0, "act_dot": 0.0, "qfrc_passive": 0.0}
    kept = lay.dof_index  # a dropped free body's rows are not eomgen's
    for _ in range(samples):
        q, v, ctrl = state(model, m, rng)
        act = rng.uniform(-1, 1, m.na) if activated(model) else None
        data = mujoco_at(m, lay, q, v, ctrl, act)
        T = velocity_map(lay, data.qpos)
        drift = np.zeros(m.nv)  # Ṫ v on the free joint's linear block
        if lay.free is not None:
            qa, da = lay.free
            R = rotation_of_quaternion(data.qpos[qa + 3:qa + 7])
            drift[da:da + 3] = R @ np.cross(v[3:6], v[0:3])
        qacc = constrained(m, data) if model.couplings else data.qacc_smooth
        pairs = {"qfrc_passive": (namespace["passive_forces"](q, v), T.T @ data.qfrc_passive)}
        if act is None:
            qdd = namespace["forward_dynamics_ctrl"](q, v, ctrl)
            pairs["qfrc_actuator"] = (namespace["actuator_forces"](q, v, ctrl),
                                      T.T @ data.qfrc_actuator)
        else:
            both = np.ravel(namespace["forward_dynamics_act"](q, v, ctrl, act))
            qdd = both[:model.dof]
            pairs["act_dot"] = (both[model.dof:], data.act_dot)
        pairs[reference] = ((T @ np.ravel(qdd) + drift)[kept], qacc[kept])
        for name, (ours, theirs) in pairs.items():
            ours = np.reshape(ours, np.shape(theirs))
            scale = max(np.abs(theirs).max(), 1e-300)
            worst[name] = max(worst[name], float(np.abs(ours - theirs).max() / scale))
    return worst


def speed(model, m, repeats: int) -> tuple[float, list[float], list[float], list[float]]:
    folder = Path(tempfile.mkdtemp())
    start = time.perf_counter()
    generate(model, folder, backends=["fast"], functions=["forward_dynamics_ctrl"], cache=False)
    build = time.perf_counter() - start
    path = next(folder.glob("*_fast.*.so"))
    spec = importlib.util.spec_from_file_location(path.name.split(".")[0], path)
    fast = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fast)
    lay = layout(m, model)
    q, v, ctrl = state(model, m, np.random.default_rng(1))
    data = mujoco_at(m, lay, q, v, ctrl)
    ours, theirs, calls = [], [], 200
    for r in range(repeats):
        for tag in (("ours", "theirs") if r % 2 == 0 else ("theirs", "ours")):
            start = time.perf_counter()
            if tag == "ours":
                for _ in range(calls):
                    fast.forward_dynamics_ctrl(q, v, ctrl)
                ours.append((time.perf_counter() - start) / calls * 1e6)
            else:
                for _ in range(calls):
                    mujoco.mj_forward(m, data)
                theirs.append((time.perf_counter() - start) / calls * 1e6)
    return build, ours, theirs, sorted(a / b for a, b in zip(ours, theirs))


def spread(values: list[float]) -> str:
    s = sorted(values)
    return f"{statistics.median(s):.2f} ({s[len(s) // 10]:.2f}–{s[9 * len(s) // 10]:.2f})"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="*", default=list(MODELS))
    parser.add_argument("--samples", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=301)
    parser.add_argument("--no-speed", action="store_true")
    parser.add_argument("--folder", type=Path, default=None,
                        help="read <folder>/<name>.xml instead of gymnasium's assets")
    options = parser.parse_args()
    met = True
    print(f"load average {os.getloadavg()[0]:.1f}; MuJoCo {mujoco.__version__}")
    for name in options.models:
        path = (options.folder or assets()) / f"{name}.xml"
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            model = eomgen.load(path)
        left_out = [str(w.message) for w in caught if "left out" in str(w.message)]
        m = mujoco.MjModel.from_xml_path(str(path))
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        try:
            namespace = numpy_module(model)
        except eomgen.EomgenError as exc:  # an output eomgen refuses for this model
            met = False
            print(f"{name:26s} nv {model.dof:2d} nu {m.nu:2d}  refused: {exc}")
            continue
        worst = accuracy(model, m, namespace, options.samples)
        met &= max(worst.values()) <= 1e-9 and not left_out
        print(f"{name:26s} nv {model.dof:2d} nu {m.nu:2d}  "
              + "  ".join(f"{k} {e:.1e}" for k, e in worst.items())
              + f"  left out: {len(left_out)}")
        if not options.no_speed and not activated(model):  # forward_dynamics_ctrl's speed
            build, ours, theirs, ratios = speed(model, m, options.repeats)
            ratio = statistics.median(ratios)
            met &= ratio <= 0.5
            print(f"{'':26s} fast build {build:.1f} s; forward_dynamics_ctrl {spread(ours)} µs, "
                  f"mj_forward {spread(theirs)} µs, ratio {ratio:.3f} "
                  f"(load {os.getloadavg()[0]:.1f})")
    print(f"targets (≤ 1e-9, no 'left out', ratio ≤ 0.5): {'met' if met else 'not met'}")
    return 0 if met else 2


if __name__ == "__main__":
    sys.exit(main())
