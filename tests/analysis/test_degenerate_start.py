"""A start configuration that stands for no configuration at all (a quaternion or a planar
joint's ``(cos θ, sin θ)`` of zero length) is refused before anything is integrated: one line
naming the joint and its entries, from the CLI (exit 2, nothing written) and from the API
(ValueError). A short but nonzero one stands for its normalised value, as the kinds say, and
is integrated to the same trajectory as the unit one."""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.model.configuration import DEGENERATE_LENGTH, degenerate
from eomgen.parsers import load
from support import run_in_process, write

BALL_AND_PLANE = """
name: ball_and_plane
links:
  - {name: base}
  - {name: arm, mass: 1.0, com: [0, 0, -0.4], inertia: {ixx: 0.1, iyy: 0.12, izz: 0.05}}
  - {name: puck, mass: 0.5, com: [0.1, 0, 0], inertia: {ixx: 0.01, iyy: 0.01, izz: 0.02}}
joints:
  - {name: shoulder, type: spherical, parent: base, child: arm}
  - {name: slide, type: planar, parent: arm, child: puck, origin: {xyz: [0, 0, -0.8]}}
"""


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    return load(write(tmp_path_factory.mktemp("degenerate") / "ball_and_plane.yaml",
                      BALL_AND_PLANE))


def test_which_entries_are_named(model):
    assert model.configuration_names == ("shoulder_qx", "shoulder_qy", "shoulder_qz",
                                         "shoulder_qw", "slide_x", "slide_y", "slide_cos",
                                         "slide_sin")
    good = np.array([0, 0, 0, 1, 0.3, -0.2, 1, 0.0])
    assert degenerate(good, model) is None
    tiny = good.copy()
    tiny[0:4] *= 10 * DEGENERATE_LENGTH  # short, not zero: it stands for the unit one
    assert degenerate(tiny, model) is None
    pair = good.copy()
    pair[6:8] = 0.0
    assert degenerate(pair, model) == ("joint 'slide': its (cos, sin) pair (slide_cos, "
                                       "slide_sin) has zero length; give a unit one")
    both = pair.copy()
    both[0:4] = 0.0  # the first joint is named
    assert degenerate(both, model).startswith("joint 'shoulder': its quaternion (shoulder_qx,"
                                              " shoulder_qy, shoulder_qz, shoulder_qw)")


def test_the_cli_refuses_in_one_line(model, tmp_path):
    out = tmp_path / "out"
    result = run_in_process("simulate", model.source, "--q0", "0,0,0,1,0.3,-0.2,0,0",
                            "--duration", "0.05", "-o", out)
    assert result.returncode == 2, result.stderr
    assert result.stderr.strip().splitlines()[-1] == (
        "eomgen: error: --q0: joint 'slide': its (cos, sin) pair (slide_cos, slide_sin) has "
        "zero length; give a unit one")
    assert not out.exists()


def test_the_api_refuses_and_a_short_quaternion_is_the_unit_one(model):
    from eomgen.analysis.simulate import RK4, System, simulate

    system = System(model)
    q0 = np.array([0.1, -0.2, 0.3, 0.9, 0.3, -0.2, 0.6, 0.8])
    qd0 = np.array([0.5, -0.3, 0.2, 0.1, 0.0, 1.0])
    with pytest.raises(ValueError, match="q0: joint 'shoulder': its quaternion"):
        simulate(system, RK4(0.01), np.r_[np.zeros(4), q0[4:]], qd0, 0.05, points=3)
    unit, _ = simulate(system, RK4(0.01), q0, qd0, 0.05, points=3)
    short = q0.copy()
    short[0:4] *= 1e-6
    scaled, _ = simulate(system, RK4(0.01), short, qd0, 0.05, points=3)
    np.testing.assert_allclose(scaled.q[-1], unit.q[-1], rtol=0, atol=1e-12)
