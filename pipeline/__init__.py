"""Scene model and validation, stage runner, cache, executors and the CLI."""
