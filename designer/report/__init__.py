"""Build sheets: one document model rendered to Markdown, HTML and text, plots, and bundle writing."""

from ..core.exports import lazy_exports

#: module -> the names of its ``__all__`` re-exported here, each module imported on first use (a command
#: pays only for what it runs); a name several modules share, or a module's own name, is reached through
#: its module (designer.core.exports)
__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    "bundle": ("draw_early", "schematic_pictures", "write_design"),
    "document": ("columns", "fmt_pct", "fmt_time", "image", "subhead", "table", "text", "to_html", "to_text"),
    "plots": ("bode_plot", "decimate", "histogram_plot", "localise_figure", "loop_gain_plot", "png_bytes", "step_plot",
              "time_unit"),
    "render": ("ahead", "running", "start", "stop", "submit", "submit_many"),
    "schematic": ("Sheet", "check_connectivity"),
    "tolerance": ("csv_texts", "histogram_plots", "histogram_words", "limit_text", "section", "title"),
    "wiring": ("BOM_HEADER", "CATALOGUE_WORDS", "bench_rows", "bom_csv", "bom_rows", "net_text", "wiring_rows"),
})
