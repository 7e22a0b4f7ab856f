"""The accumulation table of Boso et al. (2021), Fig. 4, as an engine-neutral scene.

Frame and units (SI): x along the belt (the belt moves towards +x), y across the table, z up;
the belt surface is the plane z = 0. Top view::

      y = width  +---------------------------+.
                 |                           |  `.  tilted wall, length l, angle theta
                 |   rectangular section     |    `.   below the +x direction
                 |   (square packing)        | tri-  `.
                 |                           | angular |  <- gate: plate in the plane
                 |                           | section |     x = x_end, slides along y
      y = 0      +---------------------------+---------+ ..  opening 0 <= y <= w(t)
               x = 0                    x = length    x = x_end = length + l cos(theta)

* Rectangular section 0 <= x <= ``length``, 0 <= y <= ``width``, closed upstream by a wall at
  x = 0 and on the sides by the walls y = 0 ("lower") and y = ``width`` ("upper").
* Constricted (triangular) section: the lower side wall runs on to x_end; the upper boundary is
  one vertical tilted wall from (length, width), of length l = ``tilted_wall_length`` at the
  angle theta = ``tilted_wall_angle_deg`` below +x. Its tip is at (x_end, y_tip) with
  y_tip = width - l sin(theta): the tilted wall alone leaves a gap 0 <= y <= y_tip at x = x_end
  ("the length of the tilted wall and the angle univocally define the geometry of the
  opening", paper, section on Fig. 4).
* The gate (the only moving wall) is a vertical plate in the plane x = x_end that slides along
  y, in its own plane, between the lower side wall and the tilted wall's tip. Its lower edge is
  at y = w(t), so the opening is 0 <= y <= w(t) with

      w(t) = opening_width + gate_amplitude * sin(2 pi t / gate_period + gate_phase).

  ``gate_amplitude`` is A of the paper (the paper sweeps A in {1, 2, 5, 7.5} cm) and
  ``opening_width`` is the mean width w0. Sliding in its own plane means the gate never opens
  a gap to another wall, whatever A. The gate plate reaches up past the tilted wall's tip by
  A plus one sphere radius, so at its lowest position it still closes y_tip.
  The opening must never close and must stay inside the gap the tilted wall leaves:
  0 < w0 - A and w0 + A <= y_tip (validated). The minimum width w0 - A may be smaller than a
  sphere diameter: this is allowed on purpose, since clogging is what the paper's A = 1 cm run
  shows; :attr:`AccumulationTable.clogging_possible` says whether it can happen.
  For the paper's sweep A in {1, 2, 5, 7.5} cm on one geometry, keep the narrowest opening at
  2 cm with opening_width = A + 0.02 m; that needs y_tip >= 2 A + 0.02 m = 0.17 m at
  A = 7.5 cm, e.g. tilted_wall_length = 0.24 m at 45 degrees (840 spheres still fit).
* Spheres whose centre passes x_end + radius have left through the opening and are removed
  (with ``refeed``, re-inserted upstream at x = pitch/2, one site per row of the square
  packing; the most upstream square column is then left empty at t = 0).

The start configuration follows Fig. 4: a hexagonal packing fills the triangular section
(columns parallel to y, sqrt(3)/2 pitch apart along x, every other column shifted by half a
pitch; the first column half a pitch downstream of x = length), and a square packing fills
the rectangular section from the interface x = ``length`` upstream, column by column, until
``n_spheres`` are placed (the most upstream column may be partial, centred in y). The pitch is
one diameter times (1 + ``packing_gap``), and every sphere keeps half of that gap from the walls,
so nothing touches at t = 0.

Tags (paper Fig. 4, whose image is not in the source text, so these rules are our reading of
the caption and text; all are chosen on the start positions):

* FIRST_LINE (magenta): every sphere of the square column nearest the constricted section
  (centres at x = length - pitch/2): "the spheres lying close to the constricted section ...
  initially at the boundary ... with square packing on the rectangular part and hexagonal on
  the triangular side".
* RECTANGULAR_CENTRE (cyan): the square-packed sphere, not in the first line, nearest the
  centroid of all square-packed start positions.
* TRIANGULAR_CENTRE (green): the hexagonally packed sphere nearest the centroid of all
  hexagonally packed start positions.
* UPPER_VERTEX (yellow): the hexagonally packed sphere nearest the corner (length, width) where
  the tilted wall meets the upper side wall.
* LOWER_VERTEX (blue): the hexagonally packed sphere nearest the corner (length, 0), the
  triangular section's vertex on the lower side wall.
* NONE: every other sphere.
"""
from __future__ import annotations

import copy
import dataclasses
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np
from scipy.spatial import cKDTree

