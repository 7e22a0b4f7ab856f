"""Elastic materials (SI units: Pa, kg/m³).

Every material value in demfem is explicit: a :class:`Material` carries Young's modulus,
Poisson's ratio and density, validated on construction. Three glass presets are provided:

* :data:`PAPER_GLASS` — the values of Boso et al. (E = 45 GPa). The paper gives E only;
  ν = 0.22 and ρ = 2230 kg/m³ are the values of the DEM anchor scene
  (``shared/anchors/dem/scene.py``) and of borosilicate glass.
* :data:`BOROSILICATE_3_3` — borosilicate glass 3.3 (ISO 3585 / DIN 7080 type, e.g. DURAN):
  E = 63 GPa, ν = 0.20, ρ = 2230 kg/m³ (ISO 3585:1998 property table; manufacturer sheets).
* :data:`TYPE_I_TUBING_GLASS` — USP/Ph. Eur. Type I neutral borosilicate tubing glass
  (α ≈ 4.9e-6 /K class, e.g. FIOLAX clear): E = 73 GPa, ν = 0.20, ρ = 2340 kg/m³
  (manufacturer data sheets; the ranges quoted in the design notes are 64–74 GPa, ν ≈ 0.2,
  2230–2340 kg/m³).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from demfem.errors import check_positive, check_range

__all__ = [
    "Material",
    "PAPER_GLASS",
    "BOROSILICATE_3_3",
    "TYPE_I_TUBING_GLASS",
    "PRESETS",
]


@dataclass(frozen=True)
class Material:
    """A linear-elastic isotropic material.

    Parameters
    ----------
    E:
        Young's modulus, Pa; finite and > 0.
    nu:
        Poisson's ratio, dimensionless; in (-1, 0.5).
    density:
        Mass density, kg/m³; finite and > 0.
    name:
        Free label used in tables and plots.
    """

    E: float
    nu: float
    density: float
    name: str = "material"

    def __post_init__(self) -> None:
        object.__setattr__(self, "E", check_positive("E", self.E))
        object.__setattr__(self, "nu", check_range("nu", self.nu, -1.0, 0.5))
        object.__setattr__(self, "density", check_positive("density", self.density))

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + ν)), Pa."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def p_wave_speed(self) -> float:
        """Dilatational wave speed c_d = √(E (1−ν) / (ρ (1+ν)(1−2ν))), m/s."""
        nu = self.nu
        return math.sqrt(self.E * (1.0 - nu) / (self.density * (1.0 + nu) * (1.0 - 2.0 * nu)))

    def with_modulus(self, E: float) -> "Material":
        """The same material with Young's modulus ``E`` (Pa): the paper's E sweeps."""
        return Material(E=E, nu=self.nu, density=self.density, name=f"{self.name} (E={E:.3g} Pa)")


PAPER_GLASS = Material(E=45e9, nu=0.22, density=2230.0, name="glass (Boso et al., E=45 GPa)")
BOROSILICATE_3_3 = Material(E=63e9, nu=0.20, density=2230.0, name="borosilicate 3.3")
TYPE_I_TUBING_GLASS = Material(E=73e9, nu=0.20, density=2340.0, name="Type I tubing glass")

PRESETS = {
    "paper_glass": PAPER_GLASS,
    "borosilicate_3_3": BOROSILICATE_3_3,
    "type_i_tubing_glass": TYPE_I_TUBING_GLASS,
}
