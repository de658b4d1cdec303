"""Readers for vector animations: Lottie (.json/.lottie/.tgs), SVG (static, SMIL, sequences)."""
