"""The op-amp PID controller of seed 001 (sections V.3-V.13, Figures 65-66):
tuning rules, sizing of the six op-amp blocks from E-series parts, the
realised controller's transfer function, a closed-loop ngspice deck and its
verification, and the ``design-pid`` build sheet.

Modules: :mod:`.spec` (the request, validated once), :mod:`.plant_spec` (where the
plant comes from, validated once), :mod:`.plant` (the plant resolved), :mod:`.tuning`
(the reaction curve and the FOPDT each of its rules takes), :mod:`.rules` (every
rule, on any model), :mod:`.blocks` (topology, formulas, static
checks), :mod:`.selection` (joint E-series part selection), :mod:`.model`
(realised controller and closed loop), :mod:`.sensitivity` (the loop's sensitivity peak Ms), :mod:`.optimize`
(gains within the op-amps' limits), :mod:`.netlist` (closed-loop deck),
:mod:`.verify` (SPICE run and failure detection), :mod:`.design`
(orchestration), :mod:`.result` (the typed result and its JSON),
:mod:`.report` (build sheet).
"""

from ..core.exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "plant": ("LoopNames", "PLANT_PREFIX", "Plant", "PlantCircuit", "circuit_from_cascade", "circuit_from_json", "circuit_plant",
              "parse_part_values", "part_items", "resolve_plant", "SEED_LOOP_NAMES",
              "pair_model", "sallen_key_circuit", "sallen_key_plant", "seed_loop_names"),
    "modelloop": ("FAR_FACTOR", "LEAK_LOOP_GAIN", "TABLE_STEP_FRACTION", "limits", "loop_figures", "size"),
    "loopchecks": ("MAX_STEADY_STATE_ERROR", "designators", "kick_note", "named", "spice_notes", "stage_checks",
                   "steady_state_check"),
    "blocks": ("PidParts", "THESIS_BENCH", "continuous_parts", "seed_bench_parts", "seed_parts", "static_checks"),
    "delayloop": ("MAX_STEPS", "STEP_BUDGET", "closed_loop_step", "parse_loop", "pid_tf", "step_figures"),
    "delaymargins": ("loop_margins", "loop_response"),
    "design": ("SEED_BENCH_PLANT", "analyse", "analyze_pid", "built_controller", "corner_frequencies", "ideal_pair",
               "design_model_pid", "design_pid", "edged", "ideal_crossover_hz", "leak_limit_hz", "loop_dc_gain",
               "plant_of", "response_grid", "run_spice", "simulation_controller", "stage_waves"),
    "model": ("SLEW_DELAY_FRACTION", "assemble", "controller_tf", "dc_gain", "ideal_loop", "inverting_stage",
              "loop_gain", "margins", "reference", "slew_delay", "waveform_limits"),
    "netlist": ("closed_loop_deck", "controller_netlist", "loop_netlist", "model_loop_deck", "plant_circuit",
                "plant_ref_prefix"),
    "optimize": ("Context", "KICK_POINTS", "ModelOptimizeResult", "SEARCH_POINTS", "SEARCH_STEP_FRACTION", "evaluate",
                 "optimize_model_loop", "slew_delay_stages"),
    "plant_spec": ("PLANT_FIELDS", "PlantSource", "filter_plant_from_json", "plant_from_json", "voltage_range"),
    "plant_source": ("model_from_json", "model_from_result", "result_kind", "sallen_key_model"),
    "reduction": ("ModelFopdt", "ModelIntegrating", "ModelSopdt", "ModelTf", "from_process", "half_rule",
                  "model_step", "model_tangent"),
    "report": ("MODEL_PLOTS", "PLOTS", "bom", "build_board", "draw_early", "plots", "plots_of", "sections", "summary_text",
               "title_of", "write_outputs"),
    "result": ("Achieved", "AnalyticLoop", "LoopFigures", "PidResult", "RobustCheck", "RuleRow", "Waveforms"),
    "rules": ("GIVEN", "HALF_RULE", "REACTION_CURVE_RULES", "RuleTuning", "TANGENT", "TANGENT_T63", "applicable",
              "parallel_to_series", "series_to_parallel", "tune_model"),
    "schematic": ("PLANT_BLOCK", "draw_loop", "draw_model_loop"),
    "sensitivity": ("sensitivity_peak",),
    "selection": ("R_CORNER_MAX", "brute_force", "objective", "select_parts"),
    "spec": ("CONTROLLER_FIELDS", "PLAIN_PARAMS", "PidSpec", "analyzed_name", "controller_as_built",
             "controller_from_json", "default_name", "pid_spec"),
    "tuning": ("Fopdt", "RULE_MODEL", "model_reaction_curve", "reaction_curve", "tune"),
    "verify": ("loop_metrics", "oscillation", "stages"),
})
