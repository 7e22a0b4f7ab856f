"""The contact-edge tension as the flaws feel it: the stress-gradient (flaw-depth) correction.

The tension at the edge of a Hertz contact is confined to a thin skin: right at r = a it falls
like √(z/a) with depth (the pressure's square-root edge; at z = 0.01 a the normal load's
σ_rr is already 30 % of its surface value), just outside the contact it decays over a depth of
order r − a. Handling flaws on glass are 10–50 µm deep, the contact radius of a 0.1–100 N
cartridge contact 30–350 µm: the flaw may be as deep as the stressed layer. A surface flaw of
depth c_f then does not see the surface peak. Following the analysis of Hertzian fracture
(Frank & Lawn 1967, Proc. R. Soc. A 299; Warren 1978, Acta Metall. 26, 1759; Lawn,
*Fracture of Brittle Solids*, 1993, §8.5), a straight surface crack of depth c_f normal to the
surface, in the stress σ(z) that acts across its plane before it opens, has

    K = 2 √(c_f/π) ∫_0^{c_f} σ(z) / √(c_f² − z²) dz  =  K of a uniform σ_eq,
    σ_eq(c_f) = (2/π) ∫_0^{π/2} σ(c_f sin θ) dθ,

(the free-surface factor 1.12 is the same in both and drops out). σ_eq is the stress the
flaw feels: the surface value for c_f → 0, less in a field that decays with depth. Flaws sit
everywhere on the handled surface, so the critical one is where σ_eq is largest: Warren found
it outside the contact, where the surface tension is a little lower but reaches deeper. This
module tabulates, in units of p0,

    F(d, μ) = max over r ≥ a of σ_eq(r; c_f),   d = c_f / a,

for the circular contact (normal load: Hamilton's explicit subsurface field,
:func:`demfem.stress.hertz.circular_subsurface_stresses`; sliding traction q = μ p: Cerruti
quadrature, :func:`demfem.stress.hamilton.tangential_depth_parts`), σ = σ_rr along the
sliding direction on the trailing side, and for the sliding line contact (McEwen 1949,
:func:`demfem.stress.hertz.line_sliding_stresses`, d = c_f / b). The ratio F(d, μ)/F(0, μ) is
the factor by which :func:`demfem.stress.contact_stresses` lowers the contact-edge tension
when given a ``flaw_depth``; an elliptical contact uses the circular factor at its equivalent
radius √(ab). Assumptions: flaws normal to the surface (the initial ring-crack direction),
the crack does not disturb the field (Frank & Lawn), the shell's bending stress is constant
over c_f ≪ t, and the Weibull effective area of the surface field is kept.

How large it is: for the normal load alone the best-placed flaw of depth 0.01 a feels 75 %
of the surface tension (4–10 c_f outside the contact), of depth 0.1 a 28 %, of depth 0.3 a
8 % (the tests print the table). With σ_0 = 70 MPa and K_Ic ≈ 0.75 MPa √m the handled
surface's characteristic flaw is c = (K_Ic/(1.12 σ_0))²/π ≈ 30 µm deep, i.e. 0.1–1 a for
the contacts of the table: the correction is not small, and is the classical reason why
Hertzian cracks need far more load than the surface tension suggests (Auerbach's law).

Dimensionless; the grids: d in [1e-5, 10] (31 values, log), μ as the caller's, r − a in units
of c_f on 15 points up to 100 c_f, 10 Gauss points in θ.
"""
from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from demfem.errors import check_range
from demfem.stress.hamilton import tangential_depth_parts
from demfem.stress.hertz import circular_subsurface_stresses, line_sliding_stresses

__all__ = ["DEPTH_RATIOS", "TANGENTIAL_TABLE_FILE", "equivalent_stress", "circle_flaw_table",
           "line_flaw_table", "flaw_factor", "tabulate_tangential", "write_tangential_table"]

