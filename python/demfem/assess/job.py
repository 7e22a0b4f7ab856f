"""What one stage of ``demfem assess`` is (:class:`Stage`), what it works on
(:class:`JobContext`: the job's checked settings and what the earlier stages produced) and
the loop that goes through the stages (:func:`run_stages`).

A stage has a name (one of :data:`demfem.assess.stages.STAGES`), a title for its console
header, the files it writes, :meth:`Stage.run` (compute, write the files, return them with
what it computed) and :meth:`Stage.load` (read its files back, for a stage completed
before). :func:`demfem.assess.run.assess` checks the job's arguments and hands the stages
(:data:`demfem.assess.job_stages.JOB_STAGES`) to :func:`run_stages` with one
:class:`~demfem.assess.stages.StageBook`.

**What a finished folder keeps.** A stage's files are of two kinds: its products
(:attr:`Stage.files`: what the user opens, and what a re-run of the finished folder reads
back) and its intermediates (:attr:`Stage.intermediates`: what only the later stages read).
While the job is unfinished both are kept, so that an interrupted job resumes at its first
unfinished stage. Once the last stage has completed, :func:`run_stages` records each stage's
digest (:meth:`Stage.digest`: the few numbers its console lines need, e.g. the event
counts) in ``stages.json`` and removes the intermediates (:meth:`StageBook.finish
<demfem.assess.stages.StageBook.finish>`): this is the only place that decides what a
finished folder keeps. A re-run of the finished folder with the same settings reads each
stage back from its products and digest (:meth:`Stage.recall`) and prints the same lines
and returns the same document; a finished folder with a damaged or missing product reruns
from the first stage whose intermediates are gone (the DEM).

SI units throughout: m, s, kg, N, Pa.
"""
from __future__ import annotations

import abc
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional

if TYPE_CHECKING:
    from demfem.assess.stages import StageBook
    from demfem.dem.steady import SteadyRule
    from demfem.risk.fatigue import SlowCrackGrowth
    from demfem.scenes.table import AccumulationTable
    from demfem.stress.stress_model import StressModel

__all__ = ["JobContext", "Stage", "StageOutput", "run_stages"]


@dataclass
class JobContext:
    """The settings of one assessment, checked, and what its stages produced so far.

    Attributes:
        table: the table (:class:`demfem.scenes.table.AccumulationTable`), re-fed if asked.
        settings: the job's settings as recorded in ``stages.json``.
        out: the output folder.
        log: where the console lines go.
        duration: simulated time of the table, s (the longest, when run until steady).
        sample_interval: time between recorded samples, s.
        rule: the steady rule (:class:`demfem.dem.steady.SteadyRule`) of a run until steady;
            None for a fixed duration.
        discard_before: start of the statistics window of a fixed-duration run, s.
        min_speed: minimum normal impact speed of an event, m/s.
        throughput: cartridges per hour of the user's line; None: the table's own discharge.
        model: the stress model (``"contact"``, ``"shell"`` or a
            :class:`demfem.stress.stress_model.StressModel`).
        pair_geometry: the contact of two cartridges (``"crossed"`` or ``"parallel"``).
        stress_young_modulus: Young's modulus of the stresses, Pa.
        slow_crack_growth: the slow-crack-growth law (:data:`demfem.risk.SCG_BOROSILICATE`)
            or None.
        surfaces: ``inner`` and ``outer`` surface strengths (:class:`demfem.risk`
            surfaces), their ``source`` in words and the ``measured`` ones.
        flaw_depth: depth of the outer surface's flaws, m; None: the surface value.
        place: where on the cartridge the events land (:data:`demfem.assess.places.
            PLACE_MODES`: ``"mix"``, the full-shape table's weights, or one place).
        csv: also write the tables as CSV.
        threads: DEM threads.
        checkpoint_every: wall time between DEM checkpoints, s.
        fresh: the job replaces an earlier one in ``out``.
        progress: a progress bar on standard error for the DEM stage.
        seed: the perturbed start's seed, or None for the scene's own start.
        produced: what each completed stage produced, by stage name (see each stage; None
            for a stage of a finished folder whose intermediates are gone).
        digests: each stage's digest (:meth:`Stage.digest`), by stage name: what its
            console lines and the later stages' need of it.
    """

    table: AccumulationTable
    settings: dict[str, Any]
    out: Path
    log: Callable[[str], None]
    duration: float
    sample_interval: float
    rule: Optional[SteadyRule]
    discard_before: float
    min_speed: float
    throughput: Optional[float]
    model: str | StressModel
    pair_geometry: str
    stress_young_modulus: float
    slow_crack_growth: Optional[SlowCrackGrowth]
    surfaces: dict[str, Any]
    flaw_depth: Optional[float]
    csv: bool
    threads: int
    checkpoint_every: float
    fresh: bool
    progress: bool
    seed: Optional[int]
    produced: dict[str, Any] = field(default_factory=dict)
    digests: dict[str, Any] = field(default_factory=dict)
    place: str = "mix"

    def window(self) -> tuple[float, float]:
        """The statistics window (start, end), s, once the DEM stage has run: every whole
        gate period since the warm-up for a run until steady, else from ``discard_before``;
        the end is where the table run stopped."""
        end = float(self.produced["dem"].info["duration"])
        start = min(self.rule.warmup, end) if self.rule is not None else self.discard_before
        return start, end


