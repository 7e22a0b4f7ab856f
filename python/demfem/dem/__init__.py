"""Discrete element method: numpy in, numpy out, around the Rust engine ``DemSimulation``.

Build a simulation from arrays and plain dicts (helpers below), then advance it with
:func:`run`, which reports progress (simulated time, steps per second, ETA) and stops cleanly
on Ctrl-C at a step boundary (``SimulationInterrupted``). SI units: m, kg, s, N, Pa.

Example::

    from demfem import dem
    glass = dem.material(45e9, 0.22, 2230.0, friction=0.2, restitution=0.5)
    belt = dem.plane((0, 0, 0), (0, 0, 1), surface_velocity=(0.2, 0, 0))
    sim = dem.DemSimulation(positions, radii, [glass], [belt],
                            ["gravity", "belt", "friction", "rotation", "damping"])
    dem.run(sim, 1.0, progress=print)

The recorded runs of the accumulation table live in the submodules (imported on their own,
not by this package): :mod:`demfem.dem.table_run` (:func:`~demfem.dem.table_run.run_table`,
:class:`~demfem.dem.table_run.TableRun`, checkpoints, the sweep runner),
:mod:`demfem.dem.table_record` (what a run records as it goes) and :mod:`demfem.dem.steady`
(the rule that stops a run once its collision rate is steady).
"""
from __future__ import annotations

import time as _time
from dataclasses import dataclass
from typing import Any, Callable, Optional, Sequence

from demfem._core import DemSimulation, RigidSimulation

__all__ = [
    "DemSimulation",
    "Progress",
    "material",
    "plane",
    "polygon",
    "strip",
    "cuboid",
    "mesh",
    "harmonic",
    "constant_velocity",
    "rotation",
    "run",
    "from_scene",
    "refeed_removed",
    "refeed_removed_bodies",
    "scene_walls",
    "check_state",
    "CONTACT_MODELS",
]

CONTACT_MODELS = ("hertz_mindlin", "hertz_reissner_mindlin", "linear", "fem_line")

Vector = Sequence[float]


def material(
    young_modulus: float,
    poisson_ratio: float,
    density: float,
    *,
    friction: float = 0.0,
    restitution: float = 1.0,
    rolling_friction: float = 0.0,
    shell_stiffness: float = float("inf"),
) -> dict[str, float]:
    """A material dict: E (Pa), ν, ρ (kg/m³), μ, e, μ_r, shell stiffness k_R (N/m, inf = none)."""
    return {
        "young_modulus": young_modulus,
        "poisson_ratio": poisson_ratio,
        "density": density,
        "friction": friction,
        "restitution": restitution,
        "rolling_friction": rolling_friction,
        "shell_stiffness": shell_stiffness,
    }


def _wall(kind: str, material: int, surface_velocity: Optional[Vector], motion: Optional[dict[str, Any]], **geo: Any) -> dict[str, Any]:
    w: dict[str, Any] = {"type": kind, "material": material, **geo}
    if surface_velocity is not None:
        w["surface_velocity"] = tuple(float(x) for x in surface_velocity)
    if motion is not None:
        w["motion"] = motion
    return w


