"""``python -m eomgen.reduction``: the subprocess of :func:`eomgen.reduction.measure_derivation`
(reads a pickled model and outputs on stdin, writes the cost as JSON on stdout)."""

from .cost import measure_main

measure_main()
