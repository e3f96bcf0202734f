"""docs/derivatives.md's iLQR example, run as written on the planar 2-link arm's fast module (the
module generated as the document's command line says)."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.codegen.backends.casadi_backend import c_compiler
from eomgen.codegen.backends.fast_backend import python_headers
from eomgen.codegen.generate import render_files

DOC = Path(__file__).resolve().parents[2] / "docs" / "derivatives.md"


@pytest.mark.skipif(c_compiler() is None or python_headers() is None,
                    reason="needs a C compiler and Python's C headers")
def test_the_ilqr_example_reaches_its_goal(tmp_path, monkeypatch):
    text = DOC.read_text(encoding="utf-8")
    command = re.search(r"eomgen generate (\S+) --backend fast --outputs (\S+)", text)
    assert command, "the document's command line"
    (block,) = re.findall(r"```python\n(.*?)```", text, flags=re.S)[:1]
    model = eomgen.load(eomgen.example_path("planar_2link"))
    assert command.group(1).endswith("planar_2link.yaml")
    for f in render_files(model, ["fast"], functions=command.group(2).split(",")):
        path = tmp_path / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "planar_2link_fast", raising=False)
    namespace: dict = {}
    exec(compile(block, str(DOC), "exec"), namespace)  # noqa: S102 - our own document
    X, costs, x_goal = namespace["X"], namespace["costs"], namespace["x_goal"]
    assert all(b < a for a, b in zip(costs, costs[1:]))        # every accepted step descends
    assert costs[-1] < 1e-3 * costs[0]
    np.testing.assert_allclose(X[-1], x_goal, atol=0.02)       # at the goal, at rest
    # the trajectory is the robot's: every step is the Euler step of its forward dynamics
    robot, h, n = namespace["robot"], namespace["h"], namespace["n"]
    qdd = robot.forward_dynamics_aba(X[:-1, :n], X[:-1, n:], namespace["U"])
    np.testing.assert_allclose(X[1:, n:], X[:-1, n:] + h * qdd, rtol=1e-12, atol=1e-12)
