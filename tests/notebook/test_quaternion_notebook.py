"""``eomgen notebook`` on a model with a ball joint (the pendulum of docs/legged.md: a ball
shoulder and a revolute elbow, q with 5 entries, v with 4): the notebook states the chart
(q̇ = configuration_rate(q, v) ≠ v, M v̇ + C v + g = τ, integrate), shows no textbook cells
(they take every joint as a coordinate), and (slow) runs in a real kernel: its derived τ and M
agree with Pinocchio's rnea and crba there, and its simulation moves q with the quaternion's
rate."""

from __future__ import annotations

import nbformat
import pytest

import eomgen
from eomgen.teach.notebook import build_notebook
from support import run_cli, write
from support.extras import need

PENDULUM = """name: pendulum
links:
  - {name: base}
  - {name: upper, mass: 1.5, com: [0, 0, -0.4], inertia: {ixx: 0.05, iyy: 0.06, izz: 0.01}}
  - {name: lower, mass: 0.7, com: [0, 0, -0.3], inertia: {ixx: 0.02, iyy: 0.02, izz: 0.01}}
joints:
  - {name: shoulder, type: spherical, parent: base, child: upper}
  - {name: elbow, type: revolute, parent: upper, child: lower, origin: {xyz: [0, 0, -0.8]},
     axis: [0, 1, 0]}
"""


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory):
    path = write(tmp_path_factory.mktemp("pendulum") / "pendulum.yaml", PENDULUM)
    return path, eomgen.load(path)


def test_notebook_states_the_chart_and_leaves_out_the_textbook(pendulum):
    path, model = pendulum
    nb = build_notebook(model, path)
    text = "\n".join(cell.source for cell in nb.cells)
    intro = nb.cells[0].source
    assert "configuration $q$ has 5 entries" in intro and "velocity $v$ has 4" in intro
    assert "$\\dot q \\ne v$" in intro and "M(q)\\,\\dot v + C(q, v)\\,v + g(q) = \\tau" in intro
    assert "\\ddot q" not in text
    for needle in ("configuration_rate(q, v, model)", "integrate(neutral(model)",
                   "to_pinocchio(model)", "difference(q0", "eomgen.verify"):
        assert needle in text, needle
    assert "textbook_derivation" not in text and "regressor_form" not in text
    assert nbformat.writes(nb) == nbformat.writes(build_notebook(model, path))


@pytest.mark.slow
def test_notebook_runs_and_agrees_with_pinocchio(pendulum, tmp_path):
    nbclient = need("nbclient")
    need("ipykernel")
    need("pinocchio")
    out = tmp_path / "pendulum.ipynb"
    result = run_cli("notebook", pendulum[0], "-o", out)
    assert result.exit_code == 0, result.output
    nb = nbformat.read(out, as_version=4)
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    printed = "".join(o.get("text", "") for o in outputs)
    for check in ("largest |tau - rnea|:", "largest |M - crba|:"):
        assert float(printed.split(check)[1].split()[0]) < 1e-9, check
    assert any("image/png" in o.get("data", {}) for o in outputs)


def test_a_lone_ball_joint_is_never_shown_in_textbook_form(tmp_path):
    """Three virtual joints and a small program would pass the teaching-size bound, but the
    textbook form would print the chart's angles (s_2, c_3) as if they were coordinates: the
    rich display (the notebook's ``dyn`` cell) shows the program's summary instead."""
    from eomgen.present.notation import teaching_sized

    path = write(tmp_path / "ball.yaml", PENDULUM.replace("name: pendulum", "name: ball").split(
        "  - {name: lower")[0] + "joints:\n  - {name: shoulder, type: spherical, parent: base, "
        "child: upper}\n")
    dyn = eomgen.derive(eomgen.load(path))
    assert dyn.model.dof == 3 and not teaching_sized(dyn)
    tex = dyn._repr_latex_()
    assert "s_{2}" not in tex and "c_{3}" not in tex and "shoulder" in tex
