"""eomgen's generated code against Pinocchio on fair terms (Franka Panda, fingers locked).

Each peer is timed through its plain public call on data already in its own layout:
``pin.rnea(model, data, q, qd, qdd)``, ``pin.crba``, ``pin.computeCoriolisMatrix``,
``pin.computeGeneralizedGravity`` and ``pin.aba`` on Pinocchio's own model of the URDF
(``buildModelFromUrdf`` + ``buildReducedModel`` with the fingers locked 2 cm open, as the scene
``examples/scenes/panda_fingers_locked.yaml`` does), whose joint order equals eomgen's, so no
conversion is needed or timed. eomgen is generated once (``--backend numpy,fast``) from the
same URDF and scene.

1. One state from Python: the fast module (``<robot>_fast``, a C extension) against the plain
   Pinocchio call, each output; target ours/Pinocchio ≤ 0.5.
2. Batches of N states (1,000 and 10,000): the fast module and the NumPy module on the (N, 7)
   arrays against a Python loop of plain Pinocchio calls storing into a preallocated array;
   target ours/Pinocchio ≤ 1/3 for the best eomgen route.

Every comparison first checks that both sides agree (relative to the largest value). Times are
medians over ``--repeats`` timings with the spread (min–max) beside them; the ratio is the
median of the per-repeat ratios, both sides timed in turns in the same process, so that a
change in the machine's load affects both alike. The clock is the process's CPU time
(``time.process_time``), which waiting for a CPU on a shared machine does not inflate
(``--clock wall`` for ``time.perf_counter``); every timed call is single-threaded. Nothing
asserts on a time.

Usage::

    python benchmarks/fair_speed.py            # about a minute
    python benchmarks/fair_speed.py --quick    # fewer calls and repeats
    python benchmarks/fair_speed.py --markdown benchmarks/results/fair_speed.md
"""

from __future__ import annotations

import argparse
import importlib.util
import platform
import statistics
import sys
import tempfile
import time
import timeit
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # measure this checkout, not some installed copy
sys.path.insert(0, str(ROOT / "benchmarks"))

import eomgen  # noqa: E402
from codegen_speed import erd_robots_dir  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402