from demfem.errors import InvalidParameterError, check_range
from demfem.io.atomic import write_text_atomic
from demfem.materials import PAPER_GLASS, Material
from demfem.cartridge import Cartridge


__all__ = [
    "AccumulationTable",
    "SceneDescription",
    "Tag",
    "TAG_NAMES",
    "cartridge_sites",
    "wall_displacement",
    "wall_velocity",
]

#: Particle kinds of the table: equivalent spheres, bead clumps, exact cartridge shapes.
PARTICLES = ("sphere", "clump", "cylinder", "revolution")

#: Contact laws of the equivalent spheres a table scene may name (``contact_model``; see
#: :func:`demfem.dem.from_scene`).
TABLE_CONTACT_MODELS = ("hertz_reissner_mindlin", "hertz_mindlin", "fem_line")

#: Most start sites the constricted section of a table may hold (a bound on the site loop
#: and on memory: 10^6 spheres is far beyond what one machine runs).
MAX_START_SITES = 1e6

#: Name of this scene in scene files (the optional key ``scene``).
SCENE_NAME = "accumulation_table"


from demfem.scenes.description import (TAG_NAMES, SceneDescription, Tag,  # noqa: E402
                                       _is_bool, wall_displacement, wall_velocity)


@dataclass(frozen=True)
class AccumulationTable:
    """Parameters of the accumulation table (paper Fig. 4); SI units, validated on creation.

    See the module docstring for the geometry, the gate law and the tag rules.

    Attributes:
        n_spheres: number of equivalent spheres at t = 0 (paper: 840).
        sphere_radius: equivalent-sphere radius, m: derived from ``cartridge`` and
            ``density`` (the sphere of the cartridge's glass volume; 8.09 mm for the default,
            paper: diameter about 1.6 cm). Given, it must equal that value.
        sphere_mass: equivalent-sphere mass, kg: the cartridge's (4.94 g for the default).
            Given, it must equal that value.
        length: length of the rectangular section along the belt (x), m.
        width: width of the table across the belt (y), m.
        tilted_wall_length: length l of the tilted wall, m.
        tilted_wall_angle_deg: angle theta of the tilted wall below the belt direction +x,
            degrees, in (0, 90).
        wall_height: height of all vertical walls, m (at least one diameter).
        opening_width: mean opening width w0, m.
        gate_amplitude: amplitude A of the opening's oscillation, m; 0 keeps the gate still.
        gate_period: period T of the opening's oscillation, s.
        gate_phase: phase of the oscillation at t = 0, rad (0: the opening is w0 and widening).
        belt_velocity: belt surface speed along +x, m/s.
        gravity: magnitude of gravity along -z, m/s^2.
        young_modulus: Young's modulus of the glass (spheres and walls), Pa. The paper uses
            45 GPa; type I borosilicate is nearer 64-74 GPa.
        poisson_ratio: Poisson's ratio, in (-1, 0.5).
        density: glass density, kg/m^3 (the cartridge's mass and the contact laws).
        friction: Coulomb friction coefficient, sphere-sphere and sphere-wall (paper: 0.2).
        restitution: normal coefficient of restitution, in (0, 1].
        rolling_resistance: rolling-resistance coefficient; > 0 adds the effect
            "rolling_resistance".
        planar: keep the centres in one layer (effect "planar"): an upright 64 mm cartridge
            cannot ride on top of its neighbours the way a sphere can.
        refeed: re-insert removed spheres upstream to keep the population steady.
        packing_gap: gap between neighbouring spheres at t = 0, as a fraction of the diameter.
        particle: what stands at each start site: ``"sphere"`` (the equivalent sphere, run by
            :func:`demfem.dem.from_scene`), ``"clump"`` (the default cartridge as a rigid clump
            of beads), ``"cylinder"`` (the default cartridge as an exact parry shape) or
            ``"revolution"`` (the same exact cartridge as a body of revolution with analytic
            contact tests: the fast full shape), all upright on the belt at the sphere's
            (x, y) and run by
            :func:`demfem.rigid.from_scene`. Full shapes need ``wall_height`` at least the
            cartridge length (an upright cartridge must not lean over the walls) and cannot
            run ``planar``.
        cartridge_fraction: mixed tables: the fraction of start sites, in [0, 1], that hold
            a cartridge of the shape named by ``particle`` (not ``"sphere"``); the
            other sites hold equivalent spheres, and both run together in the rigid engine
            (:func:`demfem.rigid.from_scene`). Which sites: :func:`cartridge_sites` — exactly
            round(n f) of them, spread evenly over the site order (deterministic, no seed).
            1 (the default) fills every site with ``particle``; with ``particle = "sphere"``
            it must stay 1.
        contact_model: the equivalent spheres' contact law (:data:`TABLE_CONTACT_MODELS`):
            ``"hertz_reissner_mindlin"`` (the calibrated sphere of the paper),
            ``"hertz_mindlin"`` (no shell) or ``"fem_line"`` (the linear law fitted to the
            FEM of two cartridges side by side, for upright cartridges' line contacts).
    """

    n_spheres: int = 840
    # None: derived from the cartridge in __post_init__ (always a float afterwards)
    sphere_radius: float = None  # type: ignore[assignment]
    sphere_mass: float = None  # type: ignore[assignment]
    length: float = 0.70
    width: float = 0.34
    tilted_wall_length: float = 0.36
    tilted_wall_angle_deg: float = 45.0
    wall_height: float = 0.05
    opening_width: float = 0.04
    gate_amplitude: float = 0.02
    gate_period: float = 2.0
    gate_phase: float = 0.0
    belt_velocity: float = 0.2
    gravity: float = 9.81
    young_modulus: float = PAPER_GLASS.E
    poisson_ratio: float = PAPER_GLASS.nu
    density: float = PAPER_GLASS.density
    friction: float = 0.2
    restitution: float = 0.5
    rolling_resistance: float = 0.0
    planar: bool = False
    refeed: bool = False
    packing_gap: float = 0.01
    particle: str = "sphere"
    cartridge_fraction: float = 1.0
    contact_model: str = "hertz_reissner_mindlin"
    cartridge: Cartridge = field(default_factory=Cartridge)

    # ---- validation ------------------------------------------------------------------------

    def __post_init__(self) -> None:
        # Every float field is normalised to a Python float; a wrong type names its field.
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name == "cartridge" or (value is None and f.name in ("sphere_radius",
                                                                       "sphere_mass")):
                continue
            if f.type == "str":
                if not isinstance(value, str):
                    raise InvalidParameterError(
                        f"invalid {f.name} = {value!r}: must be a string")
            elif f.type == "bool":
                if not _is_bool(value):
                    raise InvalidParameterError(
                        f"invalid {f.name} = {value!r}: must be true or false")
                object.__setattr__(self, f.name, bool(value))
            elif f.type == "int":
                if _is_bool(value) or not (isinstance(value, (int, np.integer))
                                           or (isinstance(value, float) and value.is_integer())):
                    raise InvalidParameterError(
                        f"invalid {f.name} = {value!r}: must be a whole number")
                object.__setattr__(self, f.name, int(value))
            else:
                if _is_bool(value):
                    raise InvalidParameterError(
                        f"invalid {f.name} = {value!r}: must be a real number")
                try:
                    number = float(value)
                except (TypeError, ValueError):
                    raise InvalidParameterError(
                        f"invalid {f.name} = {value!r}: must be a real number") from None
                # Finiteness and range are checked field by field in _validate, whose
                # messages give each field's own allowed range.
                object.__setattr__(self, f.name, number)
        # the cartridge carries the table's glass; the equivalent sphere follows from both
        glass = Material(E=check_range("young_modulus", self.young_modulus, 0.0, math.inf),
                         nu=check_range("poisson_ratio", self.poisson_ratio, -1.0, 0.5),
                         density=check_range("density", self.density, 0.0, math.inf),
                         name="the table's glass")
        cart = Cartridge.from_geometry(self.cartridge, glass)
        object.__setattr__(self, "cartridge", cart)
        sphere = cart.equivalent_sphere()
        for name, derived in (("sphere_radius", sphere.radius), ("sphere_mass", sphere.mass)):
            value = getattr(self, name)
            if value is None:
                object.__setattr__(self, name, derived)
            elif (_is_bool(value) or not isinstance(value, (int, float, np.floating))
                  or not math.isclose(float(value), derived, rel_tol=1e-9)):
                raise InvalidParameterError(
                    f"invalid {name} = {value!r}: the equivalent sphere has the [cartridge]'s "
                    f"glass volume and mass, {derived:.9g} "
                    + ("m" if name == "sphere_radius" else "kg")
                    + f" at density {self.density:g} kg/m^3; set the cartridge's dimensions "
                    f"instead (or omit {name})")
        self._validate()

    def _validate(self) -> None:
        inf = math.inf
        r = self.sphere_radius
        check_range("sphere_radius", r, 0.0, inf)
        check_range("sphere_mass", self.sphere_mass, 0.0, inf)
        check_range("packing_gap", self.packing_gap, 0.0, 1.0, lo_open=False)
        pitch = self.pitch
        check_range("width", self.width, 2.0 * pitch, inf, lo_open=False)
        check_range("length", self.length, 0.0, inf)
        check_range("tilted_wall_angle_deg", self.tilted_wall_angle_deg, 0.0, 90.0)
        sin_t = math.sin(math.radians(self.tilted_wall_angle_deg))
        _explained(check_range, "tilted_wall_length", self.tilted_wall_length, 0.0,
                   self.width / sin_t,
                   why="the tilted wall must end above the lower side wall "
                       "(width - tilted_wall_length*sin(angle) > 0)")
        check_range("wall_height", self.wall_height, 2.0 * r, inf, lo_open=False)
        y_tip = self.tilted_wall_gap
        _explained(check_range, "opening_width", self.opening_width, 0.0, y_tip,
                   hi_open=False,
                   why=f"the mean opening must fit in the gap the tilted wall leaves "
                       f"(width - tilted_wall_length*sin(angle) = {y_tip:.4g} m)")
        a_max = min(self.opening_width, y_tip - self.opening_width)
        _explained(check_range, "gate_amplitude", self.gate_amplitude, 0.0, a_max,
                   lo_open=False, hi_open=self.opening_width <= y_tip - self.opening_width,
                   why=f"the opening w(t) = opening_width +- gate_amplitude must stay in "
                       f"(0, {y_tip:.4g}] m: it must never close (opening_width = "
                       f"{self.opening_width:g} m) nor outgrow the gap the tilted wall leaves")
        check_range("gate_period", self.gate_period, 0.0, inf)
        check_range("gate_phase", self.gate_phase)
        check_range("belt_velocity", self.belt_velocity, 0.0, inf, lo_open=False)
        check_range("gravity", self.gravity, 0.0, inf, lo_open=False)
        check_range("young_modulus", self.young_modulus, 0.0, inf)
        check_range("poisson_ratio", self.poisson_ratio, -1.0, 0.5)
        check_range("density", self.density, 0.0, inf)
        check_range("friction", self.friction, 0.0, inf, lo_open=False)
        check_range("restitution", self.restitution, 0.0, 1.0, hi_open=False)
        check_range("rolling_resistance", self.rolling_resistance, 0.0, inf, lo_open=False)
        # the constricted section's sites are found by a loop: bound it before it runs
        sites = (self.x_end - self.length) * self.width / (pitch * pitch * math.sqrt(3) / 2)
        if not sites <= MAX_START_SITES:
            raise InvalidParameterError(
                f"invalid width = {self.width!r} with tilted_wall_length = "
                f"{self.tilted_wall_length!r}: the constricted section would hold about "
                f"{sites:.3g} spheres of {2 * r:g} m; demfem tables hold at most "
                f"{MAX_START_SITES:g} (a table that size is not a scene one machine can run)")
        if self.contact_model not in TABLE_CONTACT_MODELS:
            raise InvalidParameterError(
                f"invalid contact_model = {self.contact_model!r}: must be one of "
                f"{TABLE_CONTACT_MODELS}")
        if self.particle not in PARTICLES:
            raise InvalidParameterError(
                f"invalid particle = {self.particle!r}: must be one of {PARTICLES}")
        check_range("cartridge_fraction", self.cartridge_fraction, 0.0, 1.0, lo_open=False,
                    hi_open=False)
        if self.particle == "sphere" and self.cartridge_fraction != 1.0:
            raise InvalidParameterError(
                f"invalid cartridge_fraction = {self.cartridge_fraction!r} with particle = "
                "'sphere': the fraction of sites holding cartridges needs particle = 'clump', "
                "'cylinder' or 'revolution' (the cartridge shape); with spheres it must be 1")
        if self.particle != "sphere":
            length = self.cartridge.length
            _explained(check_range, "wall_height", self.wall_height, length, inf,
                       lo_open=False,
                       why=f"particle = {self.particle!r} stands upright cartridges of "
                           f"{length:g} m: the walls must be at least that high")
            if self.planar:
                raise InvalidParameterError(
                    f"invalid planar = True with particle = {self.particle!r}: full-shape "
                    "cartridges move in three dimensions (planar is for spheres)")
            if self.rolling_resistance > 0:
                raise InvalidParameterError(
                    f"invalid rolling_resistance = {self.rolling_resistance!r} with particle = "
                    f"{self.particle!r}: full shapes roll by their shape, the rolling-"
                    "resistance model is for spheres; use 0")
        n_hex = len(self._hexagonal_sites())
        if n_hex < 3:
            # the start tags the triangular section's centre and both vertices: three sites
            l_max = self.width / sin_t
            l_min = self._shortest_tilted_wall(3, l_max)
            allowed = (f"[{l_min:.4g}, {l_max:.4g}) m" if l_min is not None
                       else "none at this width, angle and sphere size")
            raise InvalidParameterError(
                f"invalid tilted_wall_length = {self.tilted_wall_length!r}: the triangular "
                f"section leaves room for {n_hex} spheres, at least 3 are needed (its centre "
                f"and both vertices are tagged); must be in {allowed} with width = "
                f"{self.width:g} m, tilted_wall_angle_deg = {self.tilted_wall_angle_deg:g} "
                f"and a packing pitch of {self.pitch:.4g} m")
        n_min, n_max = self._sphere_count_range()
        if not n_min <= self.n_spheres <= n_max:
            raise InvalidParameterError(
                f"invalid n_spheres = {self.n_spheres}: must be in [{n_min}, {n_max}] for this "
                f"table ({n_min - 2 * self.rows_in_rectangle} fit the triangular section, plus "
                f"at least two square columns of {self.rows_in_rectangle}; a longer `length` "
                "holds more" + (", and refeed keeps the most upstream column free)"
                                if self.refeed else ")"))

    # ---- derived geometry ------------------------------------------------------------------

    @property
    def sphere_diameter(self) -> float:
        """Sphere diameter, m."""
        return 2.0 * self.sphere_radius

    @property
    def pitch(self) -> float:
        """Centre distance of neighbours in the start packings, m."""
        return self.sphere_diameter * (1.0 + self.packing_gap)

    @property
    def x_end(self) -> float:
        """x of the opening (the gate plane), m."""
        return self.length + self.tilted_wall_length * math.cos(
            math.radians(self.tilted_wall_angle_deg))

    @property
    def tilted_wall_gap(self) -> float:
        """y of the tilted wall's tip: the widest opening the geometry allows, m."""
        return self.width - self.tilted_wall_length * math.sin(
            math.radians(self.tilted_wall_angle_deg))

    @property
    def rows_in_rectangle(self) -> int:
        """Rows (along y) of the square packing."""
        return int(math.floor(self.width / self.pitch + 1e-9))

    @property
    def min_opening_width(self) -> float:
        """Narrowest opening w0 - A, m."""
        return self.opening_width - self.gate_amplitude

    @property
    def max_opening_width(self) -> float:
        """Widest opening w0 + A, m."""
        return self.opening_width + self.gate_amplitude

    @property
    def clogging_possible(self) -> bool:
        """True if the narrowest opening is narrower than a sphere diameter, so a sphere can
        be held at the opening (allowed on purpose: the paper's A = 1 cm run clogs)."""
        return self.min_opening_width < self.sphere_diameter

    def opening_width_at(self, t: np.ndarray | float) -> np.ndarray:
        """Opening width w(t) = w0 + A sin(2 pi t / T + phase), m, at times ``t`` (s)."""
        t = np.asarray(t, float)
        return self.opening_width + self.gate_amplitude * np.sin(
            2.0 * math.pi * t / self.gate_period + self.gate_phase)

    @property
    def effects(self) -> tuple[str, ...]:
        """The physics this scene needs, derived from the parameters (DESIGN section 3)."""
        names = []
        if self.gravity > 0:
            names.append("gravity")
        if self.belt_velocity > 0:
            names.append("belt")
        if self.gate_amplitude > 0:
            names.append("moving_walls")
        if self.friction > 0:
            names.append("friction")
        # Rotation is needed whenever friction acts: the belt makes the spheres roll.
        if self.friction > 0:
            names.append("rotation")
        names.append("damping")
        if self.planar:
            names.append("planar")
        if self.rolling_resistance > 0:
            names.append("rolling_resistance")
        return tuple(names)

    # ---- start positions -------------------------------------------------------------------

    def _shortest_tilted_wall(self, n_sites: int, l_max: float) -> float | None:
        """Shortest tilted-wall length (m, to 1 %) below ``l_max`` whose triangular section
        holds ``n_sites`` hexagonal sites, other fields as they are; None if there is none
        (used for the validation message only)."""
        probe = copy.copy(self)
        length = max(self.pitch / 20.0, self.tilted_wall_length)
        for _ in range(5000):
            if not length < l_max:
                break
            object.__setattr__(probe, "tilted_wall_length", length)
            if len(probe._hexagonal_sites()) >= n_sites:
                return length
            length *= 1.01
        return None

    def _hexagonal_sites(self) -> np.ndarray:
        """(k, 2) centres of the hexagonal packing of the constricted section, in columns
        parallel to y from the interface x = length towards the opening."""
        p, half = self.pitch, 0.5 * self.pitch
        theta = math.radians(self.tilted_wall_angle_deg)
        # Inward unit normal of the tilted wall and a point on it.
        normal = np.array([-math.sin(theta), -math.cos(theta)])
        corner = np.array([self.length, self.width])
        sites = []
        column = 0
        while True:
            x = self.length + half + column * p * math.sqrt(3.0) / 2.0
            if x > self.x_end - half:
                break
            y = half if column % 2 == 0 else p
            while y <= self.width - half:
                if (np.array([x, y]) - corner) @ normal >= half:
                    sites.append((x, y))
                y += p
            column += 1
        return np.array(sites, float).reshape(-1, 2)

    def _square_row_y(self) -> np.ndarray:
        """y of the rows of the square packing, m, centred across the table (the width need
        not be a whole number of pitches)."""
        rows = self.rows_in_rectangle
        return (0.5 * (self.width - rows * self.pitch) + 0.5 * self.pitch
                + self.pitch * np.arange(rows))

    def _square_columns_available(self) -> int:
        """Square columns that fit between the back wall and the interface."""
        columns = int(math.floor(self.length / self.pitch + 1e-9))
        return columns - 1 if self.refeed else columns

    def _sphere_count_range(self) -> tuple[int, int]:
        n_hex = len(self._hexagonal_sites())
        rows = self.rows_in_rectangle
        return n_hex + 2 * rows, n_hex + rows * self._square_columns_available()

    def start_positions(self) -> tuple[np.ndarray, np.ndarray]:
        """Start centres (N, 3) in m and tags (N,), hexagonal sites first, then the square
        columns from the interface upstream (see the module docstring)."""
        p, half, r = self.pitch, 0.5 * self.pitch, self.sphere_radius
        hexagonal = self._hexagonal_sites()
        rows = self.rows_in_rectangle
        n_square = self.n_spheres - len(hexagonal)
        y_rows = self._square_row_y()
        sites = []
        for k in range(n_square):
            column, row = divmod(k, rows)
            in_column = min(rows, n_square - column * rows)
            # A partial (most upstream) column is centred in y.
            row += (rows - in_column) // 2
            sites.append((self.length - half - column * p, y_rows[row]))
        square = np.array(sites, float)
        xy = np.vstack([hexagonal, square])
        positions = np.column_stack([xy, np.full(len(xy), r)])

        tags = np.zeros(len(xy), np.int32)
        n_hex = len(hexagonal)
        sq_index = np.arange(n_hex, len(xy))
        # the first line is the most downstream square column (index < rows), whatever the
        # table's length (an isclose on x loses it at km scales)
        first_line = sq_index[np.arange(len(square)) < min(rows, len(square))]
        tags[first_line] = Tag.FIRST_LINE
        rest = sq_index[tags[sq_index] == Tag.NONE]
        centre = square.mean(axis=0)
        tags[rest[np.argmin(np.linalg.norm(xy[rest] - centre, axis=1))]] = Tag.RECTANGULAR_CENTRE
        hex_index = np.arange(n_hex)
        chosen: list[int] = []
        for tag, target in ((Tag.TRIANGULAR_CENTRE, hexagonal.mean(axis=0)),
                            (Tag.UPPER_VERTEX, np.array([self.length, self.width])),
                            (Tag.LOWER_VERTEX, np.array([self.length, 0.0]))):
            k = int(hex_index[np.argmin(np.linalg.norm(hexagonal - target, axis=1))])
            if k in chosen:
                raise InvalidParameterError(
                    f"invalid tilted_wall_length = {self.tilted_wall_length:g}: the triangular "
                    f"section holds too few spheres ({n_hex}) to tag its centre and both "
                    "vertices separately; use a longer tilted wall")
            chosen.append(k)
            tags[k] = tag
        return positions, tags

    # ---- walls -----------------------------------------------------------------------------

    def walls(self) -> list[dict[str, Any]]:
        """The walls at their reference position (see :class:`SceneDescription`)."""
        h, W, L, xe = self.wall_height, self.width, self.length, self.x_end
        y_tip = self.tilted_wall_gap
        theta = math.radians(self.tilted_wall_angle_deg)
        fixed = {"kind": "fixed"}
        still = np.zeros(3)

        def plane(name, point, normal, top_view, surface_velocity=still):
            return {"name": name, "kind": "plane", "point": np.array(point, float),
                    "normal": np.array(normal, float), "motion": dict(fixed),
                    "surface_velocity": np.array(surface_velocity, float),
                    "material": "glass",
                    "top_view": None if top_view is None else np.array(top_view, float)}

        def vertical_polygon(name, a, b, normal, motion):
            vertices = np.array([[a[0], a[1], 0.0], [b[0], b[1], 0.0],
                                 [b[0], b[1], h], [a[0], a[1], h]])
            return {"name": name, "kind": "polygon", "vertices": vertices,
                    "normal": np.array(normal, float), "motion": motion,
                    "surface_velocity": still.copy(), "material": "glass",
                    "top_view": np.array([a, b], float)}

        gate_top = y_tip + self.gate_amplitude + self.sphere_radius
        gate_motion = ({"kind": "harmonic", "direction": np.array([0.0, 1.0, 0.0]),
                        "amplitude": self.gate_amplitude, "period": self.gate_period,
                        "phase": self.gate_phase}
                       if self.gate_amplitude > 0 else dict(fixed))
        return [
            plane("belt", (0, 0, 0), (0, 0, 1), None, (self.belt_velocity, 0, 0)),
            plane("back", (0, 0, 0), (1, 0, 0), [(0, 0), (0, W)]),
            plane("lower_side", (0, 0, 0), (0, 1, 0), [(0, 0), (xe, 0)]),
            plane("upper_side", (0, W, 0), (0, -1, 0), [(0, W), (L, W)]),
            vertical_polygon("tilted", (L, W), (xe, y_tip),
                             (-math.sin(theta), -math.cos(theta), 0.0), dict(fixed)),
            vertical_polygon("gate", (xe, self.opening_width), (xe, gate_top),
                             (-1.0, 0.0, 0.0), gate_motion),
        ]

    # ---- the description -------------------------------------------------------------------

    def build(self) -> SceneDescription:
        """The engine-neutral :class:`SceneDescription` of this table, checked for overlaps
        and for spheres outside the walls."""
        positions, tags = self.start_positions()
        n = len(positions)
        r, half = self.sphere_radius, 0.5 * self.pitch
        refeed = None
        if self.refeed:
            y_rows = self._square_row_y()
            sites = np.column_stack([np.full(len(y_rows), half), y_rows,
                                     np.full(len(y_rows), r)])
            refeed = {"sites": sites, "velocity": np.zeros(3)}
        description = SceneDescription(
            positions=positions,
            radii=np.full(n, r),
            masses=np.full(n, self.sphere_mass),
            tags=tags,
            tag_names=dict(TAG_NAMES),
            walls=self.walls(),
            effects=self.effects,
            materials={"glass": {
                "young_modulus": self.young_modulus,
                "poisson_ratio": self.poisson_ratio,
                "density": self.density,
                "friction": self.friction,
                "restitution": self.restitution,
                "rolling_resistance": self.rolling_resistance,
            }},
            particle_material="glass",
            gravity=np.array([0.0, 0.0, -self.gravity]),
            removal={"kind": "half_space", "point": np.array([self.x_end + r, 0.0, 0.0]),
                     "normal": np.array([1.0, 0.0, 0.0])},
            refeed=refeed,
            planar=self.planar,
            parameters=dataclasses.asdict(self),
        )
        description.check_start_positions()
        if self.particle != "sphere":
            self._check_cartridge_clearance(description)
        return description

    def _check_cartridge_clearance(self, description: "SceneDescription") -> None:
        """Raise if two upright cartridges at the start sites would overlap or one would
        cross a wall: neighbours' axes must be at least one body diameter apart, and every
        axis at least one body radius inside every wall (the walls are vertical)."""
        r_body = 0.5 * self.cartridge.body_outer_diameter
        xy = description.positions[:, :2]
        tree = cKDTree(xy)
        pairs = tree.query_pairs(2.0 * r_body, output_type="ndarray")
        if len(pairs):
            i, j = (int(k) for k in pairs[0])
            raise InvalidParameterError(
                f"invalid start positions for particle = {self.particle!r}: cartridges {i} "
                f"and {j} are {float(np.linalg.norm(xy[i] - xy[j])):.4g} m apart, less than "
                f"the body diameter {2 * r_body:g} m")
        for w in description.walls:
            if w["name"] == "belt":
                continue
            point = w["point"] if w["kind"] == "plane" else w["vertices"][0]
            signed = (description.positions - point) @ np.asarray(w["normal"])
            k = int(np.argmin(signed))
            if signed[k] < r_body:
                raise InvalidParameterError(
                    f"invalid start positions for particle = {self.particle!r}: cartridge {k} "
                    f"is {signed[k]:.4g} m from wall {w['name']!r}, less than its body radius "
                    f"{r_body:g} m")

    # ---- scene files -----------------------------------------------------------------------

    @classmethod
    def from_dict(cls, values: Mapping[str, Any], source: str = "scene") -> "AccumulationTable":
        """A table from a mapping of field names to values; unknown keys are errors."""
        allowed = [f.name for f in dataclasses.fields(cls)]
        values = dict(values)
        scene = values.pop("scene", SCENE_NAME)
        if scene != SCENE_NAME:
            raise InvalidParameterError(
                f"invalid scene = {scene!r} in {source}: must be {SCENE_NAME!r}")
        for key in values:
            if key not in allowed:
                raise InvalidParameterError(
                    f"unknown key {key!r} in {source}; allowed keys: scene, "
                    + ", ".join(allowed) + " (a [cartridge] table)")
        if "cartridge" in values:
            values["cartridge"] = Cartridge.from_geometry(values["cartridge"], source=source)
        return cls(**values)

    @classmethod
    def from_toml(cls, path: str | Path) -> "AccumulationTable":
        """Load a table from a TOML file of ``key = value`` lines named as the fields (SI
        units); missing keys take their defaults, unknown keys are errors."""
        from demfem.io.toml_file import read_toml

        path = Path(path)
        values = read_toml(path)
        for key, value in values.items():
            if isinstance(value, dict) and key != "cartridge":
                raise InvalidParameterError(
                    f"invalid [{key}] in {path}: the scene file is flat, one `key = value` "
                    "per field, and one table, [cartridge] (its dimensions, m)")
        return cls.from_dict(values, source=str(path))

    def to_toml(self, path: str | Path) -> Path:
        """Write this table as a TOML scene file (atomically); returns the path."""
        return write_text_atomic(path, self.toml_text())

    def toml_text(self) -> str:
        """The TOML text that :meth:`from_toml` reads back to an equal table."""
        lines = ["# demfem accumulation-table scene (SI units: m, kg, s, Pa; angle in degrees).",
                 "# Geometry, gate law and tag rules: the docstring of demfem.scenes.table.",
                 "# Missing keys take their defaults; unknown keys are errors.",
                 f'scene = "{SCENE_NAME}"']
        def number(value: float) -> str:
            if value != 0 and not 1e-4 <= abs(value) < 1e5:
                # Shortest round-trip form, readable for moduli: 4.5e+10, not 45000000000.0.
                return np.format_float_scientific(value, unique=True, trim="0")
            return repr(float(value))

        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name in ("cartridge", "sphere_radius", "sphere_mass"):
                continue  # the [cartridge] table below; the sphere follows from it
            if isinstance(value, str):
                text = json.dumps(value)
            elif isinstance(value, bool):
                text = "true" if value else "false"
            elif isinstance(value, int):
                text = str(value)
            else:
                text = number(value)
            unit = _UNITS.get(f.name, "")
            lines.append(f"{f.name} = {text}" + (f"  # {unit}" if unit else ""))
        lines += ["", "# the cartridge (m); the equivalent sphere of the DEM has its mass and "
                  "glass volume", "[cartridge]"]
        lines += [f"{k} = {number(v)}" for k, v in self.cartridge.geometry_dict().items()]
        return "\n".join(lines) + "\n"


