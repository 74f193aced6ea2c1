"""The domain-free floor every wing stands on: errors, units, E-series,
op-amps, input ranges, files, LTI maths, waveforms, metrics, comparison,
checks and JSON."""
