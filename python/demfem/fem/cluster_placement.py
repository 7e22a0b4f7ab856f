"""Placement of tilted and lifted cartridges in the seven-cartridge cluster.

A cartridge's own frame has its axis along z, the open end's centre at the origin, the glass
from z = 0 to its ``length`` (m). A :class:`Placement` puts it on the belt: x_world = R x + t
(R a 3×3 proper rotation, t in m). The cluster (:class:`demfem.scenes.cluster.CartridgeCluster`)
places cartridges 2 and 3 with :func:`place_hitter`:

* **tilt** (degrees): the axis turned about the horizontal axis z × h perpendicular to the
  heading h (right-hand rule), so that a positive tilt leans the top forward along the heading
  (the top end leads and hits first) and a negative tilt leans it back (the bottom end leads);
* **lift**: the lowest point of the glass (for a tilted cartridge the outer edge of its open
  end on the trailing or leading side) is ``lift + offset_z`` above the belt;
* **gap**: the cartridge is then moved along its site direction (the line from 1's axis to its
  site) until the closest approach of its outer surface to 1's is ``gap`` (m).

Clearances are measured on the exact outer envelope (the revolved outer profile
:meth:`demfem.cartridge.Cartridge.radii_at`, closed by the end faces) sampled at the mesh's node
columns (``n_theta`` around) and every ``dz`` along the axis, radially (horizontal distance from
the other body's axis minus its outer radius at that height, in the other body's frame), both
ways: the points of A against the envelope of B and those of B against A's. On the cylindrical
body against a point or an edge this is the true normal gap; on the shoulder cone it is the gap
along the radius (larger than the normal one by 1/cos of the cone's slope at most).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError
from demfem.fem.mesh import rotation_about

__all__ = ["Placement", "tilt_rotation", "envelope_points", "clearance", "place_hitter",
           "closest_approach",
           "ANY_TILT_LIMIT_DEG"]

#: Largest |tilt| accepted, degrees: beyond ~13° the flange, not the body's shoulder edge,
#: leads a top-first impact, and the paper's DEM found the cartridges upright.
ANY_TILT_LIMIT_DEG = 10.0

#: Axial spacing of the envelope's sample rings, m.
DEFAULT_DZ = 2.5e-4


@dataclass(frozen=True)
class Placement:
    """A rigid placement x_world = ``rotation`` @ x + ``translation`` of a cartridge's own
    frame (axis z, open end at z = 0); m."""

    rotation: np.ndarray
    translation: np.ndarray

    def apply(self, points: np.ndarray) -> np.ndarray:
        """World coordinates (N, 3) m of points (N, 3) m given in the cartridge's frame."""
        return np.asarray(points, float) @ self.rotation.T + self.translation

    def local(self, points: np.ndarray) -> np.ndarray:
        """The cartridge-frame coordinates (N, 3) m of world points (N, 3) m."""
        return (np.asarray(points, float) - self.translation) @ self.rotation

    @property
    def axis(self) -> np.ndarray:
        """The cartridge's axis (open end to top) in the world, unit vector."""
        return self.rotation[:, 2].copy()


def tilt_rotation(heading_deg: float, tilt_deg: float) -> np.ndarray:
    """Rotation (3×3) by ``tilt_deg`` about the horizontal axis z × h, h = (cos, sin, 0) of
    ``heading_deg``: the axis z goes to cos(tilt) z + sin(tilt) h (top forward for tilt > 0)."""
    h = math.radians(heading_deg)
    return rotation_about((-math.sin(h), math.cos(h), 0.0), tilt_deg)


def envelope_points(cartridge: Cartridge, n_theta: int, dz: float = DEFAULT_DZ) -> np.ndarray:
    """Points (N, 3) m on the outer envelope of ``cartridge`` in its own frame: the outer
    profile at every station and every ``dz`` along the axis, at ``n_theta`` angles around
    (those of the mesh's node columns, 0° included), plus the end faces' outer rings."""
    zs, _, _ = cartridge.stations()
    n = max(2, int(math.ceil(cartridge.length / dz)) + 1)
    z = np.unique(np.concatenate([zs, np.linspace(0.0, cartridge.length, n)]))
    _, ro = cartridge.radii_at(z)
    th = np.radians(np.arange(int(n_theta)) * 360.0 / int(n_theta))
    zz = np.repeat(z, th.size)
    rr = np.repeat(ro, th.size)
    tt = np.tile(th, z.size)
    return np.column_stack([rr * np.cos(tt), rr * np.sin(tt), zz])


