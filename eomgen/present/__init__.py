"""Presentation for people: how eomgen writes a derivation for a reader, apart from code
generation.

* :mod:`~eomgen.present.printer`: SymPy's LaTeX printer in textbook notation (``q_{1}``,
  ``s_{1}``, ``c_{12}``, shortest round-trip floats), the escaping of user text, the breaking
  of long sums into display lines;
* :mod:`~eomgen.present.readability`: regrouping that makes small derivations read like a
  textbook (terms by body mass, by trigonometric factor, named Christoffel factors);
* :mod:`~eomgen.present.grouping`: that regrouping applied to the M, C and g of a textbook
  derivation, as every document prints them;
* :mod:`~eomgen.present.notation`: the document options and the teaching-sized bounds
  (:class:`~eomgen.present.notation.LatexConfig`, ``textbook_for``), the printer of one
  derivation and the layout of equations;
* :mod:`~eomgen.present.sections`: the sections of the derivation document (description,
  textbook steps, program of named subexpressions, regressor) as printed LaTeX.

Used alike by the LaTeX backend (:mod:`eomgen.codegen.backends.latex_backend`), the handout
(:mod:`eomgen.teach`), the notebook (:mod:`eomgen.teach.notebook`) and the Jupyter display
(:mod:`eomgen.present.display`). Nothing here imports :mod:`eomgen.codegen`; this package's own
``__init__`` imports nothing, so that the display can import what it prints with lazily.
"""
