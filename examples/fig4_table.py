"""Paper Fig. 4: the accumulation table seen from above at t = 0, with its tagged spheres.

Builds the scene from ``table_default.toml`` (next to this script) and writes

* ``fig4_table.png``: top view, tags coloured as in the paper (triangular centre green,
  rectangular centre cyan, upper vertex yellow, lower vertex blue, first line magenta);
* ``fig4_table.vtp``: the start configuration for ParaView (point data: radius, tag).

Run:  python examples/fig4_table.py [output directory]
"""
import sys
from pathlib import Path

from demfem.io import write_vtp
from demfem.plots import plot_table_snapshot
from demfem.scenes import AccumulationTable, Tag


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    table = AccumulationTable.from_toml(Path(__file__).with_name("table_default.toml"))
    scene = table.build()
    plot_table_snapshot(out / "fig4_table.png", scene)
    write_vtp(out / "fig4_table.vtp", scene.positions,
              {"radius": scene.radii, "tag": scene.tags})
    print(f"{scene.n_particles} spheres, effects: {', '.join(scene.effects)}")
    print(f"opening w(t) = {table.opening_width:g} m + {table.gate_amplitude:g} m "
          f"sin(2 pi t / {table.gate_period:g} s): from {table.min_opening_width:g} to "
          f"{table.max_opening_width:g} m (sphere diameter {table.sphere_diameter:g} m)")
    for tag in Tag:
        if tag != Tag.NONE:
            print(f"{scene.tag_names[tag]:>20}: {int((scene.tags == tag).sum())} sphere(s)")
    print(f"wrote {out / 'fig4_table.png'} and {out / 'fig4_table.vtp'}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("demfem_out"))
