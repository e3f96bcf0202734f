"""``python -m eomgen.cli``: the ``eomgen`` command (what the ``eomgen`` script runs)."""

from . import main

if __name__ == "__main__":
    main()
