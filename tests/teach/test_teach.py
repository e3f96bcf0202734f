"""``eomgen teach``: the handout's mathematics, its four formats, and the command.

By stage: the regrouped expressions equal the derived ones (SymPy, exactly) and the textbook's
closed forms for the planar two-link arm; the handout data follows the textbook sequence and
switches to named subexpressions for large models; the LaTeX compiles with pdflatex and the
PDF's text (pdftotext) holds the two-link equations; the HTML is self-contained and headless
Chromium typesets its math (tests/browser.py); Markdown carries ``$…$`` math; output is
deterministic; the CLI writes all files or none.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import unicodedata
from pathlib import Path

import pytest
import sympy as sp
from click.testing import CliRunner

import eomgen
from support import CORPUS, ROOT
from eomgen.cli import main
from eomgen.errors import GenerationError
from eomgen.symbolic.textbook import textbook_derivation
from eomgen.teach import FORMATS, build_handout, handout_files, parse_formats
from eomgen.teach import readability as rd
from eomgen.teach.content import HALF, _quadratic_terms, named_coriolis
from eomgen.teach.document import (Equations, Figure, Handout, Paragraph, Section, Table,
                                   code, prose)
from eomgen.teach.formats import HtmlFormat, MarkdownFormat, TexFormat

PDFLATEX = shutil.which("pdflatex")
PDFTOTEXT = shutil.which("pdftotext")
needs_pdflatex = pytest.mark.skipif(PDFLATEX is None or PDFTOTEXT is None,
                                    reason="pdflatex and pdftotext are not installed "
                                           "(.ci/run installs texlive-latex-base, poppler-utils)")

m1, m2, l1, lc1, lc2, I1, I2, g = sp.symbols("m1 m2 l1 lc1 lc2 I1 I2 g", real=True)


@pytest.fixture(scope="module")
def arm():
    return eomgen.load(eomgen.example_path("planar_2link"))


@pytest.fixture(scope="module")
def arm_symbols(arm):
    """The textbook's names bound to the model's own symbols."""
    return {p.name: p.symbol for p in arm.parameters}


@pytest.fixture(scope="module")
def arm_dynamics(arm):
    return eomgen.derive(arm, outputs=("M", "C", "g"), simplify=False)


@pytest.fixture(scope="module")
def arm_book(arm):
    return textbook_derivation(arm)


@pytest.fixture(scope="module")
def arm_handout(arm):
    return build_handout(arm)


# -- readability: regrouping never changes the value ---------------------------------------

def _value(terms) -> sp.Expr:
    return sp.Add(*terms).doit().subs(HALF, sp.Rational(1, 2))


def test_mass_grouping_is_the_textbook_form_of_M(arm_book, arm_symbols):
    s = arm_symbols
    q2 = sp.Symbol("q2", real=True)
    masses = [s["m1"], s["m2"]]
    grouped = rd.by_mass(arm_book.M[0, 0], masses)
    # Spong: M11 = m1 lc1² + m2 (l1² + lc2² + 2 l1 lc2 cos q2) + I1 + I2
    assert grouped[0] == sp.Mul(s["m1"], sp.UnevaluatedExpr(s["lc1"] ** 2), evaluate=False)
    inner = grouped[1].args[1]
    assert grouped[1].args[0] == s["m2"]
    assert sp.expand(inner - (s["l1"] ** 2 + s["lc2"] ** 2
                              + 2 * s["l1"] * s["lc2"] * sp.cos(q2))) == 0
    assert set(grouped[2:]) == {s["I1"], s["I2"]}
    for i in range(2):
        for j in range(2):
            assert sp.expand(_value(rd.by_mass(arm_book.M[i, j], masses))
                             - arm_book.M[i, j]) == 0


def test_trig_grouping_is_the_textbook_form_of_g(arm_book, arm_dynamics, arm_symbols):
    s = arm_symbols
    q1, q2 = arm_dynamics.q
    terms = rd.by_trig(arm_book.g[0], arm_dynamics.q)
    # Spong: g1 = (m1 lc1 + m2 l1) g cos q1 + m2 lc2 g cos(q1 + q2)
    expected = {sp.cos(q1): s["g"] * (s["m1"] * s["lc1"] + s["m2"] * s["l1"]),
                sp.cos(q1 + q2): s["g"] * s["m2"] * s["lc2"]}
    assert len(terms) == 2
    for term in terms:
        trig = next(f for f in term.args if f in expected)
        assert sp.expand(term.doit() / trig - expected[trig]) == 0


def test_group_by_factor_keeps_the_value_of_random_sums():
    x, y, a, b = sp.symbols("x y a b")
    for expr in (3 * a * x - 2 * a * y + b * x ** 2 - a, -a * x, a + b, sp.Integer(0),
                 a * sp.cos(x) - 2 * b * sp.cos(x) + sp.sin(x + y) * a):
        for factor in (True, False):
            terms = rd.group_by_factor(expr, lambda t: a if t.has(a) else None, factor=factor)
            assert sp.expand(_value(terms) - expr) == 0


def test_kinetic_energy_terms_sum_to_the_quadratic_form(arm_book, arm_dynamics, arm_symbols):
    qd = sp.Matrix(arm_dynamics.qd)
    masses = [arm_symbols["m1"], arm_symbols["m2"]]
    terms = _quadratic_terms(arm_book.M, arm_dynamics.qd, masses)
    assert sp.expand(_value(terms) - (qd.T * arm_book.M * qd)[0, 0] / 2) == 0
    for body in arm_book.bodies:  # per body too
        terms = _quadratic_terms(body.M, arm_dynamics.qd, masses)
        assert sp.expand(_value(terms) - body.K) == 0


def test_h_is_the_textbook_factor_and_C_is_written_with_it(arm_book, arm_dynamics, arm_symbols):
    s = arm_symbols
    q2 = arm_dynamics.q[1]
    qd1, qd2 = arm_dynamics.qd
    names, christoffel, C = named_coriolis(arm_dynamics, arm_book)
    assert len(names) == 1 and names[0].symbol.name == "h"
    assert sp.expand(names[0].value - s["m2"] * s["l1"] * s["lc2"] * sp.sin(q2)) == 0
    h = names[0].symbol
    # Spong: C = [[-h q̇2, -h (q̇1 + q̇2)], [h q̇1, 0]]
    assert (C - sp.Matrix([[-h * qd2, -h * (qd1 + qd2)], [h * qd1, 0]])).applyfunc(
        sp.expand) == sp.zeros(2, 2)
    # and with h substituted, the derived C (exact, from the straight-line program)
    derived = arm_dynamics.C
    assert (C.subs(h, names[0].value) - derived).applyfunc(
        lambda e: sp.simplify(sp.expand_trig(e))) == sp.zeros(2, 2)


def test_no_name_when_christoffel_symbols_share_no_factor():
    a, b, q = sp.symbols("a b q")
    assert rd.common_christoffel_factors([a * sp.sin(q), b * sp.cos(q), a * b, a + b, q * a,
                                          b * q]) == []
    assert rd.common_christoffel_factors([a]) == []  # too simple to be worth a name


# -- the handout's content ------------------------------------------------------------------

def test_two_link_handout_follows_the_textbook_sequence(arm_handout):
    titles = [s.title for s in arm_handout.sections]
    assert titles == [
        "The robot", "Method and notation", "Step 1: positions of the centres of mass",
        "Step 2: velocities", "Step 3: kinetic energy", "Step 4: potential energy",
        "Step 5: the mass matrix", "Step 6: Christoffel symbols and the Coriolis matrix",
        "Step 7: the gravity vector", "Step 8: the equations of motion",
        "Adaptive control: the Slotine–Li regressor", "Verified properties"]
    robot = arm_handout.sections[0].blocks
    assert any(isinstance(b, Figure) and b.name == "sketch" for b in robot)
    tables = [b for b in robot if isinstance(b, Table)]
    assert len(tables) == 3  # joints, links, parameters
    assert len(tables[0].rows) == 3  # joint1, joint2, tip_fixed


def _equations(section) -> dict[str, str]:
    return {eq.lhs: " ".join(eq.lines) for b in section.blocks if isinstance(b, Equations)
            for eq in b.equations}


def test_symmetric_entries_are_shown_once(arm_handout):
    mass = _equations(arm_handout.sections[6])
    assert set(mass) == {"M_{1,1}", "M_{1,2}", "M_{2,2}"}
    christoffel = _equations(arm_handout.sections[7])
    assert r"\Gamma_{1,1,2} = \Gamma_{1,2,1}" in christoffel
    assert r"\Gamma_{1,2,1}" not in christoffel


def test_verification_section_reports_numbers(arm_handout, arm_dynamics):
    section = arm_handout.sections[-1]
    table = next(b for b in section.blocks if isinstance(b, Table))
    assert len(table.rows) == 6
    results = ["".join(s.value for s in row[2]) for row in table.rows]
    assert results[0] == "identically zero"  # M symmetric, exactly
    ratio = float(results[1].split(r"\ge")[1])  # λmin/λmax of M over the samples
    assert ratio == pytest.approx(eomgen.verify(arm_dynamics).checks[1].max_rel_error, rel=0.05)
    assert 0 < ratio < 1
    for text in results[3:]:
        error = float(text.split()[0])
        assert 0 <= error < 1e-12
    assert all("".join(s.value for s in row[3]) == "passed" for row in table.rows)
    assert any("All checks passed." in "".join(s.value for s in b.content)
               for b in section.blocks if isinstance(b, Paragraph))


def test_large_model_switches_to_named_subexpressions_and_says_so():
    model = eomgen.load(eomgen.example_path("puma560_dh"))
    handout = build_handout(model, check=False)
    titles = [s.title for s in handout.sections]
    assert "The derivation as named subexpressions" in titles
    assert not any(t.startswith("Step ") for t in titles)
    section = handout.sections[titles.index("The derivation as named subexpressions")]
    first = "".join(s.value for s in section.blocks[0].content)
    assert "switches to named subexpressions" in first and "6 joints" in first
    shown = sum(len(b.equations) for b in section.blocks if isinstance(b, Equations))
    assert 0 < shown < 1000  # a readable number of lines, not pages of algebra
    verify_text = "".join(s.value for s in handout.sections[-1].blocks[0].content)
    assert "Not checked numerically" in verify_text


def test_parameter_without_value_is_drawn_with_one_and_not_checked(tmp_path):
    text = eomgen.example_path("planar_2link").read_text().replace(
        '  lc2: {value: 0.5,  description', '  lc2: {description')
    path = tmp_path / "arm.yaml"
    path.write_text(text)
    handout = build_handout(eomgen.load(path))
    caption = next(b for b in handout.sections[0].blocks if isinstance(b, Figure)).caption
    assert any(s.kind == "code" and s.value == "lc2" for s in caption)
    verification = "".join(s.value for s in handout.sections[-1].blocks[0].content)
    assert "Not checked numerically" in verification and "lc2" in verification


# -- inline content and escaping -------------------------------------------------------------

HOSTILE = r"$x$ \input{/etc/passwd} <script>alert(1)</script> *a* _b_ | `c` # 100%"


@pytest.mark.parametrize("fmt", [TexFormat(), MarkdownFormat(), HtmlFormat()],
                         ids=["tex", "md", "html"])
def test_user_text_is_escaped(fmt):
    out = fmt.inline(prose("robot ", code(HOSTILE), " and $m_{1}$"))
    if fmt.name == "tex":
        assert r"\input" not in out and r"\textbackslash{}input" in out and "$m_{1}$" in out
        assert "$x$" not in out
    elif fmt.name == "md":
        assert "``" not in out or out.count("`") >= 4
        assert out.endswith("$m_{1}$")
    else:
        assert "<script>" not in out and "&lt;script&gt;" in out and "<math" in out


def test_markdown_text_escapes_markup():
    out = MarkdownFormat().text(HOSTILE)
    assert r"\$x\$" in out and r"\*a\*" in out and r"\_b\_" in out and r"\|" in out
    assert r"\<script\>" in out and r"\# 100%" in out


# -- formats ----------------------------------------------------------------------------------

def _pdf_text(pdf: bytes, tmp_path: Path) -> str:
    path = tmp_path / "handout.pdf"
    path.write_bytes(pdf)
    text = subprocess.run([PDFTOTEXT, str(path), "-"], capture_output=True, check=True,
                          text=True).stdout
    return re.sub(r"\s+", "", unicodedata.normalize("NFKC", text))


@needs_pdflatex
def test_pdf_compiles_and_holds_the_two_link_equations(arm_handout, tmp_path):
    [pdf] = FORMATS["pdf"](arm_handout)
    assert pdf.name == "planar_2link_handout.pdf" and pdf.content.startswith(b"%PDF")
    text = _pdf_text(pdf.content, tmp_path)
    dot, ddot = "\u0307", "\u0308"  # combining dot and diaeresis: q̇, q̈ after NFKC
    expected = [
        "l1c1+lc2c12", "l1s1+lc2s12",                # the centre of mass of link 2
        "P=g(l1m2+lc1m1)s1+glc2m2s12",               # potential energy
        "M2,2=m2lc2",                                # M22 = m2 lc2² + I2 (the ² is lifted)
        "h=m2l1lc2s2",                               # h = m2 l1 lc2 sin q2
        "Γ1,1,2=Γ1,2,1=−h", "Γ1,2,2=−h", "Γ2,1,1=h",
        "g1=g(l1m2+lc1m1)c1+glc2m2c12", "g2=glc2m2c12",
        f"τ1=M1,1q{ddot}1+M1,2q{ddot}2−hq{dot}2(2q{dot}1+q{dot}2)+g1",
        f"τ2=M1,2q{ddot}1+M2,2q{ddot}2+hq{dot}12+g2",
        "Allcheckspassed.",
    ]
    missing = [e for e in expected if unicodedata.normalize("NFKC", e) not in text]
    assert not missing, f"not in the PDF's text: {missing}"


def _pdf_pages(pdf: bytes, tmp_path: Path) -> list[str]:
    """The text of each page of ``pdf`` (a table's row on one line), without white space."""
    path = tmp_path / "pages.pdf"
    path.write_bytes(pdf)
    text = subprocess.run([PDFTOTEXT, "-layout", str(path), "-"], capture_output=True, check=True,
                          text=True).stdout
    return [re.sub(r"\s+", "", unicodedata.normalize("NFKC", page)) for page in text.split("\f")]


def _page_of(pages: list[str], text: str) -> int:
    found = [k for k, page in enumerate(pages) if re.sub(r"\s+", "", text) in page]
    assert found, f"{text!r} is not in the PDF"
    return found[0]


@needs_pdflatex
def test_tables_start_on_the_page_of_their_introduction(arm_handout, tmp_path):
    """Issue 29: the two-link handout's parameter table had its introduction at the foot of
    page 1 and its heading and rows on page 2. A table's introduction, heading and first row
    share a page; every table of the handout is checked."""
    [pdf] = FORMATS["pdf"](arm_handout)
    pages = _pdf_pages(pdf.content, tmp_path)
    tables = [
        ("Joints, in the order of the joint vector", "variablejointtypeparent", "joint1revolutebase"),
        ("Links: mass (kg), centre of mass", "linkmasscentreofmassinertia", "basemassless"),
        ("Parameters: symbols kept in the equations", "symbolvaluemeaning",
         "inertia of link 1 about z"),
        ("eomgen checked what it derived", "propertycheckedlargesterror", "M symmetric"),
    ]
    for introduction, heading, first_row in tables:
        page = _page_of(pages, introduction)
        assert _page_of(pages, heading) == page, f"the heading of {introduction!r} moved on"
        assert _page_of(pages, first_row) == page, f"the rows of {introduction!r} moved on"


@needs_pdflatex
def test_long_tables_repeat_their_heading_and_never_leave_it_alone(tmp_path):
    """A table too long for one page keeps its heading with its first rows, and repeats it on
    the next page, wherever the page before it ends."""
    rows = tuple((prose(f"row{k}"), prose(f"value{k}")) for k in range(70))
    for lines in range(50, 60):  # the table starts near the foot of page 1, a line apart
        handout = Handout("long", "Long table", (Section("Text", (
            Paragraph(prose(" ".join(["Words that fill the page before the table."] * 2 * lines))),
            Paragraph(prose("The long table:")),
            Table((prose("name"), prose("content")), rows))),))
        [pdf] = FORMATS["pdf"](handout)
        pages = _pdf_pages(pdf.content, tmp_path)
        first = _page_of(pages, "The long table:")
        assert _page_of(pages, "namecontent") == first
        assert _page_of(pages, "row0value0") == first
        last = _page_of(pages, "row69value69")
        assert last > first and "namecontent" in pages[last]


@needs_pdflatex
def test_pdf_is_deterministic(arm_handout):
    assert FORMATS["pdf"](arm_handout)[0].content == FORMATS["pdf"](arm_handout)[0].content


def test_pdf_without_pdflatex_is_a_clear_error(arm_handout, monkeypatch):
    import eomgen.teach.formats as formats

    monkeypatch.setattr(formats.shutil, "which", lambda name: None)
    with pytest.raises(GenerationError, match="needs pdflatex.*--format tex, html or md"):
        formats.write_pdf(arm_handout)


@needs_pdflatex
def test_pdflatex_failure_names_the_error(arm_handout, tmp_path):
    fake = tmp_path / "pdflatex"
    fake.write_text("#!/bin/sh\necho '! Undefined control sequence.'\nexit 1\n")
    fake.chmod(0o755)
    from eomgen.teach.formats import write_pdf

    with pytest.raises(GenerationError, match="Undefined control sequence"):
        write_pdf(arm_handout, pdflatex=str(fake))


def test_markdown_handout(arm_handout):
    files = {f.name: f.content for f in FORMATS["md"](arm_handout)}
    md = files["planar_2link_handout.md"]
    assert "planar_2link_sketch.svg" in files and files["planar_2link_sketch.svg"].startswith("<?xml")
    assert "](planar_2link_sketch.svg)" in md
    assert "## Step 6: Christoffel symbols and the Coriolis matrix" in md
    assert "h &= m_{2} l_{1} l_{c2} s_{2}" in md
    blocks = re.findall(r"\$\$\n(.*?)\n\$\$", md, re.S)
    assert len(blocks) > 10 and all(b.startswith(r"\begin{aligned}") for b in blocks)
    assert md.count("$") % 2 == 0  # every inline formula closed


def test_html_is_self_contained(arm_handout):
    [page] = FORMATS["html"](arm_handout)
    text = page.content
    assert "<script" not in text and "<link" not in text and "src=" not in text
    assert not re.search(r"(?:href|src)\s*=\s*[\"']?https?:", text)
    assert text.count("<math") > 50 and "<svg" in text
    assert 'encoding="application/x-tex"' in text  # the TeX rides along as text
    # capital Greek upright as in TeX (MathML would slant a one-letter <mi>)
    assert '<mi mathvariant="normal">&#x00393;</mi>' in text and "<mi>&#x00393;</mi>" not in text


@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_every_format_is_deterministic(arm, fmt):
    if fmt == "pdf" and PDFLATEX is None:
        pytest.skip("pdflatex is not installed")
    first = handout_files(arm, [fmt], check=False)
    second = handout_files(arm, [fmt], check=False)
    assert [(f.name, f.content) for f in first] == [(f.name, f.content) for f in second]


def test_formats_in_a_fresh_process_match(tmp_path):
    """Byte-identical across processes with different hash seeds (md + svg, html): this
    process (its hash seed random unless the caller fixed it) and a fresh one with another."""
    import os
    arguments = ["teach", "--format", "md,html", "--no-check", "--quiet", "-o"]
    here = CliRunner().invoke(main, [*arguments, str(tmp_path / "here")])
    assert here.exit_code == 0, here.output
    seed = "4242" if os.environ.get("PYTHONHASHSEED") != "4242" else "0"
    subprocess.run([sys.executable, "-m", "eomgen.cli", *arguments, str(tmp_path / "fresh")],
                   check=True, env={**os.environ, "PYTHONHASHSEED": seed}, capture_output=True)
    outs = [{p.name: p.read_bytes() for p in sorted((tmp_path / which).iterdir())}
            for which in ("here", "fresh")]
    assert outs[0] == outs[1] and len(outs[0]) == 3


# -- the browser: the HTML's math is typeset, not raw TeX -----------------------------------

@pytest.mark.browser
def test_html_math_is_rendered_in_headless_chromium(arm_handout, tmp_path):
    from support.browser import (assert_math_rendered, chromium_available, headless_chromium,
                         math_rendering_report)

    reason = chromium_available()
    if reason:
        pytest.skip(reason)
    [page] = FORMATS["html"](arm_handout)
    path = tmp_path / page.name
    path.write_text(page.content, encoding="utf-8")
    with headless_chromium(width=1000, height=900) as driver:
        # the matrices' entries (inner tables) must show one band of ink per row
        report = math_rendering_report(driver, path, tmp_path / "handout.png",
                                       ink_selector='math[display="block"] mtable mtable')
    assert_math_rendered(report, expected_min_math=100)
    assert len(report.fractions_stacked) >= 5 and len(report.ink_bands) >= 8
    assert report.screenshot.stat().st_size > 50_000
    for words in ("Step 6: Christoffel symbols and the Coriolis matrix", "All checks passed."):
        assert words in report.text
    assert not report.console_errors


# -- the command ------------------------------------------------------------------------------

def test_parse_formats():
    assert parse_formats("pdf, html") == ["pdf", "html"]
    assert parse_formats("all") == list(FORMATS)
    with pytest.raises(GenerationError, match="unknown handout format docx"):
        parse_formats("pdf,docx")


def test_cli_writes_every_file(tmp_path):
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["teach", "--format", "html,md,tex", "-o", str(out)])
    assert result.exit_code == 0, result.output
    names = sorted(p.name for p in out.iterdir())
    assert names == ["planar_2link_handout.html", "planar_2link_handout.md",
                     "planar_2link_handout.tex", "planar_2link_sketch.pdf",
                     "planar_2link_sketch.svg"]
    assert "checking the derivation against Newton-Euler" in result.stderr


