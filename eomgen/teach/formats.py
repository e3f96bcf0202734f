"""The handout in four formats: LaTeX, PDF (LaTeX through pdflatex), Markdown and HTML.

Each format is a small class that says how to write the three kinds of inline content (text,
math, code) and displayed equations; the page layout is a template in ``templates/teach/``.
:data:`FORMATS` maps a format name to its function ``Handout -> list[GeneratedFile]``.

* ``tex``: ``<stem>_handout.tex`` and the sketch ``<stem>_sketch.pdf`` it includes (plain
  pdflatex: amsmath, geometry, longtable, graphicx).
* ``pdf``: ``<stem>_handout.pdf``, the ``tex`` output compiled twice by pdflatex in a temporary
  folder (``SOURCE_DATE_EPOCH`` fixed, so the same input gives the same bytes).
* ``md``: ``<stem>_handout.md`` with ``$…$`` and ``$$…$$`` math (GitHub, Jupyter, pandoc) and
  the sketch ``<stem>_sketch.svg``.
* ``html``: one self-contained ``<stem>_handout.html``: the math converted to MathML by
  latex2mathml when the file is written (browsers render MathML natively: no script, no font
  or network fetch; the LaTeX source rides along in each formula's ``annotation``), the sketch
  inlined as SVG.
"""

from __future__ import annotations

import html
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path
from typing import Callable

from ..common.templating import render
from ..errors import GenerationError
from ..common.output import GeneratedFile
from ..present.printer import latex_comment, latex_escape
from .document import Equations, Figure, Handout, Inline, Paragraph, Table

#: The figures, numbered in order of appearance.
FIGURE_NAMES = {"sketch": 1}


class _Format:
    """How one output format writes inline content and equations."""

    name = ""
    template = ""

    def text(self, value: str) -> str:
        raise NotImplementedError

    def math(self, tex: str) -> str:
        raise NotImplementedError

    def code(self, value: str) -> str:
        raise NotImplementedError

    def equations(self, block: Equations) -> str:
        raise NotImplementedError

    def figure_file(self, handout: Handout, figure: Figure) -> str:
        raise NotImplementedError

    def inline(self, content: Inline) -> str:
        return "".join(getattr(self, span.kind)(span.value) for span in content)

    def block(self, handout: Handout, block) -> dict:
        if isinstance(block, Paragraph):
            return {"kind": "paragraph", "text": self.inline(block.content)}
        if isinstance(block, Equations):
            return {"kind": "equations", "text": self.equations(block)}
        if isinstance(block, Table):
            return {"kind": "table", "small": block.small,
                    "headings": [self.cell(h) for h in block.headings],
                    "rows": [[self.cell(c) for c in row] for row in block.rows]}
        if isinstance(block, Figure):
            return {"kind": "figure", "number": FIGURE_NAMES[block.name],
                    "file": self.figure_file(handout, block),
                    "caption": self.inline(block.caption)}
        raise TypeError(f"unknown block {block!r}")

    def cell(self, content: Inline) -> str:
        return self.inline(content)

    def section(self, handout: Handout, section) -> dict:
        return {"title": self.text(section.title),
                "blocks": [self.block(handout, b) for b in section.blocks]}

    def render(self, handout: Handout) -> str:
        sections = [self.section(handout, s) for s in handout.sections]
        return render(self.template, title=self.text(handout.title), sections=sections,
                      header=list(handout.header), comment=self.comment)

    def comment(self, line: str) -> str:
        raise NotImplementedError


def _aligned_rows(block: Equations) -> str:
    """The body of an ``align*`` / ``aligned`` environment: one row per line, aligned at the
    relation sign, continuation lines indented."""
    rows = []
    for eq in block.equations:
        rows.append(f"{eq.lhs} &{eq.relation} {eq.lines[0]}")
        rows += [f"&\\quad {{}}{line}" for line in eq.lines[1:]]
    return " \\\\\n".join(rows)


#: Typographic characters of eomgen's own sentences, as pdflatex writes them (other non-ASCII
#: characters, from user text, are shown by :func:`latex_escape` as code points).
_TEX_TYPOGRAPHY = {"\u2013": "--", "\u2014": "---", "\u2019": "'", "\u00a0": "~"}


#: A table of at most this many rows is kept on one page with its introduction; a longer one
#: (longtable, its heading repeated on every page) keeps its heading and KEEP_FIRST_ROWS rows.
KEEP_ROWS = 20
KEEP_FIRST_ROWS = 5


