"""Stages: each turns named inputs into named outputs by calling engine kernels."""