#: The sliding traction's σ_eq on the (d, r-offset) grid, ν-free parts T0, T1 (σ = T0 + ν T1),
#: shipped because the Cerruti quadrature behind it takes seconds; rewritten by
#: :func:`write_tangential_table`, checked against fresh quadrature by the tests.
TANGENTIAL_TABLE_FILE = Path(__file__).with_name("flaw_depth_tangential.json")

#: d = c_f / (contact radius or half-width) of the tables.
DEPTH_RATIOS = np.geomspace(1e-5, 10.0, 31)
#: r − a in units of c_f at which σ_eq is evaluated (the maximum over these is taken; it lies
#: at 4–10 c_f from the edge for the normal load).
_R_OFFSETS = np.array([0.0, 0.1, 0.3, 0.6, 1.0, 1.6, 2.5, 4.0, 6.5, 10.0, 16.0, 25.0, 40.0,
                       60.0, 100.0])
_GT, _GW = np.polynomial.legendre.leggauss(10)
_THETA = 0.25 * math.pi * (_GT + 1.0)                 # Gauss nodes on (0, π/2)
_THETA_W = 0.25 * math.pi * _GW


def equivalent_stress(profile: Any, depth: float) -> float:
    """σ_eq(c_f) = (2/π) ∫_0^{π/2} σ(c_f sin θ) dθ of a callable depth ``profile`` σ(z) (any
    unit; z in the same unit as ``depth`` c_f > 0): the uniform stress giving the same K on a
    straight surface crack of depth c_f (Frank & Lawn 1967)."""
    c = check_range("depth", depth, 0.0, math.inf)
    values = np.asarray(profile(c * np.sin(_THETA)), float)
    return float(2.0 / math.pi * np.sum(_THETA_W * values))


def tabulate_tangential(n_theta: int = 64, n_panels: int = 8) -> dict[str, Any]:
    """σ_eq (per μ p0) of the sliding traction's ν-free parts T0, T1 on the grid
    :data:`DEPTH_RATIOS` × r-offsets (Cerruti quadrature,
    :func:`demfem.stress.hamilton.tangential_depth_parts`): the content of
    :data:`TANGENTIAL_TABLE_FILE`."""
    d = DEPTH_RATIOS[:, None, None]
    shape = (DEPTH_RATIOS.size, _R_OFFSETS.size, _THETA.size)
    r = np.broadcast_to(1.0 + d * _R_OFFSETS[None, :, None], shape)
    z = np.broadcast_to(d * np.sin(_THETA)[None, None, :], shape)
    t0, t1 = tangential_depth_parts(r, z, n_theta, n_panels)
    w = 2.0 / math.pi * _THETA_W
    return {"depth_ratios": DEPTH_RATIOS.tolist(), "r_offsets": _R_OFFSETS.tolist(),
            "theta_nodes": int(_THETA.size), "t0": (t0 @ w).tolist(), "t1": (t1 @ w).tolist(),
            "units": "sigma_eq / (mu p0), sigma = t0 + nu t1; d = c_f / a; r - a = offset c_f",
            "source": ("Frank-Lawn equivalent stress of the sliding traction q = mu p of a "
                       "circular Hertz contact on the normal to the surface behind the contact; "
                       f"Cerruti quadrature, n_theta = {n_theta}, n_panels = {n_panels}")}


def write_tangential_table(path: Path = TANGENTIAL_TABLE_FILE) -> Path:
    """Recompute :func:`tabulate_tangential` and write it (JSON) to ``path``."""
    from demfem.io.strict_json import write_json_atomic

    return write_json_atomic(path, tabulate_tangential())


@lru_cache(maxsize=1)
def _circle_tangential_parts() -> tuple[np.ndarray, np.ndarray]:
    """(T0, T1) σ_eq of the sliding traction on the (d, r-offset) grid, shape (31, 15) each:
    the shipped table when its grid is this module's, else computed afresh."""
    try:
        data = json.loads(TANGENTIAL_TABLE_FILE.read_text(encoding="utf-8"))
        same = (np.allclose(data["depth_ratios"], DEPTH_RATIOS, rtol=1e-12, atol=0.0)
                and np.allclose(data["r_offsets"], _R_OFFSETS, rtol=0.0, atol=0.0)
                and data["theta_nodes"] == _THETA.size)
    except (OSError, ValueError, KeyError, TypeError):
        same = False
    if not same:
        data = tabulate_tangential()
    return np.asarray(data["t0"], float), np.asarray(data["t1"], float)


