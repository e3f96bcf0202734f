"""The registry of code generation targets: :class:`Backend`, :func:`register` (called by each
backend in its own module under :mod:`eomgen.codegen.backends`), :func:`available_backends` and
:func:`loadable_backends`, and :class:`Loaded` (a generated module imported back)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

from ..common.output import GeneratedFile


@dataclass(frozen=True)
class Backend:
    """A code generation target: ``generate(job, config) -> files``.

    ``needs`` lists derived outputs (``"M"``, ``"C"``, ``"g"``, ``"tau"``) the backend needs
    whatever functions are asked (a derivation document needs M, C and g); empty when it prints
    just the asked functions. ``config`` is the backend's config dataclass (its defaults are used
    when a caller passes none; ``config().suffix`` names its main file); ``order`` places it in
    :func:`available_backends` (and so in ``--backend all``). ``reserved`` are names its modules
    bind themselves (``np``); no parameter of any backend's module takes them. ``printer`` is
    its SymPy printer class, when it has one.

    ``load(folder, stem) -> Loaded`` imports the code the backend wrote into ``folder`` for the
    module stem ``stem`` and says how to call its functions (None: nothing callable from
    Python, e.g. LaTeX); ``requires`` are the Python packages that needs (optional extras).
    Tests and benchmarks loop over the backends that have ``load`` and whose ``requires`` are
    installed (:func:`loadable_backends`), so a new backend is tested without being listed.

    A backend that compiles has two stages: ``emit(job, config) -> files`` renders the text
    files (no compiler involved) and ``build(job, emitted, config) -> files`` compiles the
    binaries from them; its ``generate`` is the two in a row. Both are None for a backend
    whose ``generate`` only renders text. :meth:`files` runs a backend with or without its
    build.
    """

    name: str
    description: str
    generate: Callable[..., list[GeneratedFile]]
    needs: tuple[str, ...] = ()
    config: type | None = None
    order: int = 1000
    reserved: tuple[str, ...] = ()
    printer: type | None = None
    load: Callable[[Path, str], "Loaded"] | None = None
    requires: tuple[str, ...] = ()
    emit: Callable[..., list[GeneratedFile]] | None = None
    build: Callable[..., list[GeneratedFile]] | None = None

    def files(self, job: "Job", build: bool = True) -> list[GeneratedFile]:
        """The backend's files for ``job`` (default config): with ``build``, what
        :attr:`generate` gives; without, only the text files :attr:`emit` renders (nothing
        compiled). A backend without a build step gives the same files either way."""
        if build or self.emit is None:
            return self.generate(job)
        return self.emit(job)


@dataclass(frozen=True)
class Loaded:
    """A generated module imported by its backend's ``load``.

    ``namespace`` holds the module's names (functions, ``JOINT_NAMES`` …; for CasADi the
    ``casadi.Function`` objects by name). ``call(function, *inputs, **parameters)`` runs one of
    its functions on the input vectors in the registry's order (``eomgen.outputs.OUTPUTS``) and
    returns an array-like result: what a user's plain call gives (a CasADi function is called
    by name, so a parameter left out takes its default, as in the others)."""

    namespace: Mapping[str, Any]
    call: Callable[..., Any]


BACKENDS: dict[str, Backend] = {}


def register(name: str, description: str, needs: tuple[str, ...] = (), config: type | None = None,
             order: int = 1000, reserved: tuple[str, ...] = (), printer: type | None = None,
             load: Callable[[Path, str], Loaded] | None = None, requires: tuple[str, ...] = (),
             emit: Callable[..., list[GeneratedFile]] | None = None,
             build: Callable[..., list[GeneratedFile]] | None = None):
    """Decorator registering ``generate(job, config=...) -> list[GeneratedFile]`` as backend
    ``name``, with its config dataclass ``config``, the identifiers its modules bind
    (``reserved``), its printer class, how to load what it wrote (``load``, ``requires``) and,
    for a backend that compiles, its two stages ``emit`` and ``build`` (see
    :class:`Backend`). Backends are listed by ``order``, then name."""

    def decorate(function: Callable[..., list[GeneratedFile]]):
        BACKENDS[name] = Backend(name, description, function, tuple(needs), config, order,
                                 tuple(reserved), printer, load, tuple(requires),
                                 emit=emit, build=build)
        ordered = sorted(BACKENDS.items(), key=lambda item: (item[1].order, item[0]))
        BACKENDS.clear()
        BACKENDS.update(ordered)
        return function

    return decorate


def available_backends() -> dict[str, Backend]:
    """Every registered backend, by ``order`` then name (importing :mod:`.backends` finds and
    registers the built-in ones)."""
    from . import backends  # noqa: F401  (registration)

    return dict(BACKENDS)


def loadable_backends() -> dict[str, Backend]:
    """The backends whose generated code can be imported and called here: those with a
    ``load`` whose ``requires`` are installed, by ``order`` then name."""
    from importlib.util import find_spec  # start-up time: only this listing asks

    return {name: b for name, b in available_backends().items()
            if b.load is not None and all(find_spec(r) is not None for r in b.requires)}