@pytest.mark.parametrize("robot", ["scara_rrp", "cylindrical_rpp"])
def test_sums_leave_out_zero_terms(robot, tmp_path):
    """Issue 29: the SCARA's handout printed ``τ3 = M3,3 q̈3 + 0 + g3`` and ``… + 0`` where a
    joint has no velocity terms or no gravity; zero terms are left out, and a sum of zeros is 0."""
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["teach", str(eomgen.example_path(robot)), "--format",
                                       "md,tex", "--no-check", "--quiet", "-o", str(out)])
    assert result.exit_code == 0, result.output
    for suffix in ("md", "tex"):
        text = (out / f"{robot}_handout.{suffix}").read_text()
        zero_terms = re.findall(r"[+-] 0(?= [+-]| *\\\\|\s*$)", text, flags=re.M)
        assert not zero_terms, f"{robot}_handout.{suffix} prints a zero term"
        if robot == "scara_rrp":
            assert r"\tau_{3} &= M_{3,3} \ddot{q}_{3} + g_{3}" in text
            assert r"\tau_{3} &= m_{3} \ddot{q}_{3} - g m_{3}" in text
        else:
            assert r"\tau_{2} &= M_{2,2} \ddot{q}_{2} + g_{2} \\" in text
            assert r"\tau_{3} &= m_{3} \ddot{q}_{3} - h \dot{q}_{1}^{2}" + "\n" in text
            assert r"g_{1} &= 0 \\" in text  # an all-zero sum is printed as 0


