"""The fast module's source cut into translation units that compile in parallel (issue 42).

The emitted ``<stem>_fast.c`` stays one file (a golden file, byte for byte what it was); only
its build cuts it. Each long kernel (at least :data:`UNIT_OPERATIONS` operations) goes into a
unit of its own, its one-state and lanes versions together, behind a short head that depends on
nothing but the runtime (so that its text, and the cached object compiled from it, stays the
same when the module gains or loses other outputs); the rest of the file, with each moved
definition replaced by a declaration, is the main unit (the Python interface, the composed
functions and the short kernels, which it may still inline). Moved kernels lose ``static`` and
get hidden visibility: the extension exports its init function only, as before.

The cut finds each kernel by its signature (:func:`kernel_signature`, which the template prints
too) and its end, the first line that is a lone ``}``: a kernel's body is indented. It is plain
text work on a file this package wrote; :func:`split_source` refuses (None) anything it does not
find exactly once, and the build then compiles the file as it is.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Kernels of at least this many operations are compiled as units of their own. Below it a
#: kernel compiles in a fraction of a second, and the main unit may inline it into the composed
#: functions (forward dynamics calls the mass matrix and bias kernels) as a single unit did.
UNIT_OPERATIONS = 1000

#: What makes a moved kernel visible to the other units and to no one else.
HIDDEN = '__attribute__((visibility("hidden")))'

#: The call runtime's lines that define ``eom_lanes`` (runtime/call.c), which a unit holding a
#: lanes kernel needs: from the first line to the ``#endif`` after it.
LANES_TYPE_START = "#if defined(__GNUC__)\n#define EOM_LANES "
LANES_TYPE_END = "#endif\n"


#: The runtime files whose texts :func:`split_source` puts at the head of the units.
UNIT_RUNTIME = ("fma_clones", "lanes_math", "lanes", "call")


def kernel_signature(name: str, lanes: bool = False) -> str:
    """The signature of kernel ``name``'s one-state (``<name>_one``) or lanes version, without
    ``static``: what the template prints and :func:`split_source` looks for."""
    if lanes:
        return (f"void {name}_lanes(const eom_lanes *const *x, const eom_lanes *p, "
                "eom_lanes *out)")
    return f"void {name}_one(const double *const *x, const double *p, double *out)"


@dataclass(frozen=True)
class Unit:
    """One translation unit: ``name`` (a file stem), its C text, and ``weight``, the
    operations it compiles (the order in which units are started: the longest first)."""

    name: str
    text: str
    weight: int


def _definition(source: str, signature: str) -> tuple[int, int, bool] | None:
    """Where ``static <signature>``'s definition lies in ``source``: (start, end, whether it is
    marked FMA_CLONES), start at its line's beginning, end after its closing ``}`` line; None
    unless found exactly once."""
    opening = f"static {signature}\n{{\n"
    if source.count(opening) != 1:
        return None
    start = source.index(opening)
    clone = source[max(0, start - len("FMA_CLONES ")):start] == "FMA_CLONES "
    if clone:
        start -= len("FMA_CLONES ")
    if start and source[start - 1] != "\n":
        return None
    end = source.find("\n}\n", start)
    return None if end < 0 else (start, end + 3, clone)


def _lanes_type(runtime_call: str) -> str | None:
    start = runtime_call.find(LANES_TYPE_START)
    end = runtime_call.find(LANES_TYPE_END, start)
    return None if start < 0 or end < 0 else runtime_call[start:end + len(LANES_TYPE_END)]


def split_source(source: str, module: str, kernels: list[tuple[str, int]], runtime: dict
                 ) -> list[Unit] | None:
    """``source`` (a fast module's C text) as translation units: the main unit first (named
    ``module``), then one per kernel of ``kernels`` (``(name, operations)``) with at least
    :data:`UNIT_OPERATIONS` operations, named ``<module>__<kernel>``. ``runtime`` maps the names
    of :data:`UNIT_RUNTIME` to the runtime's texts the module holds.

    None when no kernel is long enough (one unit: compile ``source``) or when a kernel's
    definition, or the runtime text a unit needs, is not found exactly as expected."""
    cuts: list[tuple[int, int, str]] = []  # (start, end, declaration) in the main unit
    units: list[Unit] = []
    for name, operations in sorted(kernels, key=lambda k: -k[1]):
        if operations < UNIT_OPERATIONS:
            continue
        one = _definition(source, kernel_signature(name))
        if one is None:
            return None
        lanes = _definition(source, kernel_signature(name, lanes=True))
        head = ["/* A kernel of the fast module, compiled as a translation unit of its own (see "
                "eomgen.codegen.backends.fast_units). */",
                "#include <math.h>", "#include <string.h>"]
        if one[2] or (lanes and lanes[2]):
            head.append(runtime["fma_clones"])
        body = []
        for found, signature in ((lanes, kernel_signature(name, lanes=True)),
                                 (one, kernel_signature(name))):
            if found is None:
                continue
            start, end, clone = found
            text = source[start:end]
            definition = text[text.index(signature):]  # from the signature, without static
            body.append(f"{HIDDEN} {'FMA_CLONES ' if clone else ''}{definition}")
            cuts.append((start, end, f"{HIDDEN} {signature};\n"))
        if lanes is not None:
            lanes_type = _lanes_type(runtime["call"])
            if lanes_type is None:
                return None
            # the lanes version first, after the vector sin/cos and the macros that use them
            body[0] = ("#if EOM_LANES > 1\n" + runtime["lanes_math"] + "\n\n" + runtime["lanes"]
                       + "\n" + body[0] + "#undef sin\n#undef cos\n#undef sqrt\n#endif\n")
            head.append(lanes_type.rstrip("\n"))
        units.append(Unit(f"{module}__{name}", "\n".join(head) + "\n\n" + "\n".join(body),
                          operations * (2 if lanes else 1)))
    if not units:
        return None
    main, at = [], 0
    for start, end, declaration in sorted(cuts):
        main += [source[at:start], declaration]
        at = end
    main.append(source[at:])
    # the main unit's weight: its short kernels, and the Python interface as one long kernel
    rest = sum(operations for _, operations in kernels if operations < UNIT_OPERATIONS)
    return [Unit(module, "".join(main), rest + UNIT_OPERATIONS), *units]


__all__ = ["HIDDEN", "UNIT_OPERATIONS", "UNIT_RUNTIME", "Unit", "kernel_signature", "split_source"]
