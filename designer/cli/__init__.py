"""Command-line layers: thin, one module per wing, common options and the one-line error contract in :mod:`.common`."""

import os

from ..core.exports import lazy_exports

# Every command's work is small-matrix numerics: one BLAS thread, set here, before any command module
# loads numpy (several threads on tiny matrices only contend, with each other and with ngspice).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")


#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "check": ("check_design_main", "check_parser",),
    "common": ("ExtendList", "FLAGS", "OneLineParser", "StoreOnce", "flag_message", "run_cli",),
    "filter": ("analyze_filter_main", "design_filter_main", "summary_text",),
    "filter_tolerance": ("OPTIMIZE_DEFAULT_BUILDS", "add_filter_tolerance", "run_tolerance", "tolerance_json",
                         "tolerance_lines", "tolerance_settings",),
    "identify": ("CAPTURE_DESTS", "FORMATS", "build_freq_parser", "capture_params", "capture_spec",
                 "identify_freq_main", "identify_main", "identify_run", "identify_spec_of",),
    "launch": ("analyze_pid", "analyze_plant", "check_design", "design_filter", "design_pid", "design_plant",
               "draws", "identify_freq", "make_prbs", "simulate_capture",),
    "pid": ("analyze_pid_main", "analyze_pid_parser", "design_pid_main", "pid_parser", "plant_capture_model",),
    "plant": ("analyze_plant_main", "analyze_plant_parser", "design_plant_main", "design_plant_parser",),
    "prbs": ("make_prbs_main",),
})
