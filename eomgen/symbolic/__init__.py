"""Symbolic derivation: straight-line programs and the algorithms that build them."""
