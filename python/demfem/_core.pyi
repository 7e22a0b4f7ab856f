"""Hand-written stubs of the compiled core (checked by ``mypy.stubtest``). SI units."""
from __future__ import annotations

import os
from collections.abc import Callable
from os import PathLike
from typing import Any, Optional, Sequence, final

import numpy as np
import numpy.typing as npt

__version__: str
__all__ = [
    "DemSimulation",
    "FemShellSolver",
    "FemTetSolver",
    "RigidSimulation",
    "fem_element_stresses",
    "fem_ball_mesh", "fem_shell_mesh",
    "fem_solve_static",
    "fem_stress_invariants",
    "fem_tet_mesh",
    "effective_mass",
    "effective_modulus",
    "effective_radius",
    "hertz_impact_duration",
    "hertz_max_overlap",
    "hertz_stiffness",
    "linearized_hertz_stiffness",
    "max_impact_force",
    "normal_force",
    "rayleigh_time_step",
    "reissner_stiffness",
    "series_stiffness",
    "tsuji_damping_for_restitution",
    "tsuji_restitution",
    "__version__",
]

def normal_force(
    overlap: npt.ArrayLike,
    model: str,
    k_h: float = ...,
    k_r: float = ...,
    k: float = ...,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Normal force (N) and tangent stiffness (N/m) of law ``model`` at each overlap (m), in
    the argument order of :func:`demfem.contact.normal_force`. ``model`` in {'hertz',
    'linear', 'hertz_reissner'}; k_h in N/m^1.5, k_r and k in N/m. A NaN or infinite overlap
    raises InvalidParameterError naming ``overlap[i]``."""

def max_impact_force(
    m_star: float, v_rel: float, model: str, k_h: float = ..., k_r: float = ..., k: float = ...
) -> float:
    """Maximum impact force (N) for effective mass m_star (kg) at v_rel (m/s) under law
    ``model`` (as :func:`demfem.contact.max_contact_force`, which takes two bodies)."""

def tsuji_restitution(zeta: float, clamp: bool = False) -> float:
    """Restitution of a Hertz impact with Tsuji damping parameter zeta (dimensionless)."""

def tsuji_damping_for_restitution(e: float, clamp: bool = False) -> float:
    """Tsuji damping parameter zeta that realises restitution e in (0, 1]."""

def rayleigh_time_step(radius: float, E: float, nu: float, density: float) -> float:
    """Rayleigh time step (s) of a sphere: radius (m), E (Pa), nu, density (kg/m^3), as
    :func:`demfem.contact.rayleigh_time_step`."""

def hertz_impact_duration(k_h: float, m_star: float, v_rel: float) -> float:
    """Duration (s) of an undamped Hertz impact: k_h (N/m^1.5), m_star (kg), v_rel (m/s)
    (:func:`demfem.contact.hertz_contact_duration` takes the two bodies instead)."""

def effective_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """E* (Pa) from 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2 (eq. 4); ``E2 = inf``: a rigid
    partner. As :func:`demfem.contact.effective_modulus`."""

def effective_radius(R1: float, R2: float) -> float:
    """R* (m) from 1/R* = 1/R1 + 1/R2 (eq. 3); ``R2 = inf``: a plane."""

def effective_mass(m1: float, m2: float) -> float:
    """m* (kg) from 1/m* = 1/m1 + 1/m2 (eq. 9); ``m2 = inf``: an immovable partner."""

def hertz_stiffness(R_star: float, E_star: float) -> float:
    """Hertz stiffness 4/3 sqrt(R*) E* (eq. 2), N/m^1.5, from the effective radius (m) and
    modulus (Pa) (:func:`demfem.contact.hertz_stiffness` takes both bodies instead)."""

def reissner_stiffness(E: float, nu: float, t: float, R: float) -> float:
    """Reissner stiffness of a thin shallow shell (eq. 6), N/m: E (Pa), nu, thickness t (m),
    mid-surface radius R (m), 0 < t < R."""

def series_stiffness(k1: float, k2: float) -> float:
    """Springs in series, 1/k = 1/k1 + 1/k2, N/m; ``inf`` for a spring that does not deflect."""

def linearized_hertz_stiffness(R_star: float, E_star: float, m_star: float, v_rel: float) -> float:
    """Linearised Hertz stiffness (eq. 13), N/m, from R* (m), E* (Pa), m* (kg), v_rel (m/s)."""

def hertz_max_overlap(k_h: float, m_star: float, v_rel: float) -> float:
    """Maximum overlap (m) of an undamped Hertz impact, (5 m* v^2 / (4 k_h))^(2/5): k_h
    (N/m^1.5), m_star (kg), v_rel (m/s)."""

@final
class DemSimulation:
    """A DEM simulation of spheres and walls.

    positions (N, 3) m; radii (N,) m; materials: list of dicts with young_modulus (Pa),
    poisson_ratio, density (kg/m^3), friction, restitution, rolling_friction, shell_stiffness
    (N/m); walls: list of dicts with type 'plane' (point, normal), 'polygon' (vertices),
    'strip' (x0, y0, x1, y1, z_bottom, z_top), 'cuboid' (center, half_extents) or 'mesh'
    (vertices (N, 3) m, triangles (M, 3) vertex indices, closed: bool, True to refuse an
    open mesh, triangle_velocities (M, 3) m/s: each triangle's own surface velocity, belts;
    two-sided, each touching face, edge and vertex counted once), plus material,
    surface_velocity (m/s) and motion ({'type': 'constant', 'velocity'},
    {'type': 'harmonic', 'direction', 'amplitude' (m), 'period' (s), 'phase' (rad)} or
    {'type': 'rotation', 'axis_point' (m), 'axis', 'angular_velocity' (rad/s)}, not for planes);
    effects: names from gravity, belt, moving_walls, friction, rotation, damping,
    rolling_resistance, planar. gravity (m/s^2) defaults to (0, 0, -9.81). dt (s) defaults
    to dt_safety x the stable limit; a larger one
    raises UnstableTimeStepError, and one above 1 s (possible only without particles)
    InvalidParameterError. Arrays of any real (integer) dtype are converted; other input
    raises InvalidParameterError naming the field; negative counts likewise.
    """

    def __new__(
        cls,
        positions: npt.ArrayLike,
        radii: npt.ArrayLike,
        materials: list[dict[str, float]],
        walls: list[dict[str, Any]],
        effects: Sequence[str],
        *,
        velocities: Optional[npt.ArrayLike] = None,
        angular_velocities: Optional[npt.ArrayLike] = None,
        material_ids: Optional[npt.ArrayLike] = None,
        tags: Optional[npt.ArrayLike] = None,
        gravity: tuple[float, float, float] = ...,
        model: str = "hertz_mindlin",
        linear_stiffness: Optional[tuple[float, float]] = None,
        clamp_normal_force: bool = True,
        dt: Optional[float] = None,
        dt_safety: float = 0.2,
        expected_max_speed: float = 1.0,
        skin: Optional[float] = None,
        threads: int = 1,
        overlap_tolerance: float = 0.01,
        record_every: int = 0,
        record_onsets: bool = False,
        removal_plane: Optional[tuple[tuple[float, float, float], tuple[float, float, float]]] = None,
        record_events: bool = False,
    ) -> DemSimulation: ...
    def removals(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]:
        """Particles removed through the outlet plane: times (s) and indices."""
    @staticmethod
    def _anchor_table(
        young_modulus: float = 45e9,
        start: str = "square",
        threads: int = 1,
        initial_vx: float = 0.0,
        record_every: int = 0,
        record_onsets: bool = False,
    ) -> DemSimulation:
        """Benchmark fixture, not part of the API: the anchor table of
        shared/anchors/dem/scene.py (the scene Yade and LIGGGHTS run in
        benches/dem_anchor_ratio.py) at E (Pa); start 'square' or 'packed'; initial_vx (m/s)
        for every sphere. Tables for use: demfem.scenes.AccumulationTable and
        demfem.dem.from_scene."""
    def step(self, n: int, chunk: int = 2000) -> None:
        """Advance n steps; the GIL is released in slices of about 0.1 s of wall time
        whatever ``chunk`` is, so Ctrl-C raises SimulationInterrupted within a fraction of a
        second. Negative n or chunk, or n steps that would make the time infinite, raise
        InvalidParameterError."""
    def run_until(self, t_end: float, chunk: int = 2000) -> int:
        """Advance to simulated time t_end (s); returns the steps taken."""
    @property
    def time(self) -> float:
        """Simulated time, s."""
    @property
    def steps(self) -> int: ...
    @property
    def dt(self) -> float:
        """Time step, s."""
    @property
    def stable_dt(self) -> float:
        """Stable time-step limit, s."""
    @property
    def stable_dt_reason(self) -> str: ...
    @property
    def effects(self) -> list[str]: ...
    def __len__(self) -> int: ...
    def positions(self) -> npt.NDArray[np.float64]:
        """Centres, m, (N, 3)."""
    def velocities(self) -> npt.NDArray[np.float64]:
        """Velocities (half step), m/s, (N, 3)."""
    def angular_velocities(self) -> npt.NDArray[np.float64]:
        """Angular velocities (half step), rad/s, (N, 3)."""
    def contact_force_sums(self) -> npt.NDArray[np.float64]:
        """Sum of contact forces per particle, N, (N, 3)."""
    def radii(self) -> npt.NDArray[np.float64]: ...
    def masses(self) -> npt.NDArray[np.float64]:
        """Masses, kg."""
    def coordination(self) -> npt.NDArray[np.uint32]: ...
    def wall_contacts(self) -> npt.NDArray[np.uint32]: ...
    def tags(self) -> npt.NDArray[np.uint32]: ...
    def alive(self) -> npt.NDArray[np.bool_]: ...
    def kinetic_energy(self) -> float:
        """Kinetic energy, J."""
    def max_overlap(self) -> float:
        """Largest overlap, m."""
    def riding_up_count(self, floor_z: float = 0.0, tolerance: float = 0.002) -> int:
        """Spheres whose centre is above floor_z + radius + tolerance (m)."""
    def remove_particle(self, i: int) -> None: ...
    def reinsert_particle(
        self, i: int, position: tuple[float, float, float], velocity: tuple[float, float, float]
    ) -> None:
        """Put removed particle i back at position (m) with velocity (m/s), no spin."""
    def frames(self) -> dict[str, npt.NDArray[Any]]:
        """time (F,), step (F,), positions/velocities/angular_velocities/contact_force_sums
        (F, N, 3), coordination/wall_contacts (F, N)."""
    def onsets(self) -> dict[str, npt.NDArray[Any]]:
        """Contact onsets: time (s), step, particle, partner, partner_is_wall, normal_speed,
        tangential_speed (m/s), position, partner_position (K, 3) (m)."""
    def contacts(self) -> dict[str, npt.NDArray[Any]]:
        """Active contacts: particle, partner, partner_is_wall, normal (K, 3), normal_force (N),
        tangential_force (K, 3) (N), overlap (m), point (K, 3) (m)."""
    def events(self) -> dict[str, npt.NDArray[Any]]:
        """Whole contacts that ended (record_events=True): time, duration (s), particle,
        partner, partner_is_wall, normal_speed, tangential_speed at onset (m/s), position,
        partner_position (K, 3) (m), peak_normal_force (N), normal_impulse (N s),
        peak_tangential_force (N), max_overlap (m), complete."""
    def open_events(self) -> dict[str, npt.NDArray[Any]]:
        """The contacts open now, as events so far (complete False)."""
    def clear_records(self) -> None: ...
    def set_phase_timing(self, on: bool) -> None:
        """Start (True, from zero) or stop the per-thread clock of the step's two phases."""
    def phase_times(self) -> list[tuple[float, float]]:
        """(force phase s, particle phase s) of each engine thread's block since
        set_phase_timing(True)."""
    def block_cuts(self) -> list[int]:
        """First particle of each engine thread's block after the first (empty on one
        thread); the cuts follow the measured times and never change the results."""
    def save_checkpoint(self, path: str | PathLike[str]) -> None: ...
    def load_checkpoint(self, path: str | PathLike[str]) -> None: ...

def fem_tet_mesh(
    z: npt.NDArray[np.float64],
    r_in: npt.NDArray[np.float64],
    r_out: npt.NDArray[np.float64],
    n_theta: int,
    n_layers: int,
    target_size: float,
    min_dihedral_deg: float = 5.0,
    max_elements: int = ...,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], dict[str, float]]:
    """Revolved linear-tet mesh of the axisymmetric body (stations z, radii in m):
    (nodes (N,3) m, tets (E,4), quality dict). Slivers below min_dihedral_deg are refused;
    so is, before meshing, a target_size giving more than max_elements (default 5e6) elements, and
    n_theta < 3 or n_layers < 1 (InvalidParameterError naming the argument)."""

