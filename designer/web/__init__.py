

from ..core.exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "forms": ("ANALYZE_PID", "ANALYZE_PLANT", "AnalyzePlantRequest", "CAPTURE_FIELDS", "CHECK", "CheckRequest",
              "DESIGN_ONLY", "FILTER", "Field", "FilterRequest", "IDENTIFY", "IDENTIFY_FILES", "PID", "PLANT",
              "PidRequest", "PlantRequest", "analyze_pid_request", "analyze_plant_request", "check_message",
              "check_request", "field_of", "filter_request", "identify_request", "page_message", "page_text",
              "pid_request", "plant_request"),
    "connections": ("BODY_GRACE_S", "GuardedH11", "HEADER_TIMEOUT_S", "MIN_BODY_RATE", "STOP_GRACE_S",
                    "StoppingServer"),
    "guard": ("CSP", "Guard", "JSON_PATHS", "PAGE_HEADER", "SECURITY_HEADERS", "Trust", "UPLOAD_PATHS",
              "error_response", "origin_of", "trust_for"),
    "jobs": ("AXES", "BODE_POINTS", "BOM_COLUMNS", "LIBRARY", "SWALLOWING_MODULES", "Superseded", "TRACES",
             "TRACE_POINTS", "analyze_pid_task", "analyze_plant_task", "bom_shown", "bundle_zip", "check_task",
             "checks_shown", "circuit_plant_page", "design_filter_task", "design_pid_task", "design_plant_task",
             "files_in", "filter_page", "histograms", "identify_page", "identify_task", "pid_page", "plant_page", "run",
             "run_task", "series_text", "temporaries_in", "warm_up", "written_since"),
    "pool": ("Busy", "DEFAULT_TIMEOUT_S", "MAX_WAITING", "Pool", "RECYCLE_AFTER", "SPARE", "STOPPED",
             "SUPERSEDED_GRACE_S", "WARM_UP"),
    "request": ("MAX_DEPTH", "MAX_JSON_BYTES", "REFUSED", "SERVERS_OWN", "check_text", "check_value", "option_name",
                "parse_json", "split_language", "value_text", "write_content"),
    "server": ("exposure_warning", "is_local", "main"),
})
