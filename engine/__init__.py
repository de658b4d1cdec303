"""Numerical kernels (numba): no file I/O, no YAML, no printing.

One module per algorithm; each exposes checked public wrappers around private
``_verb_noun`` kernels compiled with the flags of :mod:`fluidymation.engine._jit`.
"""
