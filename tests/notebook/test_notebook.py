"""Rich display in Jupyter (eomgen/present/display.py) and ``eomgen notebook`` (eomgen/teach/notebook.py): the
generated notebook for the bundled arm runs in a real kernel without a cell error."""

from __future__ import annotations

import dataclasses

import nbformat
import pytest
import sympy as sp

import eomgen
from support import run_cli as run
from eomgen.present.display import dynamics_latex, expression_latex, grouped_matrices
from eomgen.symbolic.textbook import textbook_derivation
from eomgen.teach.notebook import build_notebook
from support.extras import need


@pytest.fixture(scope="module")
def arm():
    return eomgen.load(eomgen.example_path("planar_2link"))


def test_model_html_lists_joints_escaped(arm):
    text = arm._repr_html_()
    for joint in arm.joints:
        assert f"<td>{joint.name}</td>" in text
    hostile = dataclasses.replace(arm, name="<script>x</script>", joints=tuple(
        dataclasses.replace(j, name=f"<b>{j.name}&</b>") if j.type.is_movable else j
        for j in arm.joints))
    text = hostile._repr_html_()
    assert "<script>" not in text and "<b>joint1" not in text
    assert "&lt;script&gt;" in text and "&lt;b&gt;joint1&amp;&lt;/b&gt;" in text


def test_dynamics_latex_compact_and_summary(arm):
    dyn = eomgen.derive(arm)
    tex = dyn._repr_latex_()
    assert "c_{2}" in tex and r"\dot{q}_{1}" in tex and "M = " in tex and "g = " in tex
    assert r"\cos" not in tex
    summary = dynamics_latex(dyn, max_dof=1)  # what a larger model shows
    assert "M = " not in summary and "operations" in summary and "joint1" in summary


def test_notebook_is_deterministic_without_outputs(arm):
    first = nbformat.writes(build_notebook(arm))
    assert first == nbformat.writes(build_notebook(arm))
    nb = nbformat.reads(first, as_version=4)
    assert all(not cell.get("outputs") for cell in nb.cells if cell.cell_type == "code")
    text = "\n".join(cell.source for cell in nb.cells)
    for needle in ("textbook_derivation", "Christoffel", "eomgen.verify", "rnea", "solve_ivp"):
        assert needle in text


def test_scara_base_parameters_keep_the_description_symbols():
    """Issue 29: the SCARA's notebook printed ``ZZ2R = 0.499999999999999 MX3 + ZZ2 + ZZ3``.
    The MX3 column is a dependency the grouping rules leave (a prismatic joint parallel to the
    revolute one before it); its coefficient is solved exactly, 2 a2, and the β the notebook
    prints (regressor_form through expression_latex) carries no float."""
    from eomgen.regressor import regressor_form
    from eomgen.symbolic.textbook import fourier_form

    model = eomgen.load(eomgen.example_path("scara_rrp"))
    dyn = eomgen.derive(model)
    form = regressor_form(model)
    P = {s.name: s for s in form.regressor.parameter_symbols}
    a2 = next(p.symbol for p in model.parameters if p.name == "a2")
    beta = dict(zip(form.base_names, form.beta))
    assert beta["ZZ2R"] == P["ZZ2"] + P["ZZ3"] + 2 * a2 * P["MX3"]
    assert beta["MX2R"] == P["MX2"] + P["MX3"] and beta["MY2R"] == P["MY2"] - P["MY3"]
    assert form.exact and not any(b.atoms(sp.Float) for b in form.beta)
    identity = form.Y_base * sp.Matrix(form.beta) - form.Y * form.pi
    assert all(fourier_form(e, form.regressor.q) == 0 for e in identity)
    tex = expression_latex(dyn, beta["ZZ2R"], form.latex_names)
    assert tex == r"2 \mathrm{MX}_{3} a_{2} + \mathrm{ZZ}_{2} + \mathrm{ZZ}_{3}"


