"""The simulator side: the model library, deck building blocks, and the simulator backends."""

from ..core.exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "behavioural": ("FORMS", "HINT_WH", "max_step_hint_s", "normalise", "plant_lines", "poles"),
    "deck": ("SINE_POINTS_PER_DECADE", "Amp", "Board", "GROUND", "MAX_SIM_POINTS", "Netlist", "Part", "STEPS_PER_TIME_SCALE",
             "SquareTest", "bench_circuit",
             "ac_lines", "add_supplies", "board", "finish_deck", "measure_lines", "opamp_library_text",
             "settle_error_source"),
    "model_step": ("DURATION_SETTLING_TIMES", "MAX_POINTS", "MIN_CODES", "default_duration_s", "default_step_time_s",
                   "simulate_step", "step_deck"),
    "simulate": ("DEFAULT_TIMEOUT_S", "NgspiceCli", "PySpiceShared", "error_lines", "get_simulator", "measure_names",
                 "ngspice_version", "private_env", "read_raw", "recorded_command", "tool_info", "with_raw_output"),
    "trust": ("MAX_TOTAL_BYTES", "check_deck_text", "expand_deck"),
})
