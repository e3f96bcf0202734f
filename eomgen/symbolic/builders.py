"""Who builds each output, registered where it is built.

The catalogue of outputs (:mod:`eomgen.outputs`) is data: names, inputs, shapes, units. The
functions that build them register themselves here from their own modules, as the code
backends do (:func:`eomgen.codegen.backends.register`):

* :func:`builds` — ``function(derivation, wanted) -> {symbol: sympy.Matrix}``, the builder of
  the printed outputs ``symbols`` (:meth:`eomgen.symbolic.derivation.Derivation.build` finds
  it by symbol: :func:`builder_of`);
* :func:`sizes` — ``function(model) -> int``, the length of an input the catalogue lists in
  :data:`~eomgen.outputs.INPUT_SIZES` (:func:`input_size`);
* :func:`provides` — ``function(dynamics) -> {NAME: (str, ...)}``, the module constants named
  by an output's :attr:`~eomgen.outputs.Output.constants` (:func:`constants_provider`).

Nothing here imports an algorithm: the modules that register are imported by the place that
derives (:mod:`eomgen.dynamics`), so that every builder is known before a derivation needs it.
A lookup that finds nothing says so in one line rather than guessing.
"""

from __future__ import annotations

from typing import Callable

from ..outputs import BY_SYMBOL, INPUT_SIZES, INPUTS

#: The builder of each printed output, by symbol.
BUILDERS: dict[str, Callable] = {}
#: The length of each input of :data:`~eomgen.outputs.INPUT_SIZES`, by input name.
SIZES: dict[str, Callable] = {}
#: The provider of each tuple of module constants an output declares.
CONSTANTS: dict[tuple[str, ...], Callable] = {}


def _register(table: dict, keys, function: Callable, what: str) -> Callable:
    for key in keys:
        if table.get(key, function) is not function:
            raise ValueError(f"{what} {key!r} is already registered "
                             f"({table[key].__module__}.{table[key].__qualname__})")
    for key in keys:
        table[key] = function
    return function


def builds(*symbols: str) -> Callable[[Callable], Callable]:
    """Register the decorated ``function(derivation, wanted) -> {symbol: matrix}`` as the
    builder of the printed outputs ``symbols`` (outputs sharing a builder are built in one
    call; a returned symbol the catalogue does not declare, such as the potential energy ``P``
    of the Lagrangian builder, is kept in the program as well).

    Raises
    ------
    ValueError
        For a symbol the catalogue does not declare, or one another function builds already.
    """
    unknown = [s for s in symbols if s not in BY_SYMBOL]
    if unknown or not symbols:
        raise ValueError(f"no printed output {', '.join(unknown) or '(none named)'} in the "
                         "catalogue (eomgen.outputs.catalogue)")
    return lambda function: _register(BUILDERS, symbols, function, "builder of")


def builder_of(symbol: str) -> Callable:
    """The builder registered for the printed output ``symbol``.

    Raises
    ------
    LookupError
        When no module registered one (its module was not imported: :mod:`eomgen.dynamics`
        imports every module that builds an output).
    """
    try:
        return BUILDERS[symbol]
    except KeyError:
        raise LookupError(f"no builder registered for output {symbol!r} (is the module that "
                          "builds it imported by eomgen.dynamics?)") from None


def sizes(name: str) -> Callable[[Callable], Callable]:
    """Register the decorated ``function(model) -> int`` as the length of input ``name`` (one
    of :data:`~eomgen.outputs.INPUT_SIZES`)."""
    if name not in INPUT_SIZES:
        raise ValueError(f"input {name!r} is not in eomgen.outputs.INPUT_SIZES")
    return lambda function: _register(SIZES, (name,), function, "size of input")


def input_size(name: str, model) -> int:
    """The length of input ``name`` (:data:`~eomgen.outputs.INPUTS`) for ``model``: the
    number of joints unless the catalogue lists it in :data:`~eomgen.outputs.INPUT_SIZES`,
    then what its registered function says."""
    if name not in INPUTS:
        raise ValueError(f"unknown input {name!r}; choose from {tuple(INPUTS)}")
    if name not in INPUT_SIZES:
        return model.dof
    if name not in SIZES:
        raise LookupError(f"no size registered for input {name!r} (is the module that sizes "
                          "it imported?)")
    return SIZES[name](model)


def provides(*names: str) -> Callable[[Callable], Callable]:
    """Register the decorated ``function(dynamics) -> {NAME: (str, ...)}`` as the provider of
    the module constants ``names``, in that order (an output's
    :attr:`~eomgen.outputs.Output.constants`)."""
    return lambda function: _register(CONSTANTS, (tuple(names),), function, "provider of")


def constants_provider(names: tuple[str, ...]) -> Callable:
    """The function giving the module constants ``names`` (an output's
    :attr:`~eomgen.outputs.Output.constants`).

    Raises
    ------
    LookupError
        When no module registered one.
    """
    try:
        return CONSTANTS[tuple(names)]
    except KeyError:
        raise LookupError(f"no provider registered for the module constants {tuple(names)}") \
            from None


__all__ = ["BUILDERS", "SIZES", "CONSTANTS", "builds", "builder_of", "sizes", "input_size",
           "provides", "constants_provider"]
