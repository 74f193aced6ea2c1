"""Active-filter sections as plug-ins: the :class:`Topology` abstraction (its
parts declared once, its transfer function vectorised, ideal and with the
op-amp's finite gain, its synthesis, realisability limits and netlist), the
registry of sections (Sallen-Key low- and high-pass, MFB low-, high- and
band-pass, first-order RC and inverting sections) and the :class:`Cascade` of
sections; filters from a specification (:func:`design`: scipy's prototypes,
the gain split, the op-amp check, E-series parts chosen jointly across the
stages, the ngspice proof). Below the wings: it imports ``core`` and ``spice`` only."""

from ..core.exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "inverting_highpass": ("InvertingHighPass",),
    "alternatives": ("Alternative", "alternatives_count", "design_alternatives",),
    "bench": ("BURST_CYCLES", "BUILDS", "C_TOL_PCT", "FilterBench", "R_TOL_PCT", "SEED", "StageCheck", "SweepPoint", "TableCompare",
              "TimeTest", "bench_of", "burst_tone", "nice_down", "nice_up", "passband_gain",),
    "cascade": ("Cascade", "Stage",),
    "deck": ("AC_POINTS_PER_DECADE", "ac_deck", "simulate_ac",),
    "design": ("FilterDesign", "StageDesign", "analysis_grid", "as_built", "central_delay", "delay_figures", "predistort", "section_name", "with_choice",
               "section_plans", "stage_candidates", "verify_spice",),
    "inverting_lowpass": ("InvertingLowPass",),
    "joint": ("brute_force", "delay_columns", "descend", "joint_alternatives", "joint_search", "objective", "per_stage",),
    "mfb_bandpass": ("MfbBandPass",),
    "mfb_highpass": ("MfbHighPass",),
    "mfb_lowpass": ("MfbLowPass",),
    "prototype": ("BANDPASS_METHODS", "BESSEL_NORMS", "CHEBYSHEV_CUTOFFS", "FAMILIES", "MAX_ORDER", "BESSEL_SEARCH_ORDER",
                  "RESPONSE_TYPES", "SectionPlan", "WIDE_RATIO", "DELAY_POINTS", "bandpass_from_mask", "bandpass_method", "chebyshev_3db_factor", "delay_error_pct", "group_delay",
                  "order_from_mask", "plan_bandpass", "plan_sections", "prototype_zpk", "reference_ba",
                  "reference_bandpass", "reference_response",),
    "rc_highpass": ("RcHighPass",),
    "rc_lowpass": ("RcLowPass",),
    "registry": ("REGISTRY", "get", "names", "register",),
    "report": ("FilterSheet", "SHEET_FILES", "alternative_words", "alternatives_json", "bom", "build_board", "draw_cascade", "net_label", "plots",
               "schematic", "sections", "sheet_of", "title_of", "write_folder", "write_outputs",),
    "sallen_key": ("GAIN_PARTS", "SallenKeySection",),
    "sallen_key_highpass": ("SallenKeyHighPass",),
    "sallen_key_lowpass": ("SallenKeyLowPass", "sallen_key_ratio_min",),
    "sallen_key_lowpass_figures": ("sample_figures",),
    "sallen_key_lowpass_parts": ("FIELD_OF", "KEY_OF", "REF_OF", "gain_of", "gain_refs", "json_values", "network",
                                 "part_values", "parts_of", "ratio_pair", "record_of", "refs", "section_of",),
    "sallen_key_lowpass_search": ("Candidate", "around", "scored"),
    "sallen_key_lowpass_synthesis": ("DEFAULT_R3_OHM", "GAIN_TOLERANCE", "JSON_KEYS", "NETWORK_KEYS", "SallenKeyParts", "check_parts",
                                     "coefficients", "exact_on_capacitors", "fn_zeta", "opamp_denominator", "ratios_from_rc", "realizability_notes",
                                     "pair_of", "resistors_for_caps", "seed_ratios", "wn_zeta",),
    "spec": ("FilterSpec", "TOPOLOGY_CHOICES",),
    "tables": ("TableRow", "coefficient_table", "section_3db_ratio", "table_corner",),
    "topology": ("DEFAULT_IMPEDANCE_OHM", "Figures", "KINDS", "PartSpec", "RC_MATCH", "SectionTarget", "Topology",
                 "nodal_response", "nodal_system", "open_loop_gain", "polynomial", "polyval", "quadratic_root"),
    "verify": ("BenchSignal", "NRMS_PASS", "PROOF_POINTS_PER_DECADE", "Proof", "StageDrive", "TRAN_POINTS",
               "analytic_tran", "band_edge_db", "bench_signal", "mask_edges", "opamp_aware_polys", "phase_delay_error_pct",
               "proof_deck", "prove",
               "stage_drive", "stage_polys",),
})

