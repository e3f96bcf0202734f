"""``eomgen notebook`` on an arm whose second joint is turned by π/6 (a user's report: the
notebook's own Ṁ − 2C check failed, by 4e-15, on the floats of cos(π/6)).

The notebook checks Ṁ − 2C exactly for the exact model and to 1e-12 for a model with floats, and
prints which; ``--no-check`` leaves out verify, that check and the comparisons' assertions; an
unexpected exception while building is the CLI's one error line.
"""

from __future__ import annotations

import nbformat
import pytest

import eomgen.teach.notebook
from support import run_in_process, write
from support.extras import need
from support.robots import turned_arm_yaml

SKEW = "Mdot - 2C is skew-symmetric"


def _write(tmp_path, angle: str, *options: str):
    description = write(tmp_path / f"turned_{len(options)}.yaml", turned_arm_yaml(angle))
    out = tmp_path / f"turned_{len(options)}.ipynb"
    result = run_in_process("notebook", description, "--quiet", "-o", out, *options)
    assert result.returncode == 0, result.stderr
    return nbformat.read(out, as_version=4)


def _source(nb) -> str:
    return "\n".join(cell.source for cell in nb.cells)


def _run(nb, tmp_path) -> str:
    """Execute ``nb`` in a kernel; no cell may fail; the printed text."""
    nbclient = need("nbclient", reason="the notebook is run")
    need("ipykernel", reason="the notebook is run")
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    return "".join(o.get("text", "") for o in outputs)


def test_with_and_without_checks(tmp_path):
    checked, unchecked = _write(tmp_path, "pi/6"), _write(tmp_path, "pi/6", "--no-check")
    text = _source(checked)
    assert "check_zero" in text and "assert skew.holds" in text and "assert report.passed" in text
    assert "np.allclose(tau, tau_rnea" in text
    text = _source(unchecked)
    assert "--no-check" in text
    for check in ("check_zero", "eomgen.verify(", "assert "):
        assert check not in text.replace("assert chunk.success", ""), check
    assert "largest difference:" in text  # the comparison still prints its numbers


@pytest.mark.slow
def test_the_notebook_runs_and_its_check_holds_exactly(tmp_path):
    printed = _run(_write(tmp_path, "pi/6"), tmp_path)
    assert f"{SKEW} exactly" in printed
    assert "all checks passed" in printed


@pytest.mark.slow
def test_with_floats_the_check_states_its_tolerance(tmp_path):
    printed = _run(_write(tmp_path, "0.5"), tmp_path)
    line = printed[printed.index(SKEW):].split("\n")[0]
    assert line.startswith(f"{SKEW} to 1e-12 (the model has floating-point numbers; largest "
                           "relative residual ")
    assert 0 < float(line.split("residual ")[1].rstrip(")")) < 1e-12


def test_an_unexpected_error_is_the_clis_one_line(tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise ZeroDivisionError("a defect")

    monkeypatch.setattr(eomgen.teach.notebook, "build_notebook", broken)
    description = write(tmp_path / "turned.yaml", turned_arm_yaml())
    result = run_in_process("notebook", description, "--quiet", "-o", tmp_path / "t.ipynb")
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert result.stderr.strip().splitlines() == [
        "eomgen: error: building the notebook of turned_2r failed unexpectedly "
        "(ZeroDivisionError: a defect); this is a defect of eomgen: please report it with the "
        "description (--debug shows the traceback)"]
    assert not (tmp_path / "t.ipynb").exists()
