"""``check-design``: SPICE regression checks of users' own designs, for CI.

A spec file (YAML, :mod:`.spec`; read with budgets by :mod:`.yamldoc` and
:mod:`.yamlread`, its sections by :mod:`.sections`) names a design (a plant, a
PID controller in its loop, or the user's own ngspice deck), its corners
(op-amps) and what must hold: figure limits (:mod:`.limits`, :mod:`.figures`), the design's own
checks, SPICE's agreement with the model, the tolerance band, golden
waveforms (:mod:`.golden`). :mod:`.run` runs and judges one corner,
:mod:`designer.core.workers` runs corners in worker processes with deadlines, and the results
(:mod:`.result`) are rendered as JUnit XML (:mod:`.junit`) and a Markdown
summary (:mod:`.summary`). :mod:`.batch` is a whole run, as the command
(:mod:`designer.cli.check`) and the web page's Check both call it.
"""

from ..core.exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "batch": ("CheckRun", "check_specs", "load_specs", "run_specs",),
    "figures": ("ALIASES", "BAND", "PID", "PLANT", "SECTION_BAND", "band_of", "circuit_band_of", "corner_band",
                "plant_figures",),
    "filter_kind": ("DELAY_FIGURES", "DELAY_KEYS", "FILTER_KEYS", "FilterCase", "MASK_FIGURES", "MASK_KEYS",
                    "SUB_FILTER", "corner_stages", "delay_limits", "filter_designs", "filter_figures", "mask_limits",
                    "model_grid", "run_filter", "spice_sweep",),
    "golden": ("RECORD_GOLDEN", "compare", "read_golden", "record_advice", "write_golden",),
    "junit": ("junit_xml", "visible",),
    "limits": ("Limit", "limit_from",),
    "result": ("Case", "CornerOutcome", "ERROR", "FAIL", "PASS", "SIM_ERROR", "SKIP", "SPEC_ERROR", "SpecOutcome",
               "exit_status", "headline",),
    "run": ("corner_task", "run_corner",),
    "sections": ("SUB",),
    "spec": ("TOP", "load_spec",),
    "summary": ("summary_markdown",),
    "yamldoc": ("MAX_SPEC_BYTES", "WIDER", "parse_yaml",),
    "yamlread": ("MAX_NODES",),
})