def test_units_in_descriptions_print_as_superscripts(tmp_path):
    """Issue 29: a parameter described in "[kg m^2]" printed as "kg mˆ2" in the PDF; the
    exponent of a unit is a superscript in every format (the rest of the text stays escaped)."""
    out = tmp_path / "out"
    formats = "md,html,tex" + (",pdf" if PDFLATEX else "")
    result = CliRunner().invoke(main, ["teach", str(eomgen.example_path("elbow_rrr")),
                                       "--format", formats, "--no-check", "--quiet",
                                       "-o", str(out)])
    assert result.exit_code == 0, result.output
    tex = (out / "elbow_rrr_handout.tex").read_text()
    assert "textasciicircum" not in tex
    assert r"inertia of link 1 about the waist axis {[}kg m$^{2}$" in tex
    assert r"gravitational acceleration {[}m/s$^{2}${]}" in tex
    md = (out / "elbow_rrr_handout.md").read_text()
    assert r"| inertia of link 1 about the waist axis \[kg m$^{2}$\] |" in md
    html_page = (out / "elbow_rrr_handout.html").read_text()
    assert "m^2" not in html_page and "<mn>2</mn></mrow></msup>" in html_page
    if PDFLATEX and PDFTOTEXT:
        text = subprocess.run([PDFTOTEXT, str(out / "elbow_rrr_handout.pdf"), "-"],
                              capture_output=True, text=True, check=True).stdout
        assert "ˆ" not in text and "^" not in text
        assert "waist axis [kg m2 ]" in text  # m with a raised 2


