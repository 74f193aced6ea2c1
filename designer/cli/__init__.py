"""Command-line layers: thin, one module per wing, common options and the one-line error contract in :mod:`.common`."""
