#!/usr/bin/env python3
"""demfem explicit tet contact against CalculiX 2.20 ``*DYNAMIC, EXPLICIT`` on the same
two-tube collision, same mesh, same step (issue 27 item 6).

Problem (identical in both codes): two plain glass tubes ``Cartridge.tube(11.6 mm, 1.1 mm,
20 mm)`` (PAPER_GLASS: E = 45 GPa, ν = 0.22, ρ = 2230 kg/m³), demfem's revolved-tet mesh
with 2 layers through the wall (7 752 C3D4 per tube), crossed (tube b's axis turned 90°
about the line of centres x), b closing on a at 0.2 m/s along x, no friction, no gravity,
no damping, lumped mass.

Mesh placement. As in ``demfem.fem.collide_cartridges``, but each tube is also turned
about its own axis by half an angular division (π/n_theta), so that a flat facet (not a
vertex line) faces the other tube and the initial gap is measured between the facets.
Without that turn the two vertex lines cross edge on edge; node-to-surface contact (in
either code) does not see an edge-edge crossing, and ``collide_cartridges`` on this tube
raises "the cartridges did not touch" (the nodes next to the crossing are 49 µm away
from the other facet; the bodies travel 43 µm in the run).

demfem side: a ``FemModel`` of the two bodies (``ContactOptions(penalty_scale=1,
friction=0, output_interval=5)``), run in a child process (``RAYON_NUM_THREADS=1``) until
the bodies separate, exactly as ``collide_cartridges`` does (peak normal force raw and
after its centred moving average over 1/20 of the contact; contact duration; restitution
= relative normal speed after / before from the mass-weighted body velocities).

CalculiX side: the same nodes and elements (ids = demfem's 0-based indices + 1), ELSETs
EA / EB, ``*INITIAL CONDITIONS, TYPE=VELOCITY`` on NB, element-face surfaces SA / SB of the
outer cylindrical faces (every boundary face of a tet whose three nodes lie on the outer
radius; C3D4 face numbers S1 = 1-2-3, S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1),
``*CONTACT PAIR, TYPE=NODE TO SURFACE`` slave SB, master SA, ``*SURFACE BEHAVIOR,
PRESSURE-OVERCLOSURE=LINEAR``. The linear slope: demfem's face stiffness is
k_f = s·K·A²/V (K the bulk modulus, A the face, V its tet); with the two-pass contact the
pressure per overclosure is ≈ k_f/A = s·K·A/V (N/m³); the deck uses the median of K·A/V
over the master's outer faces (CalculiX multiplies the slope by the slave node's
tributary area). Output every 5 increments/steps in both codes. CalculiX 2.20 accepts
``*CONTACT PRINT, SLAVE=SB, MASTER=SA`` CF on a NODE TO SURFACE pair but prints zeros
(CF is computed for surface-to-surface contact only; the contact elements are active, CELS
is non-zero from 5.5 µs), so ccx runs twice: a timing run (CF output only) and a physics
run with ``*NODE PRINT, NSET=NB`` V every 5 increments; the force on b is the rate of its
momentum (central difference over 10 increments, lumped masses ρV/4 computed here), the
restitution from b's final momentum and momentum conservation.

Step: CalculiX 2.20 picks its own explicit increment (its Courant estimate; see
``benches/fem_vs_calculix.py``), so ccx is first run for one increment to read it; demfem
then runs at that step when it is below demfem's certified bound (contact allowance
included), else at its own step (reported). Costs: wall and CPU (user+sys of the child,
``resource.getrusage(RUSAGE_CHILDREN)``) of each whole child; element-steps per CPU-second
from the stepping only: demfem's run loop (timed inside the child) and CalculiX's
(T_run − T_1increment), both on one thread.

Run: ``python3 benches/fem_contact_vs_calculix.py`` (writes docs/data/fem_contact_vs_calculix.json;
needs ``ccx``: apt-get install calculix-ccx).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT_JSON = ROOT / "docs" / "data" / "fem_contact_vs_calculix.json"

#: C3D4 faces in CalculiX's numbering (0-based local node indices): S1 = 1-2-3, S2 = 1-4-2,
#: S3 = 2-4-3, S4 = 3-4-1.
C3D4_FACES = ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0))


# --------------------------------------------------------------------------- geometry
def build_problem(od: float = 11.6e-3, wall: float = 1.1e-3, length: float = 20e-3,
                  layers: int = 2, v_rel: float = 0.2, tilt_deg: float = 90.0,
                  face_to_face: bool = True) -> dict:
    """The two placed tubes as plain arrays: nodes (N,3), tets (E,4) 0-based, body (N,),
    velocity (N,3), outer (N,) bool (node on the outer radius), elements per body."""
    from demfem.cartridge import Cartridge
    from demfem.fem.mesh import _sizes, cartridge_tet_mesh, rotation_about

    tube = Cartridge.tube(od, wall, length)
    _, n_theta = _sizes(tube, layers, None, None)
    m = cartridge_tet_mesh(tube, layers=layers, n_theta=n_theta)
    r_local = np.hypot(m.nodes[:, 0], m.nodes[:, 1])
    r_out = 0.5 * od
    outer = np.isclose(r_local, r_out, rtol=1e-9, atol=1e-12)
    spin = rotation_about((0.0, 0.0, 1.0), 180.0 / n_theta) if face_to_face else np.eye(3)
    r_face = r_out * math.cos(math.pi / n_theta) if face_to_face else r_out
    gap = 1e-3 * wall
    zc = 0.5 * tube.body_length
    mesh_a = m.placed(spin, (0.0, 0.0, -zc))
    tilt = rotation_about((1.0, 0.0, 0.0), tilt_deg)
    mesh_b = m.placed(spin, (0.0, 0.0, -zc)).placed(tilt, (2.0 * r_face + gap, 0.0, 0.0))
    n = m.n_nodes
    return {
        "cartridge": tube, "n_theta": n_theta, "layers": layers, "gap": gap, "v_rel": v_rel,
        "tilt_deg": tilt_deg, "meshes": (mesh_a, mesh_b),
        "nodes": np.vstack([mesh_a.nodes, mesh_b.nodes]),
        "tets": np.vstack([m.tets, m.tets + n]).astype(np.int64),
        "body": np.repeat([0, 1], n).astype(np.int64),
        "velocity": np.vstack([np.zeros((n, 3)), np.tile([-v_rel, 0.0, 0.0], (n, 1))]),
        "outer": np.concatenate([outer, outer]),
        "n_el_body": (m.n_elements, m.n_elements),
    }


def boundary_faces(tets: np.ndarray) -> list[tuple[int, int]]:
    """(element, CalculiX face number 1..4) of every face that belongs to one tet only."""
    tets = np.asarray(tets, dtype=np.int64)
    keys: dict[tuple[int, ...], list[tuple[int, int]]] = {}
    for e, t in enumerate(tets):
        for f, loc in enumerate(C3D4_FACES):
            keys.setdefault(tuple(sorted(int(t[i]) for i in loc)), []).append((e, f + 1))
    return sorted(v[0] for v in keys.values() if len(v) == 1)


def face_nodes(tets: np.ndarray, elem: int, face: int) -> tuple[int, int, int]:
    """The three nodes (0-based) of CalculiX face ``face`` (1..4) of element ``elem``."""
    t = tets[elem]
    return tuple(int(t[i]) for i in C3D4_FACES[face - 1])  # type: ignore[return-value]


def outer_faces(p: dict, body: int) -> list[tuple[int, int]]:
    """Boundary faces of ``body`` whose three nodes all lie on the outer radius."""
    tets, own = p["tets"], p["body"]
    out = []
    for e, f in boundary_faces(tets):
        nd = face_nodes(tets, e, f)
        if own[nd[0]] == body and all(p["outer"][i] for i in nd):
            out.append((e, f))
    return out


def tet_volumes(nodes: np.ndarray, tets: np.ndarray) -> np.ndarray:
    x = nodes[tets]
    return np.einsum("ij,ij->i", x[:, 1] - x[:, 0], np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0])) / 6.0


def penalty_slope(p: dict, faces: list[tuple[int, int]], E: float, nu: float, scale: float = 1.0) -> dict:
    """demfem's k_f = s·K·A²/V per face and the pressure slope k_f/A = s·K·A/V (N/m³)."""
    K = E / (3.0 * (1.0 - 2.0 * nu))
    nodes, tets = p["nodes"], p["tets"]
    vol = tet_volumes(nodes, tets)
    area, kf = [], []
    for e, f in faces:
        a, b, c = (nodes[i] for i in face_nodes(tets, e, f))
        A = 0.5 * np.linalg.norm(np.cross(b - a, c - a))
        area.append(A)
        kf.append(scale * K * A * A / vol[e])
    area, kf = np.array(area), np.array(kf)
    slope = kf / area
    return {"bulk_modulus_Pa": K, "face_area_median_m2": float(np.median(area)),
            "k_face_median_N_per_m": float(np.median(kf)), "slope_median_N_per_m3": float(np.median(slope)),
            "slope_min_N_per_m3": float(slope.min()), "slope_max_N_per_m3": float(slope.max())}


