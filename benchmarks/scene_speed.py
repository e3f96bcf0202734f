"""What a scene saves: deriving one arm of a humanoid against deriving the whole humanoid.

Usage::

    python benchmarks/scene_speed.py [--timeout 600] [--repeat 3] [--cases talos,simple_humanoid]
                                     [--csv] [--quick]

``--quick`` (a check that the script runs, not a measurement to quote): the simple humanoid
only, one process per number, timeout 60 s (the whole humanoid may then show as "> 60 s").

Cases (example-robot-data robots, outputs M, C and g):

* ``talos``: Talos (``talos_data/robots/talos_reduced.urdf``, 32 joints) against the scene
  ``examples/scenes/talos_left_arm.yaml`` (7 arm joints move, the rest is locked);
* ``simple_humanoid``: the simple humanoid (29 joints) against its left arm (7 joints, from
  ``torso`` to ``l_wrist``; a scene written here).

Every derivation runs in a fresh Python process, stopped after ``--timeout`` seconds (reported
as "> timeout"). In that process the description is loaded, then:

* **cold**: the first derivation of the process (SymPy's one-off start-up costs included, as a
  command-line run pays them);
* **warm**: a derivation after a warm-up derivation of the bundled planar 2-link arm, so that
  both sides pay the same start-up once and the time is the derivation's own.

Times are CPU seconds of the measuring process (``time.process_time``), which other load on
the machine disturbs less than wall-clock time; the CSV has the wall-clock times too. For the
scene, applying it (:func:`eomgen.apply_scene`) is timed apart and *added* to both derive
times. Each number is the best of ``--repeat`` processes (the others measure the machine's
other load). ``ops`` is SymPy ``count_ops`` of the straight-line program of each
output (``Dynamics.operation_count([name])``), the operation count of the generated code.

Targets (issue #4): the arm scene derives ≥ 10× faster and has ≥ 5× fewer operations than the
whole humanoid.
"""

from __future__ import annotations

import argparse
import csv
import json
import subprocess
import sys
import time
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULT_TAG = "RESULT "
OUTPUTS = ("M", "C", "g")
TARGET_SPEEDUP = 10.0
TARGET_OPS = 5.0

SIMPLE_HUMANOID_ARM = """\
version: 1
robot: simple_humanoid
description: The left arm of the simple humanoid, from the shoulder to the wrist.
base: torso
tips: [l_wrist]
outputs: [M, C, g]
"""

CASES = {
    "talos": ("Talos", "talos_data/robots/talos_reduced.urdf",
              ROOT / "examples" / "scenes" / "talos_left_arm.yaml", None),
    "simple_humanoid": ("simple humanoid", "simple_humanoid_description/urdf/simple_humanoid.urdf",
                        None, SIMPLE_HUMANOID_ARM),
}


def robots_dir() -> Path:
    sys.path.insert(0, str(ROOT / "tests"))
    from support import erd_robots_dir  # the one place that knows where the package puts them

    found = erd_robots_dir()
    if found is None:
        sys.exit("example-robot-data is not installed: python3 -m pip install -e '.[bench]'")
    return found


# ----------------------------------------------------------------------------------------------
# The measuring process
# ----------------------------------------------------------------------------------------------


