"""Plain-Python runtime shared by eomgen and the modules it generates.

Each module here is ordinary eomgen code *and* the text a generated module includes verbatim
(everything after its ``# --- included`` marker line), so that a rule such as when
``forward_dynamics`` warns about conditioning is written once: generated modules stay
standalone (they import nothing from eomgen), and eomgen's own solvers import the same code.
"""
