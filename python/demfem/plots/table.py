"""Top views of the accumulation table: PNG snapshots and GIF animations (paper Fig. 4, Fig. 9a/c
and Movie 1), tags coloured as in Fig. 4. Uses matplotlib's Agg backend, so no display is
needed; files are written atomically."""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402
from matplotlib.collections import EllipseCollection, LineCollection  # noqa: E402

import numpy as np  # noqa: E402

from demfem.errors import InvalidParameterError, ShapeError  # noqa: E402
from demfem.io.atomic import atomic_path  # noqa: E402
from demfem.scenes.table import TAG_NAMES, SceneDescription, Tag, wall_displacement  # noqa: E402

__all__ = ["TAG_COLOURS", "plot_table_snapshot", "animate_table"]

#: Colours of the tags in the paper's Fig. 4; untagged spheres are light grey.
TAG_COLOURS: dict[int, str] = {
    Tag.NONE: "#d0d0d0",
    Tag.TRIANGULAR_CENTRE: "green",
    Tag.RECTANGULAR_CENTRE: "cyan",
    Tag.UPPER_VERTEX: "yellow",
    Tag.LOWER_VERTEX: "blue",
    Tag.FIRST_LINE: "magenta",
}


def _wall_segments(scene: SceneDescription, time: float) -> np.ndarray:
    """(k, 2, 2) top-view traces of the walls at ``time`` (s)."""
    segments = []
    for wall in scene.walls:
        if wall["top_view"] is None:
            continue
        shift = wall_displacement(wall["motion"], time)[:2]
        segments.append(np.asarray(wall["top_view"], float) + shift)
    return np.array(segments).reshape(-1, 2, 2)


def _check_frame(positions: np.ndarray, scene: SceneDescription) -> np.ndarray:
    pos = np.asarray(positions, float)
    if pos.ndim != 2 or pos.shape != (scene.n_particles, 3):
        raise ShapeError(f"shape mismatch for positions: expected ({scene.n_particles}, 3), "
                         f"got {pos.shape}")
    return pos


def _draw(ax, scene: SceneDescription, positions: np.ndarray, time: float,
          tags: np.ndarray) -> tuple[EllipseCollection, LineCollection]:
    present = np.all(np.isfinite(positions), axis=1)
    diameters = 2.0 * scene.radii
    # Tagged spheres are drawn last so that they stay visible on top of their neighbours.
    order = np.argsort(tags != Tag.NONE, kind="stable")
    spheres = EllipseCollection(
        diameters[order], diameters[order], np.zeros(len(order)), units="xy",
        offsets=np.where(present[order, None], positions[order, :2], np.nan),
        offset_transform=ax.transData,
        facecolors=[TAG_COLOURS.get(int(t), TAG_COLOURS[Tag.NONE]) for t in tags[order]],
        edgecolors="black", linewidths=0.3)
    ax.add_collection(spheres)
    walls = LineCollection(list(_wall_segments(scene, time)), colors="black", linewidths=2.0)
    ax.add_collection(walls)
    return spheres, walls


def _setup_axes(ax, scene: SceneDescription) -> None:
    segments = _wall_segments(scene, 0.0).reshape(-1, 2)
    margin = 4.0 * float(scene.radii.max())
    lo, hi = segments.min(axis=0) - margin, segments.max(axis=0) + margin
    ax.set_xlim(lo[0], hi[0] + 0.05 * (hi[0] - lo[0]))
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x along the belt (m)")
    ax.set_ylabel("y across the table (m)")
    handles = [plt.Line2D([], [], marker="o", linestyle="", markerfacecolor=c,
                          markeredgecolor="black", label=TAG_NAMES[t])
               for t, c in TAG_COLOURS.items() if t != Tag.NONE]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    _belt_arrow(ax, scene)