def worker(case: str, kind: str, warm: bool) -> None:
    """Measure one derivation and print ``RESULT {json}``."""
    import eomgen
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene

    label, relative, scene_path, scene_text = CASES[case]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # mimic joints read as independent
        start = time.perf_counter()
        model = eomgen.load(robots_dir() / relative)
        load_s = time.perf_counter() - start
    if warm:
        eomgen.derive(eomgen.load(eomgen.example_path("planar_2link")), simplify=False)
    reduce_s = reduce_wall_s = 0.0
    if kind == "scene":
        scene = (load_scene(scene_path) if scene_path is not None
                 else load_scene(f"<{case} arm scene>", text=scene_text))
        start, wall = time.process_time(), time.perf_counter()
        model, _ = apply_scene(model, scene)
        reduce_s, reduce_wall_s = time.process_time() - start, time.perf_counter() - wall
    start, wall = time.process_time(), time.perf_counter()
    dynamics = eomgen.derive(model, outputs=OUTPUTS, simplify=False)
    derive_s, derive_wall_s = time.process_time() - start, time.perf_counter() - wall
    ops = {name: dynamics.operation_count([name]) for name in OUTPUTS}
    print(RESULT_TAG + json.dumps({"dof": model.dof, "load_s": load_s, "reduce_s": reduce_s,
                                   "derive_s": derive_s, "reduce_wall_s": reduce_wall_s,
                                   "derive_wall_s": derive_wall_s, "ops": ops}), flush=True)


def measure(case: str, kind: str, warm: bool, timeout: float, repeat: int) -> dict | None:
    """The best of ``repeat`` fresh processes; None when one runs out of time."""
    best = None
    for _ in range(repeat):
        command = [sys.executable, str(Path(__file__).resolve()), "--worker", case, kind,
                   "warm" if warm else "cold"]
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return None
        lines = [l for l in done.stdout.splitlines() if l.startswith(RESULT_TAG)]
        if done.returncode != 0 or not lines:
            sys.exit(f"measuring {case} {kind} failed:\n{done.stderr[-2000:]}")
        result = json.loads(lines[-1][len(RESULT_TAG):])
        if best is None or result["derive_s"] < best["derive_s"]:
            best = result
    return best


# ----------------------------------------------------------------------------------------------
# The report
# ----------------------------------------------------------------------------------------------


def seconds(result: dict | None, timeout: float, with_reduce: bool = False) -> str:
    if result is None:
        return f"> {timeout:g} s"
    total = result["derive_s"] + (result["reduce_s"] if with_reduce else 0.0)
    return f"{total:.2f} s"


