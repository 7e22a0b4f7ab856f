"""The cartridge: one parametric geometry from which everything else is derived.

A :class:`Cartridge` is a glass body of revolution about its axis (local z, from the open
bottom end at z = 0 to the top of the crimp flange at z = ``length``). At every height z the
glass is the annulus ``r_in(z) <= r <= r_out(z)``; both radii are continuous and piecewise
linear between :meth:`Cartridge.stations`. From this one description demfem derives the glass
volume, mass, centre of mass and inertia tensor, the equivalent sphere of the DEM, the bead
clump of full-shape DEM and (in the FEM) the solid and shell meshes. No dimension is typed
twice.

Default dimensions: a 3 mL cartridge in the style of ISO 13926-1 (pen-injector cartridges):
body outer diameter 11.6 mm and wall 1.1 mm (the DESIGN.md physics defaults), overall length
64 mm, a conical shoulder, a neck of 6.0 mm outer diameter and a crimp flange of 7.3 mm
outer diameter. The neck and flange sizes are representative values for this cartridge class
(they differ between makers); the mass that follows, ≈ 4.9 g at ρ = 2230 kg/m³, agrees with
the ≈ 5 g of a real 3 mL cartridge, and the equivalent sphere (≈ 16.2 mm) with the paper's
"about 1.6 cm". All lengths in metres.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import Any, Mapping

import numpy as np

from demfem.errors import InvalidParameterError, check_positive, check_range
from demfem.materials import PAPER_GLASS, Material

__all__ = ["Cartridge", "EquivalentSphere", "BeadClump", "MassProperties", "CARTRIDGE_PRESETS"]

# 3-point Gauss–Legendre on [0, 1]: exact for polynomials of degree <= 5. The integrands of
# volume, first moment and inertia are polynomials of degree <= 4 in z on each segment
# (radii are linear in z), so the mass properties below are exact up to round-off.
_GL_X = 0.5 + 0.5 * np.array([-math.sqrt(3.0 / 5.0), 0.0, math.sqrt(3.0 / 5.0)])
_GL_W = 0.5 * np.array([5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])


@dataclass(frozen=True)
class MassProperties:
    """Mass (kg), centre of mass (m, body frame) and inertia tensor about the centre of
    mass (kg·m², body frame, axis of symmetry = z)."""

    mass: float
    center_of_mass: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True)
class EquivalentSphere:
    """Solid sphere with the cartridge's mass and material (the paper's DEM particle).

    ``radius`` in m, ``mass`` in kg, ``moment_of_inertia`` = 2/5 m R² in kg·m².
    """

    radius: float
    mass: float
    moment_of_inertia: float
    material: Material

    @property
    def diameter(self) -> float:
        """Diameter, m."""
        return 2.0 * self.radius


@dataclass(frozen=True)
class BeadClump:
    """A rigid clump of beads standing for a cartridge in full-shape DEM.

    ``centers`` (n, 3) m, in the cartridge body frame with origin at the centre of mass and
    axis z; ``radii`` (n,) m; ``masses`` (n,) kg, summing to the cartridge mass. Each bead
    carries the glass of the slab of the wall it sits on, so the clump's mass, centre of
    mass and inertia follow from the beads (see :meth:`mass_properties`).
    """

    centers: np.ndarray
    radii: np.ndarray
    masses: np.ndarray

    @property
    def n_beads(self) -> int:
        """Number of beads."""
        return int(self.radii.shape[0])

    def mass_properties(self) -> MassProperties:
        """Mass (kg), centre of mass (m) and inertia about it (kg·m²) of the beads, each a
        solid sphere of its own mass."""
        m = self.masses
        mass = float(m.sum())
        com = (m[:, None] * self.centers).sum(axis=0) / mass
        d = self.centers - com
        inertia = np.zeros((3, 3))
        r2 = (d * d).sum(axis=1)
        for i in range(3):
            for j in range(3):
                inertia[i, j] = -(m * d[:, i] * d[:, j]).sum()
            inertia[i, i] += (m * r2).sum()
        inertia += np.eye(3) * (0.4 * m * self.radii**2).sum()
        return MassProperties(mass, com, inertia)


@dataclass(frozen=True)
class Cartridge:
    """A 3 mL glass cartridge as a body of revolution (all lengths in m).

    Parameters
    ----------
    body_outer_diameter:
        Outer diameter of the cylindrical body, m (default 11.6e-3).
    wall_thickness:
        Glass wall thickness of body, shoulder (measured horizontally) and neck, m
        (default 1.1e-3).
    length:
        Overall length from the open bottom end to the top of the flange, m (default 64e-3).
    shoulder_length:
        Axial length of the conical shoulder, m (default 4.0e-3).
    neck_outer_diameter:
        Outer diameter of the neck, m (default 6.0e-3).
    neck_length:
        Axial length of the neck, m (default 2.5e-3).
    flange_outer_diameter:
        Outer diameter of the crimp flange, m (default 7.3e-3).
    flange_length:
        Axial length of the flange including its lower chamfer, m (default 3.0e-3).
    flange_chamfer:
        Axial length over which the outer radius grows from neck to flange, m (default 0.3e-3).
    material:
        The glass (default :data:`demfem.materials.PAPER_GLASS`).
    """

    body_outer_diameter: float = 11.6e-3
    wall_thickness: float = 1.1e-3
    length: float = 64.0e-3
    shoulder_length: float = 4.0e-3
    neck_outer_diameter: float = 6.0e-3
    neck_length: float = 2.5e-3
    flange_outer_diameter: float = 7.3e-3
    flange_length: float = 3.0e-3
    flange_chamfer: float = 0.3e-3
    material: Material = field(default=PAPER_GLASS)

    def __post_init__(self) -> None:
        for name in (
            "body_outer_diameter",
            "wall_thickness",
            "length",
            "neck_outer_diameter",
            "flange_outer_diameter",
        ):
            object.__setattr__(self, name, check_positive(name, getattr(self, name)))
        for name in ("shoulder_length", "neck_length", "flange_length", "flange_chamfer"):
            object.__setattr__(
                self, name, check_range(name, getattr(self, name), 0.0, math.inf, lo_open=False)
            )
        if not isinstance(self.material, Material):
            raise InvalidParameterError(
                f"invalid material = {self.material!r}: must be a demfem.materials.Material"
            )
        r_body = 0.5 * self.body_outer_diameter
        check_range("wall_thickness", self.wall_thickness, 0.0, r_body)
        r_neck_in = 0.5 * self.neck_outer_diameter - self.wall_thickness
        if not r_neck_in > 0.0:
            raise InvalidParameterError(
                f"invalid neck_outer_diameter = {self.neck_outer_diameter!r}: must exceed "
                f"2 * wall_thickness = {2 * self.wall_thickness:g} (the neck needs a bore)"
            )
        check_range(
            "neck_outer_diameter", self.neck_outer_diameter, 2 * self.wall_thickness,
            self.body_outer_diameter, hi_open=False,
        )
        check_range(
            "flange_outer_diameter", self.flange_outer_diameter, 0.0, self.body_outer_diameter,
            hi_open=False,
        )
        if self.flange_outer_diameter < self.neck_outer_diameter:
            raise InvalidParameterError(
                f"invalid flange_outer_diameter = {self.flange_outer_diameter!r}: must be >= "
                f"neck_outer_diameter = {self.neck_outer_diameter!r}"
            )
        check_range("flange_chamfer", self.flange_chamfer, 0.0, self.flange_length, lo_open=False,
                    hi_open=False)
        if self.body_length <= 0.0:
            raise InvalidParameterError(
                f"invalid length = {self.length!r}: must exceed shoulder_length + neck_length + "
                f"flange_length = {self.length - self.body_length:g}"
            )

    @classmethod
    def tube(cls, outer_diameter: float, wall_thickness: float, length: float,
             material: Material = PAPER_GLASS) -> "Cartridge":
        """A plain open tube of ``outer_diameter``, ``wall_thickness`` and ``length`` (m): a
        cartridge without shoulder, neck or flange."""
        return cls(body_outer_diameter=outer_diameter, wall_thickness=wall_thickness,
                   length=length, shoulder_length=0.0, neck_outer_diameter=outer_diameter,
                   neck_length=0.0, flange_outer_diameter=outer_diameter, flange_length=0.0,
                   flange_chamfer=0.0, material=material)

    # ------------------------------------------------------------------ scene files
    def geometry_dict(self) -> dict[str, float]:
        """The dimensions (m) as a plain mapping: the ``[cartridge]`` table of a scene file."""
        return {f.name: float(getattr(self, f.name)) for f in fields(self)
                if f.name != "material"}

    @classmethod
    def from_geometry(cls, values: Any, material: Material = PAPER_GLASS,
                      source: str = "scene") -> "Cartridge":
        """A cartridge from a scene file's ``[cartridge]`` table: ``preset`` (one of
        :data:`CARTRIDGE_PRESETS`; default ``"iso13926_3ml"``) and any dimension overriding
        it (m), made of ``material``. Unknown keys and non-numbers are errors naming the key
        and ``source``."""
        if isinstance(values, Cartridge):
            return replace(values, material=material)
        if values is None:
            values = {}
        if not isinstance(values, Mapping):
            raise InvalidParameterError(f"invalid [cartridge] in {source}: must be a table of "
                                        "dimensions (m)")
        values = dict(values)
        values.pop("material", None)  # a saved document's copy; the scene's glass rules
        preset = values.pop("preset", "iso13926_3ml")
        if preset not in CARTRIDGE_PRESETS:
            raise InvalidParameterError(f"invalid preset = {preset!r} in [cartridge] of {source}: "
                                        f"must be one of {tuple(CARTRIDGE_PRESETS)}")
        allowed = [f.name for f in fields(cls) if f.name != "material"]
        for key, value in values.items():
            if key not in allowed:
                raise InvalidParameterError(f"unknown key {key!r} in [cartridge] of {source}; "
                                            "allowed keys: preset, " + ", ".join(allowed))
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InvalidParameterError(f"invalid {key} = {value!r} in [cartridge] of "
                                            f"{source}: must be a number of metres")
        return cls(**{**CARTRIDGE_PRESETS[preset], **values}, material=material)

    # ------------------------------------------------------------------ geometry
    @property
    def body_length(self) -> float:
        """Axial length of the cylindrical body, m."""
        return self.length - self.shoulder_length - self.neck_length - self.flange_length

    @property
    def body_mid_radius(self) -> float:
        """Mid-surface radius of the body wall, m: the shell radius of Reissner's formula."""
        return 0.5 * (self.body_outer_diameter - self.wall_thickness)

    def stations(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stations ``(z, r_in, r_out)`` of the glass, m, z increasing from 0 to ``length``.

        Between stations both radii are linear in z; they are continuous everywhere. This is
        the single geometric source used by mass properties, bead clump and FEM meshes.
        """
        t = self.wall_thickness
        rb_out = 0.5 * self.body_outer_diameter
        rn_out = 0.5 * self.neck_outer_diameter
        rf_out = 0.5 * self.flange_outer_diameter
        r_bore = rn_out - t
        z1 = self.body_length
        z2 = z1 + self.shoulder_length
        z3 = z2 + self.neck_length
        z4 = z3 + self.flange_chamfer
        z5 = self.length
        z = [0.0, z1, z2, z3, z4, z5]
        r_in = [rb_out - t, rb_out - t, r_bore, r_bore, r_bore, r_bore]
        r_out = [rb_out, rb_out, rn_out, rn_out, rf_out, rf_out]
        # drop zero-length segments (e.g. shoulder_length = 0 gives a flat step, which is kept
        # as two stations at the same z only if the radii differ)
        keep = [0]
        for k in range(1, len(z)):
            same = z[k] == z[keep[-1]] and r_in[k] == r_in[keep[-1]] and r_out[k] == r_out[keep[-1]]
            if not same:
                keep.append(k)
        return (
            np.array([z[k] for k in keep]),
            np.array([r_in[k] for k in keep]),
            np.array([r_out[k] for k in keep]),
        )

    def radii_at(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Inner and outer glass radius (m) at heights ``z`` (m), 0 <= z <= length."""
        zs, ri, ro = self.stations()
        z = np.asarray(z, dtype=float)
        return np.interp(z, zs, ri), np.interp(z, zs, ro)

    def _segment_integrals(self, z_lo: float = 0.0, z_hi: float | None = None) -> np.ndarray:
        """∫ [A, A z, π/2 (ro⁴ − ri⁴), π/4 (ro⁴ − ri⁴), A z²] dz over z_lo..z_hi with
        A = π (ro² − ri²) — exact (Gauss–Legendre, 3 points per linear segment)."""
        zs, ri, ro = self.stations()
        if z_hi is None:
            z_hi = self.length
        out = np.zeros(5)
        for k in range(len(zs) - 1):
            a, b = max(zs[k], z_lo), min(zs[k + 1], z_hi)
            if b <= a:
                continue
            zq = a + (b - a) * _GL_X
            w = (b - a) * _GL_W
            rin, rout = self.radii_at(zq)
            area = math.pi * (rout**2 - rin**2)
            q4 = rout**4 - rin**4
            out += np.array([
                (w * area).sum(),
                (w * area * zq).sum(),
                (w * 0.5 * math.pi * q4).sum(),
                (w * 0.25 * math.pi * q4).sum(),
                (w * area * zq**2).sum(),
            ])
        return out

    @property
    def glass_volume(self) -> float:
        """Volume of glass, m³."""
        return float(self._segment_integrals()[0])

    @property
    def mass(self) -> float:
        """Mass of the empty cartridge, kg."""
        return self.glass_volume * self.material.density

    def mass_properties(self) -> MassProperties:
        """Mass (kg), centre of mass (m, on the axis) and inertia tensor about the centre of
        mass (kg·m², diagonal: I_xx = I_yy transverse, I_zz axial)."""
        vol, vz, izz, ixx_disc, vz2 = self._segment_integrals()
        rho = self.material.density
        mass = rho * vol
        zc = vz / vol
        i_axial = rho * izz
        i_trans = rho * (ixx_disc + vz2) - mass * zc**2
        return MassProperties(
            mass=mass,
            center_of_mass=np.array([0.0, 0.0, zc]),
            inertia=np.diag([i_trans, i_trans, i_axial]),
        )

    @property
    def center_of_mass(self) -> np.ndarray:
        """Centre of mass, m, in the frame of :meth:`stations` (on the axis)."""
        return self.mass_properties().center_of_mass

    @property
    def inertia_tensor(self) -> np.ndarray:
        """Inertia tensor about the centre of mass, kg·m²."""
        return self.mass_properties().inertia

    # ------------------------------------------------------------------ derived bodies
    def equivalent_sphere(self) -> EquivalentSphere:
        """Solid sphere of the same mass and material (Boso et al., Fig. 2a)."""
        m = self.mass
        r = (3.0 * m / (4.0 * math.pi * self.material.density)) ** (1.0 / 3.0)
        return EquivalentSphere(radius=r, mass=m, moment_of_inertia=0.4 * m * r * r,
                                material=self.material)

    def bead_clump(self, n_beads: int = 632, bead_radius: float | None = None) -> BeadClump:
        """A clump of ``n_beads`` beads (paper: 632) standing for this cartridge.

        Beads sit in rings along the outer profile; a bead of radius ``r_b`` (default: half
        the wall thickness, so a bead spans the wall) is centred at ``r_out(z) − r_b`` so
        that the clump's envelope has the cartridge's outer diameter, and the rings run
        from z = r_b to z = length − r_b so that it has the cartridge's length. Ring counts
        follow the circumference so beads are evenly spread; the total is exactly
        ``n_beads``. Each bead carries the glass of the slab of wall between the mid-points
        to its neighbouring rings (divided equally within its ring), so the clump's mass is
        the cartridge's exactly and its centre of mass and inertia agree to well within 1 %
        (the remaining inertia difference is the wall's thickness, which point-like beads on
        one radius cannot carry). Centres are returned relative to the cartridge's centre
        of mass.
        """
        if isinstance(n_beads, bool) or not isinstance(n_beads, (int, np.integer)):
            raise InvalidParameterError(f"invalid n_beads = {n_beads!r}: must be an integer >= 24")
        if n_beads < 24:
            raise InvalidParameterError(f"invalid n_beads = {n_beads!r}: must be an integer >= 24")
        r_b = 0.5 * self.wall_thickness if bead_radius is None else check_range(
            "bead_radius", bead_radius, 0.0, 0.5 * self.neck_outer_diameter)
        # the outer profile as a polyline, sampled finely, and its arc length
        zs, _, ro_st = self.stations()
        z_fine = np.unique(np.concatenate([zs, np.linspace(r_b, self.length - r_b, 4001)]))
        z_fine = z_fine[(z_fine >= r_b) & (z_fine <= self.length - r_b)]
        _, ro_f = self.radii_at(z_fine)
        rc_f = np.maximum(ro_f - r_b, 0.0)
        ds = np.hypot(np.diff(z_fine), np.diff(rc_f))
        s_f = np.concatenate([[0.0], np.cumsum(ds)])
        s_total = s_f[-1]
        mean_circ = 2.0 * math.pi * float(np.sum(0.5 * (rc_f[1:] + rc_f[:-1]) * ds)) / s_total
        spacing = math.sqrt(s_total * mean_circ / n_beads)
        n_rings = max(2, int(round(s_total / spacing)))
        s_ring = np.linspace(0.0, s_total, n_rings)
        z_ring = np.interp(s_ring, s_f, z_fine)
        rc_ring = np.interp(s_ring, s_f, rc_f)
        weights = np.maximum(rc_ring, 1e-12)
        raw = n_beads * weights / weights.sum()
        counts = np.maximum(np.floor(raw).astype(int), 3)
        # largest-remainder correction to hit n_beads exactly
        while counts.sum() < n_beads:
            counts[np.argmax(raw - counts)] += 1
        while counts.sum() > n_beads:
            cand = np.where(counts > 3)[0]
            counts[cand[np.argmin((raw - counts)[cand])]] -= 1
        # mass of the slab each ring stands for: mid-points between rings in z
        edges = np.concatenate([[0.0], 0.5 * (z_ring[1:] + z_ring[:-1]), [self.length]])
        rho = self.material.density
        ring_mass = np.array([
            rho * self._segment_integrals(edges[k], edges[k + 1])[0] for k in range(n_rings)
        ])
        centers, radii, masses = [], [], []
        for k in range(n_rings):
            n_k = counts[k]
            phase = 0.5 * math.pi * (k % 2) / n_k  # stagger alternate rings
            theta = phase + 2.0 * math.pi * np.arange(n_k) / n_k
            centers.append(np.column_stack([
                rc_ring[k] * np.cos(theta), rc_ring[k] * np.sin(theta), np.full(n_k, z_ring[k])
            ]))
            radii.append(np.full(n_k, r_b))
            masses.append(np.full(n_k, ring_mass[k] / n_k))
        c = np.vstack(centers)
        c[:, 2] -= self.center_of_mass[2]
        return BeadClump(centers=c, radii=np.concatenate(radii), masses=np.concatenate(masses))


#: Named cartridge geometries for scene files (``[cartridge] preset = ...``), dimensions in m.
#: ``iso13926_3ml``: the default 3 mL pen-injector cartridge of this module's text (body
#: Ø 11.6 mm, wall 1.1 mm, 64 mm long; neck and flange representative of the class).
#: ``tube``: the same body as a plain open tube of the same length (no shoulder, neck or
#: flange), as the FEM verification cases use.
CARTRIDGE_PRESETS: dict[str, dict[str, float]] = {
    "iso13926_3ml": Cartridge().geometry_dict(),
    "tube": Cartridge.tube(11.6e-3, 1.1e-3, 64.0e-3).geometry_dict(),
}
