"""The Sallen-Key plant of seed 001 (sections IV.3-IV.9, Figures 43-45): the
spec, the synthesis (m/n procedure and exact resistors for given capacitors),
the joint E-series selection, the analytic models, the lab bench (test
signal, slew/swing checks, tolerance band), the netlist, the design
orchestration (``design-plant``/``analyze-plant``) and the build sheet."""
