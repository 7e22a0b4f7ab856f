"""A user's own accumulation table from one TOML scene file: walls from triangle meshes
(STL from CAD), several belts, a continuous infeed and an outlet.

The schema (every field, unit and default) is in ``docs/mesh-tables.md``; in short::

    scene = "mesh_table"
    duration = 20.0                 # s
    [particles]                     # equivalent spheres (default: the default cartridge's)
    [materials.glass]               # young_modulus (Pa), poisson_ratio, density, friction, ...
    [[meshes]]                      # file (relative to the TOML), scale, material, closed,
                                    # motion, surface_velocity
    [[belts]]                       # polygon [[x, y], ...] on the floor z = 0 (m), velocity
    [infeed]                        # rate (per minute), region [[x0, y0], [x1, y1]], velocity
    [outlet]                        # point, normal: spheres past the plane leave

Frame: z up, the floor (the belts) is the plane z = 0; spheres stand on it. The belts are
one floor mesh whose triangles carry their belt's surface velocity, so a sphere on the seam
between two belts has one contact, not two; belts must meet edge to edge (or not at all: a
T-junction is refused) and must not overlap. Spheres off every belt fall and are counted as lost.

:meth:`MeshTable.from_toml` validates everything it reads, with errors naming the file, the
field and the allowed range; :meth:`MeshTable.description` builds the engine-neutral
:class:`~demfem.scenes.table.SceneDescription` and :func:`demfem.scenes.infeed.run_mesh_table`
runs it with the continuous infeed.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from demfem.cartridge import Cartridge
from demfem.errors import InvalidParameterError, check_count, check_positive, check_range
from demfem.materials import PAPER_GLASS

__all__ = ["MeshTable", "MeshSpec", "Belt", "Infeed", "SCENE_NAME", "belt_floor",
           "check_belt_overlaps", "check_belt_seams", "max_infeed_rate", "extrude_polyline",
           "table_walls_as_mesh", "check_physical_sense", "memory_limit"]

#: Name of this scene in scene files (the key ``scene``).
SCENE_NAME = "mesh_table"

_DEFAULT_SPHERE = Cartridge().equivalent_sphere()
_MATERIAL_KEYS = ("young_modulus", "poisson_ratio", "density", "friction", "restitution",
                  "rolling_resistance")
_DEFAULT_EFFECTS = ("gravity", "belt", "friction", "rotation", "damping")


#: Largest coordinate of a scene, m (as a mesh file's, :data:`demfem.io.stl.MAX_COORDINATE`).
MAX_COORDINATE = 1e5
#: Largest speed of a belt, an arriving cartridge or a moving wall, m/s.
MAX_SPEED = 100.0
#: Most inlet sites, steadiness windows and engine threads a scene may ask for.
MAX_SITES, MAX_WINDOWS, MAX_THREADS = 100_000, 100_000, 1024
#: Memory of one sphere of the pool, bytes (engine state, neighbour lists and the runner's
#: arrays: 550 B measured at 2e5 spheres, 950 B at the peak of the build; rounded up).
POOL_BYTES_PER_SPHERE = 1000
#: Deepest static overlap of a resting sphere on the belt under its weight (Hertz), as a
#: fraction of its radius: deeper, the glass is too soft to stand on the belt.
MAX_REST_OVERLAP = 0.1


def _vec(field_name: str, value: Any, n: int, bound: float = math.inf) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(
            f"invalid {field_name} = {value!r}: must be {n} numbers") from None
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise InvalidParameterError(
            f"invalid {field_name} = {value!r}: must be {n} finite numbers")
    if np.any(np.abs(a) > bound):
        raise InvalidParameterError(
            f"invalid {field_name} = {a.tolist()}: each component must be within ±{bound:g}")
    return a


def _keys(table: Mapping[str, Any], allowed: tuple[str, ...], where: str) -> None:
    if not isinstance(table, Mapping):
        raise InvalidParameterError(f"invalid {where} = {table!r}: must be a table "
                                    f"{{key = value, ...}}, not a {type(table).__name__}")
    for key in table:
        if key not in allowed:
            raise InvalidParameterError(
                f"unknown key {key!r} in {where}; allowed keys: {', '.join(allowed)}")


def _motion(value: Any, where: str) -> dict[str, Any]:
    """A wall motion dict ({"kind": "fixed"}, "harmonic" or "constant"), validated."""
    if value is None:
        return {"kind": "fixed"}
    if not isinstance(value, Mapping):
        raise InvalidParameterError(f"invalid {where} = {value!r}: must be a table")
    kind = value.get("kind", "fixed")
    if kind == "fixed":
        _keys(value, ("kind",), where)
        return {"kind": "fixed"}
    if kind == "harmonic":
        _keys(value, ("kind", "direction", "amplitude", "period", "phase"), where)
        d = _vec(f"{where}.direction", value.get("direction", (0.0, 1.0, 0.0)), 3)
        if not np.linalg.norm(d) > 0:
            raise InvalidParameterError(f"invalid {where}.direction = {d.tolist()}: "
                                        "must be a non-zero vector")
        return {"kind": "harmonic", "direction": d / np.linalg.norm(d),
                "amplitude": check_range(f"{where}.amplitude (m)", value.get("amplitude", 0.0),
                                         0.0, MAX_COORDINATE, lo_open=False, hi_open=False),
                "period": check_positive(f"{where}.period", value.get("period", 1.0)),
                "phase": check_range(f"{where}.phase", value.get("phase", 0.0))}
    if kind == "constant":
        _keys(value, ("kind", "velocity"), where)
        return {"kind": "constant",
                "velocity": _vec(f"{where}.velocity", value.get("velocity"), 3, MAX_SPEED)}
    if kind == "rotation":
        _keys(value, ("kind", "axis_point", "axis", "angular_velocity"), where)
        axis = _vec(f"{where}.axis", value.get("axis", (0.0, 0.0, 1.0)), 3)
        if not np.linalg.norm(axis) > 0:
            raise InvalidParameterError(f"invalid {where}.axis = {axis.tolist()}: must be a "
                                        "non-zero vector")
        return {"kind": "rotation",
                "axis_point": _vec(f"{where}.axis_point", value.get("axis_point"), 3,
                                   MAX_COORDINATE),
                "axis": axis / np.linalg.norm(axis),
                "angular_velocity": check_range(f"{where}.angular_velocity (rad/s)",
                                                value.get("angular_velocity"))}
    raise InvalidParameterError(f"invalid {where}.kind = {kind!r}: must be 'fixed', "
                                "'harmonic', 'constant' or 'rotation'")


@dataclass(frozen=True, eq=False)
class MeshSpec:
    """A wall from a mesh file: its ``name``, the ``file`` (resolved), ``scale`` (the file's
    unit in m), ``material``, ``closed`` (refuse an open surface), ``motion`` (as the gate's:
    fixed, harmonic, constant) and ``surface_velocity`` (m/s); ``vertices`` (N, 3) m and
    ``triangles`` (M, 3) as read and checked."""

    name: str
    file: Path
    vertices: np.ndarray
    triangles: np.ndarray
    scale: float = 1.0
    material: str = "glass"
    closed: bool = False
    motion: dict[str, Any] = field(default_factory=lambda: {"kind": "fixed"})
    surface_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], k: int, base: Path, source: str) -> "MeshSpec":
        from demfem.io.stl import check_mesh, read_mesh

        where = f"meshes[{k}] of {source}"
        _keys(d, ("name", "file", "scale", "material", "closed", "motion",
                  "surface_velocity"), where)
        if "file" not in d:
            raise InvalidParameterError(f"invalid {where}: 'file' (the mesh's path, relative "
                                        "to the scene file) is required")
        if not isinstance(d["file"], str) or not d["file"]:
            raise InvalidParameterError(f"invalid {where}.file = {d['file']!r}: must be the "
                                        "mesh file's path (a string)")
        path = Path(d["file"])
        path = path if path.is_absolute() else base / path
        scale = check_positive(f"{where}.scale", d.get("scale", 1.0))
        closed = d.get("closed", False)
        if not isinstance(closed, bool):
            raise InvalidParameterError(f"invalid {where}.closed = {closed!r}: must be true "
                                        "or false")
        vertices, triangles = read_mesh(path, scale=scale)
        check_mesh(vertices, triangles, source=f"{path} ({where})", closed=closed)
        return cls(name=str(d.get("name", path.stem)), file=path, vertices=vertices,
                   triangles=triangles, scale=scale, material=str(d.get("material", "glass")),
                   closed=closed, motion=_motion(d.get("motion"), f"{where}.motion"),
                   surface_velocity=_vec(f"{where}.surface_velocity",
                                         d.get("surface_velocity", (0.0, 0.0, 0.0)), 3,
                                         MAX_SPEED))


@dataclass(frozen=True, eq=False)
class Belt:
    """A belt region: convex ``polygon`` (k, 2) on the floor z = 0 (m, either orientation),
    surface ``velocity`` (2,) m/s along the floor, ``material``."""

    name: str
    polygon: np.ndarray
    velocity: np.ndarray
    material: str = "glass"

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], k: int, source: str) -> "Belt":
        where = f"belts[{k}] of {source}"
        _keys(d, ("name", "polygon", "velocity", "material"), where)
        try:
            poly = np.asarray(d.get("polygon"), dtype=float)
        except (TypeError, ValueError):
            poly = np.zeros((0,))
        if poly.ndim != 2 or poly.shape[1] != 2 or len(poly) < 3 or not np.all(
                np.isfinite(poly)) or np.any(np.abs(poly) > MAX_COORDINATE):
            raise InvalidParameterError(
                f"invalid {where}.polygon = {d.get('polygon')!r}: must be at least 3 finite "
                f"[x, y] corners (m, within ±{MAX_COORDINATE:g}) of a convex polygon")
        area2 = _cross_sum(poly)
        if not abs(area2) > 0:
            raise InvalidParameterError(f"invalid {where}.polygon: zero area")
        if area2 < 0:
            poly = poly[::-1].copy()
        edges = np.roll(poly, -1, axis=0) - poly
        turn = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(
            edges, -1, axis=0)[:, 0]
        if np.any(turn < -1e-12 * abs(area2)):
            raise InvalidParameterError(f"invalid {where}.polygon: must be convex, corners in "
                                        "boundary order")
        return cls(name=str(d.get("name", f"belt{k}")), polygon=poly,
                   velocity=_vec(f"{where}.velocity", d.get("velocity", (0.0, 0.0)), 2,
                                 MAX_SPEED),
                   material=str(d.get("material", "glass")))


def _cross_sum(poly: np.ndarray) -> float:
    """Twice the signed area of a polygon (k, 2)."""
    q = np.roll(poly, -1, axis=0)
    return float(np.sum(poly[:, 0] * q[:, 1] - poly[:, 1] * q[:, 0]))


def check_belt_overlaps(belts: list[Belt], source: str) -> None:
    """Refuse two belts whose regions overlap (share more than an edge), naming both:
    separating-axis test on the convex polygons, with a tolerance of 1e-9 of their size."""
    for a in range(len(belts)):
        for b in range(a + 1, len(belts)):
            p, q = belts[a].polygon, belts[b].polygon
            size = max(np.ptp(p, axis=0).max(), np.ptp(q, axis=0).max())
            depth = math.inf
            for poly in (p, q):
                e = np.roll(poly, -1, axis=0) - poly
                for nx, ny in np.column_stack([-e[:, 1], e[:, 0]]):
                    n = np.array([nx, ny]) / math.hypot(nx, ny)
                    sp, sq = p @ n, q @ n
                    depth = min(depth, min(sp.max(), sq.max()) - max(sp.min(), sq.min()))
            if depth > 1e-9 * size:
                raise InvalidParameterError(
                    f"invalid belts in {source}: belts {belts[a].name!r} and "
                    f"{belts[b].name!r} overlap (by {depth:.3g} m); belt regions may share "
                    "edges but not area")


def check_belt_seams(belts: list[Belt], source: str) -> None:
    """Refuse belts that meet at a T-junction (a corner of one inside an edge of another):
    the seam must be an edge of the floor mesh on both sides, else a sphere on it could
    count a contact with each belt. Belts meet edge to edge (sharing both corners) or not
    at all; split the longer edge's belt at the corner to make a T-junction acceptable."""
    for a, belt in enumerate(belts):
        for b, other in enumerate(belts):
            if a == b:
                continue
            q = other.polygon
            size = max(np.ptp(belt.polygon, axis=0).max(), np.ptp(q, axis=0).max())
            tol = 1e-9 * size
            for corner in belt.polygon:
                for s, e in zip(q, np.roll(q, -1, axis=0)):
                    d = e - s
                    u = float(np.dot(corner - s, d) / np.dot(d, d))
                    if not (0.0 < u < 1.0):
                        continue
                    if min(np.linalg.norm(corner - s), np.linalg.norm(corner - e)) <= tol:
                        continue
                    if np.linalg.norm(s + u * d - corner) <= tol:
                        raise InvalidParameterError(
                            f"invalid belts in {source}: a corner {corner.tolist()} of belt "
                            f"{belt.name!r} lies inside an edge of belt {other.name!r} (a "
                            "T-junction); belts must meet edge to edge, sharing both corners "
                            f"(split {other.name!r} at that corner)")


