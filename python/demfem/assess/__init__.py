"""`demfem assess`: from every collision of the DEM of the table to a breakage probability
per cartridge (calibration → DEM → collision events → stress model → Weibull risk → report).

* :mod:`~demfem.assess.events` — impact events from the DEM's contact onsets;
* :mod:`~demfem.assess.impact` — peak force, contact radius and duration of a collision
  (calibrated Hertz–Reissner law);
* :mod:`~demfem.assess.closed_form` — surface stresses of a shell under a point load
  (Reissner's shallow shell), the source of the default stress model;
* :mod:`~demfem.assess.stress_model` — :class:`StressModel`: σ1 = β F/t² and stressed areas,
  fit from FEM runs, JSON files;
* :mod:`~demfem.assess.stress_stage` — the per-event stresses;
* :mod:`~demfem.assess.risk_stage` — probabilities per event, cartridge and hour, steady
  state, worst collisions, risk map;
* :mod:`~demfem.assess.stages`, :mod:`~demfem.assess.run` — the resumable job
  (:func:`assess`), :mod:`~demfem.assess.report` and :mod:`~demfem.assess.figures` — the
  HTML report.

See ``docs/assess.md``. SI units throughout.
"""
from __future__ import annotations

from demfem.assess.run import assess
from demfem.assess.stages import STAGES
from demfem.assess.stress_model import StressModel, closed_form_model

__all__ = ["assess", "STAGES", "StressModel", "closed_form_model"]
