"""Classical identification from step and frequency responses (seeds 000, 002, 003).

``io`` reads scope captures and Bode tables; ``preprocess`` turns a capture
into a normalised step, by stages: ``edges`` (the record checked, its steps
found), ``settle`` (baseline, final value), ``normalise`` (one step) and
``averaging`` (a square wave's steps); ``first_order``, the second-order
families ``underdamped``, ``overdamped`` and ``dc_motor`` (listed in
``second_order``) and ``refine`` (least squares) are the step methods on the
shared ``structures``, ``integrating`` the one for a response that ramps (an
integrating process's asymptote);
``step`` runs and ranks them, ``frequency`` does the same for a Bode table
(the model responses and classical readings of ``bode_readings``, the
least-squares fit of ``freqfit``, the loop margins of ``bode_margins``);
``correlation`` and ``spectral`` estimate the impulse and frequency
responses from a broadband input (a PRBS, :mod:`designer.core.prbs`, or
noise: seed 003, 2.4 and 3.2) and ``broadband`` recognises such an input and
runs both, with the step and frequency methods on their results;
``outputerror`` fits continuous-time models with dead time to any recorded
input by output error, and ``validation`` judges a model on data it was not
fitted to (fit percentage, residual tests, an ARX reference), ``ranking``
chooses the best of the models so scored (ties within the data's margin go to
fewer parameters), and ``recordview`` simulates the best models over the record they were scored on;
``against`` compares an identified plant with its design (the one use of the
plant wing) and ``report`` prints and plots the results; ``spec`` is a
request about one file (``IdentifySpec``) and ``identify_file``, what the
``identify`` command and every front end call. The waveform
readings they share (noise, crossings, derivative, tangent) are
:mod:`designer.core.waveform`.
"""

from ..core.exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "assess": ("Assessment", "Candidate", "ESTIMATION_FRACTION", "MAX_SAMPLES", "OE_INITIAL", "OE_KINDS", "ROUTES",
               "assess_result", "choose_hold", "choose_split", "identify_record", "judge_candidate",
               "match_validation", "method_process", "regular_interval"),
    "against": ("agreement_band", "compare_with_design", "load_design", "model_fn_zeta", "overshoot_from_zeta"),
    "bode_readings": ("asymptotes", "low_frequency_slope", "model_phase", "model_response", "peak_gain_db",
                      "resonant_peak", "zeta_from_peak"),
    "broadband": ("BroadbandResult", "between_levels", "check_method", "examine_input", "identify_broadband",
                  "looks_broadband", "multilevel_levels", "other_excitation", "other_input", "period_drift"),
    "correlation": ("DECAY", "circular_xcorr", "mls_impulse", "rms_error", "settling_check", "settling_time"),
    "dc_motor": ("dc_motor_position", "dc_motor_velocity"),
    "edges": ("check_samples", "find_edges", "number_text"),
    "first_order": ("FIRST_ORDER_METHODS", "METHOD_NAMES", "SUNDARESAN", "TABLE_II", "TABLE_III",
                    "exact_coefficients", "hagglund", "nishikawa", "two_point", "unit_time", "ziegler_nichols"),
    "freqfit": ("least_squares_fit",),
    "frequency": ("BAND_FACTOR", "FreqIdentifyResult", "MAX_FIT_ERROR", "corner_frequencies", "identify_freq"),
    "integrating": ("METHOD_NAME", "RAMP_TOLERANCE", "TAIL_FRACTION", "asymptote", "step_capture_ramp"),
    "io": ("BLOCK_LINES", "Capture", "CaptureInfo", "FORMATS", "FORMAT_NAMES", "FREQ_UNITS", "FileBlocks",
           "FreqData", "GAIN_UNITS", "HEAD_LINES", "INPUT_NAMES", "MAX_POINTS", "MIN_POINTS", "NUMBER",
           "OUTPUT_NAMES", "PARSED", "PHASE_UNITS", "TIME_NAMES", "check_format", "format_generic", "freq_data",
           "looks_like_step_input", "parse_capture_text", "parse_freq_table", "plain_columns", "read_capture",
           "read_freq_table", "text_lines", "unit_hint"),
    "outputerror": ("FIT_KINDS", "all_pass_pair", "HOLDS", "INITIALS", "OEFit", "OEResult", "Sampled", "fit_output_error",
                    "identify_output_error", "power_of_two", "sample_model", "simulate"),
    "overdamped": ("alfaro_123c_overdamped", "harriott", "jahanmiri_fallahi", "peeling", "stark_mollenkamp",
                   "two_pole"),
    "preprocess": ("check_window", "prepare_step"),
    "ranking": ("PARAMETERS", "Ranking", "loss_difference", "nw_lags", "parameter_count", "rank"),
    "refine": ("fit", "refine_all"),
    "recordview": ("ModelTrace", "RecordView", "record_view"),
    "report": ("bode_fit_plot", "broadband_plot", "broadband_text", "fit_plot", "freq_text", "ranked_candidates",
               "record_axes", "step_text"),
    "second_order": ("STEP_METHODS",),
    "settle": ("block_mean", "final_value"),
    "spec": ("FREQUENCY_TABLE", "IdentifySpec", "STEP_EDGE_ONLY", "STEP_ONLY", "frequency_table_header", "header_text",
             "identify_dict", "identify_file", "identify_spec"),
    "spectral": ("BANDS_PER_DECADE", "MAX_REL_ERROR", "MIN_COHERENCE", "log_bands", "periodic_response", "table_text",
                 "to_freq_data", "welch_response"),
    "step": ("IdentifyResult", "identify_step", "judge"),
    "structures": ("MODELS", "MethodResult", "iae_ise", "model_step"),
    "underdamped": ("chen", "extrema", "log_decrement", "normalized_step", "overshoot", "t4_t3", "t4_t3_ratio",
                    "t4_t3_table", "wn_from_peak_time", "zeta_from_overshoot", "zeta_from_t4_t3"),
    "validation": ("ARXModel", "Correlation", "DEFAULT_FRACTION", "RESID_LAGS", "Split", "Validation", "Z99",
                   "arx_fit", "block_means", "compare_fit", "cross_correlation", "split_record", "validate",
                   "whiteness"),
})