def _paragraph_lines(tex: str) -> int:
    """Lines a paragraph of the handout takes, generously (about 90 characters of source a
    line, plus the space between paragraphs)."""
    return len(tex) // 90 + 2


class TexFormat(_Format):
    name = "tex"
    template = "teach/handout.tex.jinja"

    def text(self, value):
        return "".join(_TEX_TYPOGRAPHY.get(ch) or latex_escape(ch) for ch in value)

    def math(self, tex):
        return f"${tex}$"

    def code(self, value):
        return r"\texttt{" + latex_escape(value) + "}"

    def equations(self, block):
        return "\\begin{align*}\n" + _aligned_rows(block) + "\n\\end{align*}"

    def section(self, handout, section):
        """The section, with the lines to keep on one page (``keep``, for ``\\keeplines``)
        set before each table: the paragraph that introduces it, its heading and its first
        rows (all of them, up to :data:`KEEP_ROWS`) go to the next page together rather than
        leave the heading, or the introduction, at the foot of a page. Before the first block
        the section heading is kept with them too."""
        out = super().section(handout, section)
        blocks = out["blocks"]
        out["keep"] = 0
        for data in blocks:
            data["keep"] = 0
        for t, (block, data) in enumerate(zip(section.blocks, blocks)):
            if not isinstance(block, Table):
                continue
            rows = len(block.rows)
            lines = 3 + (rows if rows <= KEEP_ROWS else KEEP_FIRST_ROWS)
            at = t
            if t and isinstance(section.blocks[t - 1], Paragraph):
                at = t - 1
                lines += _paragraph_lines(blocks[at]["text"])
            if at == 0:
                out["keep"] = lines + 4
            else:
                blocks[at]["keep"] = lines
        return out

    def figure_file(self, handout, figure):
        return f"{handout.stem}_{figure.name}.pdf"

    def comment(self, line):
        return latex_comment(line)


_MARKDOWN_SPECIAL = re.compile(r"([\\`*_\[\]<>|$~#])")


class MarkdownFormat(_Format):
    name = "md"
    template = "teach/handout.md.jinja"

    def text(self, value):
        return _MARKDOWN_SPECIAL.sub(r"\\\1", value).replace("\n", " ")

    def math(self, tex):
        return f"${tex}$"

    def code(self, value):
        value = value.replace("\n", " ")
        fence = "`" * (max((len(r) for r in re.findall("`+", value)), default=0) + 1)
        return f"{fence} {value} {fence}"

    def cell(self, content):
        return self.inline(content).replace("|", r"\|")

    def equations(self, block):
        return "$$\n\\begin{aligned}\n" + _aligned_rows(block) + "\n\\end{aligned}\n$$"

    def figure_file(self, handout, figure):
        return f"{handout.stem}_{figure.name}.svg"

    def comment(self, line):
        return "<!-- " + line.replace("--", "- -") + " -->"


_MATH_ELEMENT = re.compile(r"^<math[^>]*>(.*)</math>$", re.S)

#: A capital Greek letter as latex2mathml writes it (``\Gamma`` → ``<mi>&#x00393;</mi>``):
#: upright in TeX, but MathML makes a one-letter ``<mi>`` italic unless told otherwise.
_CAPITAL_GREEK = re.compile(r"<mi>(&#x00(?:39[1-9A-F]|3A[0-9]);)</mi>")


