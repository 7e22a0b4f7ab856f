"""The FEM collision of two cartridges from Python, against the calibrated contact law.

Two default 3 mL cartridges (paper glass, E = 45 GPa) meet crossed at 90° at 0.2 m/s,
meshed with linear tets, 2 layers through the wall (``demfem.fem.collide_cartridges``: the
explicit FEM with node-to-surface contact, run until they separate, σ1 sampled on the upright
cartridge's inner and outer surface). The script prints the FEM's peak force, contact time,
restitution and peak σ1; then the peak force of the same impact by the law the DEM uses (the
Hertz–Reissner series law of ``demfem.contact``, the paper's eq. 12, on the equivalent
spheres); then the stress ``demfem.stress`` (what ``demfem assess`` uses) puts on the glass at
the FEM's force. At 2 layers the two forces agree within 2 % (the FEM's force converges with
the layers: about 25, 19 and 17 N for 1, 2 and 3). The FEM's σ1 is 10–30 times below the
contact stress model's because 1 mm tets cannot resolve a Hertz patch a fraction of a
millimetre wide: take forces from the FEM, the stress at a contact from ``demfem.stress``.

Run:  python examples/fem_collision.py [LAYERS]      (2 by default; 1 is faster and coarser)

What it prints (2-core machine, shared; about 15 s):

    FEM: 49776 tets, 2 layer(s) through the wall, step 3.11e-08 s, 9.3 s of wall time
      peak force 18.85 N (raw 20.22 N), contact 79.6 us, restitution 0.803
      peak sigma1 on the upright cartridge: outer 1.78 MPa, inner 2.34 MPa (1 mm tets)
    law (Hertz-Reissner, equivalent spheres): peak force 19.15 N (+1.6 % against the FEM)
    demfem.stress at the FEM's 18.85 N (crossed, no friction): outer 51.2 MPa, inner 23.1 MPa
"""
from __future__ import annotations

import sys

import numpy as np

from demfem.cartridge import Cartridge
from demfem.contact import ContactBody, max_contact_force
from demfem.fem import collide_cartridges
from demfem.stress import contact_stresses

V_REL = 0.2         # m/s, closing speed


def main(layers: int = 2) -> dict[str, float]:
    # 1. the FEM: two cartridges, crossed, b closing on a at V_REL
    r = collide_cartridges(v_rel=V_REL, tilt_deg=90.0, layers=layers, stress_samples=20)
    print(f"FEM: {r.n_elements} tets, {layers} layer(s) through the wall, step {r.dt:.3g} s, "
          f"{r.wall_time:.1f} s of wall time")
    print(f"  peak force {r.max_force:.2f} N (raw {r.raw_max_force:.2f} N), contact "
          f"{1e6 * r.contact_duration:.1f} us, restitution {r.restitution:.3f}")
    print(f"  peak sigma1 on the upright cartridge: outer {r.peak_sigma1_outer / 1e6:.3g} MPa, "
          f"inner {r.peak_sigma1_inner / 1e6:.3g} MPa (1 mm tets)")

    # 2. the calibrated law on the equivalent spheres of the same cartridges
    body = ContactBody.from_cartridge(Cartridge())
    f_law = max_contact_force(body, body, V_REL, "hertz_reissner")
    print(f"law (Hertz-Reissner, equivalent spheres): peak force {f_law:.2f} N "
          f"({100 * (f_law / r.max_force - 1):+.1f} % against the FEM)")

    # 3. the contact stress at the FEM's force, as demfem assess evaluates it
    s = contact_stresses(np.array([r.max_force]), np.array([0.0]))
    print(f"demfem.stress at the FEM's {r.max_force:.2f} N (crossed, no friction): outer "
          f"{s.outer_sigma1_max[0] / 1e6:.3g} MPa, inner {s.inner_sigma1_max[0] / 1e6:.3g} MPa")
    return {"fem_force_N": r.max_force, "law_force_N": f_law,
            "fem_sigma1_outer_Pa": r.peak_sigma1_outer}


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2)
