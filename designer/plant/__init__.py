"""The Sallen-Key plant of seed 001 (sections IV.3-IV.9, Figures 43-45): the
spec (validated once), the synthesis (m/n procedure and exact resistors for
given capacitors, the unity-gain capacitor-ratio rule), the joint E-series
selection, the analytic models, the lab bench (test signal, slew/swing checks,
tolerance band), the netlist, the design orchestration
(``design-plant``/``analyze-plant``), its typed result and the build sheet."""
