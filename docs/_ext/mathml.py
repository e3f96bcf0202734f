"""A Sphinx math renderer for the documentation site (docs/conf.py): every ``$…$`` and
``$$…$$`` of the pages becomes MathML when the site is built, by the converter the HTML
handouts use (:class:`eomgen.teach.formats.HtmlFormat`, latex2mathml). Browsers render MathML
natively: the pages load no script and fetch nothing, so the mathematics shows offline and the
build can check it. A formula the converter cannot read is a build warning naming the page and
line (an error under ``-W``), not a formula silently shown as source.
"""

from __future__ import annotations

from docutils import nodes
from sphinx.util import logging

from eomgen.errors import GenerationError
from eomgen.teach.formats import HtmlFormat

logger = logging.getLogger(__name__)
FORMAT = HtmlFormat()


def _render(translator, node, convert) -> None:
    try:
        translator.body.append(convert(node.astext()))
    except GenerationError as error:
        logger.warning("%s", error, location=node)
        translator.body.append(translator.encode(node.astext()))
    raise nodes.SkipNode


def visit_math(translator, node) -> None:
    _render(translator, node, FORMAT.math)


def visit_displaymath(translator, node) -> None:
    translator.body.append('<div class="math-display">')
    try:
        _render(translator, node, FORMAT.displayed)
    finally:
        translator.body.append("</div>")


def setup(app):
    app.add_html_math_renderer("mathml", (visit_math, None), (visit_displaymath, None))
    app.add_css_file("mathml.css")
    return {"parallel_read_safe": True, "parallel_write_safe": True}
