"""``python -m fluidymation`` runs the command-line interface."""

import sys

from fluidymation.pipeline.cli import main

sys.exit(main())