def _max_over_r(normal: np.ndarray, tangential: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """F(d, μ) = max over r of (normal + μ tangential); inputs (n_d, n_r), μ (n_mu,)."""
    return np.max(normal[:, None, :] + mu[None, :, None] * tangential[:, None, :], axis=2)


@lru_cache(maxsize=32)
def circle_flaw_table(nu: float, mu_grid: tuple[float, ...]) -> np.ndarray:
    """F(d, μ) / p0 of the circular contact on :data:`DEPTH_RATIOS` × ``mu_grid`` (module
    docstring), shape (31, len(mu_grid))."""
    nu = check_range("nu", nu, -1.0, 0.5)
    d = DEPTH_RATIOS[:, None, None]
    r = 1.0 + d * _R_OFFSETS[None, :, None]
    z = d * np.sin(_THETA)[None, None, :]
    shape = np.broadcast_shapes(r.shape, z.shape)
    normal = circular_subsurface_stresses(-np.broadcast_to(r, shape), 0.0,
                                          np.broadcast_to(z, shape), nu)["xx"]
    normal_eq = normal @ (2.0 / math.pi * _THETA_W)
    t0, t1 = _circle_tangential_parts()
    return _max_over_r(normal_eq, t0 + nu * t1, np.asarray(mu_grid, float))


@lru_cache(maxsize=32)
def line_flaw_table(mu_grid: tuple[float, ...]) -> np.ndarray:
    """F(d, μ) / p0 of the sliding line contact (d = c_f / b) on :data:`DEPTH_RATIOS` ×
    ``mu_grid``, shape (31, len(mu_grid))."""
    d = DEPTH_RATIOS[:, None, None]
    x = -(1.0 + d * _R_OFFSETS[None, :, None])
    z = d * np.sin(_THETA)[None, None, :]
    shape = np.broadcast_shapes(x.shape, z.shape)
    st = line_sliding_stresses(np.broadcast_to(x, shape), np.broadcast_to(z, shape))
    w = 2.0 / math.pi * _THETA_W
    return _max_over_r(st["normal_xx"] @ w, st["tangential_xx"] @ w,
                       np.asarray(mu_grid, float))


def flaw_factor(table: np.ndarray, mu_grid: np.ndarray, surface: np.ndarray, depth_ratio: Any,
                mu: Any) -> np.ndarray:
    """F(d, μ) / F(0, μ): the factor on the surface peak ``surface`` (p0 units, per event) at
    depth ratios ``depth_ratio`` and friction ``mu`` (arrays), bilinear in (log d, μ); d below
    the table's first value counts as that value, above its last as the last. Clipped to
    [0, 1] (a deep flaw sees at most the surface stress, and a compressed one none)."""
    ld = np.log(np.clip(np.asarray(depth_ratio, float), DEPTH_RATIOS[0], DEPTH_RATIOS[-1]))
    grid_d = np.log(DEPTH_RATIOS)
    i = np.clip(np.searchsorted(grid_d, ld) - 1, 0, grid_d.size - 2)
    fd = (ld - grid_d[i]) / (grid_d[i + 1] - grid_d[i])
    m = np.asarray(mu, float)
    j = np.clip(np.searchsorted(mu_grid, m) - 1, 0, mu_grid.size - 2)
    fm = np.clip((m - mu_grid[j]) / (mu_grid[j + 1] - mu_grid[j]), 0.0, 1.0)
    value = ((1 - fd) * ((1 - fm) * table[i, j] + fm * table[i, j + 1])
             + fd * ((1 - fm) * table[i + 1, j] + fm * table[i + 1, j + 1]))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(surface > 0, value / surface, 0.0)
    return np.clip(ratio, 0.0, 1.0)