def _one_way(points_world: np.ndarray, other: Placement, cartridge: Cartridge) -> float:
    """Smallest radial clearance (m) of world points against ``other``'s outer envelope:
    points beside it (0 <= z <= length in its frame) count; +inf if none is."""
    p = other.local(points_world)
    z = p[:, 2]
    beside = (z >= 0.0) & (z <= cartridge.length)
    if not np.any(beside):
        return math.inf
    _, ro = cartridge.radii_at(z[beside])
    return float(np.min(np.hypot(p[beside, 0], p[beside, 1]) - ro))


def clearance(a: Placement, b: Placement, cartridge: Cartridge, n_theta: int,
              dz: float = DEFAULT_DZ, points: Optional[np.ndarray] = None) -> float:
    """Closest approach (m, radial, both ways; module text) of two placed cartridges of the
    same geometry: negative when they overlap, +inf when neither is beside the other."""
    pts = envelope_points(cartridge, n_theta, dz) if points is None else points
    return min(_one_way(a.apply(pts), b, cartridge), _one_way(b.apply(pts), a, cartridge))


def place_hitter(cartridge: Cartridge, site_xy: np.ndarray, heading_deg: float,
                 tilt_deg: float, base_z: float, gap: float, n_theta: int,
                 centre: Optional[Placement] = None, dz: float = DEFAULT_DZ) -> Placement:
    """The placement of a hitting cartridge (module text): tilted by ``tilt_deg`` about the
    horizontal axis perpendicular to ``heading_deg``, its lowest glass point at ``base_z``
    (m) above the belt, moved along the direction of ``site_xy`` (m, from 1's axis) until its
    closest approach to ``centre`` (cartridge 1's placement; default: upright, open end at
    the origin) is ``gap`` (m), to 1e-12 m."""
    site = np.asarray(site_xy, float)
    dist = float(np.hypot(*site))
    if not dist > 0:
        raise InvalidParameterError(f"invalid site_xy = {site_xy!r}: must be off 1's axis")
    u = np.array([site[0] / dist, site[1] / dist, 0.0])
    rot = tilt_rotation(heading_deg, tilt_deg)
    pts = envelope_points(cartridge, n_theta, dz)
    world = pts @ rot.T
    z_low = float(world[:, 2].min())
    one = centre or Placement(np.eye(3), np.zeros(3))
    d = cartridge.body_outer_diameter

    def placed(s: float) -> Placement:
        return Placement(rot, np.array([site[0], site[1], base_z - z_low]) + s * u)

    def gap_at(s: float) -> float:
        return clearance(placed(s), one, cartridge, n_theta, dz, pts)

    lo, hi = -0.5 * d, cartridge.length
    f_lo, f_hi = gap_at(lo) - gap, gap_at(hi) - gap
    if not (f_lo < 0 < f_hi):
        raise InvalidParameterError(
            f"invalid tilt_deg = {tilt_deg!r}: no position along the site direction gives a "
            f"start gap of {gap:g} m to cartridge 1")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        f_mid = gap_at(mid) - gap
        if f_mid < 0:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-13:
            break
    return placed(hi)


def closest_approach(a: Placement, b: Placement, cartridge: Cartridge, n_theta: int,
                     dz: float = DEFAULT_DZ, tol: float = 1e-9) -> tuple[float, np.ndarray]:
    """Where ``b`` comes closest to ``a`` (module text): the clearance (m) and the world
    points (K, 3) m of ``a``'s envelope samples within ``tol`` (m) of the closest, or, where
    ``a``'s samples are not the closest (a point or an edge of ``b`` against ``a``'s smooth
    surface), ``b``'s closest samples projected radially onto ``a``'s envelope."""
    pts = envelope_points(cartridge, n_theta, dz)

    def gaps(p_world: np.ndarray, other: Placement) -> np.ndarray:
        p = other.local(p_world)
        z = p[:, 2]
        g = np.full(len(p), np.inf)
        beside = (z >= 0.0) & (z <= cartridge.length)
        _, ro = cartridge.radii_at(z[beside])
        g[beside] = np.hypot(p[beside, 0], p[beside, 1]) - ro
        return g

    wa, wb = a.apply(pts), b.apply(pts)
    ga, gb = gaps(wa, b), gaps(wb, a)
    best = float(min(ga.min(), gb.min()))
    if not math.isfinite(best):
        return best, np.zeros((0, 3))
    if ga.min() <= gb.min() + tol:
        return best, wa[ga <= best + tol]
    near = a.local(wb[gb <= best + tol])
    r = np.hypot(near[:, 0], near[:, 1])
    _, ro = cartridge.radii_at(near[:, 2])
    near[:, :2] *= (ro / r)[:, None]
    return best, a.apply(near)
