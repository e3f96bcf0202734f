"""Regressor report: derivation time, operation counts and base-parameter counts (issue 15).

Usage::

    python benchmarks/regressor_report.py [--repeat 3] [--csv]

For the PUMA 560 (``eomgen/robots/puma560_dh.yaml``), the UR5 (example-robot-data's
``ur5_robot.urdf``) and the Panda (``panda.urdf`` with ``examples/scenes/panda_fingers_locked.yaml``):

* **Y s**: seconds of ``derive_regressor(model)``; the first run in this process (SymPy's caches
  cold) and the median and spread of ``--repeat`` further runs. Beside it, in the same run,
  ``derive(model, outputs=["tau"])`` (the Newton–Euler τ program) and the ratio.
* **Y ops / Y_base ops**: SymPy ``count_ops`` of the straight-line program computing all of Y,
  or only its base columns (unused intermediates pruned); τ ops for scale.
* **gen Y ops / gen Y_base ops**: operation counts of the generated functions ``regressor`` and
  ``base_regressor`` (what ``eomgen generate --outputs regressor,base_regressor`` prints in each
  module's docstrings), with the actuator columns the description declares (the Panda URDF's
  joint damping: 7 viscous columns); **gen s**: seconds of ``derive(model, outputs=["Y",
  "Y_base"])`` in this process (the base parameters found once, then cached).
* **b**, **b fric**: base-parameter counts by the numeric route (QR over random states), without
  and with viscous + Coulomb friction columns; **b sym**: by the closed-form grouping.

Targets (issue 15): counts PUMA 36 / 48, UR5 36, Panda 43 / 57; Panda regressor derived in
≤ 5 s; Panda base regressor ≤ 2,700 operations. Exit status 0 when all are met, 2 otherwise.
"""

from __future__ import annotations

import argparse
import csv
import statistics
import sys
import time
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import eomgen  # noqa: E402
from eomgen.codegen import make_job  # noqa: E402
from eomgen.regressor import base_parameters, derive_regressor, symbolic_base_parameters  # noqa: E402

TARGET_COUNTS = {"puma560": (36, 48), "ur5": (36, None), "panda": (43, 57)}
PANDA_SECONDS = 5.0
PANDA_BASE_OPS = 2700


def models() -> dict:
    from support import erd_robots_dir

    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out["puma560"] = eomgen.load(eomgen.example_path("puma560_dh"))
        robots = erd_robots_dir()
        if robots is None:
            print("example-robot-data not installed: UR5 and Panda skipped", file=sys.stderr)
            return out
        out["ur5"] = eomgen.load(robots / "ur_description/urdf/ur5_robot.urdf")
        panda = eomgen.load(robots / "panda_description/urdf/panda.urdf")
    scene = eomgen.load_scene(ROOT / "examples/scenes/panda_fingers_locked.yaml")
    out["panda"] = eomgen.apply_scene(panda, scene)[0]
    return out


def timed(f, repeat: int) -> tuple[float, list[float], object]:
    start = time.perf_counter()
    result = f()
    first = time.perf_counter() - start
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        runs.append(time.perf_counter() - start)
    return first, runs, result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--csv", action="store_true", help="write benchmarks/results/regressor.csv")
    parser.add_argument("--quick", action="store_true",
                        help="one repeat: checks that the script runs, not a measurement")
    args = parser.parse_args()
    if args.quick:
        args.repeat = 1
    rows = []
    ok = True
    for name, model in models().items():
        y_first, y_runs, reg = timed(lambda: derive_regressor(model), args.repeat)
        t_first, t_runs, dyn = timed(lambda: eomgen.derive(model, outputs=["tau"]), args.repeat)
        numeric = base_parameters(reg)
        friction = base_parameters(derive_regressor(model, ("viscous", "coulomb")))
        symbolic = symbolic_base_parameters(reg)
        start = time.perf_counter()
        generated = eomgen.derive(model, outputs=["Y", "Y_base"], simplify=False)
        gen_s = time.perf_counter() - start
        specs = {s.name: s.operation_count
                 for s in make_job(generated, ["regressor", "base_regressor"]).specs}
        row = {
            "robot": name, "n": reg.n, "p": reg.p,
            "Y_s_first": y_first, "Y_s_median": statistics.median(y_runs),
            "Y_s_min": min(y_runs), "Y_s_max": max(y_runs),
            "tau_s_median": statistics.median(t_runs),
            "Y_ops": reg.operation_count(), "Y_base_ops": reg.operation_count(numeric.base),
            "tau_ops": dyn.operation_count(["tau"]),
            "gen_Y_ops": specs["regressor"], "gen_Y_base_ops": specs["base_regressor"],
            "gen_s": gen_s,
            "b": numeric.count, "b_fric": friction.count, "b_sym": symbolic.count,
            "gap": numeric.gap[1] / numeric.gap[0],
        }
        rows.append(row)
        want, want_fric = TARGET_COUNTS[name]
        ok &= row["b"] == want and row["b_sym"] == want
        ok &= want_fric is None or row["b_fric"] == want_fric
        if name == "panda":
            ok &= y_first <= PANDA_SECONDS and row["Y_base_ops"] <= PANDA_BASE_OPS
            ok &= row["gen_Y_base_ops"] <= PANDA_BASE_OPS
    print("| robot | n | p | Y s first | Y s median [min, max] | τ s median | Y/τ time | "
          "Y ops | Y_base ops | τ ops | b | b fric | b sym | dropped/kept residual | "
          "gen Y ops | gen Y_base ops | gen s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['robot']} | {r['n']} | {r['p']} | {r['Y_s_first']:.2f} | "
              f"{r['Y_s_median']:.2f} [{r['Y_s_min']:.2f}, {r['Y_s_max']:.2f}] | "
              f"{r['tau_s_median']:.2f} | {r['Y_s_median'] / r['tau_s_median']:.2f} | "
              f"{r['Y_ops']} | {r['Y_base_ops']} | {r['tau_ops']} | {r['b']} | {r['b_fric']} | "
              f"{r['b_sym']} | {r['gap']:.1e} | {r['gen_Y_ops']} | {r['gen_Y_base_ops']} | "
              f"{r['gen_s']:.2f} |")
    print(f"targets: counts {TARGET_COUNTS}, Panda Y ≤ {PANDA_SECONDS} s (first run), "
          f"Panda Y_base ≤ {PANDA_BASE_OPS} ops: {'met' if ok else 'NOT met'}")
    if args.csv:
        out = HERE / "results" / "regressor.csv"
        with out.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        print(f"wrote {out}")
    return 0 if ok else 2


if __name__ == "__main__":
    sys.exit(main())
