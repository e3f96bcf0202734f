"""``eomgen teach`` on an arm whose second joint is turned by π/6 (a user's report: a traceback,
"Mdot - 2C written with named factors is not skew-symmetric", with or without ``--no-check``).

The handout is exact (√3, no 0.866…); on a model with floats (a turn of 0.5 rad) its named-factor
checks hold to 1e-12 and the handout says so; a check that fails is one error line naming the
description (exit 2, nothing written), and ``--no-check`` does not run it; an unexpected
exception is the CLI's error line too.
"""

from __future__ import annotations

import re

import pytest

import eomgen.teach
import eomgen.teach.control
from eomgen.errors import VerificationError
from eomgen.symbolic.identities import ZeroCheck
from support import run_in_process, write
from support.robots import turned_arm_yaml

FLOAT_NOTE = "The model has floating-point numbers"


@pytest.fixture(scope="module")
def turned(tmp_path_factory):
    folder = tmp_path_factory.mktemp("turned")
    return write(folder / "turned_2r.yaml", turned_arm_yaml("pi/6"))


def test_teach_writes_an_exact_handout(turned, tmp_path):
    result = run_in_process("teach", turned, "--format", "md,html", "--quiet", "-o", tmp_path)
    assert result.returncode == 0, result.stderr
    assert "Traceback" not in result.stderr
    text = (tmp_path / "turned_2r_handout.md").read_text()
    assert r"\sqrt{3}" in text and (tmp_path / "turned_2r_handout.html").is_file()
    assert not re.search(r"0\.866|1\.732|0\.5000", text)  # no float of cos/sin(π/6)
    assert FLOAT_NOTE not in text  # checked exactly
    assert "All checks passed." in text


def test_a_model_with_floats_is_checked_to_a_stated_tolerance(tmp_path):
    description = write(tmp_path / "turned_2r.yaml", turned_arm_yaml("0.5"))
    result = run_in_process("teach", description, "--format", "md", "--quiet", "-o", tmp_path)
    assert result.returncode == 0, result.stderr
    text = (tmp_path / "turned_2r_handout.md").read_text()
    note = text[text.index(FLOAT_NOTE):].split("\n")[0]
    assert "checked the skew symmetry to 1e-12 relative" in note
    residual = float(note.split("largest residual ")[1].split(")")[0])
    assert 0 < residual < 1e-12


def _failing_check(statement, residual, scale, tolerance=1e-12):
    return ZeroCheck(statement, True, 0.5, tolerance)


def test_a_failed_check_is_one_line_and_no_check_does_not_run_it(turned, tmp_path,
                                                                  monkeypatch):
    monkeypatch.setattr(eomgen.teach.control, "check_zero", _failing_check)
    out = tmp_path / "checked"
    failed = run_in_process("teach", turned, "--format", "md", "--quiet", "-o", out)
    assert failed.returncode == 2 and "Traceback" not in failed.stderr
    assert failed.stderr.strip().splitlines() == [
        f"eomgen: error: {turned}: a check of the handout failed: C written with named "
        "factors equals the derived C: FAILED, the residual is not 0 (largest relative "
        "coefficient 5.0e-01); --no-check writes the handout without its checks"]
    assert not out.exists()
    unchecked = run_in_process("teach", turned, "--format", "md", "--quiet", "--no-check",
                               "-o", tmp_path / "unchecked")
    assert unchecked.returncode == 0, unchecked.stderr


def test_handout_check_raises_a_verification_error_naming_the_description():
    class Model:
        source = "arm.yaml"

    class Dynamics:
        model = Model()

    with pytest.raises(VerificationError, match=r"^arm\.yaml: a check of the handout failed: "
                       r"x = 0: FAILED, not even to 1e-12"):
        eomgen.teach.control.handout_check(Dynamics(), "x = 0", [[1e-9]], [[1.0]])
    passed = eomgen.teach.control.handout_check(Dynamics(), "x = 0", [[1e-15]], [[1.0]])
    assert passed.holds and not passed.exact


def test_an_unexpected_error_is_the_clis_one_line(turned, tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise AssertionError("a defect")

    monkeypatch.setattr(eomgen.teach, "write_handout", broken)
    result = run_in_process("teach", turned, "--format", "md", "--quiet", "-o", tmp_path / "h")
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert result.stderr.strip().splitlines() == [
        "eomgen: error: writing the handout of turned_2r failed unexpectedly (AssertionError: "
        "a defect); this is a defect of eomgen: please report it with the description "
        "(--debug shows the traceback)"]
