"""Figures: top views of the table (snapshots and animations)."""
from demfem.plots.table import TAG_COLOURS, animate_table, plot_table_snapshot

__all__ = ["TAG_COLOURS", "animate_table", "plot_table_snapshot"]
