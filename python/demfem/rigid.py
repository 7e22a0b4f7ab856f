"""Full-shape cartridges: numpy in, numpy out, around the Rust engine ``RigidSimulation``.

A cartridge is a rigid body — a clump of beads (``Cartridge.bead_clump``, 632 beads as in the
paper), the exact body of revolution as parry3d convex pieces (``Cartridge.stations``,
particle ``"cylinder"``) or the same body of revolution with analytic contact tests (particle
``"revolution"``, the fast exact shape: frustums, edge circles and faces) —
with Hertz + Tsuji normal contacts and Mindlin–Coulomb friction, on a belt between plane and
polygon walls (the table's gate moves harmonically). Positions are centres of mass (m);
orientations are quaternions (w, x, y, z) of the cartridge frame (axis z, bottom to top);
angular velocities are in the world frame (rad/s). SI units throughout.

Example::

    from demfem import rigid
    from demfem.scenes.table import AccumulationTable
    sim = rigid.from_scene(AccumulationTable(particle="clump", wall_height=0.07).build())
    rigid.run(sim, 0.5)
    print(sim.tilt_angles())
"""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from demfem._core import RigidSimulation
from demfem.cartridge import Cartridge
from demfem.dem import Progress, material, scene_walls
from demfem.dem import run as _run
from demfem.errors import InvalidParameterError
from demfem.scenes.table import cartridge_sites

__all__ = [
    "RigidSimulation",
    "FULL_SHAPES",
    "PLACES",
    "place_of",
    "contact_places",
    "at_place",
    "shape_dict",
    "upright",
    "from_scene",
    "refeed_of",
    "run",
]

#: Particle kinds this module builds ("cylinder" is the exact parry shape, "revolution" the
#: same body of revolution with analytic contact tests).
FULL_SHAPES = ("clump", "cylinder", "revolution")


def shape_dict(particle: str, cartridge: Optional[Cartridge] = None, n_beads: int = 632) -> dict[str, Any]:
    """The engine's shape dict of ``cartridge`` (default: the default cartridge): for
    ``"clump"`` its ``n_beads``-bead clump (centres (n, 3) m about the centre of mass, radii m,
    masses kg), for ``"cylinder"`` its stations (z, r_in, r_out, m) as an exact parry shape, for
    ``"revolution"`` the same stations as the analytic body of revolution."""
    c = Cartridge() if cartridge is None else cartridge
    if particle == "clump":
        clump = c.bead_clump(n_beads)
        return {"kind": "clump", "centers": np.ascontiguousarray(clump.centers),
                "radii": np.ascontiguousarray(clump.radii),
                "masses": np.ascontiguousarray(clump.masses)}
    if particle in ("cylinder", "revolution"):
        z, r_in, r_out = c.stations()
        kind = "exact" if particle == "cylinder" else "revolution"
        return {"kind": kind, "z": z, "r_in": r_in, "r_out": r_out}
    raise InvalidParameterError(f"invalid particle = {particle!r}: must be one of {FULL_SHAPES}")


#: Places on a cartridge a contact can touch, bottom to top: the open end ("rim": within one
#: wall thickness of it, its edge and its end face), the body, the shoulder (from the
#: body–shoulder edge), the neck and the flange (its chamfer, side, edge and top).
PLACES = ("rim", "body", "shoulder", "neck", "flange")


def place_of(height: Any, cartridge: Optional[Cartridge] = None) -> np.ndarray:
    """The place (one of :data:`PLACES`, "" where the height is NaN) of contact points at
    ``height`` (m) along the cartridge axis from its open end."""
    c = Cartridge() if cartridge is None else cartridge
    h = np.asarray(height, float)
    bounds = np.cumsum([c.body_length, c.shoulder_length, c.neck_length])
    names = np.array(PLACES[1:], dtype=object)[np.searchsorted(bounds, h, side="right")]
    names = np.where(h <= c.wall_thickness, "rim", names)
    return np.where(np.isnan(h), "", names).astype(object)


