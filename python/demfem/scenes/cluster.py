"""The seven-cartridge cluster of Boso et al. (2021), Figs. 10-13, as an FEM scene.

Frame and units (SI: m, s, kg, Pa; angles in degrees): x along the belt (the belt surface
moves towards +x), y across it, z up; the belt is the rigid plane z = 0. Top view::

                 3 (120°)     4 (60°)
                      \\        /
          2 (180°) ---   1   --- 5 (0°)          belt -> +x
                      /        \\
                 7 (240°)     6 (300°)

* Cartridge 1 stands upright at the origin, cartridges 2-7 on the six sites of the hexagon
  around it, in that order, at the site angles above (measured from +x, counter-clockwise
  seen from above). All stand upright, open end down, a hair (``lift``) above the belt, and
  start at rest except 2 and 3.
* 4-7 touch 1: their centres are at ``D + touch_gap`` from 1's (D the body outer diameter),
  ``0 <= touch_gap <= touch_tolerance`` (default gap 1e-6 m, tolerance 2e-6 m; much
  smaller gaps made the penalty contact of resting neighbours run away in our tests). Ring neighbours are then ``D + touch_gap``
  apart too, so nothing overlaps at t = 0.
* 2 and 3 start ``impact_gap`` further out (centres at ``D + impact_gap``) and move at ``v2``
  and ``v3`` (m/s) along the headings ``direction_2_deg`` and ``direction_3_deg`` (degrees
  from +x, counter-clockwise from above). Heading 0° for 2 and -60° for 3 aim straight at 1
  (head-on); any other heading adds a tangential component at impact.
* Tilt and lift of 2 and 3 (default 0: upright, standing on the belt like the rest):
  ``tilt_2_deg``, ``tilt_3_deg`` (degrees, in [-10, 10]) turn the cartridge's axis about the
  horizontal axis perpendicular to its heading (z × heading, right-hand rule): **positive =
  the top leans forward along the heading, so the top end (the body's shoulder edge) leads
  and hits 1 first; negative = the top leans back, the open (bottom) end's outer edge leads**.
  ``offset_2_z``, ``offset_3_z`` (m, in [0, length / 2]) lift the cartridge: its lowest glass
  point is ``lift + offset`` above the belt (lowering into the belt is refused). A tilted or
  lifted cartridge is then moved along its site direction until the closest approach of its
  outer surface to 1's is ``impact_gap`` (measured radially on the exact outer envelope at
  the mesh's node columns, :mod:`demfem.fem.cluster_placement`); it keeps its initial
  velocity (V along its heading, horizontal: it translates, no spin). A tilt or lift that
  makes it overlap any other cartridge at t = 0 is refused, naming the field.
  :meth:`CartridgeCluster.first_contact` gives where on 1 each hitter touches first.
* Built-in load cases (paper, Fig. 10a,b): ``max`` V2 = 0.18, V3 = 0.12 m/s and ``avg`` V2 =
  0.05, V3 = 0.025 m/s, both head-on: 2 moves along the belt straight at 1, 3 comes from
  the site 60° off the belt direction straight at 1 (heading -60°). The paper took the
  angles from the DEM velocity vectors; its figure is not in the source, so head-on is our
  reading. :meth:`CartridgeCluster.from_collisions` picks speeds and angles from a DEM run.
* ``springs=True`` (Fig. 10d): each of 4-7 is held by no-tension springs to the three ghost
  cartridges of the next ring of the hexagonal pack, which would touch it at the directions
  site ± 60° and site (from its centre). For each ghost contact, the outer-surface nodes
  of the column facing the ghost (along the cylindrical body) get a spring anchored
  ``spring_length`` beyond the node along the outward normal, with rest length
  ``spring_length``: zero force at t = 0, pushing the node back when it moves outwards,
  never pulling. The stiffness of one ghost contact defaults to the calibrated equivalent
  contact stiffness of two cartridges, :func:`demfem.contact.k_eq` at the impact speed
  ``max(v2, v3)`` (eq. 15, Hertz linearised at that speed in series with both Reissner
  shells), divided evenly over the nodes of that column.
* Meshes: ``elements = "tet"`` (``layers`` elements through the wall, 1-4) or ``"shell"``
  (flat CST + DKT triangles on the mid-surface, 6 dof per node; contact on both faces, half
  the wall thickness off the mid-surface, penalty s·E·t; default element size 2 t, as
  the tets' at one layer; ``layers`` is not used; each shell is lifted by half its end thickness, so
  that its contact surface, not its mid-surface node, is ``lift`` above the belt; profile
  stations closer than half the element size are merged, so the 0.3 mm crimp step becomes
  a short cone: its ring of thin triangles would otherwise halve the stable step). The
  number of divisions around is rounded up to a multiple of 6 so that a node column of
  every cartridge faces each of its six hexagon neighbours (vertex-to-vertex at the start,
  so ``touch_gap`` is the true gap between the contact surfaces). Shell runs have no
  Rayleigh damping and no mass scaling (``mass_scaling_dt`` must be 0).
* Contact output regions of cartridge 1: region 0 = its bottom half (z < length / 2),
  region 1 = its top half.

Scene files are TOML: flat ``key = value`` lines named as the fields, plus optional
``[cartridge]`` (geometry, m) and ``[material]`` (E Pa, nu, density kg/m^3) tables; unknown
keys are errors. :meth:`CartridgeCluster.to_toml` writes one back.
"""
from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Optional

