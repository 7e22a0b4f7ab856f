"""The FEM curve of the paper's Fig. 3: the peak force of two real cartridges colliding
(explicit FEM with contact, :func:`demfem.fem.collide_cartridges`) against Young's
modulus, beside the Hertz, Reissner and Hertz–Reissner laws of the calibration.

A stored run ships with the package (``data/fig3_fem.json``); :func:`fem_force_vs_modulus`
recomputes it (a few minutes on 2 cores).
"""
from __future__ import annotations

import json
import platform
import time
from importlib import resources
from pathlib import Path
from typing import Callable, Optional, Sequence

import numpy as np

from demfem.cartridge import Cartridge
from demfem.contact import ContactBody, max_contact_force
from demfem.fem.collision import collide_cartridges
from demfem.io.atomic import write_text_atomic

STORED = "fig3_fem.json"


def fem_force_vs_modulus(E: Sequence[float] = (1e7, 1e8, 1e9, 1e10, 1e11), v_rel: float = 0.2,
                         tilts_deg: Sequence[float] = (90.0, 0.0), layers: int = 2,
                         cartridge: Optional[Cartridge] = None,
                         log: Optional[Callable[[str], None]] = print) -> dict:
    """Collide two default cartridges at ``v_rel`` (m/s) for every modulus in ``E`` (Pa) and
    every tilt (degrees: 90 crossed, 0 parallel); returns a JSON-ready dict with, per run,
    the peak force (N, filtered and raw), contact duration (s), restitution, wall time (s),
    elements and step, and the Hertz–Reissner law's force at the same E for comparison."""
    cart = cartridge or Cartridge()
    runs = []
    for tilt in tilts_deg:
        for e in E:
            mat = cart.material.with_modulus(float(e))
            c = Cartridge(**{**_fields(cart), "material": mat})
            r = collide_cartridges(c, c, v_rel=v_rel, tilt_deg=tilt, layers=layers)
            body = ContactBody.from_cartridge(c)
            row = {
                "E_Pa": float(e), "tilt_deg": float(tilt), "layers": layers,
                "max_force_N": r.max_force, "raw_max_force_N": r.raw_max_force,
                "contact_duration_s": r.contact_duration, "restitution": r.restitution,
                "wall_time_s": r.wall_time, "n_elements": r.n_elements, "dt_s": r.dt,
                "energy_balance_error": r.energy_balance_error,
                "hertz_reissner_N": max_contact_force(body, body, v_rel, "hertz_reissner"),
                "hertz_N": max_contact_force(body, body, v_rel, "hertz"),
                "reissner_N": max_contact_force(body, body, v_rel, "reissner"),
            }
            runs.append(row)
            if log:
                log(f"  tilt {tilt:4.0f} deg, E {e:8.1e} Pa: FEM {r.max_force:8.3f} N "
                    f"(Hertz-Reissner {row['hertz_reissner_N']:8.3f} N), t_c "
                    f"{r.contact_duration * 1e6:8.1f} us, e = {r.restitution:.3f}, "
                    f"{r.wall_time:6.1f} s")
    return {"v_rel_m_per_s": v_rel, "runs": runs, "machine": platform.node(),
            "date": time.strftime("%Y-%m-%d")}


def _fields(c: Cartridge) -> dict:
    from dataclasses import fields

    return {f.name: getattr(c, f.name) for f in fields(c)}


def load_stored() -> dict:
    """The stored FEM curve shipped with demfem."""
    return json.loads(resources.files("demfem.fem").joinpath("data", STORED).read_text())


def save(data: dict, path: "str | Path") -> Path:
    """Write the FEM curve as JSON, atomically."""
    return write_text_atomic(path, json.dumps(data, indent=1, allow_nan=False) + "\n")


def curve(data: dict, tilt_deg: float = 90.0) -> tuple[np.ndarray, np.ndarray]:
    """(E Pa, peak force N) of the runs at ``tilt_deg``, ascending in E."""
    rows = sorted((r for r in data["runs"] if r["tilt_deg"] == tilt_deg), key=lambda r: r["E_Pa"])
    return (np.array([r["E_Pa"] for r in rows]), np.array([r["max_force_N"] for r in rows]))
