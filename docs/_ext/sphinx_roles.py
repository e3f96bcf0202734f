"""A Griffe extension for the API reference (mkdocs.yml), for docstrings written for Sphinx
and doctest rather than Markdown:

* Sphinx's cross-reference roles (:func:`derive`, :class:`~eomgen.model.RobotModel`), which
  Markdown would show as they are, become inline code of the name (the last component after
  ``~``);
* reST's ``text::`` before an indented literal block loses one colon (Markdown shows the
  block as code anyway);
* a doctest outside a NumPy-style ``Examples`` section (lines from ``>>>`` to a blank line),
  which Markdown would run together as a paragraph, becomes a ``pycon`` code block.
"""

from __future__ import annotations

import re

import griffe

ROLE = re.compile(r":(?:py:)?(?:mod|func|class|meth|attr|data|obj|exc|const):`(~?)([^`]+)`")
LITERAL = re.compile(r"(?<=\S)::$", re.M)  # reST's "text::" before a literal block
EXAMPLES = re.compile(r"^\s*Examples?\s*\n\s*-{3,}\s*$", re.M)


def _code(match: re.Match) -> str:
    name = match.group(2)
    return f"`{name.rsplit('.', 1)[-1] if match.group(1) else name}`"


def _fence_doctests(text: str) -> str:
    out: list[str] = []
    lines = text.split("\n")
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.lstrip().startswith(">>>"):
            indent = line[:len(line) - len(line.lstrip())]
            if out and out[-1].strip():
                out.append("")
            out.append(f"{indent}```pycon")
            while i < len(lines) and lines[i].strip():
                out.append(lines[i])
                i += 1
            out.append(f"{indent}```")
            continue
        out.append(line)
        i += 1
    return "\n".join(out)


def markdown_docstring(text: str) -> str:
    """The docstring ``text`` with roles as inline code and free doctests fenced."""
    text = LITERAL.sub(":", ROLE.sub(_code, text))
    found = EXAMPLES.search(text)
    head, rest = (text[:found.start()], text[found.start():]) if found else (text, "")
    return _fence_doctests(head) + rest


class SphinxRoles(griffe.Extension):
    def on_object(self, *, obj, **kwargs) -> None:
        if obj.docstring is not None:
            obj.docstring.value = markdown_docstring(obj.docstring.value)

    def on_package(self, *, pkg, **kwargs) -> None:  # on_object does not see the root package
        self.on_object(obj=pkg)