@dataclass
class StageOutput:
    """What :meth:`Stage.run` returns: the ``files`` it wrote (recorded with their SHA-256)
    and the ``product`` it computed, or None when later stages read it back from the files
    (:meth:`Stage.load`)."""

    files: list[Path]
    product: Any = None


class Stage(abc.ABC):
    """One resumable stage of ``demfem assess`` (module docstring)."""

    #: The stage's name, one of :data:`demfem.assess.stages.STAGES`.
    name: str = ""
    #: The products it writes, kept in a finished folder, relative to the output folder
    #: (glob patterns).
    files: tuple[str, ...] = ()
    #: The files it writes for the later stages only, removed once the job has finished
    #: (names relative to the output folder).
    intermediates: tuple[str, ...] = ()

    @abc.abstractmethod
    def title(self, ctx: JobContext) -> str:
        """What the stage does, for its console header."""

    def begin(self, ctx: JobContext) -> None:
        """Log what holds whether the stage runs or is reused (after its header, before it
        runs); by default nothing."""

    @abc.abstractmethod
    def run(self, ctx: JobContext) -> StageOutput:
        """Compute the stage from ``ctx`` and write its files."""

    @abc.abstractmethod
    def load(self, ctx: JobContext) -> Any:
        """The stage's product, read back from its files (intermediates included)."""

    def recall(self, ctx: JobContext) -> Any:
        """The stage's product as a finished folder keeps it: read back from its products
        alone (its intermediates are gone); by default :meth:`load`. Only :meth:`show`,
        :meth:`answer` and the later stages' :meth:`begin` and :meth:`show` use it."""
        return self.load(ctx)

    def digest(self, ctx: JobContext) -> Optional[dict[str, Any]]:
        """What the console lines (this stage's and the later stages') need of the stage's
        product ``ctx.produced[self.name]``, as a small strict-JSON dict recorded in
        ``stages.json`` when the job finishes, for a stage with intermediates; by default
        None (nothing needed beyond :meth:`recall`)."""
        return None

    def show(self, ctx: JobContext) -> None:
        """Log the stage's result (its product is ``ctx.produced[self.name]``); by default
        nothing."""

    def answer(self, ctx: JobContext) -> dict[str, Any]:
        """What :func:`demfem.assess.assess` returns when it ends after this stage."""
        return {"stopped_after": self.name}


def run_stages(ctx: JobContext, stages: tuple[Stage, ...], book: StageBook,
               stop_after: Optional[str] = None) -> dict[str, Any]:
    """Go through ``stages`` in order on ``book`` (module docstring): a stage completed
    before is read back (:meth:`Stage.load`, or :meth:`Stage.recall` in a finished folder),
    any other runs and is recorded; the job ends after ``stop_after``. Once the last stage
    has completed, the folder is finished: the stages' digests are recorded and their
    intermediates removed. Returns the last stage's :meth:`Stage.answer`."""
    log = ctx.log
    stage = stages[0]
    for k, stage in enumerate(stages, 1):
        done = book.is_done(stage.name)
        log(f"== {k}/{len(stages)} {stage.name}: {stage.title(ctx)}"
            + (" (done before: reused) ==" if done else " =="))
        stage.begin(ctx)
        if done and book.finished:
            ctx.produced[stage.name] = stage.recall(ctx)
            ctx.digests[stage.name] = book.digest(stage.name)
        else:
            if done:
                ctx.produced[stage.name] = stage.load(ctx)
            else:
                output = stage.run(ctx)
                book.complete(stage.name, output.files)
                ctx.produced[stage.name] = (stage.load(ctx) if output.product is None
                                            else output.product)
            ctx.digests[stage.name] = stage.digest(ctx)
        stage.show(ctx)
        if stage is stages[-1]:
            book.finish({s.name: s.intermediates for s in stages},
                        {name: d for name, d in ctx.digests.items() if d is not None})
        if stage.name == stop_after:
            break
    return stage.answer(ctx)
