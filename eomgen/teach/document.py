"""The handout as plain data, independent of its output format.

A :class:`Handout` is a title and a list of :class:`Section` s; a section is a list of blocks:
:class:`Paragraph` (inline text and math), :class:`Equations` (displayed equations aligned at
their ``=``), :class:`Table` and :class:`Figure`. The renderers of :mod:`eomgen.teach.formats`
turn the same handout into LaTeX, Markdown or HTML, so every sentence and every equation is
written once.

Inline content is a tuple of :class:`Span` s of three kinds:

* ``text``: plain prose, escaped for the output format;
* ``math``: LaTeX math (without the ``$``), written by eomgen's printers, never user text;
* ``code``: a name from the description (link, joint, file), shown verbatim and escaped.

:func:`prose` builds spans from eomgen's own sentences, where ``$…$`` marks math; text that
comes from the description must be passed as :func:`code` or :func:`plain` spans, so a ``$``
or a backslash in a robot's name is never read as markup.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Union

_MATH = re.compile(r"\$([^$]+)\$")


@dataclass(frozen=True)
class Span:
    """A piece of inline content: ``kind`` is ``"text"``, ``"math"`` or ``"code"``."""

    kind: str
    value: str


Inline = tuple[Span, ...]


def plain(text: str) -> Span:
    """Text shown as it is (user text is safe here: it is escaped, never parsed)."""
    return Span("text", str(text))


#: A unit's exponent in user text: ``m^2``, ``s^-2``, ``m^{2}`` (after a letter or a bracket).
_EXPONENT = re.compile(r"(?<=[A-Za-z)\]])\^(?:\{(-?[0-9]+)\}|(-?[0-9]+))")


def described(text: str) -> Inline:
    """User text (a parameter's meaning) as plain spans, except that a unit's exponent
    (``kg m^2``, ``m/s^-2``, ``m^{2}``) is a superscript, so that the PDF prints m² and not
    ``mˆ2``. Only the matched digits become math; the rest stays escaped text.

    >>> [(s.kind, s.value) for s in described("inertia [kg m^2], g in m/s^{-2}")]
    [('text', 'inertia [kg m'), ('math', '^{2}'), ('text', '], g in m/s'), ('math', '^{-2}')]
    """
    spans: list[Span] = []
    at = 0
    for match in _EXPONENT.finditer(text):
        if match.start() > at:
            spans.append(plain(text[at:match.start()]))
        spans.append(math("^{" + (match.group(1) or match.group(2)) + "}"))
        at = match.end()
    if at < len(text) or not spans:
        spans.append(plain(text[at:]))
    return tuple(spans)


def code(text: str) -> Span:
    """A name from the description, in a monospace font."""
    return Span("code", str(text))


def math(tex: str) -> Span:
    """Inline LaTeX math (eomgen's own, not user text)."""
    return Span("math", tex)


def prose(*parts: str | Span) -> Inline:
    """Inline content from eomgen's own sentences (``$…$`` marks math) and spans.

    >>> [(s.kind, s.value) for s in prose("mass $m_{1}$ of ", code("link_1"), ".")]
    [('text', 'mass '), ('math', 'm_{1}'), ('text', ' of '), ('code', 'link_1'), ('text', '.')]
    """
    spans: list[Span] = []
    for part in parts:
        if isinstance(part, Span):
            spans.append(part)
            continue
        at = 0
        for match in _MATH.finditer(part):
            if match.start() > at:
                spans.append(plain(part[at:match.start()]))
            spans.append(math(match.group(1)))
            at = match.end()
        if at < len(part):
            spans.append(plain(part[at:]))
    return tuple(spans)


@dataclass(frozen=True)
class Paragraph:
    content: Inline


@dataclass(frozen=True)
class Equation:
    """``lhs = lines[0]``, continued on ``lines[1:]`` (each a LaTeX math string)."""

    lhs: str
    lines: tuple[str, ...]
    relation: str = "="


@dataclass(frozen=True)
class Equations:
    """Displayed equations, aligned at their relation sign."""

    equations: tuple[Equation, ...]


@dataclass(frozen=True)
class Table:
    """A table; ``headings`` and every cell are inline content."""

    headings: tuple[Inline, ...]
    rows: tuple[tuple[Inline, ...], ...]
    small: bool = False


@dataclass(frozen=True)
class Figure:
    """A figure made by the renderer from the file ``name`` (without suffix) that the handout
    carries in :attr:`Handout.figures`."""

    name: str
    caption: Inline


Block = Union[Paragraph, Equations, Table, Figure]


@dataclass(frozen=True)
class Section:
    title: str
    blocks: tuple[Block, ...]


@dataclass(frozen=True)
class Handout:
    """A teaching handout.

    Attributes
    ----------
    stem:
        File-name stem of the outputs (``planar_2link`` → ``planar_2link_handout.pdf``).
    title:
        Document title (plain text).
    sections:
        The sections, in order.
    figures:
        Figure name → function of a format (``"pdf"``, ``"svg"``, ``"png"``) returning the
        figure's bytes; rendered only by the formats that need them.
    header:
        Provenance lines (source file and hash, eomgen version), written as a comment.
    """

    stem: str
    title: str
    sections: tuple[Section, ...]
    figures: dict = field(default_factory=dict, compare=False)
    header: tuple[str, ...] = ()
