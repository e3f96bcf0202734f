"""LaTeX printing for the derivation documents: SymPy's LaTeX printer in textbook notation, the
escaping of user text, and the breaking of long sums into display lines.

Notation (all choices are made here, by overriding ``_print_<Class>`` methods; printed text is
never patched afterwards):

* joint variables ``q1, qd1, qdd1`` → ``q_{1}, \\dot{q}_{1}, \\ddot{q}_{1}``;
* compact trigonometry: ``sin(q1)`` → ``s_{1}``, ``cos(q1 + q2)`` → ``c_{12}`` (for a sum of
  joint positions with unit coefficients; indices are separated by commas when one has two
  digits: ``c_{1,10}``); other arguments print as ``\\sin(…)``;
* other names (parameters, named subexpressions) by :func:`symbol_latex`: letters then digits as
  subscript (``m1`` → ``m_{1}``, ``lc1`` → ``l_{c1}``, ``Gamma1_2_3`` → ``\\Gamma_{1,2,3}``);
  anything else as escaped upright text, so every name prints to a distinct LaTeX string;
* floats as the shortest decimal that reads back as the same double (:func:`float_parts`:
  ``0.3``, ``0.3333333333333333``, ``3.2 \\cdot 10^{-5}``; Python's ``repr``), or rounded to a
  number of significant digits when asked (``float_digits``); a factor ±1.0 prints as nothing
  and a minus sign; SymPy Rationals stay fractions (``\\frac{1}{3}``).
"""

from __future__ import annotations

import math
import re
from decimal import Decimal
from fractions import Fraction
from typing import Iterable, Sequence

import sympy as sp
from sympy.printing.latex import LatexPrinter

from ..errors import one_line

#: Characters that mean something to TeX in text mode, and what prints them literally. ``[``,
#: ``]`` and ``*`` are braced so that a name cannot become the optional argument of a ``\\\\``
#: before it (``\\\\[…]``, ``\\\\*``) in a table.
TEXT_ESCAPES = {
    "\\": r"\textbackslash{}",
    "{": r"\{",
    "}": r"\}",
    "$": r"{\char36}",  # not \$: that is the TS1 dollar, a bitmap font without cm-super
    "&": r"\&",
    "#": r"\#",
    "%": r"\%",
    "_": r"\_",
    "~": r"\textasciitilde{}",
    "^": r"\textasciicircum{}",
    "<": r"\textless{}",
    ">": r"\textgreater{}",
    "|": r"\textbar{}",
    "[": "{[}",
    "]": "{]}",
    "*": "{*}",
}

GREEK = frozenset(
    "alpha beta gamma delta epsilon zeta eta theta iota kappa lambda mu nu xi pi rho sigma tau "
    "upsilon phi chi psi omega Gamma Delta Theta Lambda Xi Pi Sigma Upsilon Phi Psi Omega".split()
)

# A name is letters, then optionally digit groups separated by single underscores, then
# optionally trailing underscores (how eomgen's program builder makes a name unique).
_NAME = re.compile(r"^(?P<letters>[A-Za-z]+)(?P<index>[0-9]+(?:_[0-9]+)*)?(?P<primes>_*)$")


def latex_escape(text: str) -> str:
    """``text`` as LaTeX text that prints it literally and cannot run any TeX command.

    Non-printable characters become visible escapes (``\\n``), non-ASCII characters their code
    point (``[U+00E9]``), so the document compiles with plain pdflatex whatever the input.

    >>> print(latex_escape(r"\\input{/etc/passwd} 100% a_b #1"))
    \\textbackslash{}input\\{/etc/passwd\\} 100\\% a\\_b \\#1
    """
    out = []
    for char in one_line(str(text)):
        if char in TEXT_ESCAPES:
            out.append(TEXT_ESCAPES[char])
        elif " " <= char <= "~":
            out.append(char)
        else:
            out.append(f"{{[}}U+{ord(char):04X}{{]}}")
    return "".join(out)


def latex_comment(text: str) -> str:
    """A one-line LaTeX comment holding ``text`` (escaped: no line break can end it early)."""
    return "% " + latex_escape(text)


def index_latex(indices: Sequence[int]) -> str:
    """Subscript of several one-based indices: ``12`` when all are single digits, else
    ``1,10``."""
    return ("" if all(i < 10 for i in indices) else ",").join(str(i) for i in indices)


