"""``eomgen excite`` and ``eomgen identify`` with the friction and armature a description
declares (issue 29 item 3): excite simulates them, identify fits them by default and the
report's description column shows the declared values, as the generated regressor has them;
``--no-friction`` leaves the friction out of both, ``--friction`` adds it where none is
declared. A two-joint URDF arm written here (shoulder about z, elbow about y) keeps the runs
short."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from support import run_in_process, write
from support.extras import need

need("scipy", reason="identification needs scipy")

#: ``<dynamics damping friction>`` of the arm's joints: FV, FC per joint.
DAMPING = {"FV1": 0.8, "FV2": 0.3}
FRICTION = {"FC1": 0.5, "FC2": 0.2}
DECLARED = {**DAMPING, **FRICTION}

ARM = """<?xml version="1.0"?>
<robot name="rubbing_arm">
  <link name="base"/>
  <link name="upper">
    <inertial><origin xyz="0.02 0.01 0.15"/><mass value="2.0"/>
      <inertia ixx="0.03" ixy="0.001" ixz="0.002" iyy="0.03" iyz="0.001" izz="0.01"/>
    </inertial>
  </link>
  <link name="fore">
    <inertial><origin xyz="0.2 0.01 0.02"/><mass value="1.0"/>
      <inertia ixx="0.004" ixy="0.0005" ixz="0.001" iyy="0.015" iyz="0.0003" izz="0.012"/>
    </inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="50" velocity="3"/>
    <dynamics damping="0.8" friction="0.5"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="30" velocity="3"/>
    <dynamics damping="0.3" friction="0.2"/>
  </joint>
</robot>
"""

#: Inertial base parameters of the arm (shoulder vertical: body 1 leaves only ZZ1R).
INERTIAL = ["ZZ1R", "MX2", "MZ2", "XX2R", "XY2", "YY2", "XZ2", "YZ2"]


def excite(tmp_path: Path, *options, name="arm.csv") -> tuple[Path, str]:
    data = tmp_path / name
    done = run_in_process("excite", tmp_path / "arm.urdf", "-o", data, "--samples", 60,
                          "--quiet", *options)
    assert done.returncode == 0, done.stderr
    return data, done.stdout


def identify(tmp_path: Path, data: Path, *options, out="id") -> tuple[list[dict], str]:
    """The report's rows (the estimates CSV) and its Markdown."""
    done = run_in_process("identify", tmp_path / "arm.urdf", data, "-o", tmp_path / out,
                          "--quiet", *options)
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader((tmp_path / out / "identify_rubbing_arm.csv").open()))
    return rows, done.stdout


@pytest.fixture
def arm(tmp_path):
    write(tmp_path / "arm.urdf", ARM)
    return tmp_path


def test_declared_friction_is_simulated_fitted_and_shown(arm):
    """1 % noise: every base parameter within 3 reported std of the description's, FV and FC
    within 3 % of the declared values, which the description column shows."""
    data, said = excite(arm, "--noise", 0.01)
    assert "efforts with the description's viscous friction and Coulomb friction" in said
    rows, report = identify(arm, data)
    assert [r["name"] for r in rows] == INERTIAL + ["FV1", "FV2", "FC1", "FC2"]
    by_name = {r["name"]: r for r in rows}
    for name, value in DECLARED.items():
        assert float(by_name[name]["description"]) == value
        assert abs(float(by_name[name]["estimate"]) - value) < 0.03 * value, by_name[name]
        assert f"| {name} | `{name}` |" in report and f"| {value:.6g} |" in report
    for r in rows:
        assert abs(float(r["estimate"]) - float(r["description"])) < 3 * float(r["std"]), r


def test_declared_armature_is_simulated_and_fitted_exactly(arm):
    """A scene's armature on top of the URDF's friction: noise-free data give back every base
    parameter (IA1 grouped into ZZ1R, IA2 into YY2R) and the friction to 1e-8."""
    scene = write(arm / "drives.yaml", "version: 1\nactuators:\n  shoulder: {armature: 0.05}\n"
                                       "  elbow: {armature: 0.02}\n")
    data, said = excite(arm, "--scene", scene)
    assert "efforts with the description's armature, viscous friction and Coulomb friction" \
        in said
    rows, _ = identify(arm, data, "--scene", scene)
    by_name = {r["name"]: r for r in rows}
    assert by_name["ZZ1R"]["expression"] == "IA1 + ZZ1 + ZZ2"
    assert by_name["YY2R"]["expression"] == "IA2 + YY2"
    assert float(by_name["YY2R"]["description"]) == pytest.approx(0.0554 + 0.02, rel=1e-12)
    for r in rows:
        estimate, declared = float(r["estimate"]), float(r["description"])
        assert abs(estimate - declared) < 1e-8 * max(1.0, abs(declared)), r


def test_no_friction_leaves_it_out_of_simulation_and_fit(arm):
    """``excite --no-friction`` simulates the rigid bodies alone: identify then finds FV = FC
    = 0 where the description declares them (shown in its column), and ``identify
    --no-friction`` fits the inertial base parameters alone, exactly."""
    data, said = excite(arm, "--no-friction")
    assert "efforts with" not in said
    rows, _ = identify(arm, data)
    for r in rows:
        if r["name"] in DECLARED:
            assert float(r["description"]) == DECLARED[r["name"]]
            assert abs(float(r["estimate"])) < 1e-8, r
    rows, report = identify(arm, data, "--no-friction", out="rigid")
    assert [r["name"] for r in rows] == INERTIAL and "FV1" not in report
    for r in rows:
        estimate, declared = float(r["estimate"]), float(r["description"])
        assert abs(estimate - declared) < 1e-8 * max(1.0, abs(declared)), r


def test_friction_adds_columns_a_description_does_not_declare(arm):
    """``--friction`` on a URDF without ``<dynamics>``: FV and FC columns whose description
    values are 0, and the noise-free estimates are 0 too."""
    write(arm / "arm.urdf", ARM.replace('<dynamics damping="0.8" friction="0.5"/>', "")
          .replace('<dynamics damping="0.3" friction="0.2"/>', ""))
    data, said = excite(arm)
    assert "efforts with" not in said
    rows, _ = identify(arm, data)
    assert [r["name"] for r in rows] == INERTIAL
    rows, _ = identify(arm, data, "--friction", out="with")
    assert [r["name"] for r in rows] == INERTIAL + ["FV1", "FV2", "FC1", "FC2"]
    for r in rows[len(INERTIAL):]:
        assert float(r["description"]) == 0.0 and abs(float(r["estimate"])) < 1e-8, r
    assert np.isfinite([float(r["std"]) for r in rows]).all()


def test_a_flexible_joint_is_one_line_exit_2_and_nothing_written(arm):
    """A stiffness (Spong's flexible joint) has no rigid-body regressor: excite and identify
    refuse it, as ``generate --outputs regressor`` does, rather than treat the joint as rigid."""
    scene = write(arm / "flexible.yaml", "version: 1\nactuators:\n"
                                         "  elbow: {armature: 0.02, stiffness: 100}\n")
    data = write(arm / "data.csv", "t,q_shoulder,q_elbow,tau_shoulder,tau_elbow\n")
    for args in (("excite", arm / "arm.urdf", "-o", arm / "out.csv"),
                 ("identify", arm / "arm.urdf", data, "-o", arm / "out")):
        done = run_in_process(*args, "--scene", scene, "--quiet")
        assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
        assert "joint 'elbow' actuator: a flexible joint has no rigid-body regressor" \
            in done.stderr
    assert sorted(p.name for p in arm.iterdir()) == ["arm.urdf", "data.csv", "flexible.yaml"]
