"""The documentation site: docs/*.md (MyST Markdown) and the API reference from the docstrings,
built by Sphinx with the Furo theme. tests/docs builds it with warnings as errors:

    python3 -m pip install -e ".[docs]"
    python3 -m sphinx -W --keep-going -b html docs site

The pages are Markdown that reads the same on GitHub: ``$…$`` and ``$$…$$`` for mathematics
(MathML, made when the site is built: docs/_ext/mathml.py), GitHub's heading anchors, and the
table of contents as ``:::{toctree}`` blocks in index.md and api/index.md.
"""

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path[:0] = [str(DOCS.parent), str(DOCS / "_ext")]  # this checkout's eomgen; mathml.py

project = "eomgen"
html_title = "eomgen"
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon", "mathml"]
exclude_patterns = ["_ext", "_static"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"

# Markdown: $…$ and $$…$$ math; ::: fences for directives (toctree, autodoc), which GitHub shows
# as text and tests/docs does not take for code; anchors for headings down to ####, spelt as
# GitHub spells them, so that links work there and here alike.
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_dmath_double_inline = True
myst_heading_anchors = 4
html_math_renderer = "mathml"

# The API reference: NumPy-style docstrings whose cross-references (:func:, :class:) are links.
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "description"
autodoc_class_signature = "separated"
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
# A type in a docstring is prose ("(n,) array"), whose words Sphinx's Python domain tries to
# link: a word that names two attributes (n, nq) is not an ambiguous cross-reference to fix.
suppress_warnings = ["ref.python"]
default_role = "code"  # `name` in a docstring is code, as it would be in Markdown

html_theme = "furo"
html_static_path = ["_static"]
html_show_sourcelink = False
html_copy_source = False
