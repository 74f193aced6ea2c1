"""The domain-free floor every wing stands on: errors, units, E-series,
op-amps, input ranges, files, LTI maths, waveforms, metrics, comparison,
checks and JSON."""

from .exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "checks": ("Check", "IDS", "SPICE_AGREEMENT"),
    "compare": ("AGREEMENT", "disagreements", "metric_deltas", "nrms", "resample", "trapezoid_weights"),
    "errors": ("DeckError", "DesignError", "EXIT_BAD_INPUT", "EXIT_CHECK_FAILED", "EXIT_OK", "EXIT_SIMULATOR",
               "ParamError", "SimulatorError"),
    "eseries": ("PartBounds", "SERIES", "TOLERANCE", "check_bounds", "nearest", "nearest_ratio_pair", "series_name",
                "smallest_series", "values"),
    "exports": ("lazy_exports",),
    "fileio": ("BLOCK_BYTES", "LimitedReader", "MAX_CAPTURE_BYTES", "MAX_CAPTURE_ROWS", "MAX_LINE_BYTES",
               "MAX_TABLE_BYTES", "MIB", "SNIFF_BYTES", "atomic_write", "check_can_create", "check_encoding",
               "check_output_file", "check_output_folder", "check_plain_name", "clean_stale", "decode", "ensure_dir",
               "link_into", "new_folder_beside", "open_limited", "os_error", "publish_folder", "read_text",
               "remove_tree", "show_cell", "shown", "size_text"),
    "i18n": ("DEFAULT", "LANGUAGES", "N_", "catalogue", "check_language", "current", "extract", "gettext", "language",
             "localise", "missing", "update_catalogue"),
    "jsonio": ("SCHEMA_VERSION", "json_safe", "read_result"),
    "lifetime": ("Interrupted", "WORDS", "die_with_parent", "finish", "forget", "install", "interruption", "native",
                 "on_exit", "owned_prefix", "preexec", "quiet", "remove_stale", "reset_in_child", "status_of",
                 "to_devnull", "words_of"),
    "lti": ("MAX_CLUSTER", "coefficients", "dense_time", "dominant_pair", "filter_foh", "freq_response",
            "pole_clusters", "response_span", "step_response"),
    "metrics": ("Overshoot", "StepMetrics", "measure_step", "step_metrics"),
    "opamps": ("OpAmp", "PACKAGE_KINDS", "Unit", "assign", "get", "names", "spare_units"),
    "prbs": ("BAND_FACTOR", "HALF_POWER", "LINES_IN_BAND", "MAX_BITS", "MIN_BITS", "PrbsPlan", "SETTLE_MARGIN",
             "awg_csv", "bits_for", "check_bits", "is_mls_length", "linear_complexity", "mls", "mls_bit_errors",
             "nice_interval", "plan_for_plant", "pwl_points", "pwl_subcircuit", "time_value_csv"),
    "process": ("ProcessModel",),
    "process_build": ("MAX_DEAD_TIME_RATIO", "fopdt", "integrating", "model_from_dict", "rational", "sopdt",
                      "underdamped"),
    "process_text": ("FORMS_TEXT", "parse_tf"),
    "ranges": ("RANGES", "Range", "help_range", "parse_in_range"),
    "stepfit": ("MODELS", "PARAMS", "data_overshoot", "fit_step", "model_overshoot_pct", "model_step",
                "overshoot_mismatch", "unphysical"),
    "units": ("figure_unit", "format_eng", "format_figure", "parse_value", "value_code"),
    "waveform": ("crossing_time", "inflection_tangent", "moving_average", "noise_sigma", "normalised_step",
                 "parabola_vertex", "peak_region", "quantum", "refine_peak", "savgol", "smooth_derivative",
                 "tangent_window"),
    "workers": ("Worker", "close_all", "run_tasks"),
})
