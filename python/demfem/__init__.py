"""demfem: DEM-FEM prediction of breakage of glass cartridges on a conveyor-belt accumulation
table (Boso et al.). SI units throughout: m, kg, s, N, Pa.

The Rust core (``demfem._core``) steps the DEM and the explicit FEM; the Python modules hold
materials, the cartridge geometry, the contact calibration, scenes and analyses.
"""
from demfem._core import __version__
from demfem.errors import DemfemError, InvalidParameterError

__all__ = ["__version__", "DemfemError", "InvalidParameterError"]
