"""The registry of description formats: each parser registers its ``load`` with :func:`register`
where it is defined, naming the file suffixes it reads and, for YAML files shared by several
formats, a ``sniff`` function that recognises its content (:func:`eomgen.parsers.load` picks
one)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..model import RobotModel


#: ``load(path, strict, defer_notices=False)``.
Loader = Callable[..., RobotModel]


@dataclass(frozen=True)
class Format:
    name: str
    suffixes: tuple[str, ...]
    load: Loader
    sniff: Callable[[str], bool] | None = None


FORMATS: list[Format] = []


def register(name: str, suffixes: tuple[str, ...], sniff: Callable[[str], bool] | None = None):
    """Decorator registering ``load(path, strict, defer_notices=False)`` for files with the
    given suffixes."""

    def decorate(load: Loader) -> Loader:
        FORMATS.append(Format(name, suffixes, load, sniff))
        return load

    return decorate