#: Units of the fields, written as comments into scene files.
_UNITS: dict[str, str] = {
    "n_spheres": "spheres at t = 0",
    "length": "m, rectangular section along the belt (x)",
    "width": "m, across the belt (y)",
    "tilted_wall_length": "m",
    "tilted_wall_angle_deg": "degrees below the belt direction, in (0, 90)",
    "wall_height": "m",
    "opening_width": "m, mean opening w0",
    "gate_amplitude": "m, A in w(t) = w0 + A sin(2 pi t / T + phase)",
    "gate_period": "s, T",
    "gate_phase": "rad",
    "belt_velocity": "m/s along +x",
    "gravity": "m/s^2 along -z",
    "young_modulus": "Pa",
    "poisson_ratio": "-",
    "density": "kg/m^3",
    "friction": "Coulomb coefficient, sphere-sphere and sphere-wall",
    "restitution": "normal coefficient of restitution",
    "rolling_resistance": "coefficient; > 0 adds the effect rolling_resistance",
    "planar": "keep centres in one layer (effect planar)",
    "refeed": "re-insert removed spheres upstream",
    "packing_gap": "gap between start neighbours, fraction of the diameter",
    "particle": "sphere, clump (632-bead cartridge), cylinder (exact cartridge, parry) or "
                "revolution (exact cartridge, analytic: the fast full shape)",
    "cartridge_fraction": "fraction of sites with a cartridge of shape particle, in [0, 1]; "
                          "the rest are equivalent spheres",
}


def cartridge_sites(n: int, fraction: float) -> np.ndarray:
    """Which of ``n`` start sites hold a cartridge in a table with ``cartridge_fraction =
    fraction``: a boolean mask with exactly ``m = round(n * fraction)`` True entries, site
    ``k`` (in the order of :meth:`AccumulationTable.start_positions`) being a cartridge when
    ``floor((k + 1) m / n) > floor(k m / n)`` — the cartridges spread evenly along the site
    order, the same on every run and machine."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise InvalidParameterError(f"invalid n = {n!r}: must be a whole number >= 0")
    check_range("cartridge_fraction", fraction, 0.0, 1.0, lo_open=False, hi_open=False)
    m = int(round(n * float(fraction)))
    k = np.arange(n, dtype=np.int64)
    return ((k + 1) * m) // max(n, 1) > (k * m) // max(n, 1)


def _explained(check, name: str, value: Any, *args: Any, why: str, **kwargs: Any) -> float:
    """Run a range check and append the physical reason for the range to its message."""
    try:
        return check(name, value, *args, **kwargs)
    except InvalidParameterError as exc:
        raise InvalidParameterError(f"{exc} ({why})") from None
