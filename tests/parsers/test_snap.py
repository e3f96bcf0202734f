"""Snapping of rotation entries within 1e-11 of 0 or ±1: visible, and optional (``--no-snap``).

The snapped model differs from the description by up to 1e-11 per entry, which shows against
tools that keep the floats (Pinocchio reads the UR5 to 1e-15 of eomgen only without snapping).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import eomgen
from eomgen.analysis.routes import compile_batch
from eomgen.dynamics import derive
from eomgen.model import SNAP_TOLERANCE, snap_summary
from support import run_in_process
from support.extras import need

ANGLE = 1.57079632679  # π/2 to 11 decimals: cos is 4.9e-12, snapped to 0

URDF = f"""<robot name="bent">
  <link name="base"/>
  <link name="arm"><inertial><mass value="2"/><origin xyz="0.3 0 0"/>
    <inertia ixx="0.1" iyy="0.2" izz="0.3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"><inertial><mass value="1"/><origin xyz="0.2 0 0"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1" rpy="{ANGLE} 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="arm"/><child link="tip"/>
    <origin xyz="0.5 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>
"""


@pytest.fixture
def bent(tmp_path):
    path = tmp_path / "bent.urdf"
    path.write_text(URDF)
    return path


def test_snapping_is_recorded_with_its_change(bent):
    model = eomgen.load(bent)
    joint = next(j for j in model.joints if j.name == "j1")
    assert joint.origin.rotation[1][1] == 0 and joint.origin.rotation[2][2] == 0  # exact zeros
    snaps = dict(model.info)["snapped"]
    assert {s.what for s in snaps} == {f"cos({ANGLE!r})"}
    assert all(s.target == 0 and s.change == abs(math.cos(ANGLE)) for s in snaps)
    assert 0 < snaps[0].change <= SNAP_TOLERANCE
    summary = snap_summary(snaps)
    assert f"largest change {abs(math.cos(ANGLE)):.1e}" in summary and "--no-snap" in summary


def test_no_snap_keeps_the_floats_exactly(bent):
    model = eomgen.load(bent, snap=False)
    joint = next(j for j in model.joints if j.name == "j1")
    assert float(joint.origin.rotation[1][1]) == math.cos(ANGLE)
    assert float(joint.origin.rotation[2][1]) == math.sin(ANGLE)
    assert "snapped" not in dict(model.info)
    # the two models differ by the snapped amount, no more: in g, which sees the first joint's
    # tilt against gravity (M does not depend on how the first joint's frame is placed)
    snapped = derive(eomgen.load(bent), outputs=("g",), simplify=False)
    kept = derive(model, outputs=("g",), simplify=False)
    q = np.array([0.4, -1.1])
    g_snapped = compile_batch(snapped.program, snapped.q, ["g"])(*q[:, None])[0][0]
    g_kept = compile_batch(kept.program, kept.q, ["g"])(*q[:, None])[0][0]
    difference = np.abs(g_snapped - g_kept).max() / np.abs(g_kept).max()
    assert 0 < difference < 100 * SNAP_TOLERANCE


def test_ur5_without_snapping_agrees_with_pinocchio_to_1e_14(erd_robots_dir):
    pin = need("pinocchio", reason="Pinocchio is the independent reference")
    path = erd_robots_dir / "ur_description/urdf/ur5_robot.urdf"
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    rng = np.random.default_rng(5)
    errors = {}
    for snap in (True, False):
        dyn = derive(eomgen.load(path, snap=snap), outputs=("M", "tau"), simplify=False)
        evaluate = compile_batch(dyn.program, dyn.q + dyn.qd + dyn.qdd, ["M", "tau"])
        worst = 0.0
        for _ in range(5):
            q, qd, qdd = rng.uniform(-3, 3, (3, 6))
            M, tau = (x[0] for x in evaluate(*q[:, None], *qd[:, None], *qdd[:, None]))
            tau_pin, M_pin = pin.rnea(model, data, q, qd, qdd), pin.crba(model, data, q)
            worst = max(worst, np.abs(tau[:, 0] - tau_pin).max() / np.abs(tau_pin).max(),
                        np.abs(M - M_pin).max() / np.abs(M_pin).max())
        errors[snap] = worst
    assert errors[False] <= 1e-14
    assert errors[True] > 1e-13  # snapping is what made the difference


def test_cli_no_snap_changes_the_output_and_the_cache_key(bent, tmp_path):
    command = ["generate", bent, "--backend", "numpy", "--cache-dir", tmp_path / "cache"]
    outputs, progress = {}, []
    for flag in ([], ["--no-snap"], []):
        out = tmp_path / ("kept" if flag else "snapped")
        result = run_in_process(*command, *flag, "-o", out)
        assert result.returncode == 0, result.stderr
        text = (out / "bent_numpy.py").read_text()
        assert outputs.setdefault(bool(flag), text) == text  # the cached run: the same file
        progress.append(result.stderr)
    assert "snapped 1 rotation/axis entry within 1e-11" in progress[0]
    assert "snapped" not in progress[1]
    assert outputs[True] != outputs[False]
    assert repr(math.cos(ANGLE)) in outputs[True] and repr(math.cos(ANGLE)) not in outputs[False]
