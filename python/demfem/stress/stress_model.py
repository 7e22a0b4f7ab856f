"""The stress model: from a collision's peak contact force to the peak max-principal stress
σ1 on the inner and on the outer glass surface, and the stressed area of each.

Thin-shell scaling (the bending stress of a shell under a concentrated load is a number times
F/t²):

    σ1_inner = β_inner F / t²,    σ1_outer = β_outer F / t²       (Pa; F in N, t in m)
    A_inner  = f_inner π a²,      A_outer  = f_outer π a²,        a = (3 F R* / (4 E*))^{1/3}

with t the wall thickness and a the Hertz contact radius of the collision. The areas are the
Weibull effective areas of the two σ1 fields (A_eff = ∫ (σ1/σ1_max)^m dA, ASTM C1683), so that
P = 1 − exp(−(A/A_0)(σ1/σ_0)^m) for each surface.

Defaults (:meth:`StressModel.default`, the shipped ``stress_model_default.json``): Reissner's
shallow-shell point-load solution (:mod:`demfem.stress.shell`) for the default 3 mL
cartridge (t = 1.1 mm, mid-surface radius 5.25 mm, ν = 0.22) loaded over the Hertz contact
patch of a reference collision (two cartridges at 0.05 m/s, E = 45 GPa: F_ref ≈ 3.9 N, a ≈
80 µm), and the default Weibull moduli (inner 10, outer 6):

* β_inner ≈ 1.78: inner surface under the load in tension (bending minus the compressive
  membrane force). The exact closed form grows like −(1/3)·3(1+ν)/(2π)·ln F: from 2.30 at
  0.27 N to 1.47 at 19 N; a constant β misses that by ±20 % over the DEM's force range. At the
  paper's worst FEM case (80 N) it gives ≈ 1.2 F/t² = 80 MPa against the paper's 94 MPa.
* β_outer ≈ 0.043: the outer surface is in compression under the load (−2.2 F/t²) and in weak
  tension in a ring about one shell radius away, where the shallow-shell theory is at its
  limit. Outer-surface risk in this model is therefore small; it is the first thing to
  check against the FEM.

:meth:`StressModel.fit` refits β_inner and β_outer from FEM runs (least squares through the
origin on σ1 against F/t²). SI units throughout.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any, Optional

import numpy as np

from demfem.errors import DemfemIOError, InvalidParameterError, ShapeError, check_positive, \
    check_range

__all__ = ["StressModel", "DEFAULT_FILE", "closed_form_model", "REFERENCE_SPEED"]

#: The shipped default model (read by :meth:`StressModel.default`).
DEFAULT_FILE = Path(__file__).with_name("stress_model_default.json")

#: Normal speed of the reference collision behind the default β and area factors, m/s.
REFERENCE_SPEED = 0.05


@dataclass(frozen=True)
class StressModel:
    """Peak surface stresses and stressed areas of a collision (module docstring).

    Attributes:
        beta_inner: σ1_inner t² / F, dimensionless (> 0: tension).
        beta_outer: σ1_outer t² / F, dimensionless (≤ 0 means the outer surface is nowhere in
            tension: no outer risk).
        thickness: wall thickness t, m.
        area_factor_inner: inner effective area / (π a²), dimensionless, ≥ 0.
        area_factor_outer: outer effective area / (π a²), dimensionless, ≥ 0.
        reference_force: force at which β and the factors were derived or fitted, N
            (information only).
        source: where the numbers come from.
    """

    beta_inner: float
    beta_outer: float
    thickness: float
    area_factor_inner: float
    area_factor_outer: float
    reference_force: float = math.nan
    source: str = "unspecified"

    def __post_init__(self) -> None:
        object.__setattr__(self, "beta_inner", check_range("beta_inner", self.beta_inner))
        object.__setattr__(self, "beta_outer", check_range("beta_outer", self.beta_outer))
        object.__setattr__(self, "thickness", check_positive("thickness", self.thickness))
        for name in ("area_factor_inner", "area_factor_outer"):
            object.__setattr__(self, name, check_range(name, getattr(self, name), 0.0,
                                                       math.inf, lo_open=False))
        if not isinstance(self.source, str):
            raise InvalidParameterError(f"invalid source = {self.source!r}: must be a string")

    # ---- the map --------------------------------------------------------------------------

    def _force(self, force: Any) -> np.ndarray:
        f = np.asarray(force, float)
        if np.any(~np.isfinite(f)) or np.any(f < 0):
            raise InvalidParameterError("invalid force: must be finite and >= 0 N")
        return f

    def sigma_inner(self, force: Any) -> np.ndarray:
        """Peak inner-surface σ1 (Pa) at peak contact force ``force`` (N)."""
        return self.beta_inner * self._force(force) / self.thickness**2

    def sigma_outer(self, force: Any) -> np.ndarray:
        """Peak outer-surface σ1 (Pa) at peak contact force ``force`` (N)."""
        return self.beta_outer * self._force(force) / self.thickness**2

    def stressed_areas(self, contact_radius: Any) -> tuple[np.ndarray, np.ndarray]:
        """(inner, outer) effective areas (m²) for Hertz contact radii ``contact_radius``
        (m)."""
        a = np.asarray(contact_radius, float)
        if np.any(~np.isfinite(a)) or np.any(a < 0):
            raise InvalidParameterError("invalid contact_radius: must be finite and >= 0 m")
        patch = math.pi * a * a
        return self.area_factor_inner * patch, self.area_factor_outer * patch

    # ---- fitting and files ----------------------------------------------------------------

    @classmethod
    def fit(cls, forces: Any, sigma_inner: Any, sigma_outer: Any,
            thickness: Optional[float] = None, source: str = "fitted to FEM runs",
            base: Optional["StressModel"] = None) -> "StressModel":
        """β_inner, β_outer by least squares through the origin on σ1 against x = F/t²:
        β = Σ x σ / Σ x². ``forces`` peak contact forces (N), ``sigma_inner`` /
        ``sigma_outer`` the peak σ1 of each run on each surface (Pa), same length ≥ 1;
        ``thickness`` t (m, default: that of ``base``). The area factors are kept from
        ``base`` (default: :meth:`default`)."""
        base = base or cls.default()
        t = base.thickness if thickness is None else check_positive("thickness", thickness)
        arrays = []
        for name, v in (("forces", forces), ("sigma_inner", sigma_inner),
                        ("sigma_outer", sigma_outer)):
            a = np.asarray(v, float).ravel()
            if a.size == 0 or not np.all(np.isfinite(a)):
                raise InvalidParameterError(f"invalid {name}: must be a non-empty sequence of "
                                            "finite numbers")
            arrays.append(a)
        f, si, so = arrays
        if not (f.size == si.size == so.size):
            raise ShapeError(f"invalid fit data: forces ({f.size}), sigma_inner ({si.size}) "
                             f"and sigma_outer ({so.size}) must have the same length")
        if np.any(f <= 0):
            raise InvalidParameterError("invalid forces: must be > 0 N")
        x = f / t**2
        sxx = float(x @ x)
        return replace(base, beta_inner=float(x @ si) / sxx, beta_outer=float(x @ so) / sxx,
                       thickness=t, reference_force=float(np.median(f)), source=source)

    def residuals(self, forces: Any, sigma_inner: Any, sigma_outer: Any) -> dict[str, float]:
        """RMS relative misfit of this model to data (as for :meth:`fit`), dimensionless."""
        f = self._force(forces)
        out = {}
        for name, s, pred in (("inner", sigma_inner, self.sigma_inner(f)),
                              ("outer", sigma_outer, self.sigma_outer(f))):
            s = np.asarray(s, float)
            scale = max(float(np.max(np.abs(s))), 1e-300)
            out[f"rms_{name}_relative"] = float(np.sqrt(np.mean((pred - s) ** 2))) / scale
        return out

    def to_dict(self) -> dict[str, Any]:
        """The fields, with units in a ``units`` entry (strict-JSON values)."""
        return {**asdict(self), "units": {"thickness": "m", "reference_force": "N",
                                          "beta_inner": "1", "beta_outer": "1",
                                          "area_factor_inner": "1", "area_factor_outer": "1"}}

    @classmethod
    def from_dict(cls, data: Any, origin: str = "stress model") -> "StressModel":
        """A model from :meth:`to_dict` output; unknown or missing keys are errors."""
        if not isinstance(data, dict):
            raise InvalidParameterError(f"invalid {origin}: must be a JSON object")
        names = {f.name for f in fields(cls)}
        body = {k: v for k, v in data.items() if k != "units"}
        unknown = sorted(set(body) - names)
        if unknown:
            raise InvalidParameterError(f"invalid {origin}: unknown keys {unknown}")
        missing = [n for n in ("beta_inner", "beta_outer", "thickness", "area_factor_inner",
                               "area_factor_outer") if n not in body]
        if missing:
            raise InvalidParameterError(f"invalid {origin}: missing keys {missing}")
        if body.get("reference_force") is None:
            body["reference_force"] = math.nan
        return cls(**body)

    def save(self, path: str | Path) -> Path:
        """Write the model as strict JSON, atomically; returns the path."""
        from demfem.io.strict_json import write_json_atomic

        return write_json_atomic(path, self.to_dict())

    @classmethod
    def load(cls, path: str | Path) -> "StressModel":
        """Read a model written by :meth:`save`."""
        path = Path(path)
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            raise DemfemIOError(f"i/o error on {path}: {exc}") from None
        except (UnicodeDecodeError, ValueError) as exc:
            raise InvalidParameterError(f"invalid stress model file {path}: {exc}") from None
        return cls.from_dict(data, origin=f"stress model file {path}")

    @classmethod
    def default(cls) -> "StressModel":
        """The shipped default (``stress_model_default.json``, see the module docstring)."""
        return cls.load(DEFAULT_FILE)


def closed_form_model(young_modulus: float = 45e9, reference_speed: float = REFERENCE_SPEED,
                      m_inner: Optional[float] = None,
                      m_outer: Optional[float] = None) -> StressModel:
    """The closed-form model of the default cartridge (how the shipped default was made):
    Reissner's shallow-shell solution loaded over the Hertz patch of two cartridges colliding
    at ``reference_speed`` (m/s) with Young's modulus ``young_modulus`` (Pa); area factors for
    the Weibull moduli ``m_inner`` / ``m_outer`` (default: :mod:`demfem.risk.defaults`)."""
    from demfem.stress.shell import closed_form_coefficients
    from demfem.assess.impact import cartridge_body, contact_radius, pair_constants
    from demfem.cartridge import Cartridge
    from demfem.contact import max_contact_force
    from demfem.risk.defaults import INNER_SURFACE, OUTER_SURFACE

    cart = Cartridge()
    body = cartridge_body(young_modulus)
    v = check_positive("reference_speed", reference_speed)
    force = max_contact_force(body, body, v, "hertz_reissner")
    p = pair_constants(body, body)
    a = float(contact_radius(force, p["r_star"], p["e_star"]))
    cf = closed_form_coefficients(cart.wall_thickness, cart.body_mid_radius, body.nu, a,
                                  m_inner or INNER_SURFACE.weibull_modulus,
                                  m_outer or OUTER_SURFACE.weibull_modulus)
    return StressModel(
        beta_inner=cf.beta_inner, beta_outer=cf.beta_outer, thickness=cart.wall_thickness,
        area_factor_inner=cf.area_factor_inner, area_factor_outer=cf.area_factor_outer,
        reference_force=force,
        source=("closed form: Reissner shallow spherical shell under a radial load spread over "
                "the Hertz patch (Reissner 1946; Timoshenko & Woinowsky-Krieger 1959, sec. 58, "
                f"ln(l/c) + 0.6159), default 3 mL cartridge t = {cart.wall_thickness:g} m, "
                f"R = {cart.body_mid_radius:g} m, nu = {body.nu:g}; reference collision of two "
                f"cartridges at {v:g} m/s, E = {young_modulus:g} Pa (F = {force:.4g} N, "
                f"a = {a:.4g} m); effective areas for Weibull m = "
                f"{m_inner or INNER_SURFACE.weibull_modulus:g} (inner), "
                f"{m_outer or OUTER_SURFACE.weibull_modulus:g} (outer)"))
