"""Calibration of the equivalent sphere: maximum contact force against Young's modulus for
the Hertz, Reissner and Hertz–Reissner laws (the analogue of Boso et al., Fig. 3).

SI units: moduli in Pa, speeds in m/s, forces in N.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from demfem.cartridge import Cartridge
from demfem.contact import (MODELS, ContactBody, hertz_contact_duration, k_eq,
                            max_contact_force, rayleigh_time_step)
from demfem.errors import check_positive
from demfem.io import savefig_atomic, write_text_atomic

__all__ = ["CalibrationTable", "calibration_report", "force_vs_modulus", "plot_force_vs_modulus"]


@dataclass(frozen=True)
class CalibrationTable:
    """Maximum contact force (N) per model (rows of ``forces``, in :data:`MODELS` order)
    against Young's modulus ``E`` (Pa) at relative speed ``v_rel`` (m/s)."""

    E: np.ndarray
    v_rel: float
    models: tuple[str, ...]
    forces: np.ndarray
    k_eq: np.ndarray

    def to_csv(self) -> str:
        """The table as CSV text (E in Pa, forces in N, k_eq in N/m)."""
        head = "E_Pa," + ",".join(f"F_{m}_N" for m in self.models) + ",k_eq_N_per_m"
        rows = [head]
        for i, e in enumerate(self.E):
            rows.append(f"{e:.6e}," + ",".join(f"{f:.6e}" for f in self.forces[:, i])
                        + f",{self.k_eq[i]:.6e}")
        return "\n".join(rows) + "\n"

    def format(self) -> str:
        """The table as aligned text for a terminal."""
        head = f"{'E [Pa]':>10} " + " ".join(f"{m + ' [N]':>20}" for m in self.models)
        lines = [head]
        for i, e in enumerate(self.E):
            lines.append(f"{e:10.3e} " + " ".join(f"{f:20.4f}" for f in self.forces[:, i]))
        return "\n".join(lines)


def force_vs_modulus(cartridge: Optional[Cartridge] = None,
                     E: "Optional[Sequence[float] | np.ndarray]" = None,
                     v_rel: float = 0.2) -> CalibrationTable:
    """Maximum force of two identical cartridges (as equivalent bodies) colliding head-on
    at ``v_rel`` (m/s), for each Young's modulus in ``E`` (Pa; default 25 values, 1e7–1e11),
    and each of the four models."""
    cartridge = cartridge or Cartridge()
    v_rel = check_positive("v_rel", v_rel)
    E_arr = np.logspace(7, 11, 25) if E is None else np.asarray(E, dtype=float)
    forces = np.zeros((len(MODELS), E_arr.size))
    keq = np.zeros(E_arr.size)
    for j, e in enumerate(E_arr):
        body = ContactBody.from_cartridge(
            Cartridge(**{**_fields(cartridge), "material": cartridge.material.with_modulus(e)}))
        for i, model in enumerate(MODELS):
            forces[i, j] = max_contact_force(body, body, v_rel, model)  # type: ignore[arg-type]
        keq[j] = k_eq(body, body, v_rel)
    return CalibrationTable(E=E_arr, v_rel=v_rel, models=MODELS, forces=forces, k_eq=keq)


def _fields(c: Cartridge) -> dict:
    from dataclasses import fields

    return {f.name: getattr(c, f.name) for f in fields(c)}


