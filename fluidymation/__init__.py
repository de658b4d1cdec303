"""Fluidymation: vector animations stylized with moving exemplars of artistic media.

The code lives in three layers, imported one way only:
``fluidymation.pipeline`` (scenes, CLI) → ``fluidymation.stages`` → ``fluidymation.engine``.
"""

__version__ = "0.1.0"