import numpy as np

from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError, check_range
from demfem.io.atomic import write_text_atomic
from demfem.materials import PAPER_GLASS, Material

__all__ = ["CartridgeCluster", "LOAD_CASES", "SITE_ANGLES_DEG", "ClusterParts",
           "cluster_from_run"]

SCENE_NAME = "cartridge_cluster"

#: Site angles of cartridges 2-7 around 1, degrees from +x (counter-clockwise from above).
SITE_ANGLES_DEG = (180.0, 120.0, 60.0, 0.0, -60.0, -120.0)

#: Built-in load cases (paper, Fig. 10a,b): speeds m/s, headings degrees.
LOAD_CASES: dict[str, dict[str, float]] = {
    "max": {"v2": 0.18, "v3": 0.12, "direction_2_deg": 0.0, "direction_3_deg": -60.0},
    "avg": {"v2": 0.05, "v3": 0.025, "direction_2_deg": 0.0, "direction_3_deg": -60.0},
}

#: Largest speed accepted for 2, 3 and the belt, m/s.
MAX_SPEED = 10.0

_UNITS = {
    "case": "label of the load case",
    "v2": "m/s, speed of cartridge 2",
    "v3": "m/s, speed of cartridge 3",
    "direction_2_deg": "degrees from +x (belt direction), counter-clockwise from above; 0 = at 1",
    "direction_3_deg": "degrees from +x, counter-clockwise from above; -60 = at 1",
    "springs": "4-7 held by no-tension springs to ghost neighbours",
    "spring_stiffness": "N/m per ghost contact; 0 = the calibrated k_eq at max(v2, v3)",
    "spring_length": "m, rest length of the ghost springs",
    "elements": "tet or shell",
    "layers": "tet elements through the wall, 1-4",
    "target_size": "m, element size along and around; 0 = 2 t / layers (shells: 2 t)",
    "belt_speed": "m/s along +x",
    "belt_friction": "Coulomb coefficient, cartridge-belt",
    "friction": "Coulomb coefficient, cartridge-cartridge",
    "gravity": "m/s^2 along -z",
    "touch_gap": "m, gap 1 to 4-7 at t = 0 (<= touch_tolerance)",
    "touch_tolerance": "m, largest gap that counts as touching",
    "impact_gap": "m, gap 1 to 2 and 3 at t = 0",
    "lift": "m, gap between the cartridges' open ends and the belt at t = 0",
    "penalty_scale": "contact penalty scale (1 = OpenRadioss default)",
    "mass_scaling_dt": "s, raise masses so the step is at least this; 0 = none",
    "coordination": "touching neighbours of 1 in the DEM case it stands for (information)",
    "tilt_2_deg": "degrees in [-10, 10] about z x heading; + top leads, - bottom leads",
    "tilt_3_deg": "degrees in [-10, 10] about z x heading; + top leads, - bottom leads",
    "offset_2_z": "m in [0, length/2], lift of 2 above lift",
    "offset_3_z": "m in [0, length/2], lift of 3 above lift",
}

#: The hitters' tilt and lift fields, by cartridge index (0-based: 2 -> 1, 3 -> 2).
_HITTER_FIELDS = {1: ("tilt_2_deg", "offset_2_z", "direction_2_deg"),
                  2: ("tilt_3_deg", "offset_3_z", "direction_3_deg")}


def _flag(name: str, value: Any) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidParameterError(f"invalid {name} = {value!r}: must be true or false")
    return bool(value)


@dataclass(frozen=True)
class ClusterParts:
    """What :meth:`CartridgeCluster.parts` builds: placed meshes of 1-7, their velocities,
    site centres (7, 2) m, the region of each node of 1, and the ghost springs."""

    meshes: list
    velocities: list
    centres: np.ndarray
    regions_1: np.ndarray
    springs: list
    spring_stiffness_per_contact: float
    n_theta: int