def plot_force_vs_modulus(table: CalibrationTable, path: "str | Path",
                          fem: "Optional[tuple[np.ndarray, np.ndarray] | dict[str, tuple[np.ndarray, np.ndarray]]]" = None) -> Path:
    """Write the Fig. 3 analogue (log–log force against E) as a PNG at ``path``.
    ``fem`` = (E, F), or {label: (E, F)}, adds FEM points (E in Pa, F in N)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = {"hertz": "Hertz only", "reissner": "Reissner only",
              "hertz_reissner": "Hertz–Reissner (eq. 12)", "linearized": "linearised (eqs. 13–15)"}
    styles = {"hertz": "-", "reissner": "--", "hertz_reissner": "-", "linearized": ":"}
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for i, m in enumerate(table.models):
        ax.loglog(table.E, table.forces[i], styles[m], lw=2 if m == "hertz_reissner" else 1.4,
                  label=labels[m])
    curves = {"FEM (two cartridges)": fem} if isinstance(fem, tuple) else (fem or {})
    for (label, (e_fem, f_fem)), mark in zip(curves.items(), ("ko", "ks", "k^", "kv")):
        ax.loglog(e_fem, f_fem, mark, mfc="none" if mark != "ko" else "k", label=label)
    ax.set_xlabel("Young's modulus E [Pa]")
    ax.set_ylabel("maximum contact force [N]")
    ax.set_title(f"Two cartridges colliding at v_rel = {table.v_rel:g} m/s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    out = savefig_atomic(fig, path, dpi=130)
    plt.close(fig)
    return out


def calibration_report(v_rel: float = 0.2, cartridge: "Optional[Cartridge]" = None) -> str:
    """The equivalent sphere of ``cartridge`` (default: the default 3 mL cartridge), as text:
    glass volume (mm^3), mass (g), centre of mass (mm), inertia (kg m^2), sphere diameter (mm),
    Reissner stiffness (N/m), Hertz contact time at ``v_rel`` (m/s) and the Rayleigh time step
    (s)."""
    cart = Cartridge() if cartridge is None else cartridge
    sphere = cart.equivalent_sphere()
    body = ContactBody.from_cartridge(cart)
    mp = cart.mass_properties()
    m = cart.material
    what = ("Default cartridge (3 mL, ISO 13926-1 style)" if cart == Cartridge() else
            f"The scene's cartridge ({cart.body_outer_diameter * 1e3:g} mm x "
            f"{cart.length * 1e3:g} mm, wall {cart.wall_thickness * 1e3:g} mm)")
    return "\n".join([
        f"{what}, glass: {m.name}",
        f"  glass volume        {cart.glass_volume * 1e9:10.1f} mm^3",
        f"  mass                {cart.mass * 1e3:10.3f} g",
        f"  centre of mass z    {mp.center_of_mass[2] * 1e3:10.2f} mm from the open end",
        f"  inertia (Ixx, Izz)  {mp.inertia[0, 0]:10.3e} {mp.inertia[2, 2]:10.3e} kg m^2",
        f"  equivalent sphere   {sphere.diameter * 1e3:10.2f} mm diameter",
        f"  Reissner k_R        {body.k_reissner:10.3e} N/m (t = {cart.wall_thickness * 1e3:g} mm,"
        f" R = {cart.body_mid_radius * 1e3:g} mm)",
        f"  Hertz contact time  {hertz_contact_duration(body, body, v_rel) * 1e6:10.2f} us"
        f" at {v_rel:g} m/s",
        f"  Rayleigh time step  "
        f"{rayleigh_time_step(sphere.radius, m.E, m.nu, m.density) * 1e6:10.3f} us",
    ])


def write_calibration(out_dir: "str | Path", table: CalibrationTable,
                      fem: "Optional[dict[str, tuple[np.ndarray, np.ndarray]]]" = None) -> tuple[Path, Path]:
    """Write ``calibration.csv`` and ``calibration_force_vs_E.png`` into ``out_dir``;
    ``fem`` ({label: (E Pa, F N)}) adds FEM curves to the plot."""
    out_dir = Path(out_dir)
    csv = write_text_atomic(out_dir / "calibration.csv", table.to_csv())
    png = plot_force_vs_modulus(table, out_dir / "calibration_force_vs_E.png", fem)
    return csv, png


def sweep_point(params: dict) -> dict:
    """Sweep runner (``demfem sweep --runner demfem.calibration:sweep_point``): maximum force
    (N) of two default cartridges for ``params`` with ``E`` (Pa, default 45e9) and ``v_rel``
    (m/s, default 0.2), for every model."""
    from demfem.cartridge import Cartridge

    unknown = set(params) - {"E", "v_rel"}
    if unknown:
        from demfem.errors import InvalidParameterError

        raise InvalidParameterError(
            f"invalid sweep parameter(s) {sorted(unknown)}: allowed are ['E', 'v_rel']")
    c = Cartridge()
    table = force_vs_modulus(c, [float(params.get("E", c.material.E))],
                             float(params.get("v_rel", 0.2)))
    return {f"F_{m}_N": float(table.forces[i, 0]) for i, m in enumerate(table.models)}
