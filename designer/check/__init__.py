"""``check-design``: SPICE regression checks of users' own designs, for CI.

A spec file (YAML, :mod:`.spec`; read with budgets by :mod:`.yamldoc` and
:mod:`.yamlread`, its sections by :mod:`.sections`) names a design (a plant, a
PID controller in its loop, or the user's own ngspice deck), its corners
(op-amps) and what must hold: figure limits (:mod:`.limits`, :mod:`.figures`), the design's own
checks, SPICE's agreement with the model, the tolerance band, golden
waveforms (:mod:`.golden`). :mod:`.run` runs and judges one corner,
:mod:`designer.core.workers` runs corners in worker processes with deadlines, and the results
(:mod:`.result`) are rendered as JUnit XML (:mod:`.junit`) and a Markdown
summary (:mod:`.summary`). The command is :mod:`designer.cli.check`.
"""