@pytest.mark.parametrize("args,message", [
    (["--format", "docx"], "unknown handout format docx"),
    ([str(CORPUS / "urdf_cycle.urdf"), "--format", "md"], "urdf_cycle.urdf"),
])
def test_cli_bad_input_writes_nothing(tmp_path, args, message):
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["teach", *args, "-o", str(out)])
    assert result.exit_code == 2
    assert message in result.stderr and result.stderr.count("\n") == 1
    assert not out.exists()


def test_cli_pdf_failure_writes_nothing(tmp_path, monkeypatch):
    """pdf fails (no pdflatex) after html was rendered: neither is written."""
    import eomgen.teach.formats as formats

    monkeypatch.setattr(formats.shutil, "which", lambda name: None)
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["teach", "--format", "html,pdf", "--no-check",
                                       "-o", str(out)])
    assert result.exit_code == 2 and "needs pdflatex" in result.stderr
    assert not out.exists()


@pytest.mark.parametrize("name", ["valid_urdf_names_latex.urdf", "valid_yaml_hostile_text.yaml",
                                  "valid_urdf_names_code_injection.urdf"])
def test_hostile_descriptions_give_safe_handouts(name, tmp_path):
    formats = ["html", "md", "tex"] + (["pdf"] if PDFLATEX else [])
    files = {f.name: f.content for f in
             handout_files(eomgen.load(CORPUS / name), formats, check=False)}
    html_page = next(v for k, v in files.items() if k.endswith(".html"))
    assert "<script" not in html_page
    if PDFLATEX:
        assert next(v for k, v in files.items() if k.endswith(".pdf")).startswith(b"%PDF")


