"""`demfem assess`: from every collision of the DEM of the table to a breakage probability
per cartridge (calibration → DEM → collision events → stress model → Weibull risk → report).

* :mod:`~demfem.assess.events` — impact events from the DEM's contact onsets;
* :mod:`~demfem.assess.impact` — peak force, contact radius and duration of a collision
  (calibrated Hertz–Reissner law);
* :mod:`demfem.stress` — the stresses at a contact (contact field and shell bending) and
  the former shell-only :class:`StressModel` (σ1 = β F/t²);
* :mod:`~demfem.stress.stage` — the per-event stresses;
* :mod:`~demfem.assess.risk_stage` — probabilities per event, cartridge and hour, steady
  state, worst collisions, risk map;
* :mod:`~demfem.assess.stages`, :mod:`~demfem.assess.run` — the resumable job
  (:func:`assess`), its stages (:mod:`~demfem.assess.job_stages`, each a
  :class:`~demfem.assess.job.Stage`), :mod:`~demfem.assess.report` and
  :mod:`~demfem.assess.figures` — the HTML report.

See ``docs/assess.md``. SI units throughout.
"""
from __future__ import annotations

from demfem.assess.run import assess
from demfem.assess.stages import STAGES
from demfem.assess.tables import load_assessment
from demfem.stress.stress_model import StressModel, closed_form_model

__all__ = ["assess", "STAGES", "StressModel", "closed_form_model", "load_assessment"]
