"""A YAML joint's ``spring: {stiffness, reference}`` (eomgen.model.Spring): read, in
``passive_forces`` as −k (q − q_ref) − d q̇, refused in one line where it makes no sense."""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedError
from support import write

ROBOT = """name: two
links:
  - {{name: base}}
  - {{name: l1, mass: 1, com: [0.5, 0, 0], inertia: {{ixx: 0.1, iyy: 0.1, izz: 0.1}}}}
  - {{name: l2, mass: 2, com: [0.2, 0, 0], inertia: {{ixx: 0.1, iyy: 0.1, izz: 0.1}}}}
joints:
  - {{name: j1, type: revolute, parent: base, child: l1, axis: [0, 1, 0], {spring}}}
  - {{name: j2, type: prismatic, parent: l1, child: l2, spring: {{stiffness: 5}},
      actuator: {{damping: 0.5}}}}
"""


def test_the_spring_is_in_the_passive_forces(tmp_path):
    path = write(tmp_path / "two.yaml", ROBOT.format(
        spring="spring: {stiffness: 2, reference: 0.3}"))
    module = eomgen.derive(eomgen.load(path), outputs=("tau_p",)).lambdify().module
    rng = np.random.default_rng(1)
    for _ in range(3):
        q, v = rng.normal(size=2), rng.normal(size=2)
        expected = [-2 * (q[0] - 0.3), -5 * q[1] - 0.5 * v[1]]
        assert np.allclose(module.passive_forces(q, v).ravel(), expected, rtol=1e-14)


@pytest.mark.parametrize("spring, problem", [
    ("spring: {stiffness: -1}", "spring stiffness: a negative stiffness"),
    ("spring: {reference: 1}", "spring"),
    ("spring: {stiffness: 1, ref: 0}", "spring"),
])
def test_a_wrong_spring_is_refused_by_name(tmp_path, spring, problem):
    path = write(tmp_path / "two.yaml", ROBOT.format(spring=spring))
    with pytest.raises((UnsupportedError, eomgen.errors.DescriptionError)) as raised:
        eomgen.load(path)
    message = str(raised.value)
    assert "joints[0] 'j1' spring" in message and problem in message and "\n" not in message