def belt_floor(belts: list[Belt]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The belts as one floor mesh at z = 0: vertices (N, 3) m (shared corners welded, so
    that seams are edges of the mesh), triangles (M, 3) (a fan per belt) and each triangle's
    surface velocity (M, 3) m/s."""
    from demfem.io.stl import weld_vertices

    corners, velocity = [], []
    for belt in belts:
        p = belt.polygon
        for k in range(1, len(p) - 1):
            corners.append([p[0], p[k], p[k + 1]])
            velocity.append([belt.velocity[0], belt.velocity[1], 0.0])
    c = np.asarray(corners, float)
    c3 = np.concatenate([c, np.zeros(c.shape[:2] + (1,))], axis=2)
    vertices, index = weld_vertices(c3.reshape(-1, 3))
    return vertices, index.reshape(-1, 3), np.asarray(velocity, float)


@dataclass(frozen=True, eq=False)
class Infeed:
    """Cartridges arriving continuously: ``rate`` per minute, placed at rest relative to
    ``velocity`` (2,) m/s on the floor inside the rectangle ``region`` ((x0, y0), (x1, y1)),
    m, at sites one pitch apart, never overlapping a sphere already there."""

    rate: float
    region: np.ndarray
    velocity: np.ndarray

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], source: str) -> "Infeed":
        where = f"[infeed] of {source}"
        _keys(d, ("rate", "region", "velocity"), where)
        rate = check_positive(f"infeed.rate (cartridges per minute) in {source}",
                              d.get("rate"))
        try:
            region = np.asarray(d.get("region"), dtype=float)
        except (TypeError, ValueError):
            region = np.zeros(0)
        if region.shape != (2, 2) or not np.all(np.isfinite(region)) or np.any(
                np.abs(region) > MAX_COORDINATE):
            raise InvalidParameterError(
                f"invalid infeed.region = {d.get('region')!r} in {source}: must be "
                "[[x0, y0], [x1, y1]] (m), two corners of a rectangle on the floor (within "
                f"±{MAX_COORDINATE:g} m)")
        region = np.sort(region, axis=0)
        velocity = _vec(f"infeed.velocity in {source}", d.get("velocity", (0.0, 0.0)), 2,
                        MAX_SPEED)
        if not np.linalg.norm(velocity) > 0:
            raise InvalidParameterError(
                f"invalid infeed.velocity = {velocity.tolist()} in {source}: must be non-zero "
                "(m/s; the speed at which cartridges leave the inlet)")
        return cls(rate=rate, region=region, velocity=velocity)

    def sites(self, radius: float, gap: float) -> np.ndarray:
        """Insertion sites (k, 3), m: a square grid of pitch 2 r (1 + gap) inside the
        region, at height r, ordered across the flow (the direction of ``velocity``) first,
        most downstream row first."""
        pitch = 2.0 * radius * (1.0 + gap)
        lo, hi = self.region[0] + radius, self.region[1] - radius
        if np.any(hi < lo):
            return np.zeros((0, 3))
        nx = int(math.floor((hi[0] - lo[0]) / pitch)) + 1
        ny = int(math.floor((hi[1] - lo[1]) / pitch)) + 1
        if nx * ny > MAX_SITES:
            raise InvalidParameterError(
                f"invalid infeed.region = {self.region.tolist()} m: {nx * ny} inlet sites of "
                f"pitch {pitch:.3g} m, more than {MAX_SITES}; an inlet is a strip along the "
                "belt's width, not the whole table")
        xs = lo[0] + 0.5 * (hi[0] - lo[0] - (nx - 1) * pitch) + pitch * np.arange(nx)
        ys = lo[1] + 0.5 * (hi[1] - lo[1] - (ny - 1) * pitch) + pitch * np.arange(ny)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        xy = np.column_stack([gx.ravel(), gy.ravel()])
        u = self.velocity / np.linalg.norm(self.velocity)
        along = xy @ u
        across = xy @ np.array([-u[1], u[0]])
        order = np.lexsort((across, -np.round(along / pitch)))
        return np.column_stack([xy[order], np.full(len(xy), radius)])

    def max_rate(self, radius: float, gap: float) -> float:
        """The largest rate (per minute) the inlet can place without overlap: a row of sites
        across the flow is cleared every pitch / |velocity| seconds."""
        return max_infeed_rate(self.region, self.velocity, radius, gap)


def max_infeed_rate(region: np.ndarray, velocity: np.ndarray, radius: float,
                    gap: float) -> float:
    """Sites across the flow × |velocity| / pitch × 60: cartridges per minute."""
    pitch = 2.0 * radius * (1.0 + gap)
    u = np.asarray(velocity, float) / np.linalg.norm(velocity)
    corners = np.array([[region[0][0], region[0][1]], [region[1][0], region[0][1]],
                        [region[1][0], region[1][1]], [region[0][0], region[1][1]]])
    width = float(np.ptp(corners @ np.array([-u[1], u[0]])))
    depth = float(np.ptp(corners @ u))
    if width < 2 * radius or depth < 2 * radius:
        return 0.0
    across = int(math.floor((width - 2 * radius) / pitch)) + 1
    return across * float(np.linalg.norm(velocity)) / pitch * 60.0


@dataclass(frozen=True, eq=False)
class MeshTable:
    """A table from a scene file (see the module docs and ``docs/mesh-tables.md``).

    Attributes: ``meshes`` (walls), ``belts``, ``infeed``, ``outlet`` ({"point", "normal"}
    m: spheres whose centre passes the plane along ``normal`` leave), ``materials`` (name ->
    values, SI), ``particle_material``, ``sphere_radius`` (m), ``pool`` (most spheres on
    the table at once), ``packing_gap`` (inlet site spacing, fraction of a diameter),
    ``effects``, ``model`` (contact model of :func:`demfem.dem.from_scene`), ``duration``
    (s), ``window`` (s, of the steadiness measure), ``lost_below`` (m: spheres whose centre
    falls below this height are removed as lost), ``threads``, ``source`` (the file)."""

    meshes: list[MeshSpec]
    belts: list[Belt]
    infeed: Infeed
    outlet: dict[str, np.ndarray]
    materials: dict[str, dict[str, float]]
    particle_material: str = "glass"
    sphere_radius: float = _DEFAULT_SPHERE.radius
    pool: int = 600
    packing_gap: float = 0.05
    effects: tuple[str, ...] = _DEFAULT_EFFECTS
    model: str = "hertz_reissner_mindlin"
    duration: float = 20.0
    window: float = 2.0
    lost_below: float = -0.05
    threads: int = 1
    source: str = "scene"

    # ---- scene files -----------------------------------------------------------------------

    @classmethod
    def from_toml(cls, path: str | Path) -> "MeshTable":
        """Read and validate a scene file; mesh paths are relative to it."""
        from demfem.io.toml_file import read_toml

        path = Path(path)
        return cls.from_dict(read_toml(path), base=path.parent, source=str(path))

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, base: Path = Path("."),
                  source: str = "scene") -> "MeshTable":
        """A table from a parsed scene document (see :meth:`from_toml`)."""
        _keys(d, ("scene", "duration", "window", "threads", "model", "effects", "particles",
                  "materials", "meshes", "belts", "infeed", "outlet", "lost_below"), source)
        if d.get("scene") != SCENE_NAME:
            raise InvalidParameterError(
                f"invalid scene = {d.get('scene')!r} in {source}: must be {SCENE_NAME!r}")
        materials = {"glass": {"young_modulus": PAPER_GLASS.E, "poisson_ratio": PAPER_GLASS.nu,
                               "density": PAPER_GLASS.density, "friction": 0.2,
                               "restitution": 0.5, "rolling_resistance": 0.0}}
        if not isinstance(d.get("materials", {}), Mapping):
            raise InvalidParameterError(f"invalid materials in {source}: must be tables "
                                        "[materials.NAME]")
        for key in ("meshes", "belts"):
            if not isinstance(d.get(key, []), list):
                raise InvalidParameterError(f"invalid {key} in {source}: must be a list of "
                                            f"tables [[{key}]]")
        for name, m in (d.get("materials") or {}).items():
            where = f"materials.{name} of {source}"
            if not isinstance(m, Mapping):
                raise InvalidParameterError(f"invalid {where}: must be a table")
            _keys(m, _MATERIAL_KEYS, where)
            base_m = dict(materials.get(name, materials["glass"]))
            base_m.update(m)
            materials[name] = {
                "young_modulus": check_positive(f"{where}.young_modulus", base_m["young_modulus"]),
                "poisson_ratio": check_range(f"{where}.poisson_ratio", base_m["poisson_ratio"],
                                             -1.0, 0.5),
                "density": check_positive(f"{where}.density", base_m["density"]),
                "friction": check_range(f"{where}.friction", base_m["friction"], 0.0, math.inf,
                                        lo_open=False),
                "restitution": check_range(f"{where}.restitution", base_m["restitution"], 0.0,
                                           1.0, hi_open=False),
                "rolling_resistance": check_range(f"{where}.rolling_resistance",
                                                  base_m["rolling_resistance"], 0.0, math.inf,
                                                  lo_open=False)}
        particles = d.get("particles") or {}
        _keys(particles, ("radius", "material", "pool", "packing_gap"),
              f"[particles] of {source}")
        pm = str(particles.get("material", "glass"))
        radius = check_range(f"particles.radius (m) in {source}",
                             particles.get("radius", _DEFAULT_SPHERE.radius), 0.0, 1.0)
        meshes = [MeshSpec.from_dict(m, k, base, source)
                  for k, m in enumerate(d.get("meshes") or [])]
        belts = [Belt.from_dict(b, k, source) for k, b in enumerate(d.get("belts") or [])]
        if not belts:
            raise InvalidParameterError(f"invalid belts in {source}: at least one [[belts]] "
                                        "region is needed (the floor the spheres stand on)")
        check_belt_overlaps(belts, source)
        check_belt_seams(belts, source)
        for what, name in ([(f"meshes[{k}].material", m.material) for k, m in enumerate(meshes)]
                           + [(f"belts[{k}].material", b.material) for k, b in enumerate(belts)]
                           + [("particles.material", pm)]):
            if name not in materials:
                raise InvalidParameterError(
                    f"invalid {what} = {name!r} in {source}: must be one of "
                    f"{sorted(materials)} (define it under [materials.{name}])")
        if "infeed" not in d:
            raise InvalidParameterError(f"invalid {source}: an [infeed] table is required")
        infeed = Infeed.from_dict(d["infeed"], source)
        gap = check_range(f"particles.packing_gap in {source}",
                          particles.get("packing_gap", 0.05), 0.0, 1.0, lo_open=False)
        limit = infeed.max_rate(radius, gap)
        if infeed.rate > limit:
            raise InvalidParameterError(
                f"invalid infeed.rate = {infeed.rate:g} per minute in {source}: the inlet "
                f"region {infeed.region.tolist()} m at {np.linalg.norm(infeed.velocity):g} m/s "
                f"places at most {limit:.4g} cartridges per minute without overlap (rows "
                "of sites across the flow, one pitch apart); lower the rate, widen the region "
                "or raise infeed.velocity")
        outlet = d.get("outlet")
        if not isinstance(outlet, Mapping):
            raise InvalidParameterError(f"invalid {source}: an [outlet] table with point and "
                                        "normal (the plane spheres leave through) is required")
        _keys(outlet, ("point", "normal"), f"[outlet] of {source}")
        normal = _vec(f"outlet.normal in {source}", outlet.get("normal"), 3)
        if not np.linalg.norm(normal) > 0:
            raise InvalidParameterError(f"invalid outlet.normal in {source}: must be non-zero")
        out = {"point": _vec(f"outlet.point in {source}", outlet.get("point"), 3),
               "normal": normal / np.linalg.norm(normal)}
        effects = d.get("effects")
        if effects is not None and (not isinstance(effects, list) or not all(
                isinstance(e, str) for e in effects)):
            raise InvalidParameterError(f"invalid effects = {effects!r} in {source}: must be "
                                        "a list of effect names, e.g. [\"gravity\", \"belt\"]")
        if effects is None:
            effects = list(_DEFAULT_EFFECTS)
            if any(m.motion["kind"] != "fixed" for m in meshes):
                effects.append("moving_walls")
            if not any(np.any(b.velocity) for b in belts) and not any(
                    np.any(m.surface_velocity) for m in meshes):
                effects.remove("belt")
        duration = check_positive(f"duration (s) in {source}", d.get("duration", 20.0))
        from demfem.dem import CONTACT_MODELS

        model = d.get("model", "hertz_reissner_mindlin")
        if model not in CONTACT_MODELS:
            raise InvalidParameterError(f"invalid model = {model!r} in {source}: must be one "
                                        f"of {CONTACT_MODELS}")
        threads = check_count(f"threads in {source}", d.get("threads", 1), lo=1)
        if threads > MAX_THREADS:
            raise InvalidParameterError(f"invalid threads = {threads} in {source}: must be in "
                                        f"[1, {MAX_THREADS}]")
        table = cls(meshes=meshes, belts=belts, infeed=infeed, outlet=out, materials=materials,
                    particle_material=pm, sphere_radius=radius,
                    pool=check_count(f"particles.pool in {source}", particles.get("pool", 600),
                                     lo=1),
                    packing_gap=gap, effects=tuple(effects), model=model,
                    duration=duration,
                    window=check_range(f"window (s) in {source}",
                                       d.get("window", duration / 10), duration / MAX_WINDOWS,
                                       duration, lo_open=False, hi_open=False),
                    lost_below=check_range(f"lost_below (m) in {source}",
                                           d.get("lost_below", -0.05)),
                    threads=threads, source=source)
        check_physical_sense(table)
        return table

    # ---- the engine-neutral description ----------------------------------------------------

    @property
    def sphere_mass(self) -> float:
        """Mass of a sphere, kg (its material's density × volume)."""
        rho = self.materials[self.particle_material]["density"]
        return rho * 4.0 / 3.0 * math.pi * self.sphere_radius ** 3

    def parking(self) -> np.ndarray:
        """Where the pool's spheres wait before they are fed (k, 3), m: a square grid one
        metre below the floor, out of reach of every wall."""
        n = self.pool
        side = int(math.ceil(math.sqrt(n)))
        pitch = 2.5 * self.sphere_radius
        k = np.arange(n)
        lo = np.min([m.vertices.min(axis=0) for m in self.meshes]
                    + [np.append(b.polygon.min(axis=0), 0.0) for b in self.belts], axis=0)
        return np.column_stack([lo[0] + pitch * (k % side), lo[1] + pitch * (k // side),
                                np.full(n, lo[2] - 1.0)])

    def description(self):
        """The :class:`~demfem.scenes.table.SceneDescription`: the pool parked (the runner
        removes it before the first step), the meshes and the belts' floor as mesh walls,
        the outlet as the removal half-space."""
        from demfem.scenes.table import SceneDescription

        fixed = {"kind": "fixed"}
        walls = []
        for m in self.meshes:
            walls.append({"name": m.name, "kind": "mesh", "vertices": m.vertices,
                          "triangles": m.triangles, "closed": m.closed,
                          "motion": m.motion, "surface_velocity": m.surface_velocity,
                          "material": m.material, "top_view": None})
        v, t, tv = belt_floor(self.belts)
        # one floor mesh: its material is the first belt's (per-belt materials would need one
        # wall per material; refused below rather than silently merged)
        materials = {b.material for b in self.belts}
        if len(materials) > 1:
            raise InvalidParameterError(
                f"invalid belts in {self.source}: all belts must share one material (got "
                f"{sorted(materials)}); the floor is one mesh wall")
        walls.append({"name": "belts", "kind": "mesh", "vertices": v, "triangles": t,
                      "triangle_velocities": tv, "closed": False, "motion": dict(fixed),
                      "surface_velocity": np.zeros(3), "material": self.belts[0].material,
                      "top_view": None})
        n = self.pool
        return SceneDescription(
            positions=self.parking(), radii=np.full(n, self.sphere_radius),
            masses=np.full(n, self.sphere_mass), tags=np.zeros(n, np.int32),
            tag_names={0: "untagged"}, walls=walls, effects=self.effects,
            materials=self.materials, particle_material=self.particle_material,
            gravity=np.array([0.0, 0.0, -9.81]),
            removal={"kind": "half_space", "point": self.outlet["point"],
                     "normal": self.outlet["normal"]},
            refeed=None, planar="planar" in self.effects,
            parameters={"scene": SCENE_NAME, "source": self.source,
                        "meshes": [{"name": m.name, "file": str(m.file),
                                    "triangles": int(len(m.triangles))} for m in self.meshes],
                        "belts": [{"name": b.name, "polygon": b.polygon.tolist(),
                                   "velocity": b.velocity.tolist()} for b in self.belts],
                        "infeed_rate_per_minute": self.infeed.rate,
                        "sphere_radius": self.sphere_radius, "pool": self.pool})

    def summary_fields(self) -> dict[str, Any]:
        """The scene's settings for the run's summary (plain JSON values)."""
        return {"scene": SCENE_NAME, "source": self.source,
                "meshes": [{"name": m.name, "file": str(m.file), "scale": m.scale,
                            "triangles": int(len(m.triangles)), "motion": m.motion["kind"]}
                           for m in self.meshes],
                "belts": [{"name": b.name, "velocity_m_s": b.velocity.tolist()}
                          for b in self.belts],
                "infeed_rate_per_minute": self.infeed.rate,
                "infeed_max_rate_per_minute": self.infeed.max_rate(self.sphere_radius,
                                                                   self.packing_gap),
                "sphere_radius_m": self.sphere_radius, "pool": self.pool,
                "duration_s": self.duration, "window_s": self.window,
                "effects": list(self.effects), "model": self.model}

    def job_settings(self, duration: float) -> dict[str, Any]:
        """What makes a run's result, for its output folder's record
        (:class:`demfem.jobs.OutputFolder`): every field but the mesh arrays and the source
        path (the mesh files join as inputs by their SHA-256, :meth:`input_files`), and the
        run's ``duration`` (s). Strict-JSON values."""
        from demfem.io.strict_json import finite_or_none

        return finite_or_none({
            "scene": SCENE_NAME, "duration_s": float(duration),
            "meshes": [{"name": m.name, "scale": m.scale, "material": m.material,
                        "closed": m.closed, "motion": m.motion,
                        "surface_velocity": m.surface_velocity} for m in self.meshes],
            "belts": [{"name": b.name, "polygon": b.polygon, "velocity": b.velocity,
                       "material": b.material} for b in self.belts],
            "infeed": {"rate": self.infeed.rate, "region": self.infeed.region,
                       "velocity": self.infeed.velocity},
            "outlet": self.outlet, "materials": self.materials,
            "particle_material": self.particle_material, "sphere_radius": self.sphere_radius,
            "pool": self.pool, "packing_gap": self.packing_gap, "effects": list(self.effects),
            "model": self.model, "window": self.window, "lost_below": self.lost_below})

    def input_files(self) -> dict[str, Path]:
        """The mesh files the table was read from, by the name ``meshes[k]``."""
        return {f"meshes[{k}]": m.file for k, m in enumerate(self.meshes)}

    def replace(self, **changes: Any) -> "MeshTable":
        """A copy with some fields changed (e.g. a shorter ``duration``)."""
        return dataclasses.replace(self, **changes)


def check_physical_sense(table: MeshTable) -> None:
    """Refuse a scene that would run to a meaningless result, naming its file, the field and
    the limit: the pool's memory above half this machine's (an estimate, before anything is
    allocated); ``lost_below`` not below the belts; an inlet site off every belt, or on the
    exit side of the outlet plane (or within a radius of it); glass too soft to stand on the
    belt (its Hertz rest overlap under its weight above :data:`MAX_REST_OVERLAP` of its
    radius)."""
    src, r = table.source, table.sphere_radius
    need, limit = table.pool * POOL_BYTES_PER_SPHERE, memory_limit()
    if need > limit:
        raise InvalidParameterError(
            f"invalid particles.pool = {table.pool} in {src}: the pool's spheres need about "
            f"{need / 1e9:.3g} GB of memory ({POOL_BYTES_PER_SPHERE} bytes each), more than "
            f"the limit of {limit / 1e9:.3g} GB (half this machine's memory); the pool is the "
            "most cartridges on the table at once: a few thousand at most")
    if not table.lost_below < 0.0:
        raise InvalidParameterError(
            f"invalid lost_below = {table.lost_below!r} m in {src}: must be below the belts "
            f"(z = 0; a cartridge on a belt has its centre at z = r = {r:.4g} m), e.g. -0.05: "
            "spheres whose centre falls below it are counted as lost")
    sites = table.infeed.sites(r, table.packing_gap)
    for k, site in enumerate(sites):
        if not any(_inside(b.polygon, site[:2]) for b in table.belts):
            raise InvalidParameterError(
                f"invalid infeed.region = {table.infeed.region.tolist()} m in {src}: its "
                f"inlet site {k} at {site[:2].tolist()} m is not over any belt: a cartridge "
                "placed there would fall")
    p, n = table.outlet["point"], table.outlet["normal"]
    past = (sites - p) @ n
    if len(past) and float(past.max()) > -r:
        k = int(np.argmax(past))
        raise InvalidParameterError(
            f"invalid outlet in {src}: the inlet site {sites[k].tolist()} m is "
            f"{'past' if past[k] > 0 else 'within one radius of'} the outlet plane (point "
            f"{p.tolist()}, normal {n.tolist()}): cartridges would leave as they arrive; the "
            "outlet is downstream of the inlet, its normal pointing out of the table")
    glass = table.materials[table.particle_material]
    belt = table.materials[table.belts[0].material]
    e_star = 1.0 / sum((1.0 - m["poisson_ratio"] ** 2) / m["young_modulus"]
                       for m in (glass, belt))
    rest = (3.0 * table.sphere_mass * 9.81 / (4.0 * e_star * math.sqrt(r))) ** (2.0 / 3.0)
    if rest > MAX_REST_OVERLAP * r:
        raise InvalidParameterError(
            f"invalid materials.{table.particle_material}.young_modulus = "
            f"{glass['young_modulus']:g} Pa in {src}: a cartridge resting on the belt would "
            f"sink {rest:.3g} m into it under its own weight (Hertz, against "
            f"{table.belts[0].material!r} at {belt['young_modulus']:g} Pa), more than "
            f"{MAX_REST_OVERLAP:g} of its radius {r:.3g} m: it would fall through the belt; "
            "the glass is far stiffer (45 GPa in the paper; 1e7 Pa is soft enough for fast "
            "runs)")


def memory_limit() -> float:
    """Half the machine's physical memory, bytes (8 GB where it cannot be read)."""
    import os

    try:
        return 0.5 * os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return 8e9


def _inside(polygon: np.ndarray, point: np.ndarray) -> bool:
    """Whether ``point`` lies in (or on) the convex counter-clockwise ``polygon`` (m)."""
    edges = np.roll(polygon, -1, axis=0) - polygon
    rel = point - polygon
    cross = (edges[:, 0] * rel[:, 1] - edges[:, 1] * rel[:, 0]) / np.linalg.norm(edges, axis=1)
    return bool(np.all(cross >= -1e-9 * float(np.ptp(polygon, axis=0).max())))


def extrude_polyline(xy: Any, height: float, *, spacing: float,
                     layers: int) -> tuple[np.ndarray, np.ndarray]:
    """A vertical wall mesh over the plan polyline ``xy`` (k, 2), m, from z = 0 to ``height``
    (m): each segment cut into pieces of at most ``spacing`` (m) along it and ``layers`` rows
    up, two triangles per cell, corners shared between neighbouring segments. For examples,
    tests and benchmarks (CAD exports the same kind of mesh)."""
    xy = np.asarray(xy, float)
    height = check_positive("height", height)
    spacing = check_positive("spacing", spacing)
    layers = check_count("layers", layers, lo=1)
    points = [xy[0]]
    for a, b in zip(xy[:-1], xy[1:]):
        pieces = max(1, int(math.ceil(np.linalg.norm(b - a) / spacing)))
        for k in range(1, pieces + 1):
            points.append(a + (b - a) * (k / pieces))
    plan = np.asarray(points)
    nu, nz = len(plan), layers + 1
    z = np.linspace(0.0, height, nz)
    vertices = np.column_stack([np.repeat(plan, nz, axis=0), np.tile(z, nu)])
    cells = []
    for i in range(nu - 1):
        for j in range(layers):
            a, b = i * nz + j, (i + 1) * nz + j
            cells += [[a, b, b + 1], [a, b + 1, a + 1]]
    return vertices, np.asarray(cells, np.int64)


def table_walls_as_mesh(table: Any, *, triangles: int = 10_000, spacing: float | None = None):
    """The default-style :class:`~demfem.scenes.table.AccumulationTable` ``table`` with its
    fixed vertical walls (back, lower and upper sides, tilted wall) replaced by one mesh wall
    over their trace, about ``triangles`` triangles (or cells of ``spacing`` m), of the walls'
    height; the belt plane and the gate stay analytic. The analytic side planes are infinite,
    the mesh ends where the spheres cannot go: the lower side wall runs 5 cm past the gate,
    the back and upper walls span the table. For the comparison of mesh and analytic walls
    on the same geometry (``tests/python/test_mesh_walls.py``,
    ``benches/mesh_walls_cost.py``)."""
    d = table.build()
    h, W, L, xe = table.wall_height, table.width, table.length, table.x_end
    trace = np.array([(xe + 0.05, 0.0), (0.0, 0.0), (0.0, W), (L, W), (xe, table.tilted_wall_gap)])
    length = float(np.sum(np.linalg.norm(np.diff(trace, axis=0), axis=1)))
    if spacing is None:
        spacing = math.sqrt(2.0 * length * h / triangles)
    vertices, cells = extrude_polyline(trace, h, spacing=spacing,
                                       layers=max(1, round(h / spacing)))
    keep = [w for w in d.walls if w["name"] in ("belt", "gate")]
    mesh = {"name": "walls_mesh", "kind": "mesh", "vertices": vertices, "triangles": cells,
            "closed": False, "motion": {"kind": "fixed"}, "surface_velocity": np.zeros(3),
            "material": "glass", "top_view": None}
    return dataclasses.replace(d, walls=keep[:1] + [mesh] + keep[1:])
