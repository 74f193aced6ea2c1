"""Build sheets: one document model rendered to Markdown, HTML and text, plots, and bundle writing."""