def _belt_arrow(ax, scene: SceneDescription) -> None:
    """An arrow in the lower left corner along the belt's surface velocity, labelled with
    its speed (m/s); nothing if the scene has no moving belt."""
    for w in scene.walls:
        v = np.asarray(w.get("surface_velocity", np.zeros(3)), float)[:2]
        if w.get("name") == "belt" and np.linalg.norm(v) > 0:
            d = v / np.linalg.norm(v)
            start = np.array([0.03, 0.06])
            end = start + 0.12 * d * np.array([1.0, 2.2])  # axes fractions: table is wide
            ax.annotate("", xy=tuple(end), xytext=tuple(start), xycoords="axes fraction",
                        arrowprops={"arrowstyle": "-|>", "color": "tab:blue", "lw": 2.0})
            ax.annotate(f"belt {np.linalg.norm(v):.3g} m/s", xy=tuple(end),
                        xycoords="axes fraction", xytext=(4, -3), textcoords="offset points",
                        color="tab:blue", fontsize="small", va="center")
            return


def plot_table_snapshot(path: str | Path, scene: SceneDescription,
                        positions: np.ndarray | None = None, time: float = 0.0,
                        tags: np.ndarray | None = None, dpi: int = 150) -> Path:
    """Draw the table seen from above at ``time`` (s) and write it as a PNG; returns the path.

    Args:
        path: output PNG.
        scene: the scene description (walls, radii, tags).
        positions: (N, 3) centres in m at ``time``; NaN rows (removed spheres) are skipped.
            Defaults to the start positions.
        time: simulated time in s, which places the gate.
        tags: (N,) tag codes; defaults to ``scene.tags``.
        dpi: resolution.
    """
    pos = _check_frame(scene.positions if positions is None else positions, scene)
    tags = scene.tags if tags is None else np.asarray(tags)
    fig, ax = plt.subplots(figsize=(10, 4.5))
    try:
        _setup_axes(ax, scene)
        _draw(ax, scene, pos, time, tags)
        ax.set_title(f"t = {time:.2f} s")
        fig.tight_layout()
        with atomic_path(path, suffix=".png") as tmp:
            fig.savefig(tmp, dpi=dpi, format="png")
    finally:
        plt.close(fig)
    return Path(path)


def animate_table(path: str | Path, scene: SceneDescription, positions: np.ndarray,
                  times: Sequence[float], fps: int = 10, dpi: int = 80) -> Path:
    """Write an animated GIF of the table seen from above (like the paper's Movie 1).

    Args:
        path: output GIF.
        scene: the scene description.
        positions: (n_frames, N, 3) centres in m; NaN rows are removed spheres.
        times: (n_frames,) simulated times, s.
        fps: frames per second of the animation (GIF frame times are whole
            milliseconds, so a whole number of frames per second).
        dpi: resolution.
    """
    frames = np.asarray(positions, float)
    frame_times = np.asarray(times, float)
    if frames.ndim != 3 or frames.shape[1:] != (scene.n_particles, 3):
        raise ShapeError(f"shape mismatch for positions: expected (n_frames, "
                         f"{scene.n_particles}, 3), got {frames.shape}")
    if frame_times.shape != (len(frames),):
        raise ShapeError(f"shape mismatch for times: expected ({len(frames)},), "
                         f"got {frame_times.shape}")
    if isinstance(fps, bool) or not isinstance(fps, (int, np.integer)) or fps < 1:
        raise InvalidParameterError(f"invalid fps = {fps!r}: must be a whole number >= 1")
    fig, ax = plt.subplots(figsize=(10, 4.5))
    try:
        _setup_axes(ax, scene)
        spheres, walls = _draw(ax, scene, frames[0], float(frame_times[0]), scene.tags)
        order = np.argsort(scene.tags != Tag.NONE, kind="stable")
        title = ax.set_title("")
        fig.tight_layout()

        def update(k: int):
            present = np.all(np.isfinite(frames[k]), axis=1)
            spheres.set_offsets(np.where(present[order, None], frames[k][order, :2], np.nan))
            walls.set_segments(list(_wall_segments(scene, float(frame_times[k]))))
            title.set_text(f"t = {frame_times[k]:.2f} s")
            return spheres, walls, title

        animation = FuncAnimation(fig, update, frames=len(frames), blit=False)
        with atomic_path(path, suffix=".gif") as tmp:
            animation.save(tmp, writer=PillowWriter(fps=fps), dpi=dpi)
    finally:
        plt.close(fig)
    return Path(path)
