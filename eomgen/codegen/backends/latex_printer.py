"""Deprecated: moved to :mod:`eomgen.present.printer` (LaTeX printing for people is
presentation, not code generation). This module re-exports its public names so that old imports
keep working; import from :mod:`eomgen.present.printer` instead.
"""

from ...present.printer import (  # noqa: F401  (deprecated re-exports)
    COMPUTED_DIGITS, GREEK, POSITIONAL_EXPONENTS, TEXT_ESCAPES, DerivationLatexPrinter,
    display_width, float_parts, float_text, index_latex, latex_comment, latex_escape, pack,
    symbol_latex, written_number,
)