def lumped_mass(nodes: np.ndarray, tets: np.ndarray, rho: float) -> np.ndarray:
    m = np.zeros(len(nodes))
    np.add.at(m, tets.ravel(), np.repeat(rho * tet_volumes(nodes, tets) / 4.0, 4))
    return m


# --------------------------------------------------------------------------- CalculiX deck
def _id_lines(ids, per_line: int = 8) -> str:
    ids = [str(int(i) + 1) for i in ids]
    return "\n".join(", ".join(ids[i:i + per_line]) for i in range(0, len(ids), per_line)) + "\n"


def _surface(name: str, faces: list[tuple[int, int]]) -> str:
    return f"*SURFACE, NAME={name}, TYPE=ELEMENT\n" + "".join(f"{e + 1}, S{f}\n" for e, f in faces)


def write_deck(p: dict, faces_a, faces_b, slope: float, total_time: float, material,
               friction: float = 0.0, output_every: int = 5, initial_increment: float = 1e-9,
               print_velocities: bool = False) -> str:
    """CalculiX deck: both tubes (C3D4), b's initial velocity, node-to-surface contact
    (slave SB, master SA, linear pressure-overclosure ``slope`` N/m³), explicit step.

    Output every ``output_every`` increments: CF of the contact pair (CalculiX 2.20 prints
    zeros for NODE TO SURFACE pairs, kept for its timing run) and, when
    ``print_velocities``, V of every node of NB (the force comes from b's momentum)."""
    nodes, tets, body = p["nodes"], p["tets"], p["body"]
    out = ["*HEADING", "demfem vs CalculiX: two crossed glass tubes, C3D4, explicit contact",
           "*NODE, NSET=NALL"]
    out += [f"{i + 1}, {x[0]:.12e}, {x[1]:.12e}, {x[2]:.12e}" for i, x in enumerate(nodes)]
    s = "\n".join(out) + "\n"
    for name, b in (("EA", 0), ("EB", 1)):
        s += f"*ELEMENT, TYPE=C3D4, ELSET={name}\n"
        s += "".join(f"{e + 1}, {t[0] + 1}, {t[1] + 1}, {t[2] + 1}, {t[3] + 1}\n"
                     for e, t in enumerate(tets) if body[t[0]] == b)
    s += "*ELSET, ELSET=EALL\nEA, EB\n"
    s += "*NSET, NSET=NA\n" + _id_lines(np.nonzero(body == 0)[0])
    s += "*NSET, NSET=NB\n" + _id_lines(np.nonzero(body == 1)[0])
    s += (f"*MATERIAL, NAME=GLASS\n*ELASTIC\n{material.E:.6e}, {material.nu}\n"
          f"*DENSITY\n{material.density}\n")
    s += "*SOLID SECTION, ELSET=EALL, MATERIAL=GLASS\n"
    s += _surface("SA", faces_a) + _surface("SB", faces_b)
    s += "*CONTACT PAIR, INTERACTION=GLASS2GLASS, TYPE=NODE TO SURFACE\nSB, SA\n"
    s += "*SURFACE INTERACTION, NAME=GLASS2GLASS\n"
    s += f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{slope:.6e}\n"
    if friction > 0:
        s += f"*FRICTION\n{friction}, {slope * 1e-3:.6e}\n"
    v = p["velocity"][np.nonzero(body == 1)[0][0]]
    s += "*INITIAL CONDITIONS, TYPE=VELOCITY\n"
    s += "".join(f"NB, {d + 1}, {v[d]:.6e}\n" for d in range(3) if v[d] != 0.0)
    s += "*STEP, INC=100000000\n*DYNAMIC, EXPLICIT\n"
    s += f"{min(initial_increment, total_time):.9e}, {total_time:.12e}\n"
    s += f"*CONTACT PRINT, SLAVE=SB, MASTER=SA, FREQUENCY={int(output_every)}\nCF\n"
    if print_velocities:
        s += f"*NODE PRINT, NSET=NB, FREQUENCY={int(output_every)}\nV\n"
    s += "*END STEP\n"
    return s


