"""The code blocks of README.md and docs/*.md, read for tests/docs (the rule is in
tests/README.md).

A block is fenced with three backticks at the start of a line and names its language:

* ``python``: run in process, the file's blocks in order in one namespace;
* ``console``: a shell session; each ``$ `` line (with its ``\\`` continuation lines) is a
  command run in a subprocess, the lines without ``$ `` are its output;
* ``text``, ``yaml``, ``pycon`` and the other languages of :data:`SHOWN`: what is shown (output,
  data, formulas, generated code), not run (``yaml`` must parse).

Markers, HTML comments (invisible on the rendered page) on the lines right before a ``python``
or ``console`` block:

* ``<!-- not-run: REASON -->``: not runnable, and why;
* ``<!-- needs: MODULE[, MODULE] -->``: runs only where those optional modules import (the
  extras jax, torch: CI installs them);
* ``<!-- run-with: OPTIONS -->``: a long run made small: OPTIONS are appended to each
  ``eomgen`` command of the block (the last of a repeated option wins), e.g.
  ``--duration 0.1``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from support import DOCS, ROOT

#: Languages whose blocks are run.
PYTHON = "python"
CONSOLE = "console"
RUN = (PYTHON, CONSOLE)
#: Languages whose blocks are shown, not run: output, data, formulas, generated code.
SHOWN = ("text", "yaml", "pycon", "c", "latex", "csv", "markdown")

MARKER = re.compile(r"^<!-- (not-run|needs|run-with): (.+?) -->$")
FENCE = re.compile(r"^```(.*)$")


@dataclass(frozen=True)
class Block:
    path: Path          #: the Markdown file
    line: int           #: line number of the opening fence (1-based)
    language: str       #: the fence's info string ("" when none)
    text: str           #: the block's content, ending with a newline
    not_run: str | None  #: the reason of a not-run marker right before it, else None
    needs: tuple[str, ...] = ()  #: the optional modules a needs marker names
    run_with: str = ""  #: the options a run-with marker appends to each eomgen command

    @property
    def where(self) -> str:
        path = self.path.relative_to(ROOT) if self.path.is_relative_to(ROOT) else self.path
        return f"{path}:{self.line}"

    def commands(self) -> list[str]:
        """A console block's commands: the ``$ `` lines with their continuation lines."""
        commands, current = [], None
        for line in self.text.splitlines():
            if current is not None:
                current.append(line)
            elif line.startswith("$ "):
                current = [line[2:]]
            else:
                continue
            if not line.rstrip().endswith("\\"):
                commands.append("\n".join(current))
                current = None
        return commands


def markdown_files() -> list[Path]:
    """README.md and every page of docs/ (not docs/_ext/)."""
    pages = sorted(p for p in DOCS.rglob("*.md") if not p.relative_to(DOCS).parts[0].startswith("_"))
    return [ROOT / "README.md", *pages]


def blocks(path: Path) -> list[Block]:
    """The fenced code blocks of ``path``, in order."""
    lines = path.read_text(encoding="utf-8").splitlines()
    found, i = [], 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if not opening:
            i += 1
            continue
        end = next((j for j in range(i + 1, len(lines)) if lines[j].rstrip() == "```"), None)
        assert end is not None, f"{path}:{i + 1}: a fence that is never closed"
        markers, k = {}, i - 1
        while k >= 0 and (marker := MARKER.match(lines[k].strip())):
            assert marker.group(1) not in markers, f"{path}:{k + 1}: a repeated marker"
            markers[marker.group(1)] = marker.group(2)
            k -= 1
        found.append(Block(path, i + 1, opening.group(1).strip(),
                           "".join(line + "\n" for line in lines[i + 1:end]),
                           markers.get("not-run"),
                           tuple(markers["needs"].split(", ")) if "needs" in markers else (),
                           markers.get("run-with", "")))
        i = end + 1
    return found


def indented_code(path: Path) -> list[int]:
    """Lines that start an indented code block (four spaces after a blank line, outside a
    fence and not continuing a list item): blocks that name no language."""
    lines = path.read_text(encoding="utf-8").splitlines()
    starts, in_fence, paragraph_start = [], False, ""
    for i, line in enumerate(lines):
        if FENCE.match(line):
            in_fence = not in_fence
            continue
        if in_fence:
            continue
        previous = lines[i - 1] if i else ""
        if previous.strip() == "" and line.strip():
            if line.startswith("    ") and not re.match(r"\s*([-*+]|\d+\.)\s", paragraph_start):
                if not (starts and _continues(lines, starts[-1], i)):
                    starts.append(i)
            elif not line.startswith("    "):
                paragraph_start = line
    return [s + 1 for s in starts]


def _continues(lines: list[str], start: int, i: int) -> bool:
    """Line ``i`` continues the indented block starting at ``start`` (only blank or indented
    lines between)."""
    return all(not line.strip() or line.startswith("    ") for line in lines[start:i])
