"""Every MJCF file of a corpus (the gymnasium and dm_control wheels) read by eomgen and checked
against MuJoCo: M (armature removed) against ``mj_fullM`` minus the armature, the drive mass
matrix M + diag(armature) against ``mj_fullM``, h = τ(q, v, 0) against ``qfrc_bias``, the
drives' damping against ``qfrc_damper``; free joints through the velocity map of
:mod:`eomgen.parsers.mjcf.convert`. Equalities (issue 26): ``joint`` equalities are couplings
(the references above are then projected, ``Tᵀ (·) T``, at states where the followers sit
where their couplings put them) and ``connect``/``weld`` are loops, whose Jacobian's
translational rows are compared with MuJoCo's ``efc_J`` (``J_l``); each file's equalities are
listed.

Usage::

    pip download --no-deps gymnasium dm_control -d wheels   # where PyPI is reachable
    python benchmarks/mjcf_corpus.py wheels/*.whl            # or folders of XML files
    python benchmarks/mjcf_corpus.py wheels/*.whl --samples 3 --max-dof 200

Each ``.xml`` file is classified: MuJoCo cannot compile it on its own (an include fragment, an
asset list, a part assembled in Python: the compiler's message is shown), it has no joint (an
arena, a prop, materials), eomgen refuses it (the reason), or it loads; a model that loads is
derived (outputs M and h, the generated NumPy module in memory) and compared at ``--samples``
random states (configurations uniform in [-1, 1], unit quaternion, velocities normal). The
worst relative error (max |ours − MuJoCo| / max |MuJoCo|) of each quantity is printed, with the
time to load and derive (one run; the machine is shared, so times are indicative).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import warnings
import zipfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import eomgen  # noqa: E402
from eomgen.errors import EomgenError  # noqa: E402
from eomgen.model import coupling_map, joint_actuators  # noqa: E402
from eomgen.parsers.mjcf import compile_mjcf  # noqa: E402
from eomgen.parsers.mjcf.convert import (  # noqa: E402
    layout, mujoco_dynamics, to_mujoco, velocity_map)

TOLERANCE = 1e-10


def xml_files(sources: list[str], scratch: Path) -> list[tuple[str, Path]]:
    """``(label, path)`` of every ``.xml`` under the folders, or inside the wheels (unpacked
    into ``scratch`` so that includes and meshes resolve)."""
    found = []
    for source in sources:
        path = Path(source)
        if path.suffix == ".whl":
            target = scratch / path.stem
            with zipfile.ZipFile(path) as wheel:
                wheel.extractall(target)
            base = target
        else:
            base = path
        for xml in sorted(base.rglob("*.xml")):
            found.append((f"{path.name.split('-')[0]}:{xml.relative_to(base)}", xml))
    return found


def relative(got, expected) -> float:
    got, expected = np.asarray(got, dtype=float), np.asarray(expected, dtype=float)
    got = got.reshape(expected.shape)
    return float(np.abs(got - expected).max() / max(np.abs(expected).max(), 1e-300))


def compare(path: Path, samples: int, seed: int = 0) -> tuple[dict[str, float], int, int, bool]:
    """Worst relative errors, DOF, number of warnings of one model that loads, and whether
    eomgen's velocity coordinates are MuJoCo's in MuJoCo's order (the free joint first)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = eomgen.load(path)
        m = compile_mjcf(path)
    caught = [w for w in caught if "MuJoCo's compiler" not in str(w.message)]
    outputs = ("M", "h", "J_l") if model.loops else ("M", "h")
    module = eomgen.derive(model, outputs=outputs).lambdify().module
    lay = layout(m, model)
    drives = joint_actuators(model)  # every movable joint's, followers included
    T = (np.array(coupling_map(model)[0].evalf(), dtype=float) if model.couplings
         else np.eye(model.dof))
    armature = T.T @ np.diag([float(a.armature) for a in drives]) @ T
    damping = T.T @ np.diag([float(a.damping) for a in drives]) @ T
    rng = np.random.default_rng(seed)
    worst: dict[str, float] = {}
    for _ in range(samples):
        q = rng.uniform(-1, 1, model.nq)
        for joint in model.quaternion_joints:
            k = joint.quaternion
            q[k:k + 4] /= np.linalg.norm(q[k:k + 4])
        v = rng.normal(size=model.dof)
        ref = mujoco_dynamics(m, lay, q, v)
        M = np.asarray(module.mass_matrix(q)).reshape(ref["M"].shape)
        got = {"M": M, "M_a": M + armature, "h": module.nonlinear_effects(q, v),
               "damper": -damping @ v}
        if model.loops:
            got["J_l"], ref["J_l"] = loop_rows(m, lay, model, module, q)
        for name, value in got.items():
            if name == "damper" and not np.abs(ref[name]).any():
                error = float(np.abs(value).max())  # both zero: an absolute check
            else:
                error = relative(value, ref[name])
            worst[name] = max(worst.get(name, 0.0), error)
    nv_free = 6 if model.free_flyer else 0
    in_order = list(lay.dof_index[nv_free:]) == sorted(lay.dof_index[nv_free:]) and (
        not model.free_flyer or lay.free[1] == 0)
    return worst, model.dof, len(caught), in_order


