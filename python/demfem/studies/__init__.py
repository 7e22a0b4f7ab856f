"""The paper's DEM studies (Figs. 5-9): one function per figure that runs its table runs
(:func:`demfem.dem.table_run.sweep_point` through :func:`demfem.sweep.sweep`), analyses and
plots them. See :mod:`demfem.studies.figures`."""
