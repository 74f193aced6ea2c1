"""Tolerance analysis (issue 17): what fraction of real builds meets a spec.

A design's parts vary within their tolerances (:mod:`.parts`); samples of
them are drawn reproducibly, sample i a function of (seed, i) alone
(:mod:`.sampling`); an engine computes every figure of every sample at once
(:mod:`.plant`: the Sallen-Key plant, analytic, vectorised over the samples, through the generic chunk function);
:mod:`.stats` turns the figures into statistics, a yield with its Wilson
interval, variance shares and the part to buy tighter. Imports go
front ends -> check -> tolerance -> wings.
"""

from ..core.exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "mcspec": ("MonteCarloSpec", "loop_tolerance", "plant_tolerance", "section_tolerance"),
    "chunks": ("lost_twice", "run_chunk",),
    "cluster": ("CONNECT_TIMEOUT", "ClusterStart", "DaskPool", "WORKERS", "cluster_ahead", "parse_dask", "probe",),
    "filter": ("BANDPASS_FIGURES", "FilterContext", "FilterMonteCarlo", "LOWHIGH_FIGURES",
               "YieldOptimum", "figures_of", "filter_monte_carlo", "filter_spec_yield", "filter_worst_case", "mask_limits", "nominal_parts",
               "optimize_yield", "series_of", "spice_context", "stage_responses",),
    "loop": ("LIMITABLE", "LoopContext", "STEP_POINTS", "kick_grid", "loop_figures", "loop_monte_carlo",
             "loop_parts", "loop_series", "loop_worst_case", "parse_loop_limit",),
    "montecarlo": ("MAX_SAMPLES", "MAX_TARGET_CI", "MIN_SAMPLES", "MonteCarlo", "NO_SLEW", "NO_SLEW_SECTION", "TARGET_ROUND",
                   "apply_engine", "check_section_spread", "check_target_ci", "parse_target_ci", "plant_monte_carlo", "plant_parts",
                   "plant_worst_case",),
    "parts": ("DISTRIBUTIONS", "MAX_TOL", "check_items", "opamp_nominal", "parse_tolerance", "resolve",),
    "plant": ("plant_figures",),
    "runner": ("CHUNKS_PER_WORKER", "Draw", "MAX_JOBS", "MIN_CHUNK", "Runner", "SPICE_MIN_CHUNK", "SPICE_WORK",
               "Scale", "parse_jobs",),
    "sampling": ("CHUNK", "SAMPLERS", "deviations", "unit_samples", "values",),
    "spice_ac": ("AcContext", "POINTS_PER_DECADE", "SPAN", "fit", "section_chunk", "section_evaluate",),
    "spice_engine": ("batched", "commands", "measures", "parse", "step_sections",),
    "spice_loop_mc": ("loop_monte_carlo_engine",),
    "spice_mc": ("drawn_values", "plant_context", "plant_monte_carlo_engine", "replay_parts", "replay_values", "run_engine",
                 "section_analysis", "section_context", "section_engine", "section_monte_carlo_engine",
                 "section_step_chunk", "section_step_context", "spice_samples",
                 "step_settings",),
    "stats": ("Limit", "Z95", "figure_stats", "variance_shares", "wilson",),
    "worstcase": ("WorstCase", "worst_case",),
    "yields": ("ENGINES", "FILTER", "LOOP", "PLANT", "SECTION", "SECTION_SPICE", "TABLES", "counted", "figure_table",
               "spec_yield",),
})