def test_scene_turns_a_real_arm_into_a_teaching_example(tmp_path):
    """The Panda with all but its shoulder and elbow locked (examples/scenes): a two-joint
    handout in the textbook sequence, saying which joints the scene locked, whose M, C, g pass
    every check against Newton–Euler on the reduced model. (That reduction equals Pinocchio's
    buildReducedModel is tests/test_scenes.py's business.)"""
    from support import erd_robots_dir

    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    scene = ROOT / "examples" / "scenes" / "panda_two_joints.yaml"
    out = tmp_path / "out"
    result = CliRunner().invoke(main, [
        "teach", str(robots / "panda_description" / "urdf" / "panda.urdf"),
        "--scene", str(scene), "--format", "md", "-o", str(out)])
    assert result.exit_code == 0, result.output
    md = (out / "panda_handout.md").read_text()
    assert "## Step 6: Christoffel symbols and the Coriolis matrix" in md
    # 8 coordinates of the whole Panda: finger_joint2 <mimic>s finger_joint1
    assert "panda_two_joints.yaml" in md and "Moving: 2 of 8 joints" in md
    assert "` panda_joint6 ` = 1.5708" in md
    assert "| $M$ positive definite |" in md and "FAILED" not in md
    assert md.count("| passed |") == 6


def test_numbers_lead_their_groups():
    """Numeric descriptions: 8.08 c_1 (the number first), and K takes the ½ into the number."""
    q1 = sp.Symbol("q1")
    qd1 = sp.Symbol("qd1")
    assert rd.by_trig(8.08 * sp.cos(q1) - 0.85 * sp.sin(q1), [q1]) == [
        8.08 * sp.cos(q1), -0.85 * sp.sin(q1)]
    assert _quadratic_terms(sp.Matrix([[0.5]]), [qd1], []) == [0.25 * qd1 ** 2]


