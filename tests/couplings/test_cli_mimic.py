"""``--mimic independent`` (issue 26): every command that reads a description can read the
followers of its couplings (URDF <mimic>, MJCF joint equalities) as independent joints, one
warning each; the default honours them. Checked against eomgen's float Newton–Euler recursion
on the whole tree (eomgen.numeric.newton_euler), which the generated code does not use.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from eomgen.numeric.newton_euler import M_rnea, numeric_model
from eomgen.model import uncoupled
from support import load_quietly, relative, run_cli

MIMIC = Path(__file__).resolve().parent.parent / "corpus" / "valid_urdf_mimic.urdf"


def generated(tmp_path, *options):
    result = run_cli("generate", MIMIC, "--backend", "numpy", "--no-cache", "-o", tmp_path,
                     *options)
    namespace: dict = {}
    if result.exit_code == 0:
        exec((tmp_path / "corpus_arm_numpy.py").read_text(encoding="utf-8"), namespace)
    return result, namespace


def test_mimic_independent_generates_the_follower_as_a_joint(tmp_path):
    result, module = generated(tmp_path, "--mimic", "independent")
    assert result.exit_code == 0, result.output
    assert module["JOINT_NAMES"] == ("shoulder", "finger_joint")
    warned = [line for line in result.stderr.splitlines() if "finger_joint" in line]
    assert len(warned) == 1 and "read as an independent joint (--mimic independent)" in warned[0]
    whole = numeric_model(uncoupled(load_quietly(MIMIC)))
    q = np.array([0.4, 0.03])  # the follower off its coupling: 0.03 ≠ 0.5 · 0.4
    assert relative(module["mass_matrix"](q).reshape(2, 2), M_rnea(whole, q)) < 1e-12


def test_mimic_honour_is_the_default(tmp_path):
    result, module = generated(tmp_path)
    assert result.exit_code == 0, result.output
    assert module["JOINT_NAMES"] == ("shoulder",)
    result, honoured = generated(tmp_path / "h", "--mimic", "honour")
    assert honoured["JOINT_NAMES"] == ("shoulder",) and "independent" not in result.stderr


@pytest.mark.parametrize("command", ["verify", "bench", "notebook", "teach", "simulate",
                                     "excite", "identify"])
def test_every_command_taking_a_description_has_the_option(command):
    result = run_cli(command, "--help")
    assert result.exit_code == 0 and "--mimic [honour|independent]" in result.output


def test_mimic_independent_under_strict_is_refused(tmp_path):
    result, _ = generated(tmp_path, "--mimic", "independent", "--strict")
    assert result.exit_code == 2 and not list(tmp_path.iterdir())
    assert "finger_joint" in result.stderr
