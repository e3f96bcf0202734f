"""A notebook made by ``eomgen notebook`` is handed to students: it holds the description's
text (and the scene's), so it runs after being moved away from the description, whose folder
is then gone; it is byte-identical for the same input; a description naming files of its own
(an MJCF include) is loaded by its path relative to the notebook instead."""

from __future__ import annotations

import ast
import shutil

import nbformat
import numpy as np
import pytest

import eomgen
from eomgen.teach.notebook import build_notebook, text_literal
from eomgen.numeric import numeric_model, rnea
from support import run_cli, write as write_file
from support.extras import need

#: The planar arm with a heavier second link: a notebook that loaded the bundled file instead
#: of its own copy would print other torques.
HEAVIER = ("  m2:  {value: 1.0,", "  m2:  {value: 1.7,")


@pytest.fixture()
def description(tmp_path):
    text = eomgen.example_path("planar_2link").read_text()
    assert HEAVIER[0] in text
    return write(tmp_path / "teacher" / "my_arm.yaml", text.replace(*HEAVIER))


def write(path, text: str):
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_file(path, text)


def _cells(nb) -> list[str]:
    return [cell.source for cell in nb.cells if cell.cell_type == "code"]


def _load(nb, folder, monkeypatch) -> eomgen.RobotModel:
    """Run the notebook's cells up to the one that makes ``model`` in ``folder`` (the
    folder Jupyter runs the notebook in)."""
    monkeypatch.chdir(folder)
    namespace: dict = {}
    for source in _cells(nb):
        exec(compile(source, "<cell>", "exec"), namespace)  # noqa: S102
        if "model" in namespace:
            return namespace["model"]
    raise AssertionError("no cell makes the model")


@pytest.mark.parametrize("text", [
    "plain\nlines\n", "no newline at the end", 'ends with a quote"', '"""', 'a """ b',
    "back\\slash \\n not a newline\\", "tab\tand\r\ncarriage return\r", "\x00 nul", "",
    "ünïcödé ∂q",
])
def test_text_literal_reads_back_exactly(text):
    assert ast.literal_eval(text_literal(text)) == text


def test_notebook_holds_the_description_and_repeats_byte_for_byte(description, tmp_path,
                                                                    monkeypatch):
    model = eomgen.load(description)
    first = nbformat.writes(build_notebook(model, description))
    assert first == nbformat.writes(build_notebook(model, description))
    nb = nbformat.reads(first, as_version=4)
    assert str(description.parent) not in first and "my_arm.yaml" in first
    embedded = ast.literal_eval(_cells(nb)[0].split("=", 1)[1].strip())
    assert embedded == description.read_text()
    shutil.rmtree(description.parent)  # the teacher's folder is gone
    elsewhere = tmp_path / "student"
    elsewhere.mkdir()
    loaded = _load(nb, elsewhere, monkeypatch)
    assert loaded.parameter_values == model.parameter_values
    assert loaded.joint_names == model.joint_names


def test_scene_is_written_in_as_well(description, tmp_path, monkeypatch):
    scene = write(tmp_path / "teacher" / "payload.yaml", (
        "version: 1\nrobot: planar_2link\nlocked:\n  joint2: 0.5\n"))
    reduced = eomgen.apply_scene(eomgen.load(description), eomgen.load_scene(scene)).model
    nb = build_notebook(reduced, description, scene=scene)
    text = nbformat.writes(nb)
    assert str(tmp_path) not in text
    shutil.rmtree(description.parent)
    elsewhere = tmp_path / "student"
    elsewhere.mkdir()
    loaded = _load(nb, elsewhere, monkeypatch)
    assert loaded.joint_names == reduced.joint_names == ("joint1",)


def test_mjcf_with_an_include_is_loaded_relative_to_the_notebook(tmp_path, monkeypatch):
    """MuJoCo's compiler reads an MJCF's includes and meshes from its folder: such a
    description stays a file, named relative to where the notebook is written."""
    need("mujoco", reason="the description is MJCF")
    write(tmp_path / "robots" / "link.xml", (
        '<mujoco><body name="link" pos="0 0 -0.1"><joint name="hinge" axis="0 1 0"/>'
        '<geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.02" mass="0.5"/></body>'
        "</mujoco>"))
    path = write(tmp_path / "robots" / "pendulum.xml", (
        '<mujoco model="pendulum"><worldbody><include file="link.xml"/></worldbody></mujoco>'))
    result = run_cli("notebook", path, "-o", tmp_path / "class" / "pendulum.ipynb")
    assert result.exit_code == 0, result.output
    nb = nbformat.read(tmp_path / "class" / "pendulum.ipynb", as_version=4)
    assert "eomgen.load('../robots/pendulum.xml')" in "\n".join(_cells(nb))
    assert str(tmp_path) not in nbformat.writes(nb)
    assert _load(nb, tmp_path / "class", monkeypatch).joint_names == ("hinge",)


@pytest.mark.slow
def test_moved_notebook_runs_in_a_kernel(description, tmp_path):
    """Made in one folder, moved to another, the description's folder deleted: the notebook
    runs in a real kernel without a cell error, with the description it holds (its torques
    are those of the heavier arm, from eomgen's numeric Newton–Euler here)."""
    nbclient = need("nbclient", reason="the notebook is run")
    need("ipykernel", reason="the notebook is run")
    made = tmp_path / "made" / "arm.ipynb"
    result = run_cli("notebook", description, "-o", made)
    assert result.exit_code == 0, result.output
    model = eomgen.load(description)
    shutil.rmtree(description.parent)
    moved = tmp_path / "handed_out" / "arm.ipynb"
    moved.parent.mkdir()
    shutil.move(made, moved)
    shutil.rmtree(made.parent)
    nb = nbformat.read(moved, as_version=4)
    nbclient.NotebookClient(nb, timeout=180, kernel_name="python3", resources={
        "metadata": {"path": str(moved.parent)}}).execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    printed = "".join(o.get("text", "") for o in outputs)
    shown = printed.split("tau (RNEA):")[1].split("]")[0].strip(" [")
    n = model.dof  # the notebook's sample state
    q0, qd0, qdd0 = (np.linspace(0.3, 0.9, n), np.linspace(-0.5, 0.7, n),
                     np.linspace(1.0, -1.0, n))
    expected = rnea(numeric_model(model), q0, qd0, qdd0)
    bundled = rnea(numeric_model(eomgen.load(eomgen.example_path("planar_2link"))),
                   q0, qd0, qdd0)
    assert np.allclose([float(x) for x in shown.split()], expected, rtol=1e-6)
    assert not np.allclose(expected, bundled, rtol=1e-3)