def contact_places(sim: RigidSimulation, cartridge: Optional[Cartridge] = None,
                   walls: Optional[list[Any]] = None) -> dict[str, np.ndarray]:
    """Every contact onset of ``sim`` with where it touched each body: ``sim.onsets()``
    plus ``height_body`` and ``height_partner`` (m along the axis from the open end; NaN
    for walls and spheres), ``place_body`` and ``place_partner`` (:data:`PLACES`, "" where
    there is none), ``body_kind`` and ``partner_kind`` ("cartridge", "sphere" or "wall"),
    ``axis_angle_deg`` (the angle between the two axes, or between the axis and a wall's
    surface, degrees) and, with the scene's ``walls`` (dicts with a name, or names, in the
    engine's order), ``partner_name`` (the wall's name, "" for bodies)."""
    c = Cartridge() if cartridge is None else cartridge
    events = dict(sim.onsets())
    zc = float(c.center_of_mass[2])
    is_sphere = np.asarray(sim.is_sphere(), bool)
    body = np.asarray(events["body"], int)
    partner = np.asarray(events["partner"], int)
    wall = np.asarray(events["partner_is_wall"], bool)
    for side, key in (("body", "point_body"), ("partner", "point_partner")):
        height = np.asarray(events[key], float).reshape(-1, 3)[:, 2] + zc
        events[f"height_{side}"] = height
        events[f"place_{side}"] = place_of(height, c)
    kinds = np.where(is_sphere, "sphere", "cartridge").astype(object)
    events["body_kind"] = kinds[body] if len(body) else np.zeros(0, dtype=object)
    partner_kind = np.full(len(partner), "wall", dtype=object)
    bodies = ~wall
    partner_kind[bodies] = kinds[partner[bodies]]
    events["partner_kind"] = partner_kind
    events["axis_angle_deg"] = np.degrees(np.asarray(events["axis_angle"], float))
    if walls is not None:
        names = [w["name"] if isinstance(w, dict) else str(w) for w in walls]
        events["partner_name"] = np.array(
            [names[p] if is_wall and p < len(names) else "" for p, is_wall in zip(partner, wall)],
            dtype=object)
    return events


def at_place(events: dict[str, np.ndarray], place: str, side: str = "body") -> np.ndarray:
    """Mask of the events of :func:`contact_places` that touched ``place`` (one of
    :data:`PLACES`) on the ``side`` ("body" or "partner") body."""
    if place not in PLACES:
        raise InvalidParameterError(f"invalid place = {place!r}: must be one of {PLACES}")
    if side not in ("body", "partner"):
        raise InvalidParameterError(f"invalid side = {side!r}: must be 'body' or 'partner'")
    return np.asarray(events[f"place_{side}"] == place, bool)


def upright(n: int) -> np.ndarray:
    """(n, 4) identity quaternions (w, x, y, z): cartridges standing, axis along +z."""
    q = np.zeros((n, 4))
    q[:, 0] = 1.0
    return q


