"""The floor every layer stands on: files written atomically (output), progress lines, the
C compiler, short reprs, the one Jinja environment."""