# -- drives: flexible joints (Spong), armature and friction ---------------------------------

def _drive_residuals(model, textbook: bool = True):
    """The handout's drive equations as residuals (``terms − lhs``, every name replaced by its
    value), beside eomgen.analysis.actuators' own, for the same derivation; ``textbook=False``: as
    written for large models (``C_{i,j}`` in place of the Christoffel factors)."""
    from eomgen.analysis.actuators import spong_dynamics
    from eomgen.teach.content import (abbreviation_values, drive_equations, has_drives,
                                      spring_values)
    assert has_drives(model)
    dyn = eomgen.derive(model, outputs=("M", "C", "g"), simplify=False)
    book = textbook_derivation(model) if textbook else None
    coriolis = named_coriolis(dyn, book) if textbook else None
    spong = spong_dynamics(dyn)
    links, motors = drive_equations(spong, book, coriolis)
    values = abbreviation_values(dyn, coriolis) | spring_values(spong)

    def residuals(equations):
        return sp.Matrix([sp.Add(*terms).subs(values) - lhs.subs(values)
                          for lhs, terms in equations])
    return spong, residuals(links), residuals(motors)


def _exactly_equal(a: sp.Matrix, b: sp.Matrix) -> bool:
    return a.shape == b.shape and (a - b).applyfunc(sp.simplify) == sp.zeros(*a.shape)


