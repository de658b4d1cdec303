"""Slow, obvious reference versions of engine kernels, for tests on tiny inputs."""