def fem_ball_mesh(radius: float, n: int) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Tet mesh of a ball of ``radius`` m (2n cells across): (nodes (N,3) m, tets (E,4))."""

def fem_shell_mesh(
    z: npt.NDArray[np.float64],
    r_in: npt.NDArray[np.float64],
    r_out: npt.NDArray[np.float64],
    n_theta: int,
    target_size: float,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.float64]]:
    """Mid-surface triangle mesh: (nodes (N,3) m, triangles (T,3), thickness (T,) m)."""

def fem_solve_static(
    nodes: npt.NDArray[np.float64],
    tets: npt.NDArray[np.int64],
    young_modulus: float | None = None,
    poisson_ratio: float | None = None,
    loads: npt.NDArray[np.float64] | None = None,
    fixed_dofs: npt.NDArray[np.int64] | None = None,
    fixed_values: npt.NDArray[np.float64] | None = None,
    *,
    youngs_modulus: float | None = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Sparse Cholesky solve K u = f: (u (N,3) m, reactions (N,3) N). E in Pa.

    Every argument is required; ``youngs_modulus`` is the old name of ``young_modulus``."""

def fem_element_stresses(
    nodes: npt.NDArray[np.float64],
    tets: npt.NDArray[np.int64],
    young_modulus: float | None = None,
    poisson_ratio: float | None = None,
    u: npt.NDArray[np.float64] | None = None,
    *,
    youngs_modulus: float | None = None,
) -> npt.NDArray[np.float64]:
    """Element stresses (E,6) Pa in the order xx, yy, zz, yz, xz, xy.

    Every argument is required; ``youngs_modulus`` is the old name of ``young_modulus``."""