@pytest.mark.parametrize("example", ["planar_2link", "puma560_dh", "elbow_rrr"])
@pytest.mark.slow
def test_cli_notebook_runs_without_errors(tmp_path, example):
    """The notebooks of the bundled examples execute without a cell error (the 6-joint PUMA
    takes the large-model path: no textbook cells, summaries instead)."""
    nbclient = need("nbclient")
    need("ipykernel")
    path = tmp_path / "arm.ipynb"
    result = run("notebook", eomgen.example_path(example), "-o", path)
    assert result.exit_code == 0, result.output
    assert path.is_file() and not list(tmp_path.glob(".*.tmp"))
    nb = nbformat.read(path, as_version=4)
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    assert any("image/png" in o.get("data", {}) for o in outputs)  # the simulation plot
    printed = "".join(o.get("text", "") for o in outputs)
    checks = ("largest |Y pi - tau|:", "largest |Y_base beta - Y pi|:")
    if example == "puma560_dh":  # the regressor cells are for teaching-sized models only
        assert not any(check in printed for check in checks)
    else:  # Y π = M q̈ + C q̇ + g and Y_base β = Y π, checked in the notebook at a state
        for check in checks:
            assert float(printed.split(check)[1].split()[0]) < 1e-9, check
    if example != "puma560_dh":  # the textbook cells print M grouped by body mass, as the
        # document and the handout do: the same M, the same LaTeX as the rich display's
        dyn = eomgen.derive(eomgen.load(eomgen.example_path(example)))
        book = textbook_derivation(dyn.model)
        M = grouped_matrices(book)["M"]
        assert sp.expand(M.doit() - book.M) == sp.zeros(*M.shape)
        tex = "M = " + expression_latex(dyn, M)
        assert tex[4:] in dynamics_latex(dyn)
        latex = [o.data["text/latex"] for o in outputs if "text/latex" in o.get("data", {})]
        assert any(tex in text for text in latex)
        assert any(r"\mathrm{ZZ}_{1}^{R} = " in text for text in latex)  # a grouped β
        # the Slotine–Li cell in the handout's notation: q̇_{r,1}, not \textrm{qd\_r1}
        assert any(r"\dot{q}_{r,1}" in text for text in latex)
        assert not any("qd\\_r" in text or "qdd\\_r" in text for text in latex)


def test_every_block_of_the_cells_template_is_a_cell_of_some_notebook():
    """templates/notebook/cells.jinja holds the notebook's cells, one block each, and nothing
    else: the blocks the notebooks render, over every choice (description written in or named
    by its path, with or without a scene, quaternion joints, teaching-sized, --no-check), are
    exactly the template's blocks, each once per notebook, markdown blocks named ``*_text``."""
    from itertools import product

    from eomgen.teach.notebook import CELLS_TEMPLATE, cell_blocks
    from eomgen.teach.embedded import EmbeddedSource
    from eomgen.common.templating import environment

    sources = [EmbeddedSource("arm.yaml", description='"""..."""'),
               EmbeddedSource("arm.xml", relative="robots/arm.xml"),
               EmbeddedSource("arm.yaml", description='"""..."""', scene="s.yaml",
                              scene_text='"""..."""')]
    used = set()
    for source, chart, small, check in product(sources, *[(False, True)] * 3):
        if chart and small:
            continue  # no textbook form with quaternion joints
        blocks = cell_blocks(source, chart, small, check)
        assert len(blocks) == len(set(blocks)), blocks
        assert blocks[1] == "robot_text" and blocks[-2:] == ["simulation_text",
                                                             "simulation_code"]
        used.update(blocks)
    template = set(environment().get_template(CELLS_TEMPLATE).blocks)
    assert used == template
    assert all(block.endswith(("_text", "_code")) for block in template)


def test_cli_notebook_bad_description(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("robot: [unclosed\n")
    out = tmp_path / "bad.ipynb"
    for description in (bad, tmp_path / "missing.urdf"):
        result = run("notebook", description, "-o", out)
        assert result.exit_code == 2, result.output
        assert not out.exists()


def test_cli_notebook_refuses_parameters_without_values(tmp_path):
    """The notebook's checks and simulation are numeric: a parameter without a value would make
    them fail cell by cell, so the command refuses up front and names the parameter."""
    text = eomgen.example_path("planar_2link").read_text().replace(
        "  m2:  {value: 1.0,  description", "  m2:  {description")
    description = tmp_path / "arm.yaml"
    description.write_text(text)
    out = tmp_path / "arm.ipynb"
    result = run("notebook", description, "-o", out)
    assert result.exit_code == 2
    assert "arm.yaml: parameters: the notebook's numeric cells need a value for m2" in result.output
    assert not out.exists()