def ratio(a: float | None, b: float | None, bound: bool = False) -> str:
    if a is None or b is None or b == 0:
        return "–"
    return ("> " if bound else "") + f"{a / b:.1f}×"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--timeout", type=float, default=None,
                        help="seconds each derivation may take (default 600; 60 with --quick)")
    parser.add_argument("--repeat", type=int, default=None,
                        help="processes per number (best; default 3, 1 with --quick)")
    parser.add_argument("--cases", default=None,
                        help="comma-separated cases (default: all; simple_humanoid with --quick)")
    parser.add_argument("--quick", action="store_true",
                        help="the simple humanoid, one process per number, timeout 60 s")
    parser.add_argument("--csv", action="store_true",
                        help="also write benchmarks/results/scene_speed.csv")
    parser.add_argument("--worker", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.timeout is None:
        args.timeout = 60.0 if args.quick else 600.0
    if args.repeat is None:
        args.repeat = 1 if args.quick else 3
    if args.cases is None:
        args.cases = "simple_humanoid" if args.quick else ",".join(CASES)
    if args.worker:
        case, kind, warm = args.worker
        worker(case, kind, warm == "warm")
        return
    robots_dir()
    print(f"scene speed: outputs {', '.join(OUTPUTS)}; every derivation in a fresh process, best "
          f"of {args.repeat}, timeout {args.timeout:g} s; CPU seconds; scene times include "
          "applying the scene")
    rows = []
    for case in [c.strip() for c in args.cases.split(",") if c.strip()]:
        if case not in CASES:
            sys.exit(f"unknown case {case!r} (known: {', '.join(CASES)})")
        label = CASES[case][0]
        results = {(kind, warm): measure(case, kind, warm, args.timeout, args.repeat)
                   for kind in ("whole", "scene") for warm in (True, False)}
        whole, scene = results[("whole", True)], results[("scene", True)]
        whole_cold, scene_cold = results[("whole", False)], results[("scene", False)]
        if scene is None:
            sys.exit(f"{label}: the scene's own derivation took longer than {args.timeout:g} s")

        def total(r, reduce):
            return None if r is None else r["derive_s"] + (r["reduce_s"] if reduce else 0.0)

        ops_whole = sum(whole["ops"].values()) if whole else None
        ops_scene = sum(scene["ops"].values())
        speed = total(whole, False) / total(scene, True) if whole else None
        speed_cold = (total(whole_cold, False) / total(scene_cold, True)
                      if whole_cold and scene_cold else None)
        fewer = ops_whole / ops_scene if ops_whole else None
        print()
        print(f"{label}: whole robot ({whole['dof'] if whole else '?'} joints) against the arm "
              f"scene ({scene['dof']} joints; applying the scene: {scene['reduce_s']:.2f} s)")
        print(f"  {'':14} {'warm':>10} {'cold':>10} {'ops':>7}   ops M / C / g")
        for name, warm_r, cold_r, reduce in (("whole", whole, whole_cold, False),
                                              ("arm scene", scene, scene_cold, True)):
            ops = warm_r["ops"] if warm_r else None
            print(f"  {name:14} {seconds(warm_r, args.timeout, reduce):>10} "
                  f"{seconds(cold_r, args.timeout, reduce):>10} "
                  f"{sum(ops.values()) if ops else '–':>7}   "
                  + (" / ".join(str(ops[n]) for n in OUTPUTS) if ops else "–"))
        bound = whole is None
        speed_text = (ratio(args.timeout, total(scene, True), True) if bound
                      else f"{speed:.1f}×")
        print(f"  {'ratio':14} {speed_text:>10} "
              f"{(f'{speed_cold:.1f}×' if speed_cold else '–'):>10} "
              f"{(f'{fewer:.1f}×' if fewer else '–'):>7}   "
              + (" / ".join(f"{whole['ops'][n] / scene['ops'][n]:.1f}×" for n in OUTPUTS)
                 if whole else "–"))
        met_speed = bound or (speed is not None and speed >= TARGET_SPEEDUP)
        met_ops = fewer is not None and fewer >= TARGET_OPS
        print(f"  targets: ≥ {TARGET_SPEEDUP:g}× faster (warm): {'met' if met_speed else 'missed'}; "
              f"≥ {TARGET_OPS:g}× fewer operations: "
              f"{'met' if met_ops else ('unknown' if fewer is None else 'missed')}")
        rows.append({
            "case": label, "dof_whole": whole["dof"] if whole else "",
            "dof_scene": scene["dof"], "reduce_s": f"{scene['reduce_s']:.3f}",
            "whole_warm_s": f"{whole['derive_s']:.2f}" if whole else f"> {args.timeout:g}",
            "scene_warm_s": f"{total(scene, True):.2f}",
            "whole_cold_s": f"{whole_cold['derive_s']:.2f}" if whole_cold else f"> {args.timeout:g}",
            "scene_cold_s": f"{total(scene_cold, True):.2f}" if scene_cold else "",
            "whole_warm_wall_s": f"{whole['derive_wall_s']:.2f}" if whole else "",
            "scene_warm_wall_s": (f"{scene['derive_wall_s'] + scene['reduce_wall_s']:.2f}"),
            "speedup_warm": f"{speed:.2f}" if speed else "",
            "speedup_cold": f"{speed_cold:.2f}" if speed_cold else "",
            "ops_whole": ops_whole or "", "ops_scene": ops_scene,
            "ops_ratio": f"{fewer:.2f}" if fewer else "",
            **{f"ops_{n}_whole": whole["ops"][n] if whole else "" for n in OUTPUTS},
            **{f"ops_{n}_scene": scene["ops"][n] for n in OUTPUTS},
        })
    if args.csv and rows:
        path = HERE / "results" / "scene_speed.csv"
        path.parent.mkdir(exist_ok=True)
        with path.open("w", newline="", encoding="utf-8") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        print(f"\nwrote {path.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