def symbol_latex(name: str) -> str:
    """The LaTeX of a symbol name (distinct names give distinct LaTeX).

    * ``g`` → ``g``; ``theta`` → ``\\theta``; ``mass`` → ``\\mathrm{mass}``;
    * letters and digits: one letter or a Greek name is the base and the digits its subscript,
      two letters put the second into the subscript: ``m1`` → ``m_{1}``, ``lc1`` → ``l_{c1}``,
      ``alpha2`` → ``\\alpha_{2}``, longer words are upright (``link1`` → ``\\mathrm{link}_{1}``);
    * digit groups separated by ``_`` are comma-separated indices: ``Gamma1_2_3`` →
      ``\\Gamma_{1,2,3}``;
    * trailing underscores become primes: ``s1_`` → ``s_{1}'``;
    * anything else is escaped upright text: ``m_link`` → ``\\textrm{m\\_link}``.

    >>> [symbol_latex(n) for n in ("lc1", "I1", "Gamma1_2_3", "R2_00", "s1_", "m_link")]
    ['l_{c1}', 'I_{1}', '\\\\Gamma_{1,2,3}', 'R_{2,00}', "s_{1}'", '\\\\textrm{m\\\\_link}']
    """
    match = _NAME.match(name)
    if match is None:
        return r"\textrm{" + latex_escape(name) + "}"
    letters, index, primes = match["letters"], match["index"], match["primes"]
    subscript = ",".join(index.split("_")) if index else ""
    if letters in GREEK:
        base = "\\" + letters
    elif len(letters) == 1:
        base = letters
    elif len(letters) == 2 and index:
        base, subscript = letters[0], letters[1] + subscript
    else:
        base = r"\mathrm{" + letters + "}"
    tex = f"{base}_{{{subscript}}}" if subscript else base
    return tex + "'" * len(primes)


#: Significant digits of floats computed from the description's (see ``written_floats`` of
#: :class:`DerivationLatexPrinter`): the last one or two of 17 are rounding noise.
COMPUTED_DIGITS = 15

#: Floats print positionally when their decimal exponent k (``d.ddd × 10^k``) is in this range,
#: else in scientific notation: ``0.0001``, ``123456``, ``1.5 \\cdot 10^{-5}``, ``10^{6}``.
POSITIONAL_EXPONENTS = range(-4, 6)


def float_parts(value: float, digits: int | None = None) -> tuple[str, str, int]:
    """The sign (``""`` or ``"-"``), significant digits (no trailing zeros) and decimal
    exponent ``k`` of ``value = ±d.ddd × 10^k``: the shortest decimal that reads back as the
    same double (as :func:`repr`), or ``value`` rounded to ``digits`` significant digits.

    >>> float_parts(0.1 + 0.2), float_parts(0.3), float_parts(-2.5e-7), float_parts(1/3, 6)
    (('', '30000000000000004', -1), ('', '3', -1), ('-', '25', -7), ('', '333333', -1))
    """
    text = repr(float(value)) if digits is None else f"{float(value):.{digits}g}"
    number = Decimal(text)
    if number == 0:
        return "", "0", 0
    sign, digit_tuple, exponent = number.normalize().as_tuple()
    significant = "".join(map(str, digit_tuple))
    return ("-" if sign else ""), significant, exponent + len(significant) - 1


def float_text(value: float, digits: int | None = None, times: str = r" \cdot ") -> str:
    """``value`` as LaTeX: the digits of :func:`float_parts`, positional for decimal exponents
    in :data:`POSITIONAL_EXPONENTS`, else ``mantissa \\cdot 10^{k}`` (``times`` joins them).
    Whole numbers print without a decimal point (``2``, not ``2.0``).

    >>> [float_text(x) for x in (0.3, 2.0, 1 / 3, -1.5e-5, 1e6, 6.02214076e23)]
    ['0.3', '2', '0.3333333333333333', '-1.5 \\\\cdot 10^{-5}', '10^{6}', '6.02214076 \\\\cdot 10^{23}']
    """
    sign, significant, k = float_parts(value, digits)
    if k in POSITIONAL_EXPONENTS:
        if k < 0:
            return sign + "0." + "0" * (-k - 1) + significant
        whole, fraction = significant[:k + 1].ljust(k + 1, "0"), significant[k + 1:]
        return sign + whole + ("." + fraction if fraction else "")
    mantissa = significant[0] + ("." + significant[1:] if len(significant) > 1 else "")
    power = f"10^{{{k}}}"
    return sign + (power if mantissa == "1" else mantissa + times + power)