def plane(point: Vector, normal: Vector, *, material: int = 0, surface_velocity: Optional[Vector] = None,
          motion: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Infinite plane through ``point`` (m), ``normal`` towards the particles."""
    return _wall("plane", material, surface_velocity, motion, point=tuple(point), normal=tuple(normal))


def polygon(vertices: Sequence[Vector], *, material: int = 0, surface_velocity: Optional[Vector] = None,
            motion: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Convex planar polygon (two-sided), vertices (m) in boundary order."""
    return _wall("polygon", material, surface_velocity, motion, vertices=[list(v) for v in vertices])


def strip(x0: float, y0: float, x1: float, y1: float, z_bottom: float, z_top: float, *, material: int = 0,
          motion: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Vertical wall strip above the segment (x0, y0)–(x1, y1), from z_bottom to z_top (m)."""
    return _wall("strip", material, None, motion, x0=x0, y0=y0, x1=x1, y1=y1, z_bottom=z_bottom, z_top=z_top)


def cuboid(center: Vector, half_extents: Vector, *, material: int = 0,
           motion: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Solid axis-aligned box: centre and half extents (m)."""
    return _wall("cuboid", material, None, motion, center=tuple(center), half_extents=tuple(half_extents))


def mesh(vertices: Any, triangles: Any, *, material: int = 0, closed: bool = False,
         surface_velocity: Optional[Vector] = None, triangle_velocities: Any = None,
         motion: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Triangle-mesh wall (two-sided): ``vertices`` (N, 3) m, ``triangles`` (M, 3) vertex
    indices; ``closed`` refuses an open surface; ``triangle_velocities`` (M, 3) m/s gives
    each triangle its own surface velocity (several belts in one floor)."""
    import numpy as np

    w = _wall("mesh", material, surface_velocity, motion,
              vertices=np.ascontiguousarray(vertices, dtype=float),
              triangles=np.ascontiguousarray(triangles, dtype=np.int64), closed=bool(closed))
    if triangle_velocities is not None:
        w["triangle_velocities"] = np.ascontiguousarray(triangle_velocities, dtype=float)
    return w


def harmonic(direction: Vector, amplitude: float, period: float, phase: float = 0.0) -> dict[str, Any]:
    """Wall motion x(t) = x0 + A sin(2π t / T + φ) along ``direction``; A in m, T in s."""
    return {"type": "harmonic", "direction": tuple(direction), "amplitude": amplitude, "period": period, "phase": phase}


def rotation(axis_point: Vector, axis: Vector, angular_velocity: float) -> dict[str, Any]:
    """Wall motion: rotation about the axis through ``axis_point`` (m) along ``axis``
    (right-handed) at ``angular_velocity`` rad/s (a star wheel); not for planes."""
    return {"type": "rotation", "axis_point": tuple(axis_point), "axis": tuple(axis),
            "angular_velocity": angular_velocity}


def constant_velocity(velocity: Vector) -> dict[str, Any]:
    """Wall motion x(t) = x0 + v t, v in m/s."""
    return {"type": "constant", "velocity": tuple(velocity)}


@dataclass(frozen=True)
class Progress:
    """Progress of a run: simulated time and target (s), speed (steps/s, simulated s per
    wall s) and the estimated wall time left (s)."""

    time: float
    t_end: float
    steps: int
    steps_per_second: float
    simulated_per_wall_second: float
    eta_seconds: float


def run(
    sim: "DemSimulation | RigidSimulation",
    t_end: float,
    *,
    progress: Optional[Callable[[Progress], None]] = None,
    report_every: float = 1.0,
    chunk_steps: int = 2000,
    refeed: Optional[dict[str, Any]] = None,
) -> int:
    """Advance ``sim`` to simulated time ``t_end`` (s); call ``progress`` about every
    ``report_every`` wall seconds. Returns the steps taken. Ctrl-C raises
    ``SimulationInterrupted`` with the state consistent at a step boundary.

    ``refeed``: a scene's ``{"sites": (k, 3) m, "velocity": (3,) m/s}``; after every chunk,
    removed particles are put back at the first free sites (:func:`refeed_removed`). For a
    ``RigidSimulation`` the sites are the centres of mass of the bodies put back, upright
    (:func:`refeed_removed_bodies`; :func:`demfem.rigid.refeed_of` turns a scene's sphere
    sites into them, with ``"sphere_sites"`` for the spheres of mixed tables)."""
    if refeed is not None and not isinstance(sim, (DemSimulation, RigidSimulation)):
        from demfem.errors import InvalidParameterError

        raise InvalidParameterError(
            f"invalid refeed for a {type(sim).__name__}: re-feeding is implemented for "
            "DemSimulation and RigidSimulation")
    start_steps = sim.steps
    start_wall = _time.perf_counter()
    last_report = start_wall
    total = max(0, int(-(-(t_end - sim.time) // sim.dt)))
    done = 0
    while done < total:
        k = min(chunk_steps, total - done)
        sim.step(k, chunk=k)
        done += k
        if refeed is not None and isinstance(sim, RigidSimulation):
            refeed_removed_bodies(sim, refeed["sites"], refeed.get("velocity", (0.0, 0.0, 0.0)),
                                  sphere_sites=refeed.get("sphere_sites"))
        elif refeed is not None and isinstance(sim, DemSimulation):
            refeed_removed(sim, refeed["sites"], refeed.get("velocity", (0.0, 0.0, 0.0)))
        now = _time.perf_counter()
        if progress is not None and (now - last_report >= report_every or done == total):
            last_report = now
            elapsed = max(now - start_wall, 1e-12)
            rate = done / elapsed
            progress(Progress(
                time=sim.time,
                t_end=t_end,
                steps=sim.steps,
                steps_per_second=rate,
                simulated_per_wall_second=rate * sim.dt,
                eta_seconds=(total - done) / rate if rate > 0 else float("inf"),
            ))
    return sim.steps - start_steps


def from_scene(
    scene: Any,
    *,
    model: str = "hertz_reissner_mindlin",
    shell_thickness: Optional[float] = None,
    shell_radius: Optional[float] = None,
    dt: Optional[float] = None,
    dt_safety: float = 0.2,
    expected_max_speed: float = 1.0,
    threads: int = 1,
    record_every: int = 0,
    record_onsets: bool = True,
    linear_stiffness: Optional[tuple[float, float]] = None,
    record_events: bool = False,
) -> DemSimulation:
    """Build the engine from an engine-neutral scene description
    (:class:`demfem.scenes.table.SceneDescription`).

    ``model``: ``"hertz_reissner_mindlin"`` (default: the calibrated equivalent sphere of the
    paper, Hertz in series with the Reissner stiffness of the cartridge wall, Mindlin
    tangential spring), ``"hertz_mindlin"``, ``"linear"`` (with ``linear_stiffness`` =
    (k_n, k_t) in N/m) or ``"fem_line"``: the linear law calibrated on the explicit FEM of two
    cartridges meeting side by side (:func:`demfem.fem.line_law.line_contact_stiffness`), for
    upright cartridges whose impacts are line contacts. The Reissner stiffness uses
    ``shell_thickness`` and ``shell_radius`` (m; default: the scene's cartridge's wall
    thickness and body mid-surface radius); walls do not bend (infinite shell stiffness).
    ``dt`` (s) defaults to ``dt_safety`` times the stable limit; a larger one is refused.
    Contact onsets are logged (``record_onsets``) because the FEM load cases come from them.
    ``record_events`` logs every whole contact with its duration (s), peak normal and
    tangential force (N), normal impulse (N s) and largest overlap (m), measured step by step
    (``sim.events()``, ``sim.open_events()``); off, it costs nothing.
    A scene that re-feeds removed spheres (``scene.refeed``) is run with
    ``run(sim, t, refeed=scene.refeed)`` or :func:`demfem.dem.table_run.run_table`.
    """
    import numpy as np

    from demfem.cartridge import Cartridge
    from demfem.contact import reissner_stiffness
    from demfem.errors import InvalidParameterError

    if model not in CONTACT_MODELS:
        raise InvalidParameterError(f"invalid model = {model!r}: must be one of {CONTACT_MODELS}")
    mats = scene.materials
    pm = mats[scene.particle_material]
    # the engine derives masses from density and radius: they must be the scene's masses
    m_engine = pm["density"] * 4.0 / 3.0 * np.pi * np.asarray(scene.radii) ** 3
    if not np.allclose(m_engine, scene.masses, rtol=1e-9, atol=0.0):
        raise InvalidParameterError(
            "invalid masses: the scene's sphere masses differ from density x sphere volume "
            f"(e.g. {float(scene.masses[0]):.6g} kg vs {float(m_engine[0]):.6g} kg); "
            "the equivalent sphere has the cartridge's mass and material, so both must agree")
    k_r = float("inf")
    if model == "hertz_reissner_mindlin":
        c = Cartridge.from_geometry((getattr(scene, "parameters", None) or {}).get("cartridge"))
        t = c.wall_thickness if shell_thickness is None else shell_thickness
        r = c.body_mid_radius if shell_radius is None else shell_radius
        k_r = reissner_stiffness(pm["young_modulus"], pm["poisson_ratio"], t, r)
    engine_model = model
    if model == "fem_line":
        from demfem.fem.line_law import line_contact_stiffness

        linear_stiffness = line_contact_stiffness(pm["young_modulus"], pm["poisson_ratio"])
        engine_model = "linear"
    elif model == "linear" and linear_stiffness is None:
        raise InvalidParameterError(
            "invalid linear_stiffness = None: model 'linear' needs (k_n, k_t) in N/m")
    names = [scene.particle_material] + [n for n in mats if n != scene.particle_material]
    materials = [material(mats[n]["young_modulus"], mats[n]["poisson_ratio"], mats[n]["density"],
                          friction=mats[n]["friction"], restitution=mats[n]["restitution"],
                          rolling_friction=mats[n].get("rolling_resistance", 0.0),
                          shell_stiffness=k_r if n == scene.particle_material else float("inf"))
                 for n in names]
    # walls are rigid: a copy of their material without a shell
    wall_index: dict[str, int] = {}
    for n in names:
        wall_index[n] = len(materials)
        materials.append({**materials[names.index(n)], "shell_stiffness": float("inf")})
    walls = scene_walls(scene, lambda name: wall_index[name])
    removal = scene.removal
    removal_plane = None
    if removal is not None:
        # the scene's normal points to the removed side, the engine's to the kept side
        removal_plane = (tuple(np.asarray(removal["point"], float)),
                         tuple(-np.asarray(removal["normal"], float)))
    return DemSimulation(
        np.ascontiguousarray(scene.positions, dtype=float),
        np.ascontiguousarray(scene.radii, dtype=float),
        materials, walls, list(scene.effects),
        tags=np.asarray(scene.tags, dtype=np.int64),
        gravity=(float(scene.gravity[0]), float(scene.gravity[1]), float(scene.gravity[2])),
        model=engine_model, linear_stiffness=linear_stiffness, dt=dt, dt_safety=dt_safety,
        expected_max_speed=expected_max_speed,
        threads=threads, record_every=record_every, record_onsets=record_onsets,
        removal_plane=removal_plane, record_events=record_events,
    )


def refeed_removed(sim: DemSimulation, sites: Any, velocity: Vector = (0.0, 0.0, 0.0)) -> int:
    """Put removed particles back, lowest index first, each at the first of ``sites``
    ((k, 3) centres, m) where it touches no alive particle, with ``velocity`` (m/s) and no
    spin. A particle for which no site is free waits for a later call. Returns how many
    were put back."""
    import numpy as np

    alive = np.asarray(sim.alive(), dtype=bool)
    dead = np.flatnonzero(~alive)
    if dead.size == 0:
        return 0
    sites = np.asarray(sites, dtype=float).reshape(-1, 3)
    vel = tuple(float(v) for v in velocity)
    radii = np.asarray(sim.radii())
    occupied = np.asarray(sim.positions())[alive]
    occupied_r = radii[alive]
    placed = 0
    for i in dead:
        for site in sites:
            gap = np.linalg.norm(occupied - site, axis=1) - (occupied_r + radii[i])
            if gap.size == 0 or gap.min() >= 0.0:
                sim.reinsert_particle(int(i), (float(site[0]), float(site[1]), float(site[2])),
                                      (vel[0], vel[1], vel[2]))
                occupied = np.vstack([occupied, site])
                occupied_r = np.append(occupied_r, radii[i])
                placed += 1
                break
        else:
            break  # every site is taken: the rest wait
    return placed


def refeed_removed_bodies(sim: RigidSimulation, sites: Any, velocity: Vector = (0.0, 0.0, 0.0),
                          *, sphere_sites: Any = None,
                          orientation: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
                          ) -> int:
    """Put removed bodies of a ``RigidSimulation`` back, lowest index first, each at the
    first of ``sites`` ((k, 3) centres of mass, m) where the engine's exact contact test finds
    it touching no alive body and no wall, with ``orientation`` (default upright: axis along
    +z), ``velocity`` (m/s) and no spin. The equivalent spheres of mixed tables go to
    ``sphere_sites`` (their centres) when given. A body for which no site is free waits, with
    every body after it, for a later call. Returns how many were put back."""
    import numpy as np

    from demfem.errors import InvalidParameterError

    def checked(name: str, value: Any) -> np.ndarray:
        a = np.asarray(value, dtype=float)
        if a.ndim > 2 or a.size % 3 or not np.all(np.isfinite(a)):
            raise InvalidParameterError(
                f"invalid {name} of shape {a.shape}: must be finite (k, 3) points, m")
        return a.reshape(-1, 3)

    dead = np.flatnonzero(~np.asarray(sim.alive(), dtype=bool))
    if dead.size == 0:
        return 0
    cartridge_sites = checked("sites", sites)
    spheres_at = cartridge_sites if sphere_sites is None else checked("sphere_sites", sphere_sites)
    v = np.asarray(velocity, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InvalidParameterError(f"invalid velocity = {velocity!r}: must be 3 finite m/s")
    vel = (float(v[0]), float(v[1]), float(v[2]))
    q = (float(orientation[0]), float(orientation[1]), float(orientation[2]),
         float(orientation[3]))
    is_sphere = np.asarray(sim.is_sphere(), dtype=bool)
    placed = 0
    for i in dead:
        for site in (spheres_at if is_sphere[i] else cartridge_sites):
            at = (float(site[0]), float(site[1]), float(site[2]))
            if sim.reinsert_body(int(i), at, q, vel, if_free=True):
                placed += 1
                break
        else:
            break  # every site is taken: the rest wait
    return placed


def scene_walls(scene: Any, material_index: Callable[[str], int]) -> list[dict[str, Any]]:
    """The walls of an engine-neutral scene description as engine wall dicts (the format of
    :func:`plane` and :func:`polygon`, shared by ``DemSimulation`` and ``RigidSimulation``);
    ``material_index`` maps a wall's material name to the engine's material index."""
    import numpy as np

    from demfem.errors import InvalidParameterError

    walls = []
    for w in scene.walls:
        motion = w.get("motion") or {"kind": "fixed"}
        kind = motion.get("kind", motion.get("type"))
        if kind == "fixed":
            mo = None
        elif kind == "harmonic":
            mo = harmonic(tuple(np.asarray(motion["direction"], float)), float(motion["amplitude"]),
                          float(motion["period"]), float(motion.get("phase", 0.0)))
        elif kind == "constant":
            mo = constant_velocity(tuple(np.asarray(motion["velocity"], float)))
        elif kind == "rotation":
            mo = rotation(tuple(np.asarray(motion["axis_point"], float)),
                          tuple(np.asarray(motion["axis"], float)),
                          float(motion["angular_velocity"]))
        else:
            raise InvalidParameterError(f"invalid wall {w.get('name')!r} motion kind = {kind!r}: "
                                        "must be 'fixed', 'harmonic', 'constant' or 'rotation'")
        sv = w.get("surface_velocity")
        sv = None if sv is None or not np.any(np.asarray(sv)) else tuple(np.asarray(sv, float))
        mat = material_index(w.get("material", scene.particle_material))
        if w["kind"] == "plane":
            walls.append(plane(tuple(np.asarray(w["point"], float)), tuple(np.asarray(w["normal"], float)),
                               material=mat, surface_velocity=sv, motion=mo))
        elif w["kind"] == "polygon":
            walls.append(polygon([list(map(float, v)) for v in np.asarray(w["vertices"])],
                                 material=mat, surface_velocity=sv, motion=mo))
        elif w["kind"] == "mesh":
            walls.append(mesh(w["vertices"], w["triangles"], material=mat,
                              closed=bool(w.get("closed", False)), surface_velocity=sv,
                              triangle_velocities=w.get("triangle_velocities"), motion=mo))
        else:
            raise InvalidParameterError(f"invalid wall {w.get('name')!r} kind = {w['kind']!r}: "
                                        "must be 'plane', 'polygon' or 'mesh'")
    return walls


def check_state(sim: DemSimulation, *, floor: Optional[tuple[Any, Any]] = None,
                overlap_fraction: float = 0.1) -> None:
    """Physical sanity check of a running simulation; raises
    :class:`demfem.errors.NumericalError` naming the sphere, the depth and the likely cause.

    * every alive sphere's centre and velocity must be finite;
    * ``floor``: (point (m), normal) of a plane that holds the spheres (the belt): no sphere
      may sink into it deeper than ``overlap_fraction`` of its radius;
    * the deepest contact overlap (:meth:`DemSimulation.max_overlap`, m) must stay below
      ``overlap_fraction`` of the smallest radius.

    Deep overlaps mean the contact stiffness is too low for the load (Young's modulus too
    low) or the time step too large; the results of such a run are not physical.
    """
    import numpy as np

    from demfem.errors import NumericalError, check_range

    frac = check_range("overlap_fraction", overlap_fraction, 0.0, 1.0, hi_open=False)
    alive = np.asarray(sim.alive(), bool)
    if not alive.any():
        return
    pos = np.asarray(sim.positions(), float)[alive]
    radii = np.asarray(sim.radii(), float)[alive]
    index = np.flatnonzero(alive)
    cause = ("the contact stiffness is too low for the load (Young's modulus too low) or "
             "the time step too large")
    bad = ~np.all(np.isfinite(pos), axis=1) | ~np.all(
        np.isfinite(np.asarray(sim.velocities(), float)[alive]), axis=1)
    if bad.any():
        i = int(index[np.argmax(bad)])
        raise NumericalError(f"sphere {i} has a non-finite position or velocity at "
                             f"t = {sim.time:.6g} s: the simulation lost stability ({cause})")
    if floor is not None:
        point = np.asarray(floor[0], float)
        normal = np.asarray(floor[1], float)
        normal = normal / np.linalg.norm(normal)
        depth = radii - (pos - point) @ normal  # penetration into the floor, m
        worst = int(np.argmax(depth / radii))
        if depth[worst] > frac * radii[worst]:
            below = int(np.count_nonzero(depth > frac * radii))
            raise NumericalError(
                f"sphere {int(index[worst])} has sunk {depth[worst]:.3g} m into the belt "
                f"(limit {frac:g} x radius = {frac * radii[worst]:.3g} m) at "
                f"t = {sim.time:.6g} s, {below} sphere(s) in all: {cause}")
    overlap = float(sim.max_overlap())
    limit = frac * float(radii.min())
    if not np.isfinite(overlap) or overlap > limit:
        raise NumericalError(
            f"max_overlap = {overlap:.3g} m exceeds {frac:g} x the sphere radius "
            f"({limit:.3g} m) at t = {sim.time:.6g} s: {cause}")