def loop_rows(m, lay, model, module, q) -> tuple[np.ndarray, np.ndarray]:
    """The translational rows of each loop's J_l, and MuJoCo's ``efc_J`` rows of the same
    equality (its first three: world axes, the same signs), in eomgen's velocities."""
    import mujoco

    data = mujoco.MjData(m)
    data.qpos[:], data.qvel[:] = to_mujoco(lay, q, np.zeros(model.dof))
    mujoco.mj_forward(m, data)
    J = np.asarray(data.efc_J).reshape(data.nefc, m.nv) @ velocity_map(lay, data.qpos)
    equality = np.asarray(data.efc_type) == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    names = [m.eq(e).name or f"eq{e}" for e in range(m.neq)]
    ours = np.asarray(module.loop_jacobian(q)).reshape(-1, model.dof)
    got, expected, row = [], [], 0
    for loop in model.loops:
        rows = np.flatnonzero(equality & (np.asarray(data.efc_id) == names.index(loop.name)))
        got.append(ours[row:row + 3])
        expected.append(J[rows[:3]])
        row += loop.size
    return np.vstack(got), np.vstack(expected)


def equalities(path: Path) -> str:
    """The kinds of the file's equalities (``2 joint, 1 connect``), or ""."""
    m = compile_mjcf(path)
    kinds = {0: "connect", 1: "weld", 2: "joint", 3: "tendon"}
    counts: dict[str, int] = {}
    for e in range(m.neq):
        kind = kinds.get(int(m.eq_type[e]), "flex/other")
        kind += "" if m.eq_active0[e] else " (inactive)"
        counts[kind] = counts.get(kind, 0) + 1
    return ", ".join(f"{n} {k}" for k, n in sorted(counts.items()))


def classify(path: Path) -> tuple[str, str]:
    """``(status, detail)``: ``"no-compile"``, ``"no-joint"``, ``"refused"`` or ``"loads"``."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = compile_mjcf(path)
    except EomgenError as exc:
        return "no-compile", exc.problem
    if m.njnt == 0:
        return "no-joint", f"{m.nbody} bodies, no joint"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            eomgen.load(path)
    except EomgenError as exc:
        return "refused", f"{exc.element}: {exc.problem}"
    return "loads", ""


def main() -> int:
    warnings.simplefilter("ignore")  # counted per model instead (compare)
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sources", nargs="+", help="wheels (.whl) or folders of .xml files")
    parser.add_argument("--samples", type=int, default=3)
    parser.add_argument("--max-dof", type=int, default=500,
                        help="load but do not derive models with more velocity coordinates")
    args = parser.parse_args()
    counts: dict[str, int] = {}
    with_equalities: dict[str, int] = {}
    failures = 0
    with tempfile.TemporaryDirectory() as scratch:
        for label, path in xml_files(args.sources, Path(scratch)):
            status, detail = classify(path)
            counts[status] = counts.get(status, 0) + 1
            kinds = equalities(path) if status in ("loads", "refused") else ""
            if kinds:
                with_equalities[status] = with_equalities.get(status, 0) + 1
            if status != "loads":
                print(f"{status:10s} {label}: {detail}"
                      + (f" [equalities: {kinds}]" if kinds else ""), flush=True)
                continue
            start = time.perf_counter()
            try:
                worst, dof, warned, in_order = compare(path, args.samples)
            except EomgenError as exc:  # e.g. above the derivation's limits
                print(f"{'error':10s} {label}: {exc}", flush=True)
                failures += 1
                continue
            seconds = time.perf_counter() - start
            ok = all(value <= TOLERANCE for value in worst.values())
            failures += not ok
            errors = "  ".join(f"{k} {v:.1e}" for k, v in worst.items())
            order = "MuJoCo's order" if in_order else "free flyer moved first"
            print(f"{'agrees' if ok else 'DIFFERS':10s} {label}: nv {dof} ({order}), "
                  f"{warned} warnings, {errors}  ({seconds:.1f} s)"
                  + (f" [equalities: {kinds}]" if kinds else ""), flush=True)
    print("summary: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
          + f"; {failures} disagree; with equalities: "
          + ", ".join(f"{k} {v}" for k, v in sorted(with_equalities.items())))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
