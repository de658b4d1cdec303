"""Default parameters and presets (YAML), read by the pipeline."""
