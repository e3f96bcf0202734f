"""A Sphinx math renderer for the documentation site (docs/conf.py): every ``$…$`` and
``$$…$$`` of the pages becomes MathML when the site is built, by the converter the HTML
handouts use (:class:`eomgen.teach.formats.HtmlFormat`, latex2mathml). Browsers render MathML
natively: the pages load no script and fetch nothing, so the mathematics shows offline and the
build can check it. A formula the converter cannot read is a build warning naming the page and
line (an error under ``-W``), not a formula silently shown as source.
"""

from __future__ import annotations

import html
import re

from docutils import nodes
from sphinx.util import logging

from eomgen.errors import GenerationError
from eomgen.teach.formats import HtmlFormat

logger = logging.getLogger(__name__)
FORMAT = HtmlFormat()


#: What latex2mathml writes, without an error, for LaTeX it does not know: an unknown command
#: as an identifier (``<mi>\\foo</mi>``), the ``&`` of an alignment outside ``array`` or a
#: matrix (``aligned`` is not supported) as a letter.
UNREAD = re.compile(r"<mi>(\\[A-Za-z]+|&amp;|&)</mi>")


def _render(translator, node, convert) -> None:
    tex = node.astext()
    try:
        out = convert(tex)
        unread = UNREAD.search(out)
        if unread:
            raise GenerationError(f"cannot convert {tex!r} to MathML: {html.unescape(unread.group(1))!r} "
                                  "is not understood (an alignment needs \\begin{array})")
        translator.body.append(out)
    except GenerationError as error:
        logger.warning("%s", error, location=node)
        translator.body.append(translator.encode(tex))
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
