"""The paper's DEM studies (Figs. 5-9): recorded table runs, a sweep runner and one function
per figure. See :mod:`demfem.studies.table_run` and :mod:`demfem.studies.figures`."""
from demfem.studies.table_run import RUN_OPTIONS, TableRun, run_table, sweep_point, table_from_params

__all__ = ["RUN_OPTIONS", "TableRun", "run_table", "sweep_point", "table_from_params"]
