"""The Sallen-Key plant of seed 001 (sections IV.3-IV.9, Figures 43-45): the
spec (validated once), the synthesis (m/n procedure and exact resistors for
given capacitors, the unity-gain capacitor-ratio rule), the joint E-series
selection, the analytic models, the lab bench (test signal, slew/swing checks,
tolerance band), the netlist, the design orchestration
(``design-plant``/``analyze-plant``), its typed result and the build sheet."""

from ..core.exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "circuit_report": ("band_png", "bench_blocks", "bench_settings", "bom", "sections", "title_of"),
    "circuit_prbs": ("band_edge_hz", "section_plan", "with_section_prbs"),
    "circuit_design": ("CircuitAnalysisSpec", "CircuitPlantResult", "GBW_MARGIN", "SPICE_DB", "SPICE_DEG",
                       "analyze_circuit_plant", "analyze_circuit_spec", "built_name", "check_circuit_parts",
                       "check_opamp_reach",
                       "design_circuit_plant", "tolerance_nominal", "SQUARE_NRMS_PASS", "SquareRun", "square_deck",
                       "with_square_test", "default_square_hz", "with_bench", "section_analysis", "step_span"),
    "circuit": ("BAND_ERROR", "BELOW_BOUND", "DEFAULT_TOPOLOGY", "FIGURES", "OPAMP_PARAMETERS", "R_BAND", "candidate_set",
                "capacitor_combinations", "circuit_figures", "corner_frequencies", "dominant_pairs", "evaluate", "listed",
                "opamp_tf", "GBW_ROUNDS", "gbw_shift", "compensate_gbw", "plant_target", "rounded", "search",
                "step_of_pair"),
    "bench": ("PEAK_MIN_DB", "PERIOD_CHECK", "SIGNAL_CHECKS", "ScopeSetup", "channel", "corner_tolerances", "no_peak_reason",
              "period_extremes", "recommend_square_wave", "rising_step", "scope_setup", "signal_checks",
              "tolerance_band", "tolerance_corners"),
    "design": ("analyze_plant", "choose_parts", "design_plant"),
    "model": ("opamp_pair", "plant_model", "plant_tf", "plant_tf_opamp", "sensitivities"),
    "netlist": ("plant_ac_deck", "plant_deck", "plant_netlist", "plant_prbs_deck", "prbs_deck"),
    "prbs": ("MAX_INTERVALS", "PERIODS", "SAMPLES_PER_INTERVAL", "attach", "check_size", "model_response",
             "op_amp_checks", "plan_for_result", "plan_of", "prbs_run", "run_deck", "with_prbs"),
    "report": ("bode_png", "prbs_blocks", "prbs_png", "prbs_texts", "prbs_waveforms_csv", "sine_text", "step_png", "summary_text", "waveforms_csv", "write_outputs"),
    "result": ("PlantResult",),
    "sallenkey": ("DEFAULT_R3_OHM", "GAIN_TOLERANCE", "JSON_KEYS", "KEY_OF", "NETWORK_KEYS", "SallenKeyParts", "check_parts",
                  "coefficients", "fn_zeta", "json_values", "ratio_pair", "ratios_from_rc", "realizability_notes",
                  "resistors_for_caps", "section_of"),
    "schematic": ("draw_plant", "draw_supplies"),
    "selection": ("Candidate", "brute_force", "joint_search"),
    "sourcing": ("DEFAULT_SERIES", "MAX_ERROR", "NOTE_ERROR", "candidates", "part_series"),
    "spec": ("AnalysisSpec", "PlantSpec"),
})