def written_number(value: float, max_denominator: int = 1000) -> sp.Expr:
    """A description's number for display: the fraction ``n/d`` (``d`` at most
    ``max_denominator``) that reads back as the same double when the shortest decimal is long
    (``1/12`` written in a description is the double 0.08333333333333333: ``\\frac{1}{12}``),
    else the Float (``0.3``, ``0.4318``).

    >>> written_number(1 / 12), written_number(2.0), written_number(0.3).is_Float
    (1/12, 2, True)
    """
    value = float(value)
    if value.is_integer() and abs(value) < 2 ** 53:
        return sp.Integer(int(value))
    if math.isfinite(value) and len(float_parts(value)[1]) > 6:
        fraction = Fraction(value).limit_denominator(max_denominator)
        if fraction.numerator / fraction.denominator == value:
            return sp.Rational(fraction.numerator, fraction.denominator)
    return sp.Float(value)


def display_width(tex: str) -> int:
    """A rough count of the glyphs ``tex`` prints (commands count one, braces and sub/superscript
    markers none): what line breaking compares with the line width."""
    width = 0
    k = 0
    while k < len(tex):
        char = tex[k]
        if char == "\\":
            k += 1
            while k < len(tex) and tex[k].isalpha():
                k += 1
            width += 1
            continue
        if char not in "{}_^ ":
            width += 1
        k += 1
    return width



def _is_zero_term(term) -> bool:
    """Whether a term of a printed sum is zero as written: the number 0 (or 0.0), or a product
    built unevaluated with such a factor. Structural only: no simplification, no assumptions."""
    if isinstance(term, sp.UnevaluatedExpr):
        return _is_zero_term(term.args[0])
    if getattr(term, "is_Number", False):
        return term == 0
    if getattr(term, "is_Mul", False):
        return any(_is_zero_term(factor) for factor in term.args)
    return term == 0