def test_flexible_arm_handout_prints_spongs_two_equations(tmp_path):
    model = eomgen.load(Path("examples/robots/flexible_2link.yaml"))
    spong, links, motors = _drive_residuals(model)
    assert _exactly_equal(links, spong.link_equations())
    assert _exactly_equal(motors, spong.motor_equations())
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["teach", "examples/robots/flexible_2link.yaml",
                                       "--format", "md", "--no-check", "-o", str(out)])
    assert result.exit_code == 0, result.output
    md = (out / "flexible_2link_handout.md").read_text()
    section = md[md.index("## Flexible joints"):]
    assert "its own spin" in section  # the reduced model's assumption is stated
    assert r"M(q)\, \ddot{q} + C(q, \dot{q})\, \dot{q} + g(q) &= K (\theta - q)," in section
    assert r"B\, \ddot{\theta} + K (\theta - q) &= \tau_{m}," in section
    # the printed rows of what was checked above, in the description's own symbols
    assert (r"\textrm{K1} \left(\theta_{1} - q_{1}\right) &= M_{1,1} \ddot{q}_{1} + M_{1,2} "
            r"\ddot{q}_{2} - h \dot{q}_{2} \left(2 \dot{q}_{1} + \dot{q}_{2}\right) + g_{1}"
            in section)
    assert (r"\textrm{K2} \left(\theta_{2} - q_{2}\right) &= M_{1,2} \ddot{q}_{1} + M_{2,2} "
            r"\ddot{q}_{2} + h \dot{q}_{1}^{2} + g_{2}" in section)
    assert r"\tau_{m,1} &= B_{1} \ddot{\theta}_{1} + \textrm{K1} \left(\theta_{1} - q_{1}\right)" \
        in section
    assert r"\tau_{m,2} &= B_{2} \ddot{\theta}_{2} + \textrm{K2} \left(\theta_{2} - q_{2}\right)" \
        in section


def _with_actuators(model, *actuators):
    from dataclasses import replace
    movable = iter(actuators)
    joints = tuple(replace(j, actuator=next(movable)) if j.type.is_movable else j
                   for j in model.joints)
    return replace(model, joints=joints)


@pytest.mark.parametrize("textbook", [True, False], ids=["textbook", "large-model form"])
def test_mixed_rigid_and_flexible_joints_with_friction(arm, textbook):
    from eomgen.model import Actuator
    model = _with_actuators(arm, Actuator(armature=0.5, damping=0.1, friction=0.2),
                            Actuator(armature=0.3, stiffness=100, damping=0.05, friction=0.1))
    spong, links, motors = _drive_residuals(model, textbook)
    assert spong.flexible == (1,)
    assert _exactly_equal(links, spong.link_equations())
    assert _exactly_equal(motors, spong.motor_equations())
    if not textbook:
        return
    md = {f.name: f.content for f in FORMATS["md"](build_handout(model, check=False))}
    section = md["planar_2link_handout.md"].split("## Flexible joints")[1]
    assert r"\tau_{1} &= " in section and r"\tau_{m,2} &= " in section
    assert r"\operatorname{sign}" in section