@dataclass(frozen=True)
class CartridgeCluster:
    """Cartridge 1 in the middle of 2-7 on the belt; 2 and 3 hit it (see the module text
    for the frame and every rule). SI units; angles in degrees. Validated on creation:
    a bad field raises :class:`demfem.errors.InvalidParameterError` naming it.

    ``tilt_2_deg``, ``tilt_3_deg`` (degrees, [-10, 10]): the hitter's axis turned about
    z × heading; > 0 the top leans forward and its shoulder edge hits 1 first, < 0 the top
    leans back and its open end's edge hits first. ``offset_2_z``, ``offset_3_z`` (m,
    [0, length/2]): its lowest glass point ``lift + offset`` above the belt. Either keeps
    the start gap ``impact_gap`` to 1 (the hitter is moved along its site direction) and is
    refused if any two cartridges would overlap at t = 0."""

    case: str = "max"
    v2: float = 0.18
    v3: float = 0.12
    direction_2_deg: float = 0.0
    direction_3_deg: float = -60.0
    springs: bool = False
    spring_stiffness: float = 0.0
    spring_length: float = 1e-3
    elements: str = "tet"
    layers: int = 2
    target_size: float = 0.0
    belt_speed: float = 0.2
    belt_friction: float = 0.2
    friction: float = 0.2
    gravity: float = 9.81
    touch_gap: float = 1e-6
    touch_tolerance: float = 2e-6
    impact_gap: float = 20e-6
    lift: float = 1e-7
    penalty_scale: float = 1.0
    mass_scaling_dt: float = 0.0
    coordination: int = 6
    tilt_2_deg: float = 0.0
    tilt_3_deg: float = 0.0
    offset_2_z: float = 0.0
    offset_3_z: float = 0.0
    cartridge: Cartridge = field(default_factory=Cartridge)

    def __post_init__(self) -> None:
        if not isinstance(self.case, str) or not self.case:
            raise InvalidParameterError(f"invalid case = {self.case!r}: must be a non-empty label")
        for name in ("v2", "v3", "belt_speed"):
            v = getattr(self, name)
            if isinstance(v, bool):
                raise InvalidParameterError(f"invalid {name} = {v!r}: must be a speed in m/s")
            check_range(name, v, 0.0, MAX_SPEED, lo_open=False, hi_open=False)
        for name in ("direction_2_deg", "direction_3_deg"):
            check_range(name, getattr(self, name), -360.0, 360.0, lo_open=False, hi_open=False)
        object.__setattr__(self, "springs", _flag("springs", self.springs))
        if self.elements not in ("tet", "shell"):
            raise InvalidParameterError(
                f"invalid elements = {self.elements!r}: must be 'tet' or 'shell'")
        if isinstance(self.layers, bool) or not isinstance(self.layers, (int, np.integer)) \
                or not 1 <= self.layers <= 4:
            raise InvalidParameterError(
                f"invalid layers = {self.layers!r}: must be an integer in [1, 4]")
        if isinstance(self.coordination, bool) or not isinstance(self.coordination, (int, np.integer)) \
                or not 0 <= self.coordination <= 12:
            raise InvalidParameterError(
                f"invalid coordination = {self.coordination!r}: must be an integer in [0, 12]")
        check_range("spring_stiffness", self.spring_stiffness, 0.0, math.inf, lo_open=False)
        check_range("spring_length", self.spring_length, 0.0, 1.0)
        check_range("target_size", self.target_size, 0.0, 0.1, lo_open=False)
        check_range("belt_friction", self.belt_friction, 0.0, 10.0, lo_open=False)
        check_range("friction", self.friction, 0.0, 10.0, lo_open=False)
        check_range("gravity", self.gravity, 0.0, 1e3, lo_open=False)
        check_range("touch_tolerance", self.touch_tolerance, 0.0, 1e-3)
        check_range("penalty_scale", self.penalty_scale, 0.0, 1e3)
        check_range("mass_scaling_dt", self.mass_scaling_dt, 0.0, 1e-3, lo_open=False)
        if self.elements == "shell" and self.mass_scaling_dt > 0:
            raise InvalidParameterError(
                f"invalid mass_scaling_dt = {self.mass_scaling_dt!r} with elements = 'shell': "
                "the shell solver has no mass scaling (must be 0)")
        check_range("lift", self.lift, 0.0, 1e-3, lo_open=False)
        if not isinstance(self.cartridge, Cartridge):
            raise InvalidParameterError(
                f"invalid cartridge = {self.cartridge!r}: must be a demfem.cartridge.Cartridge")
        gap = float(self.touch_gap)
        if not math.isfinite(gap) or gap < 0:
            raise InvalidParameterError(
                f"invalid touch_gap = {self.touch_gap!r}: negative, cartridges 4-7 would "
                "overlap their neighbours (must be in [0, touch_tolerance] m)")
        if gap > self.touch_tolerance:
            raise InvalidParameterError(
                f"invalid touch_gap = {gap!r}: must be at most touch_tolerance = "
                f"{self.touch_tolerance!r} m for 4-7 to touch 1")
        ig = float(self.impact_gap)
        if not math.isfinite(ig) or ig <= 0:
            raise InvalidParameterError(
                f"invalid impact_gap = {self.impact_gap!r}: must be > 0 m (cartridges 2 and 3 "
                "would overlap 1)")
        check_range("impact_gap", ig, 0.0, self.cartridge.body_outer_diameter)
        if self.v2 == 0 and self.v3 == 0:
            raise InvalidParameterError("invalid v2 = v3 = 0: at least one of 2 and 3 must move")
        from demfem.fem.cluster_placement import ANY_TILT_LIMIT_DEG

        for name in ("tilt_2_deg", "tilt_3_deg"):
            object.__setattr__(self, name, check_range(
                name, getattr(self, name), -ANY_TILT_LIMIT_DEG, ANY_TILT_LIMIT_DEG,
                lo_open=False, hi_open=False))
        for name in ("offset_2_z", "offset_3_z"):
            v = getattr(self, name)
            if isinstance(v, (int, float)) and not isinstance(v, bool) and v < 0:
                raise InvalidParameterError(
                    f"invalid {name} = {v!r}: negative, the cartridge would sink into the belt "
                    f"(must be in [0, {0.5 * self.cartridge.length:g}] m, a lift)")
            object.__setattr__(self, name, check_range(
                name, v, 0.0, 0.5 * self.cartridge.length, lo_open=False, hi_open=False))
        self._check_no_overlap()

    # ------------------------------------------------------------------ cases
    @classmethod
    def load_case(cls, name: str, **overrides: Any) -> "CartridgeCluster":
        """The built-in load case ``name`` ("max" or "avg"), with optional field overrides."""
        if name not in LOAD_CASES:
            raise InvalidParameterError(
                f"invalid case = {name!r}: must be one of {', '.join(LOAD_CASES)} or a scene file")
        return cls(**{"case": name, **LOAD_CASES[name], **overrides})

    @classmethod
    def from_collisions(cls, onsets: np.ndarray, which: str = "max", window: float = 2e-3,
                        **overrides: Any) -> "CartridgeCluster":
        """Pick the load case from a DEM table run's collision onsets (as the paper did by
        hand).

        ``onsets``: a table of :data:`demfem.analysis.collisions.ONSET_DTYPE` (e.g.
        ``TableRunRecord.onsets`` of :func:`demfem.dem.table_run.run_table`). A sphere
        hit twice by different partners with onsets at most ``window`` s apart is a
        candidate; its stronger impact (normal speed) becomes cartridge 2, the weaker 3.

        * ``which="max"``: the candidate whose two impacts have the largest summed normal
          speed;
        * ``which="typical"``: the medians over all candidates of the stronger and of the
          weaker speed, angle and coordination.

        The impact angle atan2(v_t, v_n) of each onset turns the head-on heading (0° for 2,
        -60° for 3) counter-clockwise by that angle (the onset table has no sign for the
        tangential part, so the side is a convention). ``coordination`` is that of the hit
        sphere at the onset. Speeds above 10 m/s are refused by the scene's validation.
        """
        from demfem.analysis.collisions import ONSET_DTYPE

        if which not in ("max", "typical"):
            raise InvalidParameterError(f"invalid which = {which!r}: must be 'max' or 'typical'")
        check_range("window", window, 0.0, math.inf, lo_open=False)
        t = np.asarray(onsets)
        names = t.dtype.names or ()
        if not names or any(n not in names for n in (ONSET_DTYPE.names or ())):
            raise InvalidParameterError(
                "invalid onsets: must be a structured array with the fields of "
                "demfem.analysis.collisions.ONSET_DTYPE")
        cands = _impact_pairs(t, float(window))
        if not cands:
            raise InvalidParameterError(
                f"invalid onsets: no sphere has two impacts by different partners within "
                f"window = {window:g} s ({len(t)} onsets)")
        if which == "max":
            best = max(cands, key=lambda c: (c[0][0] + c[1][0], c[0][0]))
            (v2, a2, z2), (v3, a3, z3) = best
            coord = max(z2, z3)
        else:
            arr = np.array([[c[0][0], c[0][1], c[1][0], c[1][1], max(c[0][2], c[1][2])]
                            for c in cands], float)
            v2, a2, v3, a3, coord = np.median(arr, axis=0)
        values: dict[str, Any] = {"case": f"dem_{which}", "v2": float(v2), "v3": float(v3),
                  "direction_2_deg": float(np.degrees(a2)),
                  "direction_3_deg": float(-60.0 + np.degrees(a3)),
                  "coordination": int(min(12, max(0, round(float(coord)))))}
        values.update(overrides)
        return cls(**values)

    # ------------------------------------------------------------------ geometry
    @property
    def material(self) -> Material:
        return self.cartridge.material

    @property
    def diameter(self) -> float:
        """Body outer diameter D, m."""
        return float(self.cartridge.body_outer_diameter)

    def sites(self) -> np.ndarray:
        """Site centres (x, y) of cartridges 1-7, (7, 2) m: 1 at the origin, 2 and 3 at
        ``D + impact_gap``, 4-7 at ``D + touch_gap`` along their site angles."""
        d = self.diameter
        out = np.zeros((7, 2))
        for k, phi in enumerate(SITE_ANGLES_DEG):
            r = d + (self.impact_gap if k < 2 else self.touch_gap)
            out[k + 1] = r * np.array([math.cos(math.radians(phi)), math.sin(math.radians(phi))])
        return out

    def is_upright(self) -> bool:
        """True when 2 and 3 stand upright on the belt (no tilt, no offset)."""
        return not any((self.tilt_2_deg, self.tilt_3_deg, self.offset_2_z, self.offset_3_z))

    def placements(self) -> list:
        """Placements of 1-7 (:class:`demfem.fem.cluster_placement.Placement`, the glass's
        own frame: axis z, open end at z = 0) at t = 0: upright at their sites with the open
        end ``lift`` above the belt, 2 and 3 tilted and lifted as set (module text)."""
        from demfem.fem.cluster_placement import Placement, place_hitter

        sites = self.sites()
        out = [Placement(np.eye(3), np.array([x, y, float(self.lift)])) for x, y in sites]
        for k, (tilt, offset, heading) in _HITTER_FIELDS.items():
            tilt_v, off_v = getattr(self, tilt), getattr(self, offset)
            if tilt_v == 0 and off_v == 0:
                continue
            try:
                out[k] = place_hitter(self.cartridge, sites[k], getattr(self, heading), tilt_v,
                                      float(self.lift) + off_v, float(self.impact_gap),
                                      self.n_theta(), centre=out[0])
            except InvalidParameterError as exc:
                raise InvalidParameterError(
                    f"invalid {tilt} = {tilt_v!r} with {offset} = {off_v!r}: {exc}") from None
        return out

    def centres(self) -> np.ndarray:
        """Positions (x, y) of the open ends' centres of 1-7 at t = 0, (7, 2) m: the sites,
        except for a tilted or lifted 2 or 3 (moved to keep the start gap)."""
        if self.is_upright():
            return self.sites()
        return np.array([p.translation[:2] for p in self.placements()])

    def first_contact(self) -> dict[str, dict[str, float]]:
        """Where 2 and 3 are closest to 1 at t = 0 (their first contact when they move
        straight at it): ``{"2": {"gap_m", "z_m", "theta_deg"}, "3": ...}``, z on 1 from its
        open end (m), theta the angle around 1 (degrees from +x); the closest of 1's
        envelope samples, ties averaged (a line contact gives its middle)."""
        from demfem.fem.cluster_placement import closest_approach

        pl = self.placements()
        out = {}
        for k in (1, 2):
            gap, pts = closest_approach(pl[0], pl[k], self.cartridge, self.n_theta())
            z = pts[:, 2] - float(self.lift)
            th = np.degrees(np.arctan2(pts[:, 1], pts[:, 0]))
            out[str(k + 1)] = {"gap_m": float(gap), "z_m": float(np.mean(z)),
                               "z_min_m": float(np.min(z)), "z_max_m": float(np.max(z)),
                               "theta_deg": float(np.mean(th))}
        return out

    def velocities(self) -> list[tuple[float, float, float]]:
        """Initial velocities of 1-7 (m/s): 2 and 3 along their headings, the rest at rest."""
        v = [(0.0, 0.0, 0.0)] * 7
        for k, speed, heading in ((1, self.v2, self.direction_2_deg), (2, self.v3, self.direction_3_deg)):
            h = math.radians(heading)
            v[k] = (speed * math.cos(h), speed * math.sin(h), 0.0)
        return v

    def _check_no_overlap(self) -> None:
        if not self.is_upright():
            self._check_placed_clearance()
            return
        c = self.centres()
        d = self.diameter
        for i in range(7):
            for j in range(i + 1, 7):
                dist = float(np.hypot(*(c[i] - c[j])))
                if dist < d * (1.0 - 1e-12):
                    raise InvalidParameterError(
                        f"invalid start positions: cartridges {i + 1} and {j + 1} overlap "
                        f"({dist:.6g} m apart, less than the diameter {d:g} m)")

    def _check_placed_clearance(self) -> None:
        """Refuse a tilt or lift that makes 2 or 3 overlap another cartridge at t = 0: pairs
        with a tilted or lifted cartridge by their envelopes' clearance, the others by their
        centre distance."""
        from demfem.fem.cluster_placement import ANY_TILT_LIMIT_DEG, clearance, envelope_points

        pl = self.placements()
        moved = {k for k in (1, 2) if not self._upright_hitter(k)}
        pts = envelope_points(self.cartridge, self.n_theta())
        c = self.sites()
        for i in range(7):
            for j in range(i + 1, 7):
                if {i, j} & moved:
                    gap = clearance(pl[i], pl[j], self.cartridge, self.n_theta(), points=pts)
                    if gap >= 0.0:
                        continue
                    names = " and ".join(f"{f} = {getattr(self, f)!r}"
                                         for q in sorted({i, j} & moved)
                                         for f in _HITTER_FIELDS[q][:2])
                    raise InvalidParameterError(
                        f"invalid {names}: cartridges {i + 1} and {j + 1} would overlap at "
                        f"t = 0 (closest approach {gap:.3g} m); tilts must be in "
                        f"[-{ANY_TILT_LIMIT_DEG:g}, {ANY_TILT_LIMIT_DEG:g}] degrees and leave "
                        "every pair apart (a smaller tilt, another heading or a lift)")
                dist = float(np.hypot(*(c[i] - c[j])))
                if dist < self.diameter * (1.0 - 1e-12):
                    raise InvalidParameterError(
                        f"invalid start positions: cartridges {i + 1} and {j + 1} overlap "
                        f"({dist:.6g} m apart, less than the diameter {self.diameter:g} m)")

    def _upright_hitter(self, k: int) -> bool:
        tilt, offset, _ = _HITTER_FIELDS[k]
        return getattr(self, tilt) == 0 and getattr(self, offset) == 0

    def n_theta(self) -> int:
        """Divisions around of the meshes: the mesher's default for the element size,
        rounded up to a multiple of 6."""
        h = self.element_size()
        n = max(12, int(math.ceil(2 * math.pi * 0.5 * self.diameter / h)))
        return int(6 * math.ceil(n / 6))

    def element_size(self) -> float:
        """``target_size`` if set, else 2 t / layers for tets and 2 t for shells (m)."""
        if self.target_size > 0:
            return float(self.target_size)
        layers = 1 if self.elements == "shell" else self.layers
        return 2.0 * self.cartridge.wall_thickness / layers

    def ghost_stiffness(self) -> float:
        """Stiffness of one ghost contact, N/m: ``spring_stiffness`` if set, else the
        calibrated k_eq of two cartridges at max(v2, v3) (eq. 15)."""
        if self.spring_stiffness > 0:
            return float(self.spring_stiffness)
        from demfem.contact import ContactBody, k_eq

        cb = ContactBody.from_cartridge(self.cartridge)
        return float(k_eq(cb, cb, max(self.v2, self.v3)))

    def parts(self) -> ClusterParts:
        """Meshes, velocities, regions and springs of the cluster (no solver yet)."""
        from demfem.fem.mesh import cartridge_shell_mesh, cartridge_tet_mesh
        from demfem.fem.model import GhostSprings

        c = self.cartridge
        n_theta = self.n_theta()
        shell = self.elements == "shell"
        base: Any
        if shell:
            base = cartridge_shell_mesh(c, target_size=self.element_size(), n_theta=n_theta,
                                        min_station_gap=0.5 * self.element_size())
            # The open end's ring carries half its thickness below it (its contact surface).
            bottom = np.unique(base.triangles[np.any(base.nodes[base.triangles][:, :, 2] <= 1e-12, axis=1)])
            tri_b = np.any(np.isin(base.triangles, bottom), axis=1)
            z0 = 0.5 * float(np.max(base.thickness[tri_b]))
        else:
            base = cartridge_tet_mesh(c, layers=int(self.layers), target_size=self.element_size(),
                                      n_theta=n_theta)
            z0 = 0.0
        centres = self.centres()
        # Each glass placement, the mesh's own offset added (a shell's open-end ring carries
        # half its thickness below its mid-surface nodes).
        meshes = [base.placed(p.rotation, p.translation + np.array([0.0, 0.0, z0]))
                  for p in self.placements()]
        regions_1 = (meshes[0].nodes[:, 2] >= self.lift + z0 + 0.5 * c.length).astype(np.int64)
        springs = []
        k_contact = 0.0
        if self.springs:
            k_contact = self.ghost_stiffness()
            ro = 0.5 * c.body_outer_diameter
            rel = base.nodes
            r = np.hypot(rel[:, 0], rel[:, 1])
            theta = np.degrees(np.arctan2(rel[:, 1], rel[:, 0]))
            # The outer surface's nodes (shells: the body's mid-surface nodes).
            r_col = ro - 0.5 * c.wall_thickness if shell else ro
            outer = (np.abs(r - r_col) < 1e-6 * ro) & (rel[:, 2] <= c.body_length + 1e-12)
            half = 0.5 * 360.0 / n_theta
            for k in range(3, 7):  # cartridges 4-7 (index 3..6)
                phi = SITE_ANGLES_DEG[k - 1]
                nodes, anchors, stiff = [], [], []
                for ghost in (phi - 60.0, phi, phi + 60.0):
                    dth = (theta - ghost + 180.0) % 360.0 - 180.0
                    col = np.flatnonzero(outer & (np.abs(dth) < half))
                    if col.size == 0:
                        continue
                    n = np.array([math.cos(math.radians(ghost)), math.sin(math.radians(ghost)), 0.0])
                    nodes.append(col)
                    anchors.append(meshes[k].nodes[col] + self.spring_length * n)
                    stiff.append(np.full(col.size, k_contact / col.size))
                springs.append(GhostSprings(body=k, nodes=np.concatenate(nodes),
                                            anchors=np.vstack(anchors),
                                            stiffness=np.concatenate(stiff),
                                            rest_length=float(self.spring_length)))
        return ClusterParts(meshes=meshes, velocities=self.velocities(), centres=centres,
                            regions_1=regions_1, springs=springs,
                            spring_stiffness_per_contact=k_contact, n_theta=n_theta)

    def build_model(self, parts: Optional[ClusterParts] = None, output_interval: int = 10):
        """The :class:`demfem.fem.FemModel` of the cluster: bodies named "1".."7" (1 first,
        with its bottom/top regions), the belt ("belt"), gravity, springs."""
        from demfem.fem.model import Body, ContactOptions, FemModel, RigidPlane

        p = parts or self.parts()
        bodies = [Body(p.meshes[0], velocity=p.velocities[0], name="1", regions=p.regions_1)]
        bodies += [Body(p.meshes[k], velocity=p.velocities[k], name=str(k + 1)) for k in range(1, 7)]
        belt = RigidPlane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0),
                          surface_velocity=(self.belt_speed, 0.0, 0.0),
                          friction=self.belt_friction, name="belt")
        return FemModel(
            bodies=bodies, material=self.material, rigid=[belt], springs=p.springs,
            contact=ContactOptions(penalty_scale=self.penalty_scale, friction=self.friction,
                                   output_interval=int(output_interval)),
            gravity=(0.0, 0.0, -self.gravity) if self.gravity > 0 else None,
            mass_scaling_dt=self.mass_scaling_dt or None)

    # ------------------------------------------------------------------ files
    def to_dict(self) -> dict[str, Any]:
        """Plain values: the flat fields, plus ``cartridge`` and ``material`` mappings."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            if f.name != "cartridge":
                out[f.name] = getattr(self, f.name)
        c = self.cartridge
        out["cartridge"] = {f.name: getattr(c, f.name) for f in dataclasses.fields(c)
                            if f.name != "material"}
        m = c.material
        out["material"] = {"E": m.E, "nu": m.nu, "density": m.density, "name": m.name}
        return out

    @classmethod
    def from_dict(cls, values: Mapping[str, Any], source: str = "scene") -> "CartridgeCluster":
        """A cluster from a mapping as :meth:`to_dict` makes; unknown keys are errors."""
        values = dict(values)
        scene = values.pop("scene", SCENE_NAME)
        if scene != SCENE_NAME:
            raise InvalidParameterError(f"invalid scene = {scene!r} in {source}: must be {SCENE_NAME!r}")
        flat = [f.name for f in dataclasses.fields(cls) if f.name != "cartridge"]
        geo = values.pop("cartridge", {}) or {}
        mat = values.pop("material", {}) or {}
        for key in values:
            if key not in flat:
                raise InvalidParameterError(
                    f"unknown key {key!r} in {source}; allowed keys: scene, "
                    + ", ".join(flat) + ", [cartridge], [material]")
        if not isinstance(geo, Mapping) or not isinstance(mat, Mapping):
            raise InvalidParameterError(f"invalid [cartridge]/[material] in {source}: must be tables")
        for key in mat:
            if key not in ("E", "nu", "density", "name"):
                raise InvalidParameterError(
                    f"unknown key {key!r} in [material] of {source}; allowed keys: E, nu, "
                    "density, name")
        base = PAPER_GLASS
        material = Material(E=mat.get("E", base.E), nu=mat.get("nu", base.nu),
                            density=mat.get("density", base.density),
                            name=mat.get("name", base.name if not mat else "glass"))
        cartridge = Cartridge.from_geometry(geo, material, source)
        try:
            return cls(**values, cartridge=cartridge)
        except TypeError as exc:  # pragma: no cover - keys are checked above
            raise InvalidParameterError(f"invalid {source}: {exc}") from None

    @classmethod
    def from_toml(cls, path: str | Path) -> "CartridgeCluster":
        """Load a cluster scene file (TOML; see the module text)."""
        from demfem.io.toml_file import read_toml

        path = Path(path)
        values = read_toml(path)
        return cls.from_dict(values, source=str(path))

    def toml_text(self) -> str:
        """The TOML text that :meth:`from_toml` reads back to an equal cluster."""
        d = self.to_dict()
        lines = ["# demfem seven-cartridge cluster (SI units: m, s, kg, Pa; angles in degrees).",
                 "# Frame, sites and rules: the docstring of demfem.scenes.cluster.",
                 "# Missing keys take their defaults; unknown keys are errors.",
                 f'scene = "{SCENE_NAME}"']
        for key, value in d.items():
            if isinstance(value, dict):
                continue
            unit = _UNITS.get(key, "")
            lines.append(f"{key} = {_toml_value(value)}" + (f"  # {unit}" if unit else ""))
        for table in ("cartridge", "material"):
            lines.append("")
            lines.append(f"[{table}]")
            for key, value in d[table].items():
                lines.append(f"{key} = {_toml_value(value)}")
        return "\n".join(lines) + "\n"

    def to_toml(self, path: str | Path) -> Path:
        """Write this cluster as a TOML scene file (atomically); returns the path."""
        return write_text_atomic(path, self.toml_text())


def _toml_value(value: Any) -> str:
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    value = float(value)
    if value != 0 and not 1e-4 <= abs(value) < 1e5:
        return np.format_float_scientific(value, unique=True, trim="0")
    return repr(value)


def _impact_pairs(table: np.ndarray, window: float) -> list:
    """Per sphere, every two onsets by different partners at most ``window`` s apart, as
    ((v_strong, angle_strong, z), (v_weak, angle_weak, z)); only approaching onsets (v_n > 0)."""
    table = table[np.asarray(table["normal_speed"], float) > 0]
    by_sphere: dict[int, list] = {}
    for row in table:
        for me, other, z in ((int(row["i"]), int(row["j"]), int(row["coordination_i"])),
                             (int(row["j"]), int(row["i"]), int(row["coordination_j"]))):
            by_sphere.setdefault(me, []).append(
                (float(row["time"]), other, float(row["normal_speed"]),
                 float(row["impact_angle"]), z))
    out = []
    for events in by_sphere.values():
        events.sort()
        for a in range(len(events)):
            for b in range(a + 1, len(events)):
                if events[b][0] - events[a][0] > window:
                    break
                if events[a][1] == events[b][1]:
                    continue
                e1, e2 = sorted((events[a], events[b]), key=lambda e: -e[2])
                out.append(((e1[2], e1[3], e1[4]), (e2[2], e2[3], e2[4])))
    return out


def cluster_from_run(run: Any, which: str = "max", **overrides: Any) -> CartridgeCluster:
    """The cluster whose load case comes from a DEM table run
    (:meth:`CartridgeCluster.from_collisions` on its onsets), with the run's cartridge, glass
    and friction. ``run``: a :class:`demfem.dem.table_run.TableRun`, a ``table_run.npz``
    or the folder of a ``demfem run`` / ``demfem assess`` that holds one."""
    from demfem.errors import DemfemIOError
    from demfem.dem.table_run import TableRun

    if not isinstance(run, TableRun):
        path = Path(run)
        f = path / "table_run.npz" if path.is_dir() else path
        if not f.is_file():
            raise DemfemIOError(f"invalid run {path}: no table run there (a demfem run or "
                                "demfem assess folder holds table_run.npz)")
        run = TableRun.load(f)
        if not len(run.onsets) and ((f.parent / "events.npz").is_file()
                                    or (f.parent / "events.parquet").is_file()):
            # an assessment keeps the digest of its onsets, and its events
            return _cluster_from_events(run, f.parent, which, overrides)
    table = run.table
    values = {"cartridge": table.cartridge, "friction": table.friction, **overrides}
    return CartridgeCluster.from_collisions(run.onsets, which=which, **values)


def _cluster_from_events(run: Any, folder: Path, which: str,
                         overrides: dict[str, Any]) -> CartridgeCluster:
    """:func:`cluster_from_run` from an assessment's events (cartridge–cartridge impacts):
    its ``events.npz`` while the job is unfinished, else its ``events.parquet`` (speeds and
    angle in single precision there)."""
    from demfem.analysis.collisions import ONSET_DTYPE

    if (folder / "events.npz").is_file():
        with np.load(folder / "events.npz", allow_pickle=False) as data:
            ev = data["events"]
        ev = ev[ev["partner"] == 0]
        columns = {k: ev[k] for k in ("i", "j", "time", "normal_speed", "tangential_speed",
                                      "impact_angle")}
    else:
        import pyarrow.parquet as pq

        from demfem.assess.impact import PARTNERS

        names = {"i": "i", "j": "j", "time": "time_s", "normal_speed": "normal_speed_m_per_s",
                 "tangential_speed": "tangential_speed_m_per_s",
                 "impact_angle": "impact_angle_deg"}
        rows = pq.read_table(folder / "events.parquet", columns=[*names.values(), "partner"])
        sphere = np.asarray(rows.column("partner").cast("string").to_numpy(
            zero_copy_only=False) == PARTNERS[0])
        columns = {k: rows.column(n).to_numpy()[sphere] for k, n in names.items()}
        columns["impact_angle"] = np.radians(np.asarray(columns["impact_angle"], float))
    onsets = np.zeros(len(columns["i"]), ONSET_DTYPE)
    for k, v in columns.items():
        onsets[k] = v
    table = run.table
    values = {"cartridge": table.cartridge, "friction": table.friction, **overrides}
    return CartridgeCluster.from_collisions(onsets, which=which, **values)