class DerivationLatexPrinter(LatexPrinter):
    """SymPy's :class:`~sympy.printing.latex.LatexPrinter` in the notation of the derivation
    documents (see the module docstring).

    Settings (besides LatexPrinter's)
    ---------------------------------
    joint_positions:
        The symbols ``q1…qn``; ``sin``/``cos`` of sums of them print compactly.
    compact_trig:
        ``s_{1}``, ``c_{12}`` for the sines and cosines of joint positions (default True).
    float_digits:
        None (default): floats print as the shortest decimal that reads back as the same double
        (:func:`float_text`); an integer rounds them to that many significant digits.
    written_floats:
        None (default), or the floats the description wrote: these print in full, and every
        other float (computed from them, its last bits rounding noise: ``0.26917800000000003``)
        is rounded to :data:`COMPUTED_DIGITS` significant digits (``0.269178``).
    symbol_names:
        LatexPrinter's own setting: explicit LaTeX for some symbols (joint symbols, names that
        would collide with the document's notation); all others go through :func:`symbol_latex`.
    """

    _default_settings = {
        **LatexPrinter._default_settings,
        "joint_positions": (),
        "compact_trig": True,
        "float_digits": None,
        "written_floats": None,
    }

    def __init__(self, settings=None):
        super().__init__(settings)
        self._joint_index = {q: k + 1 for k, q in enumerate(self._settings["joint_positions"])}

    # -- names ---------------------------------------------------------------------------------
    def _print_Symbol(self, expr, style="plain"):
        name = self._settings["symbol_names"].get(expr)
        return name if name is not None else symbol_latex(expr.name)

    # -- compact trigonometry ------------------------------------------------------------------
    def _joint_sum(self, arg) -> list[int] | None:
        """The joint indices when ``arg`` is ``q_a + q_b + …`` (unit coefficients), else None."""
        if arg in self._joint_index:
            return [self._joint_index[arg]]
        if arg.is_Add and all(term in self._joint_index for term in arg.args):
            return sorted(self._joint_index[term] for term in arg.args)
        return None

    def _compact(self, letter: str, expr, exp):
        indices = self._joint_sum(expr.args[0]) if self._settings["compact_trig"] else None
        if indices is None:  # as LatexPrinter prints functions LaTeX knows
            head = "\\" + expr.func.__name__
            head = head if exp is None else f"{head}^{{{exp}}}"
            return head + r"{\left(" + self._print(expr.args[0]) + r" \right)}"
        tex = f"{letter}_{{{index_latex(indices)}}}"
        return tex if exp is None else f"{tex}^{{{exp}}}"

    def _print_sin(self, expr, exp=None):
        return self._compact("s", expr, exp)

    def _print_cos(self, expr, exp=None):
        return self._compact("c", expr, exp)

    # -- numbers -------------------------------------------------------------------------------
    def _print_Mul(self, expr):
        """As LatexPrinter, without a coefficient of exactly ±1.0 (a float from a rotation
        matrix): ``\\cos(q_1 - q_2)``, not ``1 \\cos(q_1 - q_2)``."""
        coefficient, rest = expr.as_coeff_Mul()
        if coefficient.is_Float and abs(float(coefficient)) == 1.0 and rest != 1:
            return self._print(rest if coefficient > 0 else sp.Mul(-1, rest))
        return super()._print_Mul(expr)

    def _print_Float(self, expr):
        if not math.isfinite(float(expr)):
            return super()._print_Float(expr)
        value = float(expr)
        digits = self._settings["float_digits"]
        written = self._settings["written_floats"]
        if digits is None and written is not None and value not in written:
            digits = COMPUTED_DIGITS
        return float_text(value, digits)

    # -- line breaking -------------------------------------------------------------------------
    def print_lines(self, expr, width: int) -> list[str]:
        """``expr`` printed as display lines of at most about ``width`` glyphs: sums break
        between terms, and a long product with a sum factor as ``a \\bigl( … \\bigr)``."""
        return pack(self._tokens(sp.sympify(expr), width), width)

    def print_sum_lines(self, terms: Iterable, width: int) -> list[str]:
        """The sum of ``terms``, in the given order (not SymPy's), as display lines. Zero terms
        are left out (``M_{3,3} \\ddot{q}_{3} + g_{3}``, never ``… + 0 + g_{3}``); a sum of
        none, or of zeros only, prints as ``0``."""
        kept = [term for term in terms if not _is_zero_term(term)]
        return pack(self._sum_tokens(kept, width), width) if kept else ["0"]

    def _sum_tokens(self, terms: list, width: int) -> list[str]:
        tokens: list[str] = []
        for index, term in enumerate(terms):
            if term.is_Add:  # a sum within the sum: in parentheses, or flattened when broken
                part = self._tokens(term, width)
                if len(part) == 1:
                    part = [r"\left(" + part[0] + r"\right)"]
                sign = "" if part[0].startswith("- ") or not index else "+ "
            else:
                negative = term.could_extract_minus_sign()
                part = self._tokens(-term if negative else term, width)
                sign = "- " if negative else ("+ " if index else "")
            tokens += [sign + part[0]] + part[1:]
        return tokens

    def _tokens(self, expr, width: int) -> list[str]:
        """Pieces of the printed ``expr`` between which a line may break."""
        tex = self._print(expr)
        if display_width(tex) <= width:
            return [tex]
        if expr.is_Add:
            return self._sum_tokens(self._as_ordered_terms(expr, order=None), width)
        if expr.is_Mul:
            sums = [factor for factor in expr.args if factor.is_Add]
            if sums:
                inner = max(sums, key=lambda factor: len(factor.args))
                rest = sp.Mul(*[f for f in expr.args if f is not inner])
                prefix = {1: "", -1: "-"}.get(rest, None)
                if prefix is None:
                    prefix = self._print(rest) + " "
                part = self._tokens(inner, width - display_width(prefix) - 1)
                if len(part) > 1:
                    return ([prefix + r"\bigl(" + part[0]] + part[1:-1]
                            + [part[-1] + r"\bigr)"])
        return [tex]


def pack(tokens: Sequence[str], width: int) -> list[str]:
    """Join ``tokens`` with spaces into as few lines of about ``width`` glyphs as they fit."""
    lines: list[str] = []
    current: list[str] = []
    used = 0
    for token in tokens:
        size = display_width(token)
        if current and used + size > width:
            lines.append(" ".join(current))
            current, used = [], 0
        current.append(token)
        used += size
    if current:
        lines.append(" ".join(current))
    return lines or ["0"]