LOCKED = {"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02}
AGREEMENT = 1e-12  # max |ours - Pinocchio| / max |Pinocchio|


def panda_modules(folder: Path):
    """Generate and import the Panda's NumPy and fast modules: (numpy module, fast module)."""
    path = erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = eomgen.load(path)
    model = lock_joints(model, LOCKED)  # what examples/scenes/panda_fingers_locked.yaml does
    files = render_files(model, ["numpy", "fast"])
    modules = []
    for f in files:
        (folder / f.name).write_bytes(f.content if isinstance(f.content, bytes)
                                      else f.content.encode("utf-8"))
    for suffix in ("_numpy", "_fast"):
        candidates = [folder / f.name for f in files if f.name.startswith(f"panda{suffix}.")
                      and not f.name.endswith(".c")]
        if not candidates:
            sys.exit("fair_speed: the fast module was not compiled (no C compiler or Python.h)")
        spec = importlib.util.spec_from_file_location("panda" + suffix, candidates[0])
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        modules.append(module)
    return path, modules


def pinocchio_panda(path: Path, joint_names):
    import pinocchio as pin

    full = pin.buildModelFromUrdf(str(path))
    q_lock = pin.neutral(full)
    for name, value in LOCKED.items():
        q_lock[full.idx_qs[full.getJointId(name)]] = value
    model = pin.buildReducedModel(full, [full.getJointId(n) for n in LOCKED], q_lock)
    if tuple(model.names[1:]) != tuple(joint_names) or model.nq != len(joint_names):
        sys.exit(f"fair_speed: Pinocchio's joints {tuple(model.names[1:])} differ from "
                 f"eomgen's {joint_names}")
    return pin, model, model.createData()


CLOCK = {"cpu": time.process_time, "wall": time.perf_counter}


Samples = dict[str, list[float]]


def timed(statements: dict[str, str], namespace: dict, number: int, repeats: int,
          units: int = 1, clock=time.process_time) -> tuple[Samples, Samples]:
    """µs per unit of each statement per repeat, in turns; and ratios to the last statement."""
    timers = {k: timeit.Timer(s, globals=namespace, timer=clock)
              for k, s in statements.items()}
    for t in timers.values():
        t.timeit(max(1, number // 10))
    samples: dict[str, list[float]] = {k: [] for k in statements}
    for _ in range(repeats):
        for k, t in timers.items():
            samples[k].append(t.timeit(number) / number / units * 1e6)
    reference = list(statements)[-1]
    ratios = {k: [a / b for a, b in zip(v, samples[reference])] for k, v in samples.items()}
    return samples, ratios


def spread(values: list[float], spec: str) -> str:
    return f"{statistics.median(values):{spec}} ({min(values):{spec}}–{max(values):{spec}})"


OUTPUTS = (  # (label, our function, its inputs, Pinocchio function, its inputs)
    ("τ", "inverse_dynamics", "q, qd, qdd", "rnea", "q, qd, qdd"),
    ("M", "mass_matrix", "q", "crba", "q"),
    ("C", "coriolis_matrix", "q, qd", "computeCoriolisMatrix", "q, qd"),
    ("g", "gravity_vector", "q", "computeGeneralizedGravity", "q"),
    ("q̈", "forward_dynamics", "q, qd, qdd", "aba", "q, qd, qdd"),
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--clock", choices=sorted(CLOCK), default="cpu")
    parser.add_argument("--markdown", type=Path, help="also write the tables to this file")
    args = parser.parse_args()
    calls, repeats, batch_repeats = (2_000, 5, 3) if args.quick else (20_000, 9, 5)
    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    with tempfile.TemporaryDirectory() as tmp:
        path, (numpy_module, fast) = panda_modules(Path(tmp))
        pin, model, data = pinocchio_panda(path, fast.JOINT_NAMES)
        import casadi

        say(f"Panda, 7 joints (fingers locked). Python {platform.python_version()}, NumPy "
            f"{np.__version__}, Pinocchio {pin.__version__}, CasADi {casadi.__version__}, "
            f"eomgen {eomgen.__version__}, {platform.machine()}; {args.clock} clock.")
        rng = np.random.default_rng(0)
        q, qd, qdd = (rng.uniform(-1.5, 1.5, 7) for _ in range(3))
        namespace = dict(fast=fast, numpy_module=numpy_module, pin=pin, model=model, data=data,
                         q=q, qd=qd, qdd=qdd)
        for label, ours, inputs, theirs, pin_inputs in OUTPUTS:
            a = eval(f"fast.{ours}({inputs})", namespace)  # noqa: S307 - our own table
            b = eval(f"pin.{theirs}(model, data, {pin_inputs})", namespace)  # noqa: S307
            error = np.abs(a - b).max() / np.abs(b).max()
            if error > AGREEMENT:
                sys.exit(f"fair_speed: {ours} differs from pin.{theirs} by {error:.1e}")

        say()
        say("One state from Python, µs per call: median (min–max) over "
            f"{repeats} repeats of {calls} calls; ratio = median of per-repeat ratios.")
        say()
        say("| output | fast module | plain Pinocchio call | fast / Pinocchio | target | met |")
        say("|---|---:|---:|---:|---:|---|")
        for label, ours, inputs, theirs, pin_inputs in OUTPUTS:
            samples, ratios = timed({"ours": f"fast.{ours}({inputs})",
                                     "pin": f"pin.{theirs}(model, data, {pin_inputs})"},
                                    namespace, calls, repeats, clock=CLOCK[args.clock])
            ratio = statistics.median(ratios["ours"])
            say(f"| {label} | {spread(samples['ours'], '.2f')} | "
                f"{spread(samples['pin'], '.2f')} (`pin.{theirs}`) | {ratio:.2f} | ≤ 0.50 | "
                f"{'yes' if ratio <= 0.5 else 'NO'} |")

        for N in (1_000, 10_000):
            Q, QD, QDD = (rng.uniform(-1.5, 1.5, (N, 7)) for _ in range(3))
            namespace.update(Q=Q, QD=QD, QDD=QDD)
            loops = {}
            for label, ours, inputs, theirs, pin_inputs in OUTPUTS:
                shape = "(N, 7, 7)" if ours in ("mass_matrix", "coriolis_matrix") else "(N, 7)"
                arguments = ", ".join(f"{x.strip().upper()}[k]" for x in pin_inputs.split(","))
                source = (f"def loop_{ours}():\n    out = np.empty({shape})\n"
                          f"    for k in range(N):\n"
                          f"        out[k] = pin.{theirs}(model, data, {arguments})\n"
                          "    return out\n")
                exec(source, dict(namespace, np=np, N=N), loops)  # noqa: S102 - our own loop
            namespace.update(loops)
            batch_inputs = {x: x.upper() for x in ("q", "qd", "qdd")}
            say()
            say(f"Batch of {N:,} states, µs per state: median (min–max) over {batch_repeats} "
                "repeats; Pinocchio: a Python loop of plain calls storing into an array.")
            say()
            say("| output | fast module (loop in C) | NumPy module | Pinocchio loop | "
                "fast / Pinocchio | NumPy / Pinocchio | target (best) | met |")
            say("|---|---:|---:|---:|---:|---:|---:|---|")
            for label, ours, inputs, theirs, pin_inputs in OUTPUTS:
                arguments = ", ".join(batch_inputs[x.strip()] for x in inputs.split(","))
                check = eval(f"fast.{ours}({arguments})", namespace)  # noqa: S307
                reference = namespace[f"loop_{ours}"]()
                error = np.abs(check - reference).max() / np.abs(reference).max()
                if error > AGREEMENT:
                    sys.exit(f"fair_speed: batch {ours} differs from Pinocchio by {error:.1e}")
                samples, ratios = timed({"fast": f"fast.{ours}({arguments})",
                                         "numpy": f"numpy_module.{ours}({arguments})",
                                         "pin": f"loop_{ours}()"},
                                        namespace, 1, batch_repeats, units=N,
                                        clock=CLOCK[args.clock])
                best = min(statistics.median(ratios["fast"]), statistics.median(ratios["numpy"]))
                say(f"| {label} | {spread(samples['fast'], '.3f')} | "
                    f"{spread(samples['numpy'], '.3f')} | {spread(samples['pin'], '.2f')} | "
                    f"{statistics.median(ratios['fast']):.3f} | "
                    f"{statistics.median(ratios['numpy']):.2f} | ≤ 0.333 | "
                    f"{'yes' if best <= 1 / 3 else 'NO'} |")
    if args.markdown:
        args.markdown.parent.mkdir(parents=True, exist_ok=True)
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
