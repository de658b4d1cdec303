"""Fuzzing harness of the readers (scene YAML, Lottie JSON, SVG): mutated fixtures through the CLI,
in-process; every case must end in exit code 0 or 2 with a message naming the file (tests/fuzz/harness.py)."""