def test_rigid_joints_with_armature_and_friction(arm):
    from eomgen.analysis.actuators import rigid_with_actuators
    from eomgen.model import Actuator
    model = _with_actuators(arm, Actuator(armature=0.5, damping=0.1),
                            Actuator(armature=0.25, friction=0.2))
    spong, links, motors = _drive_residuals(model)
    assert motors.rows == 0
    rigid = rigid_with_actuators(spong.dynamics)
    assert _exactly_equal(links, rigid.tau() - sp.Matrix(spong.tau))
    handout = build_handout(model, check=False)
    assert [s.title for s in handout.sections][-2] == "Drives: armature and friction"
    md = {f.name: f.content for f in FORMATS["md"](handout)}["planar_2link_handout.md"]
    assert r"\bigl(M(q) + \operatorname{diag}(a)\bigr)" in md


def test_no_drive_section_without_actuators(arm_handout):
    assert not any("Drives" in s.title or "Flexible" in s.title for s in arm_handout.sections)


# -- contacts: the 2-link arm on a wall -----------------------------------------------------

WALL_SCENE = (ROOT / "examples" / "contacts"
              / "planar_2link_wall.yaml")


def test_wall_contact_equations_are_the_closed_form_and_newton_euler(arm):
    """J_c of the tip equals ∂p/∂q of the tip position written by hand, J̇_c q̇ its time
    derivative, and the printed torque rows (names replaced by values) equal eomgen.numeric.contacts'
    numeric inverse dynamics (Newton–Euler) at a moving state."""
    import numpy as np
    from eomgen.numeric.contacts import ContactDynamics
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene
    from eomgen.teach.content import abbreviation_values, contact_equations

    reduction = apply_scene(arm, load_scene(WALL_SCENE))
    model, contacts = reduction.model, reduction.report.contacts
    dyn = eomgen.derive(model, outputs=("M", "C", "g"), simplify=False)
    book = textbook_derivation(model)
    coriolis = named_coriolis(dyn, book)
    Jc, dJqd, F, rows = contact_equations(dyn, contacts, book, coriolis)
    s = {p.name: p.symbol for p in model.parameters}
    q, qd = sp.Matrix(dyn.q), sp.Matrix(dyn.qd)
    tip = sp.Matrix([s["l1"] * sp.cos(q[0]) + s["l2"] * sp.cos(q[0] + q[1]),
                     s["l1"] * sp.sin(q[0]) + s["l2"] * sp.sin(q[0] + q[1]), 0])
    J = tip.jacobian(q)
    assert _exactly_equal(Jc, J)
    assert _exactly_equal(dJqd, (J * qd).jacobian(q) * qd)
    state = {**dict(zip(dyn.q, (0.4, 0.9))), **dict(zip(dyn.qd, (0.3, -0.7))),
             **dict(zip(dyn.qdd, (1.1, 0.5)))}
    force = (-3.0, 1.5, 0.0)
    values = abbreviation_values(dyn, coriolis)
    numbers = {**model.parameter_values, **state, **dict(zip(F, force))}
    printed = [float(sp.Add(*terms).subs(values).subs(numbers)) for _, terms in rows]
    cd = ContactDynamics(model, contacts)
    expected = cd.inverse_dynamics([state[v] for v in dyn.q], [state[v] for v in dyn.qd],
                                   [state[v] for v in dyn.qdd], np.array(force))
    assert np.allclose(printed, expected, rtol=1e-12, atol=1e-12)


def test_wall_scene_handout_has_a_contact_section(tmp_path):
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["teach", "--scene", str(WALL_SCENE), "--format", "md",
                                       "--no-check", "-o", str(out)])
    assert result.exit_code == 0, result.output
    md = (out / "planar_2link_handout.md").read_text()
    section = md[md.index("## Contact"):md.index("## Verified properties")]
    assert r"&= \tau + J_{c}^{T} F_{c}," in section
    assert r"J_{c}(q)\, \ddot{q} + \dot{J}_{c}\, \dot{q} &= 0." in section
    assert (r"J_{c} &= \begin{pmatrix} - (l_{1} s_{1} + l_{2} s_{12}) & - l_{2} s_{12} \\ "
            r"l_{1} c_{1} + l_{2} c_{12} & l_{2} c_{12} \\ 0 & 0 \end{pmatrix}" in section)
    assert (r"\tau_{2} &= M_{1,2} \ddot{q}_{1} + M_{2,2} \ddot{q}_{2} + h \dot{q}_{1}^{2} + g_{2} "
            r"+ f_{x} l_{2} s_{12} - f_{y} l_{2} c_{12}" in section)
    assert "Row 3 of $J_{c}$ is zero" in section