def from_scene(
    scene: Any,
    *,
    particle: Optional[str] = None,
    cartridge: Optional[Cartridge] = None,
    n_beads: int = 632,
    dt: Optional[float] = None,
    expected_max_speed: float = 1.0,
    record_onsets: bool = True,
    lift: float = 1e-6,
    threads: int = 1,
) -> RigidSimulation:
    """Build the rigid engine from an engine-neutral scene description
    (:class:`demfem.scenes.table.SceneDescription`): each sphere becomes an upright
    cartridge at the sphere's (x, y) with its bottom ``lift`` (m) above the belt.

    ``particle`` (one of :data:`FULL_SHAPES`) defaults to the scene's own ``particle``
    parameter. The cartridge (default: the scene's ``[cartridge]``) must have the
    scene's particle mass at the scene's glass density, as the equivalent sphere does, so
    that spheres and full shapes carry the same mass. ``dt`` (s) defaults to the stable limit
    of the stiffest contact at ``expected_max_speed`` (m/s); a larger one is refused.
    Bodies whose centre of mass crosses the scene's removal plane are removed; a scene that
    re-feeds them runs with ``run(sim, t, refeed=refeed_of(scene))``. ``threads``:
    the contact geometry of bodies of revolution on that many threads (bitwise the same
    result; tables of 64 bodies or more).

    Mixed tables (``cartridge_fraction < 1``, see
    :class:`demfem.scenes.table.AccumulationTable`): the sites that
    :func:`demfem.scenes.table.cartridge_sites` does not pick keep their equivalent sphere
    (radius and mass of the scene, resting ``lift`` above the belt), as a one-bead body of the
    same engine, so spheres and cartridges touch each other through the same contact laws.
    ``sim.is_sphere()`` tells them apart; their tilt angles are NaN.
    """
    if particle is None:
        particle = str(scene.parameters.get("particle", "sphere"))
    if particle not in FULL_SHAPES:
        raise InvalidParameterError(
            f"invalid particle = {particle!r}: must be one of {FULL_SHAPES} "
            "(spheres run through demfem.dem.from_scene)")
    c = (Cartridge.from_geometry((getattr(scene, "parameters", None) or {}).get("cartridge"))
         if cartridge is None else cartridge)
    pm = scene.materials[scene.particle_material]
    mass = pm["density"] * c.glass_volume
    masses = np.asarray(scene.masses, float)
    if not np.allclose(masses, mass, rtol=1e-6, atol=0.0):
        raise InvalidParameterError(
            f"invalid masses: the scene's particle mass {float(masses[0]):.6g} kg differs from the "
            f"cartridge's {mass:.6g} kg at density {pm['density']:g} kg/m^3; the equivalent "
            "sphere and the full shape must carry the same mass")
    mats = [material(pm["young_modulus"], pm["poisson_ratio"], pm["density"],
                     friction=pm["friction"], restitution=pm["restitution"])]
    walls = scene_walls(scene, lambda name: 0)
    positions = np.array(scene.positions, float, copy=True)
    fraction = float(scene.parameters.get("cartridge_fraction", 1.0))
    is_cartridge = cartridge_sites(len(positions), fraction)
    radii = np.asarray(scene.radii, float)
    positions[:, 2] = np.where(is_cartridge, float(c.center_of_mass[2]), radii) + lift
    spheres = None if bool(is_cartridge.all()) else np.ascontiguousarray(~is_cartridge)
    removal_plane = None
    if scene.removal is not None:
        p = [float(x) for x in scene.removal["point"]]
        n = [-float(x) for x in scene.removal["normal"]]
        removal_plane = ((p[0], p[1], p[2]), (n[0], n[1], n[2]))
    g = np.asarray(scene.gravity, float)
    return RigidSimulation(
        np.ascontiguousarray(positions), upright(len(positions)),
        shape_dict(particle, c, n_beads), mats[0], walls, list(scene.effects),
        gravity=(float(g[0]), float(g[1]), float(g[2])), dt=dt,
        expected_max_speed=expected_max_speed, removal_plane=removal_plane,
        record_onsets=record_onsets, spheres=spheres,
        sphere_radius=None if spheres is None else float(radii[0]), threads=threads,
    )


def refeed_of(scene: Any, *, cartridge: Optional[Cartridge] = None,
              lift: float = 1e-6) -> Optional[dict[str, Any]]:
    """The re-feed of ``scene`` (``scene.refeed``, sphere centres) for the rigid engine built
    by :func:`from_scene` with the same ``cartridge`` and ``lift``: ``{"sites": (k, 3),
    "sphere_sites": (k, 3), "velocity": (3,)}`` with the sites' (x, y), cartridges' centres of
    mass and spheres' centres ``lift`` (m) above the belt, for ``run(sim, t, refeed=...)``
    (removed bodies come back upright at the first free site). ``None`` without re-feed."""
    refeed = getattr(scene, "refeed", None)
    if not refeed:
        return None
    c = (Cartridge.from_geometry((getattr(scene, "parameters", None) or {}).get("cartridge"))
         if cartridge is None else cartridge)
    xy = np.asarray(refeed["sites"], float).reshape(-1, 3)[:, :2]
    radius = float(np.asarray(scene.radii, float)[0])

    def at(z: float) -> np.ndarray:
        return np.column_stack([xy, np.full(len(xy), z + lift)])

    return {"sites": at(float(c.center_of_mass[2])), "sphere_sites": at(radius),
            "velocity": np.asarray(refeed.get("velocity", np.zeros(3)), float)}


def run(
    sim: RigidSimulation,
    t_end: float,
    *,
    progress: Optional[Callable[[Progress], None]] = None,
    report_every: float = 1.0,
    chunk_steps: int = 2000,
    refeed: Optional[dict[str, Any]] = None,
) -> int:
    """Advance ``sim`` to simulated time ``t_end`` (s), reporting progress as
    :func:`demfem.dem.run`; Ctrl-C raises ``SimulationInterrupted`` at a step boundary.
    ``refeed`` (:func:`refeed_of`): after every chunk, removed bodies are put back upright at
    the first free site."""
    return _run(sim, t_end, progress=progress, report_every=report_every,
                chunk_steps=chunk_steps, refeed=refeed)
