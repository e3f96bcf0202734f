"""The documentation site (docs/conf.py: Sphinx, MyST Markdown, the Furo theme): docs/*.md and
the API reference from the docstrings build with warnings as errors (a broken link or anchor, a
page in no table of contents, a docstring that is not valid reStructuredText, an API name that
no longer exists, a formula that cannot become MathML all fail the build)."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from support import DOCS
from support.extras import missing

_DOCS_MISSING = missing("sphinx", "myst_parser", "furo")
needs_docs = pytest.mark.skipif(_DOCS_MISSING is not None, reason=f"the site build {_DOCS_MISSING}")

#: A table of contents: MyST's ``:::{toctree}`` block (index.md) or reST's directive
#: (api/index.rst), up to the closing ``:::`` or the end of the indented block.
TOCTREE = re.compile(r"^(?::::\{toctree\}\n(?P<md>.*?)^:::$|\.\. toctree::\n(?P<rst>(?:   .*\n|\n)*))",
                     re.M | re.S)
#: An entry of the sidebar Furo writes: its level, link and title.
SIDEBAR = re.compile(r'<li class="toctree-l(\d)[^"]*"><a class="reference internal" '
                     r'href="([^"]*)">([^<]*)</a>')


def _sphinx(source, out, *options):
    return subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q",
                           "-b", "html", *options, str(source), str(out)],
                          capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The site, built once for this module's checks."""
    out = tmp_path_factory.mktemp("site")
    done = _sphinx(DOCS, out)
    assert done.returncode == 0 and done.stderr.strip() == "", done.stderr
    return out


@needs_docs
def test_the_api_reference_is_rendered_from_the_docstrings_with_links(site):
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    assert 'id="eomgen.dynamics.derive"' in api and "autofunction" not in api
    dynamics = (site / "api" / "dynamics.html").read_text(encoding="utf-8")
    assert 'id="eomgen.dynamics.Dynamics.lambdify"' in dynamics
    # a Sphinx role of a docstring (:data:`eomgen.outputs.INPUTS`) is a link to its entry
    assert 'href="codegen.html#eomgen.outputs.INPUTS"' in dynamics
    codegen = (site / "api" / "codegen.html").read_text(encoding="utf-8")
    assert 'id="eomgen.outputs.INPUTS"' in codegen
    for page in site.glob("api/*.html"):  # no role is left as it was written
        assert not re.search(r":(mod|func|class|data):`", page.read_text(encoding="utf-8")), page


@needs_docs
def test_the_formulas_are_mathml_and_the_pages_load_no_script_for_them(site):
    index = (site / "index.html").read_text(encoding="utf-8")
    display = re.search(r'<math display="block">.*?</math>', index, re.S)
    assert display, "the page's displayed equation is not MathML"
    assert "<mi>τ</mi>" in display.group(0) or "<mi>&#x003C4;</mi>" in display.group(0)
    assert "$$" not in index and not re.search(r"<script[^>]*(mathjax|katex)", index, re.I)
    derivatives = (site / "derivatives.html").read_text(encoding="utf-8")
    assert '<math display="inline">' in derivatives


@needs_docs
def test_the_sidebar_names_each_page_once(site):
    """One entry per page, the API reference's pages under it (no section named like the
    page it opens with)."""
    entries = SIDEBAR.findall((site / "api" / "dynamics.html").read_text(encoding="utf-8"))
    titles, links = [title for _, _, title in entries], [link for _, link, _ in entries]
    assert titles.count("API reference") == 1 and len(links) == len(set(links)), entries
    levels = {title: level for level, _, title in entries}
    assert levels["API reference"] == "1" and levels["Errors"] == "2"


@needs_docs
def test_a_broken_link_or_formula_fails_the_build(tmp_path):
    """The build with warnings as errors is not a formality: the same configuration
    (``-c docs``) on a page with a link to a page that does not exist, or a formula the
    converter cannot read (a syntax error, an alignment it does not know, an unknown command,
    the last two of which latex2mathml itself lets through), fails and names the page."""
    for name, text in (("link", "See [the missing page](missing.md).\n"),
                       ("formula", "The mass matrix $M(q) = \\frac{1}{$.\n"),
                       ("alignment", "$$\n\\begin{aligned} a &= b \\end{aligned}\n$$\n"),
                       ("command", "The mass matrix $\\Mass(q)$.\n")):
        source = tmp_path / name
        source.mkdir()
        (source / "index.md").write_text(f"# Home\n\n{text}", encoding="utf-8")
        done = _sphinx(source, tmp_path / f"{name}-site", "-c", str(DOCS))
        assert done.returncode != 0 and "index.md" in done.stderr, (name, done.stderr)
        assert "WARNING" in done.stderr or "ERROR" in done.stderr


def test_every_docs_page_is_in_a_table_of_contents():
    """The tables of contents (index.md, api/index.rst) list every page of docs/ and only
    pages that exist; checked without the docs extra too, so a new page left out fails
    everywhere (Sphinx warns of it too)."""
    listed = []
    for page in DOCS.rglob("*"):
        if page.suffix not in (".md", ".rst"):
            continue
        for found in TOCTREE.finditer(page.read_text(encoding="utf-8")):
            for line in (found.group("md") or found.group("rst")).splitlines():
                line = line.strip()
                if line and not line.startswith(":"):
                    target = re.fullmatch(r"(?:.*<(.+)>|(.+))", line)
                    name = target.group(1) or target.group(2)
                    listed.append(str(page.parent.relative_to(DOCS) / name).removeprefix("./"))
    present = [str(p.relative_to(DOCS).with_suffix("")) for p in DOCS.rglob("*")
               if p.suffix in (".md", ".rst") and not p.relative_to(DOCS).parts[0].startswith("_")]
    assert sorted(listed + ["index"]) == sorted(present)