def parse_contact_forces(txt: str) -> tuple[np.ndarray, np.ndarray]:
    """Times and total slave-surface force vectors (n,3) of ``*CONTACT PRINT`` CF."""
    rows = re.findall(
        r"statistics for slave set \S+, master set \S+ and time\s+(\S+)\s*\n\s*\n\s*"
        r"total surface force \(fx,fy,fz\)[^\n]*\n\s*\n\s*(\S+)\s+(\S+)\s+(\S+)", txt)
    t = np.array([float(r[0]) for r in rows])
    f = np.array([[float(r[1]), float(r[2]), float(r[3])] for r in rows]).reshape(-1, 3)
    return t, f


def parse_velocity_blocks(txt: str, nodes_1based: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every ``V`` block for set NB: times (n,) and velocities (n, len(nodes), 3)."""
    heads = list(re.finditer(r"velocities \(vx,vy,vz\) for set NB and time\s+(\S+)", txt))
    index = {int(n): i for i, n in enumerate(nodes_1based)}
    times, vel = [], []
    for k, h in enumerate(heads):
        end = heads[k + 1].start() if k + 1 < len(heads) else len(txt)
        v = np.zeros((len(index), 3))
        for line in txt[h.end():end].split("\n"):
            parts = line.split()
            if len(parts) == 4 and parts[0].isdigit() and int(parts[0]) in index:
                v[index[int(parts[0])]] = [float(x) for x in parts[1:]]
        times.append(float(h.group(1)))
        vel.append(v)
    return np.array(times), np.array(vel).reshape(len(times), len(index), 3)


def run_ccx(deck: str, workdir: Path, timeout: float, threads: int = 1) -> dict:
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / "tubes.inp").write_text(deck)
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), NUMBER_OF_CPUS=str(threads))
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(["ccx", "-i", "tubes"], cwd=workdir, env=env, capture_output=True,
                       text=True, timeout=timeout)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    (workdir / "ccx.stdout").write_text(p.stdout + "\n--- stderr ---\n" + p.stderr)
    out = {"wall_s": wall, "cpu_s": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
           "returncode": p.returncode, "finished": "Job finished" in p.stdout,
           "stdout_tail": p.stdout[-2500:], "stderr_tail": p.stderr[-1500:]}
    for key, pat in (("courant_dt", r"COURANT initial stable time increment:\s*(\S+)"),
                     ("selected_dt", r"SELECTED time increment:\s*(\S+)")):
        m = re.search(pat, p.stdout)
        out[key] = float(m.group(1)) if m else None
    incs = re.findall(r"increment\s+(\d+)\s+attempt", p.stdout)
    out["increments"] = int(incs[-1]) if incs else None
    dat = workdir / "tubes.dat"
    out["dat"] = dat.read_text() if dat.exists() else ""
    return out


# --------------------------------------------------------------------------- demfem child
def demfem_child(args: argparse.Namespace) -> int:
    from demfem.contact import ContactBody, hertz_contact_duration
    from demfem.fem.model import Body, ContactOptions, FemModel
    from demfem.fem.result import moving_average

    p = build_problem(layers=args.layers, face_to_face=not args.vertex_to_vertex)
    tube = p["cartridge"]
    mat = tube.material
    ma, mb = p["meshes"]

    def model(dt=None):
        return FemModel(bodies=[Body(ma, name="a"), Body(mb, velocity=(-p["v_rel"], 0, 0), name="b")],
                        material=mat, dt=dt,
                        contact=ContactOptions(penalty_scale=args.penalty_scale, friction=args.friction,
                                               output_interval=args.output_every))

    own = model()
    own_dt, own_limit = own.dt_step, float(own.solver.dt_limit)
    dt_req = args.dt if args.dt and args.dt <= own_limit else None
    mdl = model(dt_req) if dt_req else own
    ca = ContactBody.from_cartridge(dataclasses.replace(tube, material=mat))
    duration = p["gap"] / p["v_rel"] + 4.0 * hertz_contact_duration(ca, ca, p["v_rel"])
    seen = {"on": False}

    def separated(m) -> bool:
        info = m.solver.contact_info() or {}
        if info.get("active_contacts", 0) > 0:
            seen["on"] = True
            return False
        return seen["on"] and (m.body_velocity(1)[0] - m.body_velocity(0)[0]) > 0.0

    r0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    res = mdl.run(duration, stop_when=separated)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    fn, _ = res.pair_force("a", "b")
    on = np.nonzero(fn > 0)[0]
    out = {"dt_s": mdl.dt_step, "own_dt_s": own_dt, "dt_limit_s": own_limit, "dt_from_ccx": bool(dt_req),
           "steps": int(mdl.solver.steps), "end_time_s": mdl.time, "n_elements": mdl.mesh.n_elements,
           "step_wall_s": wall, "step_cpu_s": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
           "time": res.time.tolist(), "force": fn.tolist(), "energy_balance_error": res.energy_balance_error(),
           "touched": bool(on.size)}
    if on.size:
        dts = res.time[1] - res.time[0]
        t_c = float(res.time[on[-1]] - res.time[on[0]] + dts)
        w = max(1, int(round(t_c / 20.0 / dts)))
        rel_after = mdl.body_velocity(1)[0] - mdl.body_velocity(0)[0]
        out.update(max_force_N=float(moving_average(fn, w).max()), raw_max_force_N=float(fn.max()),
                   contact_duration_s=t_c, contact_start_s=float(res.time[on[0]] - dts),
                   restitution=float(rel_after / p["v_rel"]), smooth_window=w)
    Path(args.demfem_child).write_text(json.dumps(out))
    return 0


def run_demfem(args: argparse.Namespace, work: Path, dt: float | None) -> dict:
    out = work / "demfem.json"
    cmd = [sys.executable, str(Path(__file__).resolve()), "--demfem-child", str(out),
           "--layers", str(args.layers), "--friction", repr(args.friction),
           "--penalty-scale", repr(args.penalty_scale), "--output-every", str(args.output_every)]
    if dt:
        cmd += ["--dt", repr(dt)]
    if args.vertex_to_vertex:
        cmd.append("--vertex-to-vertex")
    env = dict(os.environ, RAYON_NUM_THREADS="1", OMP_NUM_THREADS="1")
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, timeout=args.timeout)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    res = json.loads(out.read_text())
    res.update(process_wall_s=wall, process_cpu_s=(r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime))
    return res


# --------------------------------------------------------------------------- main
def ccx_contact_summary(t: np.ndarray, f: np.ndarray, v_rel: float) -> dict:
    fx = np.abs(f[:, 0]) if len(f) else np.zeros(0)
    fmag = np.linalg.norm(f, axis=1) if len(f) else np.zeros(0)
    on = np.nonzero(fmag > 1e-3 * max(float(fmag.max()) if len(fmag) else 0.0, 1e-300))[0]
    out = {"samples": int(len(t)), "raw_max_force_N": float(fmag.max()) if len(fmag) else 0.0,
           "raw_max_force_x_N": float(fx.max()) if len(fx) else 0.0}
    if on.size:
        dts = float(t[1] - t[0]) if len(t) > 1 else 0.0
        t_c = float(t[on[-1]] - t[on[0]] + dts)
        w = max(1, int(round(t_c / 20.0 / dts))) if dts > 0 else 1
        from demfem.fem.result import moving_average
        out.update(max_force_N=float(moving_average(fmag, w).max()), contact_duration_s=t_c,
                   contact_start_s=float(t[on[0]] - dts), smooth_window=w)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--layers", type=int, default=2)
    ap.add_argument("--friction", type=float, default=0.0)
    ap.add_argument("--penalty-scale", type=float, default=1.0)
    ap.add_argument("--output-every", type=int, default=5, help="steps between contact samples (both codes)")
    ap.add_argument("--vertex-to-vertex", action="store_true",
                    help="no half-division turn (vertex lines cross edge on edge, as collide_cartridges)")
    ap.add_argument("--workdir", default="/tmp/demfem_contact_vs_ccx")
    ap.add_argument("--timeout", type=float, default=3000.0)
    ap.add_argument("--json", default=str(OUT_JSON))
    ap.add_argument("--dt", type=float, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--demfem-child", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.demfem_child:
        return demfem_child(a)
    if shutil.which("ccx") is None:
        print("ccx not found (apt-get install calculix-ccx)", file=sys.stderr)
        return 2
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    p = build_problem(layers=a.layers, face_to_face=not a.vertex_to_vertex)
    mat = p["cartridge"].material
    fa, fb = outer_faces(p, 0), outer_faces(p, 1)
    pen = penalty_slope(p, fa, mat.E, mat.nu, a.penalty_scale)
    slope = pen["slope_median_N_per_m3"]
    n_el = len(p["tets"])
    print(f"mesh: {len(p['nodes'])} nodes, {n_el} C3D4 ({p['n_el_body'][0]} per tube, n_theta {p['n_theta']}, "
          f"{a.layers} layers); outer faces {len(fa)} + {len(fb)}; slope K·A/V = {slope:.4e} N/m³ "
          f"(range {pen['slope_min_N_per_m3']:.3e} .. {pen['slope_max_N_per_m3']:.3e})", flush=True)

    probe = run_ccx(write_deck(p, fa, fb, slope, 1e-15, mat, a.friction),
                    work / "ccx_1inc", a.timeout)
    if not probe["finished"]:
        print("CalculiX one-increment run failed:\n" + probe["stdout_tail"] + probe["stderr_tail"])
    dt_ccx = probe["courant_dt"]
    print(f"CalculiX: Courant increment {dt_ccx} s; 1 increment: wall {probe['wall_s']:.2f} s, cpu {probe['cpu_s']:.2f} s",
          flush=True)

    dm = run_demfem(a, work, dt_ccx)
    print(f"demfem: dt {dm['dt_s']:.4e} s (own {dm['own_dt_s']:.4e}, certified limit {dm['dt_limit_s']:.4e}; "
          f"{'CalculiX step' if dm['dt_from_ccx'] else 'own step'}), {dm['steps']} steps to {dm['end_time_s']:.4e} s, "
          f"stepping wall {dm['step_wall_s']:.2f} s cpu {dm['step_cpu_s']:.2f} s", flush=True)

    total = dm["end_time_s"]
    full = run_ccx(write_deck(p, fa, fb, slope, total, mat, a.friction, a.output_every),
                   work / "ccx_run", a.timeout)
    print(f"CalculiX run: wall {full['wall_s']:.1f} s, cpu {full['cpu_s']:.1f} s, finished {full['finished']}", flush=True)
    ccx = {"wall_s": full["wall_s"], "cpu_s": full["cpu_s"], "one_increment_wall_s": probe["wall_s"],
           "one_increment_cpu_s": probe["cpu_s"], "courant_dt_s": dt_ccx, "selected_dt_s": full["selected_dt"],
           "finished": full["finished"], "returncode": full["returncode"], "increments": full["increments"],
           "end_time_s": total}
    if not full["finished"]:
        ccx["error"] = full["stdout_tail"] + full["stderr_tail"]
        print("CalculiX run failed:\n" + ccx["error"])
    t_cf, f_cf = parse_contact_forces(full["dat"])
    ccx["cf_samples"] = int(len(t_cf))
    ccx["cf_max_abs_N"] = float(np.abs(f_cf).max()) if len(f_cf) else 0.0
    full.pop("dat", None)
    # Physics run: the same deck with V of every node of b every output_every increments;
    # the contact force on b is its momentum's rate, F = Δp_b/Δt (a central difference over
    # 2·output_every increments), the restitution from p_b at the end and momentum
    # conservation (p_a = p_0 − p_b).
    phys = run_ccx(write_deck(p, fa, fb, slope, total, mat, a.friction, a.output_every, print_velocities=True),
                   work / "ccx_physics", a.timeout)
    print(f"CalculiX physics run (V output): wall {phys['wall_s']:.1f} s, cpu {phys['cpu_s']:.1f} s", flush=True)
    ccx.update(physics_run_wall_s=phys["wall_s"], physics_run_cpu_s=phys["cpu_s"], physics_finished=phys["finished"])
    nb = np.nonzero(p["body"] == 1)[0]
    t_v, v_b = parse_velocity_blocks(phys.pop("dat", ""), nb + 1)
    mass = lumped_mass(p["nodes"], p["tets"], mat.density)
    m_a, m_b = float(mass[p["body"] == 0].sum()), float(mass[nb].sum())
    if len(t_v) > 2:
        pb = np.concatenate([[-p["v_rel"] * m_b], (mass[nb][None, :] * v_b[:, :, 0]).sum(axis=1)])
        tt = np.concatenate([[0.0], t_v])
        f_c = np.zeros(len(tt))
        f_c[1:-1] = (pb[2:] - pb[:-2]) / (tt[2:] - tt[:-2])
        t_c = tt
        s_out = ccx_contact_summary(t_c, np.column_stack([f_c, 0 * f_c, 0 * f_c]), p["v_rel"])
        s_out.pop("raw_max_force_x_N", None)
        ccx.update(s_out)
        ccx["time"], ccx["force"] = t_c.tolist(), f_c.tolist()
        v_b_end = pb[-1] / m_b
        v_a_end = (-p["v_rel"] * m_b - pb[-1]) / m_a
        ccx["restitution"] = float((v_b_end - v_a_end) / p["v_rel"])
    else:
        ccx["physics_error"] = phys["stdout_tail"] + phys["stderr_tail"]
    steps_c = int(math.ceil(total / full["selected_dt"] - 1e-9)) if full["selected_dt"] else None
    ccx["increments"] = steps_c
    if steps_c and full["finished"]:
        ccx["element_steps_per_cpu_s"] = n_el * (steps_c - 1) / max(full["cpu_s"] - probe["cpu_s"], 1e-9)
        ccx["element_steps_per_s"] = n_el * (steps_c - 1) / max(full["wall_s"] - probe["wall_s"], 1e-9)
    dm["element_steps_per_cpu_s"] = n_el * dm["steps"] / max(dm["step_cpu_s"], 1e-9)
    dm["element_steps_per_s"] = n_el * dm["steps"] / max(dm["step_wall_s"], 1e-9)

    res = {"problem": {"tube": "Cartridge.tube(11.6e-3, 1.1e-3, 20e-3)", "material": mat.name,
                       "E_Pa": mat.E, "nu": mat.nu, "rho": mat.density, "layers": a.layers,
                       "n_theta": p["n_theta"], "n_elements": n_el, "n_nodes": len(p["nodes"]),
                       "v_rel_m_s": p["v_rel"], "tilt_deg": p["tilt_deg"], "friction": a.friction,
                       "gap_m": p["gap"], "face_to_face": not a.vertex_to_vertex,
                       "outer_faces": [len(fa), len(fb)], "penalty": pen,
                       "ccx_slope_N_per_m3": slope, "threads": 1, "load_avg": os.getloadavg()},
           "demfem": dm, "calculix": ccx}
    if "max_force_N" in ccx and "max_force_N" in dm:
        res["comparison"] = {
            "peak_force_rel_diff_filtered": dm["max_force_N"] / ccx["max_force_N"] - 1.0,
            "peak_force_rel_diff_raw": dm["raw_max_force_N"] / ccx["raw_max_force_N"] - 1.0,
            "cpu_rate_ratio": dm["element_steps_per_cpu_s"] / ccx.get("element_steps_per_cpu_s", float("nan")),
            "wall_rate_ratio": dm["element_steps_per_s"] / ccx.get("element_steps_per_s", float("nan")),
            "targets": {"cpu_rate_ratio_min": 50.0, "peak_force_rel_tol": 0.05}}
    Path(a.json).parent.mkdir(parents=True, exist_ok=True)
    Path(a.json).write_text(json.dumps(res, indent=1) + "\n")

    print()
    row = "{:<34} {:>14} {:>14}"
    g = lambda d, k, fmt="{:.4g}": fmt.format(d[k]) if d.get(k) is not None else "-"  # noqa: E731
    print(row.format("", "demfem", "CalculiX 2.20"))
    print(row.format("step dt (s)", g(dm, "dt_s"), g(ccx, "selected_dt_s")))
    print(row.format("steps", g(dm, "steps", "{}"), g(ccx, "increments", "{}")))
    print(row.format("peak force, filtered (N)", g(dm, "max_force_N"), g(ccx, "max_force_N")))
    print(row.format("peak force, raw (N)", g(dm, "raw_max_force_N"), g(ccx, "raw_max_force_N")))
    print(row.format("contact duration (s)", g(dm, "contact_duration_s"), g(ccx, "contact_duration_s")))
    print(row.format("restitution", g(dm, "restitution"), g(ccx, "restitution")))
    print(row.format("process wall (s)", g(dm, "process_wall_s"), g(ccx, "wall_s")))
    print(row.format("process CPU user+sys (s)", g(dm, "process_cpu_s"), g(ccx, "cpu_s")))
    print(row.format("stepping CPU (s)", g(dm, "step_cpu_s"),
                     f"{ccx['cpu_s'] - probe['cpu_s']:.4g}" if full["finished"] else "-"))
    print(row.format("element-steps per CPU-s", g(dm, "element_steps_per_cpu_s"), g(ccx, "element_steps_per_cpu_s")))
    if "comparison" in res:
        c = res["comparison"]
        print(f"peak force demfem/CalculiX − 1: filtered {c['peak_force_rel_diff_filtered']:+.3f}, raw "
              f"{c['peak_force_rel_diff_raw']:+.3f} (target |·| ≤ 0.05); per CPU-second ratio "
              f"{c['cpu_rate_ratio']:.1f} (target ≥ 50)")
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