class HtmlFormat(_Format):
    """HTML with MathML made by latex2mathml (see the module docstring)."""

    name = "html"
    template = "teach/handout.html.jinja"

    def __init__(self):
        from latex2mathml.converter import convert  # start-up time: HTML handouts only

        self._convert = convert

    def _mathml(self, tex: str) -> str:
        """The MathML content (inside ``<math>``) of ``tex``."""
        try:
            out = self._convert(tex)
        except Exception as exc:  # latex2mathml raises assorted exceptions on unknown input
            raise GenerationError(f"cannot convert {tex!r} to MathML: {exc}") from exc
        match = _MATH_ELEMENT.match(out.strip())
        content = match.group(1) if match else out
        return _CAPITAL_GREEK.sub(r'<mi mathvariant="normal">\1</mi>', content)

    @staticmethod
    def _wrap(content: str, tex: str, display: str) -> str:
        return (f'<math display="{display}"><semantics><mrow>{content}</mrow>'
                f'<annotation encoding="application/x-tex">{html.escape(tex, quote=False)}'
                "</annotation></semantics></math>")

    def text(self, value):
        return html.escape(value, quote=False)

    def math(self, tex):
        return self._wrap(self._mathml(tex), tex, "inline")

    def displayed(self, tex: str) -> str:
        """One displayed formula (the documentation site's ``$$…$$``, docs/_ext/mathml.py)."""
        return self._wrap(self._mathml(tex), tex, "block")

    def code(self, value):
        return "<code>" + html.escape(value, quote=False) + "</code>"

    def equations(self, block):
        rows, source = [], []
        for eq in block.equations:
            cells = [(eq.lhs, f"{eq.relation} {eq.lines[0]}")]
            cells += [("", r"\quad {} " + line) for line in eq.lines[1:]]
            for lhs, rhs in cells:
                rows.append(f"<mtr><mtd>{self._mathml(lhs) if lhs else ''}</mtd>"
                            f"<mtd>{self._mathml(rhs)}</mtd></mtr>")
            source.append(f"{eq.lhs} &{eq.relation} " + r" \\ &\quad ".join(eq.lines))
        table = ('<mtable class="align" columnalign="right left" columnspacing="0" '
                 'displaystyle="true">'
                 + "".join(rows) + "</mtable>")
        tex = "\\begin{aligned}" + r" \\ ".join(source) + "\\end{aligned}"
        return self._wrap(table, tex, "block")

    def figure_file(self, handout, figure):
        svg = handout.figures[figure.name]("svg").decode("utf-8")
        return svg[svg.index("<svg"):]  # inline: without the XML declaration and doctype

    def comment(self, line):
        return "<!-- " + html.escape(line.replace("--", "- -"), quote=False) + " -->"


def write_tex(handout: Handout) -> list[GeneratedFile]:
    """The LaTeX source and the sketch (PDF) it includes."""
    files = [GeneratedFile(f"{handout.stem}_handout.tex", TexFormat().render(handout))]
    for name in FIGURE_NAMES:
        if name in handout.figures:
            files.append(GeneratedFile(f"{handout.stem}_{name}.pdf", handout.figures[name]("pdf")))
    return files


def write_pdf(handout: Handout, pdflatex: str | None = None, timeout: float = 600) -> list[GeneratedFile]:
    """Compile the ``tex`` output with pdflatex (twice: longtable widths settle on the second
    run) in a temporary folder; raise :class:`GenerationError` naming pdflatex's first error."""
    pdflatex = pdflatex or shutil.which("pdflatex")
    if pdflatex is None:
        raise GenerationError("the pdf format needs pdflatex, which is not installed (Debian: "
                              "apt install texlive-latex-base); --format tex, html or md "
                              "need nothing more")
    files = write_tex(handout)
    env = dict(os.environ, SOURCE_DATE_EPOCH="0", FORCE_SOURCE_DATE="1")
    with tempfile.TemporaryDirectory(prefix="eomgen-teach-") as tmp:
        for f in files:
            path = Path(tmp) / f.name
            if isinstance(f.content, bytes):
                path.write_bytes(f.content)
            else:
                path.write_text(f.content, encoding="utf-8")
        tex = files[0].name
        for _ in range(2):
            try:
                run = subprocess.run(
                    [pdflatex, "-interaction=nonstopmode", "-halt-on-error", "-no-shell-escape",
                     tex], cwd=tmp, env=env, capture_output=True, timeout=timeout)
            except subprocess.TimeoutExpired:
                raise GenerationError(f"pdflatex did not finish {tex} within {timeout:.0f} s") from None
            if run.returncode != 0:
                log = run.stdout.decode("utf-8", "replace").splitlines()
                error = next((line for line in log if line.startswith("!")), "no message")
                raise GenerationError(f"pdflatex failed on {tex}: {error.lstrip('! ')} "
                                      "(write --format tex to inspect the source)")
        pdf = (Path(tmp) / tex).with_suffix(".pdf").read_bytes()
    return [GeneratedFile(f"{handout.stem}_handout.pdf", pdf)]


def write_markdown(handout: Handout) -> list[GeneratedFile]:
    files = [GeneratedFile(f"{handout.stem}_handout.md", MarkdownFormat().render(handout))]
    for name in FIGURE_NAMES:
        if name in handout.figures:
            files.append(GeneratedFile(f"{handout.stem}_{name}.svg",
                                       handout.figures[name]("svg").decode("utf-8")))
    return files


def write_html(handout: Handout) -> list[GeneratedFile]:
    return [GeneratedFile(f"{handout.stem}_handout.html", HtmlFormat().render(handout))]


#: Format name → writer of the handout's files.
FORMATS: dict[str, Callable[[Handout], list[GeneratedFile]]] = {
    "pdf": write_pdf,
    "html": write_html,
    "md": write_markdown,
    "tex": write_tex,
}
