"""The op-amp PID controller of seed 001 (sections V.3-V.13, Figures 65-66):
tuning rules, sizing of the six op-amp blocks from E-series parts, the
realised controller's transfer function, a closed-loop ngspice deck and its
verification, and the ``design-pid`` build sheet.

Modules: :mod:`.spec` (the request, validated once), :mod:`.tuning`
(reaction-curve and FOPDT rules), :mod:`.blocks` (topology, formulas, static
checks), :mod:`.selection` (joint E-series part selection), :mod:`.model`
(realised controller and closed loop), :mod:`.optimize`
(gains within the op-amps' limits), :mod:`.netlist` (closed-loop deck),
:mod:`.verify` (SPICE run and failure detection), :mod:`.design`
(orchestration), :mod:`.result` (the typed result and its JSON),
:mod:`.report` (build sheet).
"""
