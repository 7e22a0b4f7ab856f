"""Hand-written stubs of the compiled core (checked by ``mypy.stubtest``). SI units."""
import numpy as np
import numpy.typing as npt

__version__: str
__all__ = [
    "__version__",
    "hertz_contact_duration",
    "max_impact_force",
    "normal_force",
    "rayleigh_time_step",
    "tsuji_damping_for_restitution",
    "tsuji_restitution",
]

def normal_force(
    law: str,
    overlap: npt.NDArray[np.float64],
    k_h: float = ...,
    k_r: float = ...,
    k: float = ...,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Normal force (N) and tangent stiffness (N/m) of ``law`` at each overlap (m).
    ``law`` in {'hertz', 'linear', 'hertz_reissner'}; k_h in N/m^1.5, k_r and k in N/m."""

def max_impact_force(
    law: str, m_star: float, v_rel: float, k_h: float = ..., k_r: float = ..., k: float = ...
) -> float:
    """Maximum impact force (N) for effective mass m_star (kg) at v_rel (m/s)."""

def tsuji_restitution(zeta: float, clamp: bool = False) -> float:
    """Restitution of a Hertz impact with Tsuji damping parameter zeta (dimensionless)."""

def tsuji_damping_for_restitution(e: float, clamp: bool = False) -> float:
    """Tsuji damping parameter zeta that realises restitution e in (0, 1]."""

def rayleigh_time_step(radius: float, density: float, e: float, nu: float) -> float:
    """Rayleigh time step (s) of a sphere: radius (m), density (kg/m^3), E (Pa), nu."""

def hertz_contact_duration(k_h: float, m_star: float, v_rel: float) -> float:
    """Duration (s) of an undamped Hertz impact: k_h (N/m^1.5), m_star (kg), v_rel (m/s)."""
