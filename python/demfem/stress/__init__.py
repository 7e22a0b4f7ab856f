"""`demfem.stress`: the stress the glass sees at a contact, and its Weibull effective area.

One entry point, :func:`contact_stresses`: for contact events (normal and tangential force,
N, arrays allowed) of a given geometry — two cartridges crossed at an angle, side by side, a
cartridge against a flat wall or a rail edge — the peak max-principal stress σ1 (Pa) on the
outer and inner glass surface and the Weibull effective area (m²) of each, as the
superposition of the local contact field (Hertz, Hamilton's sliding contact) and the wall's
bending (the cylindrical shell with the load's spread through the wall). See
``docs/stress.md``.

Modules, one concept each:

* :mod:`~demfem.stress.hertz` — Hertz point, elliptical and line contacts; their surface and
  subsurface stresses;
* :mod:`~demfem.stress.hamilton` — the sliding contact's tangential traction (Hamilton 1983);
* :mod:`~demfem.stress.surface_field` — the surface field of an elliptical sliding contact;
* :mod:`~demfem.stress.cylinder_load` — the wall as a cylindrical shell under a local radial
  load (point or line contact), with the thick-plate correction: the global field;
* :mod:`~demfem.stress.shell` — Reissner's shallow shell under a point or Hertzian load (the
  shell-only :class:`StressModel`'s);
* :mod:`~demfem.stress.ring` — the tube as a ring under line loads (Roark; the long line
  contact's limit, the curved-bar factors);
* :mod:`~demfem.stress.effective_area` — dimensionless effective-area tables;
* :mod:`~demfem.stress.flaw_depth` — the stress-gradient (flaw-depth) correction;
* :mod:`~demfem.stress.model` — the superposition, :func:`contact_stresses`;
* :mod:`~demfem.stress.stress_model` — :class:`StressModel`, the shell-only σ1 = β F/t² model
  of ``demfem assess`` (and :mod:`~demfem.stress.fem_fit`, its refit from FEM runs).

SI units throughout: N, m, Pa, m².
"""
from __future__ import annotations

from demfem.stress.model import GEOMETRIES, LOCATIONS, ContactStresses, contact_stresses
from demfem.stress.stress_model import StressModel, closed_form_model

__all__ = ["contact_stresses", "ContactStresses", "GEOMETRIES", "LOCATIONS", "StressModel",
           "closed_form_model"]
