"""Flat inverse dynamics of the flexible Panda as generated functions: operation counts and
generation time.

Usage::

    python benchmarks/flat_outputs.py [--repeat 3]

The Panda of example-robot-data with ``examples/scenes/panda_flexible.yaml`` (7 flexible joints,
fingers locked). Printed:

1. operations per state of ``inverse_dynamics`` (τ_L, the program differentiated), of
   ``motor_angles``, ``motor_velocities`` and ``flat_motor_torque``: SymPy ``count_ops`` of the
   function's program (the number in the generated file's header) and the operations of the
   printed NumPy code (:mod:`eomgen.symbolic.opcount`), with their ratio to ``inverse_dynamics``
   (forward mode: the k-th derivative should cost a small multiple of τ_L's program, not grow
   with expansion); and, for comparison, the size of the program
   :func:`eomgen.analysis.actuators.actuated_model` differentiates (τ_L from the Lagrangian M, C, g);
2. CPU seconds of ``derive`` for the flat outputs, and the wall seconds (median, min, max of
   ``--repeat`` runs) of ``eomgen generate --outputs motor_angles,motor_velocities,
   flat_motor_torque,flat_motor_torque_smooth --backend numpy,casadi --no-cache`` in a fresh
   process (issue 17's target for the flexible Panda: ≤ 30 s);
3. the largest relative difference, at 5 random states, between the generated NumPy
   ``flat_motor_torque`` and :func:`eomgen.analysis.actuators.flexible_inverse_dynamics`.
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import eomgen  # noqa: E402
from eomgen import actuators as A  # noqa: E402
from eomgen.codegen.functions import function_specs  # noqa: E402
from eomgen.reduction import apply_scene, load_for_scene  # noqa: E402
from eomgen.scene import load_scene  # noqa: E402
from eomgen.symbolic.opcount import program_operation_count  # noqa: E402
from flexible_joints import robots_dir  # noqa: E402

SCENE = ROOT / "examples/scenes/panda_flexible.yaml"
FUNCTIONS = ("inverse_dynamics", "motor_angles", "motor_velocities", "flat_motor_torque",
             "flat_motor_torque_smooth")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    urdf = robots_dir() / "panda_description/urdf/panda.urdf"
    scene = load_scene(SCENE)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = apply_scene(load_for_scene(urdf, scene), scene).model

    start = time.process_time()
    dyn = eomgen.derive(model, outputs=["tau", "theta_flat", "thetad_flat", "tau_flat",
                                        "tau_flat_smooth"])
    derive_s = time.process_time() - start
    specs = {s.name: s for s in function_specs(dyn, FUNCTIONS)}
    base = None
    print("function                   count_ops  printed  ratio (printed / inverse_dynamics)")
    for name in FUNCTIONS:
        printed = program_operation_count(specs[name].program)
        base = base or printed
        print(f"{name:26s} {specs[name].operation_count:9d} {printed:8d}  {printed / base:5.2f}")
    am = A.actuated_model(eomgen.derive(model))
    print(f"actuated_model's τ_L, τ̇_L, τ̈_L program (from M, C, g): count_ops "
          f"{am._taylor_source.operation_count()}")
    print(f"derive (flat outputs and tau): {derive_s:.2f} CPU s")

    walls = []
    for _ in range(args.repeat):
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            subprocess.run([sys.executable, "-c", "from eomgen.cli import main; main()",
                            "generate", str(urdf), "--scene", str(SCENE), "--outputs",
                            ",".join(FUNCTIONS[1:]), "--backend", "numpy,casadi", "--no-cache",
                            "--quiet", "-o", out], check=True, capture_output=True,
                           env={"PYTHONPATH": str(ROOT), **_env()})
            walls.append(time.perf_counter() - start)
            if len(walls) == 1:
                module = _load(Path(out) / "panda_numpy.py")
    print(f"eomgen generate numpy,casadi: median {statistics.median(walls):.2f} s wall "
          f"(min {min(walls):.2f}, max {max(walls):.2f}; {len(walls)} runs; target ≤ 30 s)")

    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(5):
        x = [rng.uniform(-1.5, 1.5, 7) for _ in range(5)]
        ref = A.flexible_inverse_dynamics(am, *x)["tau"]
        worst = max(worst, np.abs(module.flat_motor_torque(*x) - ref).max() / np.abs(ref).max())
    print(f"generated flat_motor_torque against flexible_inverse_dynamics: max relative "
          f"difference {worst:.1e} (5 random states)")


def _env() -> dict:
    import os

    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


def _load(path: Path):
    spec = importlib.util.spec_from_file_location("panda_flat_numpy", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


if __name__ == "__main__":
    main()
