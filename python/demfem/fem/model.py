"""An explicit FEM model of several bodies in contact: tetrahedral or shell bodies placed in
space with initial velocities, rigid surfaces (the belt: a plane whose surface moves, with
friction; spheres and cylinders for tests), no-tension springs to ghost points, gravity.

The bodies are joined into one mesh for the Rust solver (``demfem._core.FemTetSolver``, or
``demfem._core.FemShellSolver`` when every body is a :class:`ShellMesh`), which integrates
them with central differences and penalty contact (see ``rust/core/fem/contact``; shells:
two-sided faces offset by half the thickness, penalty s·E·t). All quantities are SI: m, s, kg, N, Pa.
"""
from __future__ import annotations

import hashlib
import math
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

from demfem import _core
from demfem.errors import InvalidParameterError, check_count, check_positive, check_range
from demfem.fem.mesh import ShellMesh, TetMesh
from demfem.fem.result import FemResult, Snapshot
from demfem.materials import Material


def _vec3(field_name: str, v: Sequence[float]) -> tuple[float, float, float]:
    a = np.asarray(v, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise InvalidParameterError(f"invalid {field_name} = {v!r}: must be 3 finite values")
    return (float(a[0]), float(a[1]), float(a[2]))


def _friction(mu: float) -> float:
    return check_range("friction", mu, 0.0, math.inf, lo_open=False)


#: The most steps one run may take (and the largest step count any option may name).
MAX_STEPS = 2_000_000_000


def _step_count(field_name: str, value: Any, lo: int) -> int:
    """``value`` as a whole number of steps in [lo, MAX_STEPS], else InvalidParameterError
    naming the field and the limit (never a raw OverflowError from the core)."""
    n = check_count(field_name, value, lo)
    if n > MAX_STEPS:
        raise InvalidParameterError(f"invalid {field_name} = {value!r}: must be a whole number "
                                    f"of steps in [{lo}, {MAX_STEPS}]")
    return n


@dataclass(frozen=True)
class Body:
    """A body: its mesh (a :class:`TetMesh` or a :class:`ShellMesh`, already placed),
    initial velocity (m/s), a name for the outputs, and optionally an output region per node
    (integers 0, 1, …; e.g. the top and bottom halves of a cartridge)."""

    mesh: Union[TetMesh, ShellMesh]
    velocity: Sequence[float] = (0.0, 0.0, 0.0)
    name: str = ""
    regions: Optional[np.ndarray] = None


@dataclass(frozen=True)
class RigidPlane:
    """A rigid plane through ``point`` (m) with ``normal`` pointing to the side the bodies
    stay on; its surface moves at ``surface_velocity`` (m/s, the belt), friction μ."""

    point: Sequence[float] = (0.0, 0.0, 0.0)
    normal: Sequence[float] = (0.0, 0.0, 1.0)
    surface_velocity: Sequence[float] = (0.0, 0.0, 0.0)
    friction: float = 0.2
    name: str = "belt"

    def _core(self) -> tuple:
        return ("plane", _vec3("point", self.point), _vec3("normal", self.normal),
                _vec3("surface_velocity", self.surface_velocity), _friction(self.friction))


@dataclass(frozen=True)
class RigidSphere:
    """A rigid solid sphere (centre m at t = 0, radius m) moving at ``velocity`` (m/s)."""

    center: Sequence[float]
    radius: float
    velocity: Sequence[float] = (0.0, 0.0, 0.0)
    friction: float = 0.0
    name: str = "sphere"

    def _core(self) -> tuple:
        return ("sphere", _vec3("center", self.center), check_positive("radius", self.radius),
                _vec3("velocity", self.velocity), _friction(self.friction))


@dataclass(frozen=True)
class RigidCylinder:
    """A rigid solid infinite cylinder: a point of its axis (m), the axis direction, radius (m)."""

    point: Sequence[float]
    axis: Sequence[float]
    radius: float
    friction: float = 0.0
    name: str = "cylinder"

    def _core(self) -> tuple:
        return ("cylinder", _vec3("point", self.point), check_positive("radius", self.radius),
                _vec3("axis", self.axis), _friction(self.friction))


Rigid = Union[RigidPlane, RigidSphere, RigidCylinder]


@dataclass(frozen=True)
class GhostSprings:
    """No-tension springs from nodes of one body to fixed ghost points: each pushes its node
    away from its anchor with stiffness·(rest_length − length) while shorter than its rest
    length and never pulls. ``nodes`` are indices into that body's mesh."""

    body: int
    nodes: np.ndarray
    anchors: np.ndarray
    stiffness: Union[float, np.ndarray]
    rest_length: Union[float, np.ndarray]


@dataclass(frozen=True)
class ContactOptions:
    """Penalty contact settings.

    ``penalty_scale`` s in k = s·K·A²/V (OpenRadioss TYPE7; 1 is its default, and the peak
    force of a Hertz impact is within 5 % of s = 10 at s = 1); ``friction`` μ between bodies;
    ``margin`` the broad phase's travel margin (m; default half the mean surface edge);
    ``contacts_per_node`` the contact springs per node the certified step allows;
    ``initial_overlap_tolerance`` (m); ``output_interval`` steps between contact samples.
    """

    penalty_scale: float = 1.0
    friction: float = 0.2
    margin: Optional[float] = None
    contacts_per_node: float = 1.0
    initial_overlap_tolerance: float = 1e-9
    output_interval: int = 10

    def __post_init__(self) -> None:
        _step_count("output_interval", self.output_interval, 1)


ProgressArg = Union[bool, Callable[[int, float], None], None]


@dataclass
class FemModel:
    """Bodies in contact, ready to run.

    ``material``: the glass of every body. ``gravity``: acceleration vector (m/s²) or None.
    ``rayleigh_alpha`` (1/s), ``rayleigh_beta`` (s): Rayleigh damping. ``safety_factor``:
    fraction of the certified stable step (contact included). ``mass_scaling_dt``: raise
    element masses so the step is at least this (s). ``dt``: a fixed step (s), refused above
    the certified limit.
    """

    bodies: Sequence[Body]
    material: Material
    rigid: Sequence[Rigid] = ()
    springs: Sequence[GhostSprings] = ()
    contact: ContactOptions = field(default_factory=ContactOptions)
    gravity: Optional[Sequence[float]] = None
    rayleigh_alpha: float = 0.0
    rayleigh_beta: float = 0.0
    safety_factor: float = 0.9
    mass_scaling_dt: Optional[float] = None
    dt: Optional[float] = None
    certified_step: bool = True

    def __post_init__(self) -> None:
        if not self.bodies:
            raise InvalidParameterError("invalid bodies = []: a model needs at least one body")
        for b in self.bodies:
            if not isinstance(b, Body):
                raise InvalidParameterError(f"invalid body {b!r}: must be a demfem.fem.Body")
        offsets = np.cumsum([0] + [b.mesh.n_nodes for b in self.bodies])
        self.node_offsets = offsets
        kinds = {isinstance(b.mesh, ShellMesh) for b in self.bodies}
        if len(kinds) != 1 or not all(isinstance(b.mesh, (TetMesh, ShellMesh)) for b in self.bodies):
            raise InvalidParameterError(
                "invalid bodies: all meshes must be TetMesh or all ShellMesh (no mixed models)")
        self.elements = "shell" if kinds == {True} else "tet"
        nodes = np.vstack([b.mesh.nodes for b in self.bodies])
        shells = [b.mesh for b in self.bodies if isinstance(b.mesh, ShellMesh)]
        tets = [b.mesh for b in self.bodies if isinstance(b.mesh, TetMesh)]
        self.mesh: Union[TetMesh, ShellMesh]
        if self.elements == "shell":
            shell_mesh = ShellMesh(
                nodes,
                np.vstack([m.triangles + offsets[i] for i, m in enumerate(shells)]).astype(np.int64),
                np.concatenate([np.asarray(m.thickness, dtype=float) for m in shells]))
            self.mesh = shell_mesh
        else:
            tet_mesh = TetMesh(
                nodes,
                np.vstack([m.tets + offsets[i] for i, m in enumerate(tets)]).astype(np.int64),
            )
            self.mesh = tet_mesh
        n = self.mesh.n_nodes
        self.body_of_node = np.repeat(np.arange(len(self.bodies)), np.diff(offsets)).astype(np.int64)
        region = np.zeros(n, dtype=np.int64)
        for i, b in enumerate(self.bodies):
            if b.regions is not None:
                r = np.asarray(b.regions)
                if r.shape != (b.mesh.n_nodes,) or (r.size and r.min() < 0):
                    raise InvalidParameterError(
                        f"invalid regions of body {i}: must be {b.mesh.n_nodes} integers >= 0")
                region[offsets[i]:offsets[i + 1]] = r
        self.region_of_node = region
        self._solver: Any
        if self.elements == "shell":
            self._check_shell_options()
            self._solver = _core.FemShellSolver(
                np.ascontiguousarray(shell_mesh.nodes, dtype=float),
                np.ascontiguousarray(shell_mesh.triangles, dtype=np.int64),
                np.ascontiguousarray(shell_mesh.thickness, dtype=float), self.material.E,
                self.material.nu, self.material.density, dt=self.dt)
        else:
            self._solver = _core.FemTetSolver(
                tet_mesh.nodes, tet_mesh.tets, self.material.E, self.material.nu,
                self.material.density, dt=self.dt, safety_factor=self.safety_factor,
                rayleigh_alpha=self.rayleigh_alpha, rayleigh_beta=self.rayleigh_beta,
                mass_scaling_dt=self.mass_scaling_dt, certified_step=self.certified_step,
                energy_interval=0)
        vel = np.zeros((n, 3))
        for i, b in enumerate(self.bodies):
            vel[offsets[i]:offsets[i + 1]] = _vec3(f"velocity of body {i}", b.velocity)
        self._solver.set_initial_velocity(vel)
        self.dt_without_contact = self._solver.dt
        if self.gravity is not None:
            g = np.asarray(_vec3("gravity", self.gravity))
            if self.elements == "shell":
                self._solver.add_gravity((float(g[0]), float(g[1]), float(g[2])))
            else:
                self._solver.set_loads(np.asarray(self._solver.mass())[:, None] * g[None, :])
        sn, sa, sk, sl = self._spring_arrays()
        c = self.contact
        self._solver.set_contact(
            self.body_of_node, self.region_of_node, penalty_scale=c.penalty_scale,
            friction=c.friction, margin=c.margin, contacts_per_node=c.contacts_per_node,
            initial_overlap_tolerance=c.initial_overlap_tolerance,
            output_interval=int(c.output_interval), rigid_surfaces=[r._core() for r in self.rigid],
            spring_nodes=sn, spring_anchors=sa, spring_stiffness=sk, spring_rest_length=sl)
        self.party_names = [b.name or f"body{i}" for i, b in enumerate(self.bodies)] + \
            [r.name for r in self.rigid]

    def _check_shell_options(self) -> None:
        """The shell solver is undamped, unscaled, with a step of 0.9 × its certified bound."""
        if self.rayleigh_alpha or self.rayleigh_beta or self.mass_scaling_dt is not None \
                or self.safety_factor != 0.9 or not self.certified_step:
            raise InvalidParameterError(
                "invalid options for shell bodies: Rayleigh damping, mass scaling, another "
                "safety_factor and an uncertified step are for tet bodies only")

    def _spring_arrays(self):
        if not self.springs:
            return None, None, None, None
        nodes, anchors, k, l0 = [], [], [], []
        for s in self.springs:
            if not 0 <= s.body < len(self.bodies):
                raise InvalidParameterError(
                    f"invalid springs body = {s.body!r}: must be in [0, {len(self.bodies)})")
            nd = np.asarray(s.nodes, dtype=np.int64).ravel()
            m = self.bodies[s.body].mesh.n_nodes
            if nd.size and (nd.min() < 0 or nd.max() >= m):
                raise InvalidParameterError(f"invalid spring nodes: must be in [0, {m}) for body {s.body}")
            an = np.asarray(s.anchors, dtype=float).reshape(-1, 3)
            if an.shape[0] != nd.size:
                raise InvalidParameterError(
                    f"invalid spring anchors: {an.shape[0]} anchors for {nd.size} nodes")
            nodes.append(nd + self.node_offsets[s.body])
            anchors.append(an)
            k.append(np.broadcast_to(np.asarray(s.stiffness, dtype=float), nd.shape))
            l0.append(np.broadcast_to(np.asarray(s.rest_length, dtype=float), nd.shape))
        return (np.concatenate(nodes), np.vstack(anchors), np.ascontiguousarray(np.concatenate(k)),
                np.ascontiguousarray(np.concatenate(l0)))

    # ------------------------------------------------------------------ state
    @property
    def solver(self) -> Any:
        """The underlying Rust solver (``_core.FemTetSolver`` or ``_core.FemShellSolver``)."""
        return self._solver

    @property
    def dt_step(self) -> float:
        """Time step in use, s."""
        return float(self._solver.dt)

    @property
    def time(self) -> float:
        """Simulated time, s."""
        return float(self._solver.time)

    def body_nodes(self, i: int) -> slice:
        """The slice of the model's nodes that belong to body ``i``."""
        return slice(int(self.node_offsets[i]), int(self.node_offsets[i + 1]))

    def body_elements(self, i: int) -> slice:
        """The slice of the model's elements that belong to body ``i``."""
        counts = np.cumsum([0] + [b.mesh.n_elements for b in self.bodies])
        return slice(int(counts[i]), int(counts[i + 1]))

    def body_velocity(self, i: int) -> np.ndarray:
        """Mass-weighted mean velocity of body ``i`` (m/s)."""
        s = self.body_nodes(i)
        m = np.asarray(self._solver.mass())[s]
        v = np.asarray(self._solver.velocity())[s]
        return (m[:, None] * v).sum(axis=0) / m.sum()

    def step_report(self) -> dict:
        """Which step limits apply: the step in use, the certified limit with contact, the
        limit without contact, and whether contact reduced the step."""
        info = self._solver.contact_info() or {}
        lim_free = float(info.get("dt_limit_without_contact", self._solver.dt_limit))
        return {
            "dt_s": float(self._solver.dt),
            "dt_limit_s": float(self._solver.dt_limit),
            "dt_limit_without_contact_s": lim_free,
            "reduced_for_contact": bool(self._solver.dt_limit < lim_free),
        }

    # ------------------------------------------------------------------ run
    def run(self, duration: float, progress: ProgressArg = False,
            snapshot_times: Sequence[float] = (), sample_every: int = 0,
            stop_when: Optional[Callable[["FemModel"], bool]] = None) -> FemResult:
        """Run for ``duration`` s (from the current time) and return the result.

        ``progress``: True for a progress bar, or a callable(steps, time_s). Ctrl-C stops at
        a step boundary with :class:`demfem.errors.SimulationInterrupted`. ``snapshot_times``
        (s): keep displacement, element σ1 and contact pressure at those times.
        ``sample_every``: steps between energy samples (default: the contact output
        interval). ``stop_when(model)``: checked after every sample; True ends the run.
        """
        check_positive("duration", duration)
        dt = self.dt_step
        n_total = int(math.ceil(duration / dt))
        if n_total > MAX_STEPS:
            raise InvalidParameterError(
                f"invalid duration = {duration!r}: {n_total} steps of {dt:g} s is beyond "
                f"{MAX_STEPS} steps")
        every = _step_count("sample_every", sample_every, 0) or int(self.contact.output_interval)
        snaps = sorted(float(t) for t in snapshot_times)
        energy_rows: list[list[float]] = []
        snapshots: list[Snapshot] = []
        bar = None
        if progress is True:
            from demfem.progress import ProgressBar
            bar = ProgressBar(duration, "fem")
        done = 0
        t0 = self.time
        self._sample_energy(energy_rows)
        while done < n_total:
            k = min(every, n_total - done)
            if snaps:
                to_snap = int(math.ceil((snaps[0] - self.time) / dt))
                if 0 < to_snap < k:
                    k = to_snap
            self._solver.run(k, chunk=max(k, 1))
            done += k
            self._sample_energy(energy_rows)
            while snaps and self.time >= snaps[0] - 0.5 * dt:
                snapshots.append(self.snapshot())
                snaps.pop(0)
            if bar is not None:
                bar(self.time - t0, done)
            elif callable(progress):
                progress(done, self.time)
            if stop_when is not None and stop_when(self):
                break
        if bar is not None:
            bar.close()
        return FemResult.from_model(self, np.asarray(energy_rows), snapshots, t0)

    def _sample_energy(self, rows: list[list[float]]) -> None:
        if self._solver.steps == 0:
            return  # energies are evaluated by the first step
        e = self._solver.energy()
        c = self._solver.contact_info() or {}
        rows.append([self.time, e["kinetic"], e["internal"], e["external_work"], e["damping_work"],
                     c.get("elastic_energy", 0.0), c.get("spring_energy", 0.0),
                     c.get("friction_work", 0.0), c.get("rigid_work", 0.0),
                     c.get("contact_work", 0.0)])

    def save_state(self, path: Union[str, Path]) -> Path:
        """Write the run's exact state (displacements, velocities, integrator and contact
        memory, energies, contact history) to ``path``, atomically, behind a header with its
        length and SHA-256 (:data:`STATE_MAGIC`). A model built from the same inputs and given
        :meth:`restore_state` continues bitwise as this one would."""
        from demfem.io.atomic import write_bytes_atomic

        return write_bytes_atomic(path, _wrap_state(bytes(self._solver.save_state())))

    def restore_state(self, path: Union[str, Path]) -> None:
        """Restore a state written by :meth:`save_state`. A damaged file (truncated, a byte
        changed, not a state file) raises :class:`demfem.errors.CheckpointError` naming it; a
        state of another model (other mesh, step, contact or springs)
        :class:`demfem.errors.ShapeError`; either way this model is left unchanged."""
        from demfem.errors import DemfemError, DemfemIOError

        path = Path(path)
        try:
            data = path.read_bytes()
        except OSError as exc:
            raise DemfemIOError(f"i/o error on {path}: {exc.strerror or exc}") from None
        payload = _unwrap_state(data, path)
        try:
            self._solver.restore_state(payload)
        except DemfemError as exc:
            raise type(exc)(f"the FEM state {path} does not fit this model: {exc}") from None

    def snapshot(self) -> Snapshot:
        """The state now: displacement (N,3) m, element σ1 (E,) Pa, contact pressure (N,) Pa
        (shells: also σ1 (E,3) on the bottom, middle and top surfaces)."""
        if self.elements == "shell":
            s = np.asarray(self._solver.surface_sigma1())
            return Snapshot(time=self.time, displacement=np.asarray(self._solver.displacement()),
                            sigma1_element=np.maximum(s[:, 0], s[:, 2]),
                            contact_pressure=np.asarray(self._solver.contact_pressure()),
                            sigma1_surfaces=s)
        stress = np.asarray(self._solver.element_stresses())
        p, _ = _core.fem_stress_invariants(stress)
        return Snapshot(time=self.time, displacement=np.asarray(self._solver.displacement()),
                        sigma1_element=np.asarray(p)[:, 0],
                        contact_pressure=np.asarray(self._solver.contact_pressure()))

    def write_vtu(self, path: Union[str, Path]) -> None:
        """Write the current state to a VTK .vtu file: for tets displacement, velocity,
        stresses, σ1 and contact pressure; for shells the mid-surface triangles with the
        nodes' displacement (m) and contact pressure (Pa), and per triangle σ1 on its bottom
        (−t/2 along its normal), middle and top (+t/2) surfaces (Pa) and its thickness (m)."""
        if self.elements == "shell":
            from demfem.io.vtk import write_vtu_triangles

            snap = self.snapshot()
            s = np.asarray(snap.sigma1_surfaces)
            mesh = self.mesh
            assert isinstance(mesh, ShellMesh)
            write_vtu_triangles(path, mesh.nodes, mesh.triangles, point_data={
                "displacement": snap.displacement, "contact_pressure": snap.contact_pressure},
                cell_data={"sigma1_bottom": s[:, 0], "sigma1_middle": s[:, 1],
                           "sigma1_top": s[:, 2], "thickness": mesh.thickness})
            return
        self._solver.write_vtu(Path(path))


#: Header of a state file of :meth:`FemModel.save_state`: this magic, the format (u32), the
#: payload's length (u64) and SHA-256 (32 bytes), then the solver's own state bytes (the one
#: checkpoint format of the core, ``rust/core/state_io.rs``: the magic ``DEMFEMST``, its
#: format, then named sections, the first the kind ``fem``; a DEM checkpoint is the same
#: format of kind ``dem``). The magic is the one the DEM checkpoints of earlier demfem
#: versions began with; those have a format other than 1 and are refused as such.
STATE_MAGIC = b"DEMFEMCK"
_CORE_MAGIC = b"DEMFEMST"
_STATE_FORMAT = 1
_STATE_HEADER = struct.Struct("<8sIQ32s")


def _wrap_state(payload: bytes) -> bytes:
    return _STATE_HEADER.pack(STATE_MAGIC, _STATE_FORMAT, len(payload),
                              hashlib.sha256(payload).digest()) + payload


def _unwrap_state(data: bytes, path: Path) -> bytes:
    """The solver's state bytes of a state file, after checking its header, length and
    SHA-256; :class:`CheckpointError` naming ``path`` otherwise."""
    from demfem.errors import CheckpointError

    def damaged(why: str) -> CheckpointError:
        return CheckpointError(f"damaged FEM state file {path}: {why}; it cannot be restored: "
                               "start the run afresh (fresh=True, --fresh on the command line)")

    if len(data) < _STATE_HEADER.size or data[:8] != STATE_MAGIC:
        if data[:8] == _CORE_MAGIC:
            # the core's bytes without this header: name the kind of its first section
            if data[12:28] == b"\x04kind" + struct.pack("<Q", 3) + b"dem":
                raise damaged("a DEM checkpoint (Simulation.save_checkpoint), not an FEM "
                              "state")
            raise damaged("a state of an earlier demfem version, without the checksum this "
                          "one needs")
        raise damaged(f"not a demfem FEM state file ({len(data)} bytes, no "
                      f"{STATE_MAGIC.decode()} header)")
    _, fmt, length, digest = _STATE_HEADER.unpack_from(data)
    if fmt != _STATE_FORMAT:
        if data[_STATE_HEADER.size:_STATE_HEADER.size + 8] != _CORE_MAGIC:
            raise damaged("a DEM checkpoint written by an older demfem checkpoint format, "
                          "not an FEM state")
        raise damaged(f"state file format {fmt}, this version reads {_STATE_FORMAT}")
    payload = data[_STATE_HEADER.size:]
    if len(payload) != length:
        raise damaged(f"{len(payload)} bytes of state where its header says {length} "
                      "(truncated or extended)")
    if hashlib.sha256(payload).digest() != digest:
        raise damaged("its SHA-256 differs from the one in its header (a byte changed)")
    return payload