def fem_stress_invariants(
    s: npt.NDArray[np.float64],
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Principal stresses (M,3) Pa (σ1 ≥ σ2 ≥ σ3) and von Mises stress (M,) Pa."""

@final
class FemTetSolver:
    """Explicit central-difference solver for linear tets (SI units)."""

    def __new__(
        cls,
        nodes: npt.NDArray[np.float64],
        tets: npt.NDArray[np.int64],
        young_modulus: float | None = None,
        poisson_ratio: float | None = None,
        density: float | None = None,
        dt: float | None = None,
        safety_factor: float = 0.9,
        rayleigh_alpha: float = 0.0,
        rayleigh_beta: float = 0.0,
        mass_scaling_dt: float | None = None,
        certified_step: bool = True,
        energy_interval: int = 100,
        *,
        youngs_modulus: float | None = None,
    ) -> FemTetSolver:
        """young_modulus (Pa), poisson_ratio and density (kg/m³) are required;
        ``youngs_modulus`` is the old name of ``young_modulus``."""
    def set_prescribed(
        self,
        dofs: npt.NDArray[np.int64],
        values: npt.NDArray[np.float64],
        kind: str = "displacement",
        rise_time: float = 0.0,
    ) -> None: ...
    def set_loads(self, loads: npt.NDArray[np.float64], rise_time: float = 0.0) -> None: ...
    def add_gravity(self, g: tuple[float, float, float]) -> None: ...
    def set_extra_loads(self, loads: npt.NDArray[np.float64]) -> None: ...
    def set_initial_velocity(self, v: npt.NDArray[np.float64]) -> None: ...
    def set_initial_displacement(self, u: npt.NDArray[np.float64]) -> None: ...
    def run(
        self, n_steps: int, chunk: int = 1000, progress: Callable[[int, float], object] | None = None
    ) -> None: ...
    @property
    def dt(self) -> float: ...
    @property
    def dt_limit(self) -> float: ...
    @property
    def time(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def added_mass(self) -> float: ...
    def save_state(self) -> bytes: ...
    def restore_state(self, state: bytes) -> None: ...
    def displacement(self) -> npt.NDArray[np.float64]: ...
    def velocity(self) -> npt.NDArray[np.float64]: ...
    def energy(self) -> dict[str, float]: ...
    def element_stresses(self) -> npt.NDArray[np.float64]: ...
    def nodal_stresses(self) -> npt.NDArray[np.float64]: ...
    def write_vtu(self, path: str | os.PathLike[str]) -> None: ...
    def set_contact(
        self,
        body_of_node: npt.NDArray[np.int64],
        region_of_node: npt.NDArray[np.int64],
        penalty_scale: float = 1.0,
        friction: float = 0.2,
        margin: float | None = None,
        contacts_per_node: float = 1.0,
        initial_overlap_tolerance: float = 1e-9,
        output_interval: int = 10,
        rigid_surfaces: list[tuple[Any, ...]] = ...,
        spring_nodes: npt.NDArray[np.int64] | None = None,
        spring_anchors: npt.NDArray[np.float64] | None = None,
        spring_stiffness: npt.NDArray[np.float64] | None = None,
        spring_rest_length: npt.NDArray[np.float64] | None = None,
    ) -> None:
        """Penalty contact between the bodies (k = s K A²/V), rigid surfaces, no-tension springs."""
    def contact_channels(self) -> list[tuple[int, int, int]]: ...
    def contact_history(self) -> npt.NDArray[np.float64]: ...
    def contact_pressure(self) -> npt.NDArray[np.float64]: ...
    def contact_info(self) -> dict[str, Any] | None: ...
    def mass(self) -> npt.NDArray[np.float64]: ...

@final
class FemShellSolver:
    """Explicit central-difference solver for flat CST + DKT shells with two-sided penalty
    contact (k = s E t per face, contact surfaces half the thickness off the mid-surface)."""

    def __new__(
        cls,
        nodes: npt.NDArray[np.float64],
        triangles: npt.NDArray[np.int64],
        thickness: npt.NDArray[np.float64],
        young_modulus: float | None = None,
        poisson_ratio: float | None = None,
        density: float | None = None,
        fixed: npt.NDArray[np.int64] | None = None,
        dt: float | None = None,
        *,
        youngs_modulus: float | None = None,
    ) -> FemShellSolver:
        """young_modulus (Pa), poisson_ratio and density (kg/m³) are required;
        ``youngs_modulus`` is the old name of ``young_modulus``."""
    def set_initial_velocity(self, v: npt.NDArray[np.float64]) -> None: ...
    def add_gravity(self, g: tuple[float, float, float]) -> None: ...
    def set_contact(
        self,
        body_of_node: npt.NDArray[np.int64],
        region_of_node: npt.NDArray[np.int64],
        penalty_scale: float = 1.0,
        friction: float = 0.2,
        margin: float | None = None,
        contacts_per_node: float = 1.0,
        initial_overlap_tolerance: float = 1e-9,
        output_interval: int = 10,
        rigid_surfaces: list[tuple[Any, ...]] = ...,
        spring_nodes: npt.NDArray[np.int64] | None = None,
        spring_anchors: npt.NDArray[np.float64] | None = None,
        spring_stiffness: npt.NDArray[np.float64] | None = None,
        spring_rest_length: npt.NDArray[np.float64] | None = None,
    ) -> None:
        """Penalty contact between shell bodies (two-sided, offset t/2), rigid surfaces, springs."""
    def run(
        self, n_steps: int, chunk: int = 1000, progress: Callable[[int, float], object] | None = None
    ) -> None: ...
    def contact_channels(self) -> list[tuple[int, int, int]]: ...
    def contact_history(self) -> npt.NDArray[np.float64]: ...
    def contact_pressure(self) -> npt.NDArray[np.float64]: ...
    def contact_info(self) -> dict[str, Any] | None: ...
    def mass(self) -> npt.NDArray[np.float64]: ...
    def save_state(self) -> bytes: ...
    def restore_state(self, state: bytes) -> None: ...
    @property
    def dt(self) -> float: ...
    @property
    def dt_limit(self) -> float: ...
    @property
    def time(self) -> float: ...
    @property
    def steps(self) -> int: ...
    def displacement(self) -> npt.NDArray[np.float64]: ...
    def velocity(self) -> npt.NDArray[np.float64]: ...
    def dofs(self) -> npt.NDArray[np.float64]: ...
    def energy(self) -> dict[str, float]: ...
    def surface_sigma1(self) -> npt.NDArray[np.float64]:
        """σ1 (E,3) Pa at the bottom (−t/2 along the normal), middle and top of each triangle."""
    def triangle_normals(self) -> npt.NDArray[np.float64]: ...

@final
class RigidSimulation:
    """Rigid cartridges (bead clumps, exact parry shapes or bodies of revolution) on a belt
    between walls.

    positions (N, 3) centres of mass, m; orientations (N, 4) quaternions (w, x, y, z) of the
    cartridge frame (axis z); shape: {'kind': 'clump', 'centers' (n, 3) m, 'radii' (n,) m,
    'masses' (n,) kg}, {'kind': 'exact', 'z', 'r_in', 'r_out'} (stations, m; mass from the
    material's density; parry compound) or {'kind': 'revolution', same stations} (analytic
    body of revolution; overlapping start poses are refused); material: dict with
    young_modulus (Pa), poisson_ratio, density (kg/m^3), friction, restitution; walls:
    'plane', 'polygon' or 'mesh' (clumps and bodies of revolution; not rotating) dicts as
    for DemSimulation
    (surface_velocity, motion); effects: names from gravity, belt, moving_walls, friction,
    rotation, damping. angular_velocities in the world frame (rad/s). dt (s) defaults to the
    stable limit at expected_max_speed (m/s); a larger one raises UnstableTimeStepError.
    removal_plane (point, normal to the kept side): bodies past it are removed. spheres (N,)
    bool flags bodies that are equivalent spheres of radius sphere_radius (m) and the
    cartridge's mass instead of cartridges (mixed tables); their orientation is that of the
    ball, their axes and tilt angles NaN. threads: the contact geometry of bodies of
    revolution on that many threads (64 bodies or more), bitwise the same result.
    """

    def __new__(
        cls,
        positions: npt.NDArray[np.float64],
        orientations: npt.NDArray[np.float64],
        shape: dict[str, Any],
        material: dict[str, float],
        walls: list[dict[str, Any]],
        effects: Sequence[str],
        *,
        velocities: Optional[npt.NDArray[np.float64]] = None,
        angular_velocities: Optional[npt.NDArray[np.float64]] = None,
        wall_material: Optional[dict[str, float]] = None,
        gravity: tuple[float, float, float] = ...,
        dt: Optional[float] = None,
        expected_max_speed: float = 1.0,
        removal_plane: Optional[tuple[tuple[float, float, float], tuple[float, float, float]]] = None,
        record_onsets: bool = False,
        spheres: Optional[npt.NDArray[np.bool_]] = None,
        sphere_radius: Optional[float] = None,
        threads: int = 1,
    ) -> RigidSimulation: ...
    def step(self, n: int, chunk: int = 2000) -> None: ...
    def run_until(self, t_end: float, chunk: int = 2000) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @property
    def stable_dt(self) -> float: ...
    @property
    def body_mass(self) -> float: ...
    def __len__(self) -> int: ...
    def positions(self) -> npt.NDArray[np.float64]: ...
    def velocities(self) -> npt.NDArray[np.float64]: ...
    def angular_velocities(self) -> npt.NDArray[np.float64]: ...
    def orientations(self) -> npt.NDArray[np.float64]: ...
    def axes(self) -> npt.NDArray[np.float64]: ...
    def tilt_angles(self) -> npt.NDArray[np.float64]: ...
    def is_sphere(self) -> npt.NDArray[np.bool_]: ...
    def alive(self) -> npt.NDArray[np.bool_]: ...
    def removals(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]: ...
    def coordination(self) -> npt.NDArray[np.uint32]: ...
    def wall_contacts(self) -> npt.NDArray[np.uint32]: ...
    def kinetic_energy(self) -> float: ...
    def max_overlap(self) -> float: ...
    def contact_points(self) -> int: ...
    def remove_body(self, i: int) -> None: ...
    def reinsert_body(
        self,
        i: int,
        position: tuple[float, float, float],
        orientation: tuple[float, float, float, float],
        velocity: tuple[float, float, float],
        *,
        if_free: bool = False,
    ) -> bool:
        """Put removed body i back at position (m, centre of mass) with orientation (unit
        quaternion (w, x, y, z) of its frame) and velocity (m/s), no spin. Raises naming the
        field (i, position, orientation, velocity) for bad input or an occupied pose (one
        where the exact shapes would touch an alive body or a wall); with if_free, an occupied
        pose returns False and the body stays removed. True when put back."""
    def reinsertions(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]:
        """Bodies put back: times (s) and indices."""
    def onsets(self) -> dict[str, npt.NDArray[Any]]:
        """Every contact onset: time (s), body, partner, partner_is_wall, normal_speed,
        tangential_speed (m/s), point (N, 3) the deepest contact point (world, m), normal
        (N, 3) (from the wall to the body, or from body to partner), point_body and
        point_partner (N, 3) that point in the cartridge frame of body and partner (m, origin
        at the centre of mass, axis z; NaN for walls and spheres), axis_angle (rad): between
        the two cartridge axes (0 to pi/2), against a wall between the axis and the wall's
        surface (0: lying along it, pi/2: standing on it); NaN with a sphere."""
        ...
    def clear_records(self) -> None: ...
