"""Floating bases and contacts: agreement with Pinocchio and generation time (issue 16 targets).

    python benchmarks/floating_contacts.py            # 10 random states, generation timed
    python benchmarks/floating_contacts.py --quick    # 3 states, no generation
    python benchmarks/floating_contacts.py --generated  # only the generated contact code

Prints, for the floating-base solo12 and Talos (legs only, everything else locked at 0), the
largest relative difference over random states between eomgen and Pinocchio's free flyer
(its own URDF reader; M, C q̇, g mapped to Euler coordinates, eomgen.numeric.floating_base) of:

* M, C q̇, g from eomgen's numeric Newton–Euler and from the derived (symbolic) program;
* constrained q̈ and F_c (eomgen.numeric.contacts) against ``pinocchio.constraintDynamics`` with 4
  CONTACT_3D (LOCAL_WORLD_ALIGNED) and 1 CONTACT_6D (LOCAL) on solo12;

and the derivation time of the floating solo12 (M, C, g; the frame kinematics of its feet),
and the wall-clock time of ``eomgen generate`` with examples/contacts/solo12_standing.yaml
(all backends, no cache; the scene's outputs M, C, g).

The generated contact code (:func:`generated_contacts`, also alone with ``--generated``):
the wall-clock time of ``eomgen generate`` (fresh process, no cache) of solo12 with its 4
feet held, NumPy + CasADi, outputs M, C, g, frame_jacobians, contact_jacobian, contact_bias and
constrained_forward_dynamics; the operation counts of each printed function (and the CasADi
instructions of the composed KKT solve); and the one-state time of the compiled constrained
forward dynamics (CasADi's C code as a shared library, called through ``Function.buffer()``
on preallocated arrays; and the fast C extension module's ``constrained_forward_dynamics(q, qd,
tau)``, which allocates its result arrays) against ``pinocchio.constraintDynamics`` (its plain Python call, on
Pinocchio's own q, v, τ arrays), interleaved in the same run: medians and quartiles of
repeated batches, and the ratio of the medians. Targets: ≤ 1e-10 (M, C q̇, g), ≤ 1e-8 (q̈,
F_c), generation ≤ 60 s. Exit status 2 when one is missed.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import eomgen  # noqa: E402
from support import erd_robots_dir  # noqa: E402
from eomgen import numeric  # noqa: E402
from eomgen.model import floating  # noqa: E402
from eomgen.numeric import floating_base  # noqa: E402
from eomgen.numeric.contacts import Contact, ContactDynamics  # noqa: E402
from eomgen.reduction import apply_scene  # noqa: E402
from eomgen.scene import load_scene  # noqa: E402
from eomgen.symbolic.evaluate import compile_program  # noqa: E402
from eomgen.symbolic.frames import derive_frames  # noqa: E402

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


def rel(a, b):
    return float(np.abs(np.asarray(a) - b).max() / np.abs(b).max())


def states(n, count, seed):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = rng.uniform(-1, 1, n)
        q[4] = rng.uniform(-1.2, 1.2)
        yield q, rng.uniform(-1, 1, n)


def load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return eomgen.load(path)


def dynamics_agreement(name, model, ref, count, derived=True):
    nm = numeric.numeric_model(model)
    worst = {"numeric": [0, 0, 0], "derived": [0, 0, 0]}
    f = None
    if derived:
        start = time.perf_counter()
        dyn = eomgen.derive(model, outputs=("M", "C", "g"))
        print(f"{name}: derive M, C, g ({model.dof} DOF) {time.perf_counter() - start:.2f} s")
        f = compile_program(dyn.program, dyn.q + dyn.qd)
    for q, qd in states(model.dof, count, 1):
        M, Cqd, g = ref.dynamics(q, qd)
        ours = {"numeric": (numeric.M_rnea(nm, q), numeric.coriolis_times_qd(nm, q, qd),
                            numeric.gravity_torques(nm, q))}
        if f is not None:
            out = f(*q, *qd)
            ours["derived"] = (out["M"], out["C"] @ qd, out["g"].ravel())
        for key, (M2, C2, g2) in ours.items():
            worst[key] = [max(w, rel(x, y)) for w, x, y in zip(worst[key], (M2, C2, g2),
                                                                  (M, Cqd, g))]
    ok = True
    for key, values in worst.items():
        if key == "derived" and f is None:
            continue
        print(f"{name} {key:8s} vs Pinocchio: M {values[0]:.1e}, C q̇ {values[1]:.1e}, "
              f"g {values[2]:.1e}")
        ok &= max(values) <= 1e-10
    return ok


def contact_agreement(path, model, count):
    import pinocchio as pin

    ref = floating_base.PinocchioFreeFlyer(path, model.joint_names)
    pm, pd, idx = ref.model, ref.data, ref.idx
    ok = True
    for kind, feet, ctype, frame in (("point", FEET, pin.ContactType.CONTACT_3D,
                                      pin.LOCAL_WORLD_ALIGNED),
                                     ("surface", FEET[:1], pin.ContactType.CONTACT_6D, pin.LOCAL)):
        cd = ContactDynamics(model, tuple(Contact(f, kind) for f in feet))
        models = pin.StdVec_RigidConstraintModel()
        for f in feet:
            fr = pm.frames[pm.getFrameId(f)]
            models.append(pin.RigidConstraintModel(ctype, pm, fr.parentJoint, fr.placement,
                                                   frame))
        datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
        pin.initConstraintDynamics(pm, pd, models, datas)
        worst = [0.0, 0.0]
        rng = np.random.default_rng(2)
        for q, qd in states(18, count, 3):
            tau = rng.uniform(-2, 2, 18)
            qdd, F = cd.constrained_forward_dynamics(q, qd, tau)
            q_pin, v = ref.state(q, qd)
            T = floating_base.velocity_map(q)
            a = pin.constraintDynamics(pm, pd, q_pin, v, np.linalg.solve(T.T, tau)[idx],
                                       models, datas, pin.ProximalSettings(1e-14, 1e-12, 1))
            a_ours = np.empty(18)
            a_ours[idx] = a
            qdd_pin = np.linalg.solve(T, a_ours - floating_base.velocity_map_dot_qd(q, qd))
            worst = [max(worst[0], rel(qdd, qdd_pin)), max(worst[1], rel(F, pd.lambda_c))]
        print(f"solo12 {len(feet)} {kind} contact(s) vs constraintDynamics: q̈ {worst[0]:.1e}, "
              f"F_c {worst[1]:.1e}")
        ok &= max(worst) <= 1e-8
    return ok


def _timed(function, number: int, repeats: int) -> np.ndarray:
    """Microseconds per call of ``function`` over ``repeats`` batches of ``number`` calls."""
    import timeit

    timer = timeit.Timer(function)
    return np.array([timer.timeit(number) / number * 1e6 for _ in range(repeats)])


def generated_contacts(solo_path) -> bool:
    """Generation time, operation counts and compiled speed of the generated contact code."""
    import casadi as ca
    import pinocchio as pin

    from eomgen.codegen import make_job
    from eomgen.codegen.functions import derived_outputs, select_functions
    from eomgen.codegen.generate import render_files

    scene = ROOT / "examples/contacts/solo12_standing.yaml"
    outputs = "M,C,g,frame_jacobians,contact_jacobian,contact_bias,constrained_forward_dynamics"
    env = {**__import__("os").environ, "PYTHONPATH": str(ROOT)}
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "eomgen.cli", "generate", str(solo_path),
                        "--scene", str(scene), "--backend", "numpy,casadi", "--outputs",
                        outputs, "-o", out, "--no-cache", "--quiet"], check=True, env=env)
        seconds = time.perf_counter() - start
    print(f"eomgen generate solo12 floating, 4 point contacts, NumPy + CasADi ({outputs}): "
          f"{seconds:.1f} s (target ≤ 60 s)")
    # the Euler chart (its map to Pinocchio's arrays below); the scene's own chart, the
    # quaternion, is timed in benchmarks/legged_speed.py
    model = apply_scene(load(solo_path),
                        dataclasses.replace(load_scene(scene), floating_base="euler")).model
    functions = select_functions(outputs.split(","))
    dyn = eomgen.derive(model, outputs=derived_outputs(functions), simplify=False)
    job = make_job(dyn, functions)
    print("operation counts (SymPy count_ops of the straight-line programs): "
          + ", ".join(f"{s.name} {s.operation_count}" for s in job.specs))
    with tempfile.TemporaryDirectory() as out:
        files = render_files(model, ["casadi", "c", "fast"], functions=functions)
        from eomgen.codegen.backends.casadi_backend import load_module_source

        sx = load_module_source(next(f.content for f in files if f.name.endswith("casadi.py")),
                                "solo_contacts_casadi")["constrained_forward_dynamics"]
        for f in files:
            path = Path(out, f.name)
            path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
                f.content)
        library = next(p for p in Path(out).glob("*.so") if "_fast." not in p.name)
        f = ca.external("constrained_forward_dynamics", str(library))
        spec = importlib.util.spec_from_file_location(
            f"{model.name}_fast", next(Path(out).glob(f"{model.name}_fast.*.so")))
        fast = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(fast)
        print(f"CasADi constrained_forward_dynamics: {sx.n_instructions()} SX instructions "
              "(M, C q̇ + g, J_c, J̇_c q̇ and the Cholesky-Schur KKT solve)")
        ref = floating_base.PinocchioFreeFlyer(solo_path, model.joint_names)
        pm, pd, idx = ref.model, ref.data, ref.idx
        models = pin.StdVec_RigidConstraintModel()
        for c in model.contacts:
            fr = pm.frames[pm.getFrameId(c.frame)]
            models.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, pm,
                                                   fr.parentJoint, fr.placement,
                                                   pin.LOCAL_WORLD_ALIGNED))
        datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
        pin.initConstraintDynamics(pm, pd, models, datas)
        settings = pin.ProximalSettings(1e-14, 1e-12, 1)
        (q, qd), = states(18, 1, 7)
        tau = np.random.default_rng(8).uniform(-2, 2, 18)
        q_pin, v = ref.state(q, qd)
        T = floating_base.velocity_map(q)
        tau_pin = np.linalg.solve(T.T, tau)[idx]
        n_in = f.n_in()
        args = [np.array(q), np.array(qd), np.array(tau)] + [np.zeros(1)] * (n_in - 3)
        qdd, F = np.zeros(18), np.zeros(12)
        buffer, evaluate = f.buffer()
        for i, x in enumerate(args):
            buffer.set_arg(i, memoryview(x))
        buffer.set_res(0, memoryview(qdd))
        buffer.set_res(1, memoryview(F))
        evaluate()
        a = pin.constraintDynamics(pm, pd, q_pin, v, tau_ff := tau_pin, models, datas, settings)
        a_ours = np.empty(18)
        a_ours[idx] = a
        qdd_pin = np.linalg.solve(T, a_ours - floating_base.velocity_map_dot_qd(q, qd))
        agree = max(rel(qdd, qdd_pin), rel(F, pd.lambda_c))
        print(f"compiled constrained_forward_dynamics vs constraintDynamics: {agree:.1e} "
              "(largest relative difference of q̈, F_c)")
        q_, qd_, tau_ = np.array(q), np.array(qd), np.array(tau)
        qdd_fast, F_fast = fast.constrained_forward_dynamics(q_, qd_, tau_)
        agree_fast = max(rel(qdd_fast, qdd_pin), rel(F_fast, pd.lambda_c))
        print(f"fast module constrained_forward_dynamics vs constraintDynamics: "
              f"{agree_fast:.1e} (largest relative difference of q̈, F_c)")
        agree = max(agree, agree_fast)
        ours, mine, theirs = [], [], []
        for _ in range(15):  # interleaved batches
            ours.append(_timed(evaluate, 2000, 1)[0])
            mine.append(_timed(lambda: fast.constrained_forward_dynamics(q_, qd_, tau_),
                               2000, 1)[0])
            theirs.append(_timed(lambda: pin.constraintDynamics(pm, pd, q_pin, v, tau_ff, models,
                                                                datas, settings), 2000, 1)[0])
        ours, mine, theirs = np.array(ours), np.array(mine), np.array(theirs)

        def summary(x):
            q1, med, q3 = np.percentile(x, [25, 50, 75])
            return f"median {med:.2f} µs (quartiles {q1:.2f}–{q3:.2f})"

        print(f"one state, solo12 + 4 contacts: eomgen CasADi C (buffer) {summary(ours)}; "
              f"Pinocchio constraintDynamics {summary(theirs)}; ratio eomgen/Pinocchio "
              f"{np.median(ours) / np.median(theirs):.2f}")
        print(f"one state, solo12 + 4 contacts: eomgen fast module (its Python call, new "
              f"result arrays) {summary(mine)}; ratio fast/Pinocchio "
              f"{np.median(mine) / np.median(theirs):.2f}")
        del buffer
    return seconds <= 60 and agree <= 1e-8


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--generated", action="store_true",
                        help="only the generated contact code (generation, op counts, speed)")
    args = parser.parse_args()
    count = 3 if args.quick else 10
    robots = erd_robots_dir()
    if robots is None:
        print("example-robot-data is not installed")
        return 1
    solo_path = robots / "solo_description/robots/solo12.urdf"
    if args.generated:
        return 0 if generated_contacts(solo_path) else 2
    solo = floating.add_floating_base(load(solo_path))
    ok = dynamics_agreement("solo12", solo,
                            floating_base.PinocchioFreeFlyer(solo_path, solo.joint_names), count)
    talos_path = robots / "talos_data/robots/talos_reduced.urdf"
    talos = load(talos_path)
    scene = load_scene("legs.yaml", text="version: 1\nfloating_base: euler\n"
                       "tips: [leg_left_6_link, leg_right_6_link]\n")
    legs = apply_scene(talos, scene).model
    locked = [j.name for j in talos.movable_joints if j.name not in legs.joint_names]
    ok &= dynamics_agreement("talos legs", legs,
                             floating_base.PinocchioFreeFlyer(talos_path, legs.joint_names, locked),
                             count)
    start = time.perf_counter()
    derive_frames(solo, FEET)
    print(f"solo12: frame kinematics of the 4 feet {time.perf_counter() - start:.2f} s")
    ok &= contact_agreement(solo_path, solo, count)
    if not args.quick:
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            subprocess.run([sys.executable, "-m", "eomgen.cli", "generate", str(solo_path),
                            "--scene", str(ROOT / "examples/contacts/solo12_standing.yaml"),
                            "-o", out, "--no-cache", "--quiet"], check=True,
                           env={**__import__("os").environ, "PYTHONPATH": str(ROOT)})
            seconds = time.perf_counter() - start
        print(f"eomgen generate solo12 floating, 4 contacts (all backends): {seconds:.1f} s "
              "(target ≤ 60 s)")
        ok &= seconds <= 60
        ok &= generated_contacts(solo_path)
    return 0 if ok else 2


if __name__ == "__main__":
    sys.exit(main())
