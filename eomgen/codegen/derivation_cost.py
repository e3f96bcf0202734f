"""Measuring what a derivation costs (a :class:`~eomgen.reduction.report.DerivationCost`): of a
finished derivation (:func:`derivation_cost`), or in a fresh Python process
(:func:`measure_derivation`, whose subprocess runs :func:`measure_main` through
``python -m eomgen.codegen.derivation_cost``). The scene's report compares the two
(:mod:`eomgen.codegen.scene_generate`)."""

from __future__ import annotations

import json
import pickle
import subprocess
import sys
import time
from typing import Sequence

from ..dynamics import derive
from ..model import RobotModel
from ..outputs import derived_symbols
from ..parsers import load
from ..reduction.report import DerivationCost
from ..robots import example_path

#: Default time limit [s] of :func:`measure_derivation`.
MEASURE_TIMEOUT = 300.0


def derivation_cost(dynamics) -> DerivationCost:
    """The cost of a finished derivation (:class:`eomgen.Dynamics`): seconds and operations per
    output (M, C, g, tau as derived)."""
    names = [n for n in derived_symbols() if n in dynamics.outputs]
    return DerivationCost(sum(t for _, t in dynamics.timings),
                          tuple((n, dynamics.operation_count([n])) for n in names))


def measure_derivation(model: RobotModel, outputs: Sequence[str],
                       timeout: float = MEASURE_TIMEOUT) -> DerivationCost:
    """Derive ``model`` in a fresh Python process, after a warm-up derivation of the bundled
    two-link arm (so SymPy's start-up costs are not counted), and return its cost; a
    derivation that takes longer than ``timeout`` seconds is stopped and reported as such."""
    payload = pickle.dumps((model, tuple(outputs)))
    try:
        done = subprocess.run([sys.executable, "-m", "eomgen.codegen.derivation_cost"],
                              input=payload, capture_output=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return DerivationCost(None, (), timeout=timeout)
    if done.returncode != 0:
        lines = done.stderr.decode("utf-8", "replace").strip().splitlines()
        return DerivationCost(None, (), error=lines[-1] if lines else f"exit {done.returncode}")
    result = json.loads(done.stdout.decode("utf-8"))
    return DerivationCost(result["seconds"], tuple((n, c) for n, c in result["operations"]))


def measure_main() -> None:  # pragma: no cover - runs in the subprocess
    model, outputs = pickle.loads(sys.stdin.buffer.read())  # noqa: S301 - our own parent
    derive(load(example_path("planar_2link")), simplify=False)
    start = time.perf_counter()
    dynamics = derive(model, outputs=outputs, simplify=False)
    seconds = time.perf_counter() - start
    cost = derivation_cost(dynamics)
    json.dump({"seconds": seconds, "operations": list(cost.operations)}, sys.stdout)


if __name__ == "__main__":  # pragma: no cover - the subprocess of measure_derivation
    measure_main()
