"""Command line: ``demfem <command>``. Run ``demfem --help`` for the list."""
from __future__ import annotations

import argparse
import os
import sys
from typing import NoReturn, Optional, Sequence

import numpy as np

from demfem.errors import (CheckpointError, DemfemError, InvalidParameterError,
                           SettingsMismatchError, SimulationInterrupted)

__all__ = ["main", "build_parser", "study_options_from_args", "package_version"]


def package_version() -> str:
    """The installed package's version (importlib.metadata), else ``demfem.__version__``."""
    try:
        from importlib.metadata import PackageNotFoundError, version

        return version("demfem")
    except (ImportError, PackageNotFoundError):
        import demfem

        return str(demfem.__version__)


class _Parser(argparse.ArgumentParser):
    """Bad arguments: one line ``demfem: error: ...`` on standard error, exit code 2."""

    def error(self, message: str) -> "NoReturn":  # type: ignore[override]
        sys.stderr.write(f"demfem: error: {message} (see '{self.prog} --help')\n")
        raise SystemExit(2)


def _add_modulus(parser: argparse.ArgumentParser, help_text: str, **kwargs) -> None:
    """``--E`` (documented) and ``--young-modulus`` (the same option), one destination."""
    parser.add_argument("--E", "--young-modulus", dest="young_modulus", help=help_text,
                        **kwargs)


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from demfem.calibration import calibration_report, force_vs_modulus, write_calibration
    from demfem.cartridge import Cartridge

    print(calibration_report(args.v_rel))
    E = np.logspace(np.log10(args.e_min), np.log10(args.e_max), args.n)
    table = force_vs_modulus(Cartridge(), E, args.v_rel)
    print(f"\nMaximum contact force, two cartridges at v_rel = {args.v_rel:g} m/s (Fig. 3 analogue):")
    print(table.format())
    from pathlib import Path

    from demfem.fem import fig3

    if args.fem:
        print(f"\nFEM: two cartridges colliding at {args.v_rel:g} m/s (explicit, contact), this takes minutes")
        data = fig3.fem_force_vs_modulus(E=[float(e) for e in np.logspace(7, 11, 5)], v_rel=args.v_rel)
        stored = fig3.save(data, Path(args.out) / "fig3_fem.json")
        print(f"wrote {stored}")
    else:
        data = fig3.load_stored()
    curves = {"FEM, crossed (tilt 90 deg)": fig3.curve(data, 90.0),
              "FEM, parallel (tilt 0 deg)": fig3.curve(data, 0.0)}
    curves = {k: v for k, v in curves.items() if len(v[0])}
    print(f"FEM points ({'computed now' if args.fem else 'stored run, --fem recomputes'}):")
    for r in sorted(data["runs"], key=lambda r: (r["tilt_deg"], r["E_Pa"])):
        print(f"  tilt {r['tilt_deg']:4.0f} deg  E {r['E_Pa']:9.2e} Pa  FEM {r['max_force_N']:8.3f} N"
              f"  Hertz-Reissner {r['hertz_reissner_N']:8.3f} N"
              f"  (Hertz-Reissner / FEM = {r['hertz_reissner_N'] / r['max_force_N']:.2f})")
    csv, png = write_calibration(args.out, table, curves)
    print(f"\nwrote {csv}\nwrote {png}")
    return 0


def _scene_kind(path: Optional[str]) -> Optional[str]:
    """The ``scene`` key of a TOML scene file (None: no file, or a table file without it)."""
    if path is None:
        return None
    from demfem.io.toml_file import read_toml

    kind = read_toml(path).get("scene")
    return kind if isinstance(kind, str) else None


def _cmd_run_mesh_table(args: argparse.Namespace) -> int:
    from demfem.scenes.infeed import run_mesh_table
    from demfem.scenes.mesh_table import MeshTable

    table = MeshTable.from_toml(args.scene)
    if args.young_modulus is not None:
        mats = {k: dict(v) for k, v in table.materials.items()}
        mats[table.particle_material]["young_modulus"] = float(args.young_modulus)
        table = table.replace(materials=mats)
    duration = args.duration if args.duration is not None else (
        min(1.0, table.duration) if args.quick else None)
    run_mesh_table(table, args.out, duration=duration, threads=args.threads,
                   log=lambda line: print(line, flush=True))
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from demfem.pipeline import run_pipeline

    from demfem.scenes.mesh_table import SCENE_NAME as MESH_TABLE

    if _scene_kind(args.scene) == MESH_TABLE:
        return _cmd_run_mesh_table(args)

    duration = args.duration if args.duration is not None else (0.1 if args.quick else 1.0)
    sample = args.sample_interval if args.sample_interval is not None else min(
        0.01 if args.quick else 0.02, duration)
    run_pipeline(args.out, duration=duration, young_modulus=args.young_modulus,
                 sample_interval=sample, threads=args.threads, progress=True,
                 log=lambda line: print(line, flush=True), scene=args.scene,
                 fresh=args.fresh)
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    from demfem.sweep import parse_grid_option, sweep

    grid = parse_grid_option(args.grid)

    def progress(done: int, total: int) -> None:
        print(f"\r  runs finished: {done}/{total}", end="", flush=True)

    if args.replicas is not None:
        from demfem.assess.ranking import ranked_sweep

        ranking = ranked_sweep(grid, args.runner, args.out, args.replicas,
                               rank_by=args.rank_by or "broken_per_hour", seed=args.seed,
                               scheduler=args.scheduler, n_workers=args.workers,
                               progress=progress)
        print()
        print(ranking.text())
        print(f"written: {args.out}/results.csv, {args.out}/ranking.json")
        return 0
    res = sweep(grid, args.runner, args.out, scheduler=args.scheduler, n_workers=args.workers,
                progress=progress)
    print(f"\nran {res.ran}, skipped {res.skipped} already finished; table: {res.table_path}")
    print(res.table_path.read_text(), end="")
    if args.rank_by:
        missing = [r for r in res.records if args.rank_by not in r["result"]]
        if missing:
            raise InvalidParameterError(
                f"invalid --rank-by {args.rank_by!r}: not a result of the runner (results: "
                f"{sorted(res.records[0]['result'])})")
        ranked = sorted(res.records, key=lambda r: float(r["result"][args.rank_by]))
        print(f"ranked by {args.rank_by} (lowest first):")
        for k, r in enumerate(ranked, 1):
            point = ", ".join(f"{n}={r['params'][n]}" for n in grid)
            print(f"  {k:3d}  {point}  {args.rank_by} = {float(r['result'][args.rank_by]):.4g}")
    return 0


#: Defaults of the figure studies: (duration s, moduli Pa) for a full run and for --quick.
_STUDY_DEFAULTS = {
    "fig5": ((10.0, "1e7"), (0.3, "1e7")),
    "fig6": ((8.0, "1e7,1e8,1e9"), (0.3, "1e7,1e8")),
    "fig7": ((8.0, "1e7,1e8,1e9"), (0.3, "1e7,1e8")),
    "fig8": ((10.0, "1e7"), (0.3, "1e7")),
}


def study_options_from_args(args: argparse.Namespace):
    """The :class:`demfem.studies.figures.StudyOptions` of a parsed `demfem figN` command line
    (used by the scripts in examples/ too)."""
    from pathlib import Path

    from demfem.studies.figures import StudyOptions

    (duration, moduli), (q_duration, q_moduli) = _STUDY_DEFAULTS[args.command]
    if args.quick:
        duration, moduli = q_duration, q_moduli
    duration = args.duration if args.duration is not None else duration
    text = args.young_modulus if args.young_modulus is not None else moduli
    try:
        values = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise ValueError(f"invalid --E {text!r}: must be Young's moduli in Pa, comma "
                         "separated, e.g. 1e7,1e8") from None
    sample = args.sample_interval if args.sample_interval is not None else (
        0.02 if args.quick else 0.05)
    return StudyOptions(out=Path(args.out), duration=duration, moduli=values,
                        sample_interval=sample, scheduler=args.scheduler,
                        workers=args.workers)


def durations_from_args(args: argparse.Namespace) -> dict[float, float]:
    """Per-modulus durations of `demfem fig6|fig7 --E-duration E=SECONDS ...` as
    {E (Pa): simulated time (s)}."""
    out: dict[float, float] = {}
    for item in getattr(args, "E_duration", None) or []:
        e_text, sep, d_text = item.partition("=")
        try:
            if not sep:
                raise ValueError
            e, d = float(e_text), float(d_text)
        except ValueError:
            raise InvalidParameterError(
                f"invalid --E-duration {item!r}: must be E=SECONDS, Young's modulus in Pa and "
                "simulated time in s, e.g. 1e7=60") from None
        out[e] = d
    return out


def _cmd_study(args: argparse.Namespace) -> int:
    from demfem.studies import figures

    opts = study_options_from_args(args)
    if args.command == "fig5":
        result = figures.fig5(opts, discard_before=args.discard_before)
        print(f"gentlest set-up: {result['gentlest']} (paper: A=2cm T=2s V=0.2m/s)")
    elif args.command == "fig6":
        figures.fig6(opts, stiff_duration=args.stiff_duration,
                     durations=durations_from_args(args))
    elif args.command == "fig7":
        figures.fig7(opts, stiff_duration=args.stiff_duration,
                     durations=durations_from_args(args))
    else:
        figures.fig8_9(opts, snapshot_times=tuple(float(x) for x in args.snapshots.split(",")))
    print(f"figures in {opts.out}")
    return 0


def _add_study(sub, name: str, help_text: str) -> argparse.ArgumentParser:
    (duration, moduli), (q_duration, _) = _STUDY_DEFAULTS[name]
    s = sub.add_parser(name, help=help_text)
    s.add_argument("--duration", type=float, default=None,
                   help=f"simulated time per run, s ({duration:g}; --quick: {q_duration:g})")
    _add_modulus(s, f"Young's modulus/moduli, Pa ({moduli})", default=None,
                 metavar="E1,E2,...")
    s.add_argument("--quick", action="store_true",
                   help="a smoke run (0.3 s simulated per run) with the same outputs")
    s.add_argument("--sample-interval", type=float, default=None,
                   help="time between recorded samples, s (0.05; --quick: 0.02)")
    s.add_argument("--out", default="demfem_out/studies",
                   help="output folder; runs are kept in <out>/runs and reused")
    s.add_argument("--scheduler", default=None,
                   help="Dask scheduler address, or 'serial'; default: a LocalCluster")
    s.add_argument("--workers", type=int, default=None, help="LocalCluster worker processes")
    s.set_defaults(func=_cmd_study)
    return s


def _cmd_equivalence(args: argparse.Namespace) -> int:
    from demfem.equivalence import StudyConfig, run_study

    from demfem.errors import check_positive

    check_positive("duration", args.duration)
    config = StudyConfig(n_spheres=args.n, young_modulus=args.young_modulus,
                         t_end=args.duration)
    result = run_study(config, args.out, progress=lambda msg: print("  " + msg, flush=True))
    print(result["markdown"], end="")
    print(f"written: {args.out}/equivalence.csv, .md, .png")
    return 0


def _cmd_assess(args: argparse.Namespace) -> int:
    from demfem.assess import assess
    from demfem.scenes.mesh_table import SCENE_NAME as MESH_TABLE

    if _scene_kind(args.scene) == MESH_TABLE:
        raise InvalidParameterError(
            f"invalid scene {args.scene}: 'demfem assess' runs accumulation-table scenes; a "
            f"{MESH_TABLE!r} scene runs with 'demfem run' (throughput, residence time, "
            "steadiness), its breakage assessment is not implemented yet")

    model = args.stress_model
    if model is not None and model not in ("contact", "shell"):
        from demfem.assess import StressModel

        model = StressModel.load(model)
    flaw: object = args.flaw_depth
    if flaw == "none":
        flaw = None
    elif flaw != "characteristic":
        try:
            flaw = float(str(args.flaw_depth))
        except ValueError:
            raise InvalidParameterError(f"invalid --flaw-depth {args.flaw_depth!r}: must be "
                                        "characteristic, none or a depth in m") from None
    settings = dict(duration=args.duration, quick=args.quick, full=args.full,
                    throughput=args.throughput, stress_model=model, refeed=not args.no_refeed,
                    csv=args.csv, pair_geometry=args.pair_geometry, place=args.place,
                    flaw_depth=flaw, strength=args.strength)
    if args.replicas is not None or args.precision is not None:
        from demfem.assess.replicas import assess_replicas

        assess_replicas(args.scene, out=args.out,
                        replicas=2 if args.replicas is None else args.replicas,
                        precision=args.precision, scheduler=args.scheduler,
                        n_workers=args.workers, seed=0 if args.seed is None else args.seed,
                        fresh=args.fresh, reports=not args.no_reports,
                        **({} if args.max_replicas is None
                           else {"max_replicas": args.max_replicas}),
                        log=lambda line: print(line, flush=True), **settings)
        return 0
    result = assess(args.scene, out=args.out, fresh=args.fresh, threads=args.threads,
                    seed=args.seed, progress=True, log=lambda line: print(line, flush=True),
                    **settings)
    if "summary" in result:
        from demfem.assess.headline import headline

        print(headline(result["summary"]) + f" (report: {args.out}/report.html)")
    return 0


def _cmd_stress_model(args: argparse.Namespace) -> int:
    from demfem.stress.fem_fit import DEFAULT_GRID, QUICK_GRID, fit_from_fem

    fit_from_fem(args.out, grid=QUICK_GRID if args.quick else DEFAULT_GRID, layers=args.layers,
                 young_modulus=args.young_modulus, scheduler=args.scheduler,
                 n_workers=args.workers, log=lambda line: print(line, flush=True))
    return 0


def _cmd_cluster(args: argparse.Namespace) -> int:
    from pathlib import Path

    from demfem.scenes.cluster import LOAD_CASES, CartridgeCluster, cluster_from_run
    from demfem.fem.cluster_run import run_cluster

    overrides = {"springs": args.springs}
    if args.elements is not None:
        overrides["elements"] = args.elements
    if args.layers is not None:
        overrides["layers"] = args.layers
    if args.from_run is not None:
        cluster = cluster_from_run(Path(args.from_run), args.pick, **overrides)
    elif args.case in LOAD_CASES:
        cluster = CartridgeCluster.load_case(args.case, **overrides)
    elif args.case.endswith(".toml"):
        import dataclasses

        base = CartridgeCluster.from_toml(Path(args.case))
        if not args.springs:
            overrides.pop("springs")
        cluster = dataclasses.replace(base, **overrides)
    else:
        raise InvalidParameterError(f"invalid --case {args.case!r}: must be max, avg or a "
                                    "SCENE.toml file")
    s = run_cluster(cluster, duration=args.duration, out=args.out, progress=True,
                    n_snapshots=args.snapshots, fresh=args.fresh,
                    log=lambda line: print(line, flush=True))
    fp = s["force_peaks"]
    print("peak normal / tangential force on 1, smoothed over "
          f"{s['smoothing_s'] * 1e6:g} us (N): " + "; ".join(
              f"{k} {v['normal_N']:.3g} / {v['tangential_N']:.3g}" for k, v in fp.items()))
    print("raw peak normal force on 1 (N, the penalty contact's step-to-step peak): "
          + "; ".join(f"{k} {v.get('raw_normal_N', float('nan')):.3g}" for k, v in fp.items()))
    print(f"peak sigma1 on 1: {s['sigma1_body_max_Pa'] / 1e6:.4g} MPa; outputs in {args.out}")
    return 0


def _cmd_strength_fit(args: argparse.Namespace) -> int:
    from demfem.risk.strength_file import strength_fit_command

    return strength_fit_command(args)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``demfem`` command."""
    from demfem.assess.run import STEADY_DEFAULT, STEADY_FULL, duration_help
    p = _Parser(prog="demfem", description="DEM-FEM breakage of glass cartridges on a "
                "conveyor-belt accumulation table (SI units).")
    p.add_argument("--version", action="version", version=f"demfem {package_version()}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    c = sub.add_parser("calibrate", help="equivalent sphere and Fig. 3: max force vs E per law")
    c.add_argument("--v-rel", type=float, default=0.2, help="relative impact speed, m/s (0.2)")
    c.add_argument("--e-min", type=float, default=1e7, help="smallest Young's modulus, Pa (1e7)")
    c.add_argument("--e-max", type=float, default=1e11, help="largest Young's modulus, Pa (1e11)")
    c.add_argument("--n", type=int, default=9, help="number of moduli, log-spaced (9)")
    c.add_argument("--out", default="demfem_out", help="output directory (demfem_out)")
    c.add_argument("--fem", action="store_true",
                   help="recompute the FEM curve (two cartridges colliding; minutes) instead of "
                        "drawing the stored run")
    c.set_defaults(func=_cmd_calibrate)
    r = sub.add_parser("run", help="calibration, DEM of a table scene and its analysis "
                       "(no risk; the main job is 'demfem assess')")
    r.add_argument("scene", nargs="?", default=None, metavar="SCENE.toml",
                   help="table scene file (see examples/table_default.toml, or a "
                        "'mesh_table' scene: examples/mesh_table/mesh_table.toml; default: "
                        "the built-in default table)")
    r.add_argument("--duration", type=float, default=None,
                   help="simulated time of the table, s (1.0; --quick: 0.1)")
    _add_modulus(r, "Young's modulus of the glass, Pa (default: the scene's; built-in "
                 "default: the paper's 4.5e10)", type=float, default=None)
    r.add_argument("--sample-interval", type=float, default=None,
                   help="time between recorded samples, s (0.02; --quick: 0.01)")
    r.add_argument("--threads", type=int, default=min(2, os.cpu_count() or 1),
                   help="DEM engine threads (2 where the machine has 2 cores or more; results "
                        "are bitwise the same on any number)")
    r.add_argument("--quick", action="store_true", help="a smoke run with the same outputs")
    r.add_argument("--out", default="demfem_out/run", help="output directory (demfem_out/run); "
                   "the same run there resumes from its checkpoint, another one is refused")
    r.add_argument("--fresh", "--overwrite", dest="fresh", action="store_true",
                   help="replace the run in --out (its outputs and checkpoint are removed)")
    r.set_defaults(func=_cmd_run)
    s = sub.add_parser("sweep", help="run a parameter grid on Dask (LocalCluster by default)")
    s.add_argument("--runner", required=True,
                   help="'module:function' run per point, e.g. demfem.calibration:sweep_point")
    s.add_argument("--grid", action="append", required=True, metavar="NAME=v1,v2,...",
                   help="one parameter and its values; repeat for more (Cartesian product)")
    s.add_argument("--out", default="demfem_out/sweep", help="output directory")
    s.add_argument("--scheduler", default=None,
                   help="Dask scheduler address (tcp://host:8786), or 'serial'; "
                        "default: a LocalCluster on this machine")
    s.add_argument("--workers", type=int, default=None, help="LocalCluster worker processes")
    s.add_argument("--rank-by", default=None, metavar="KEY",
                   help="print the points ranked by this result (lowest first), e.g. "
                        "broken_per_hour with --runner demfem.assess.sweep_runner:risk_point")
    s.add_argument("--replicas", type=int, default=None, metavar="R",
                   help="R paired replicas per set-up (seeds --seed ... --seed+R-1: common "
                        "random starts), ranked by --rank-by (default broken_per_hour) with "
                        "each set-up's 95%% interval and whether its difference to the best "
                        "is real (paired tests, Holm-corrected); --out/ranking.json")
    s.add_argument("--seed", type=int, default=0,
                   help="with --replicas: the first replica's seed (0)")
    s.set_defaults(func=_cmd_sweep)
    f5 = _add_study(sub, "fig5", "Fig. 5: first-line force for A, T, V_belt and the gentlest "
                    "set-up")
    f5.add_argument("--discard-before", type=float, default=1.0,
                    help="start of the force statistics used for the ranking, s (1)")
    for name, text in (("fig6", "Fig. 6: coordination number against time for several E"),
                       ("fig7", "Fig. 7: rectangular-centre speed against time for several E")):
        f = _add_study(sub, name, text)
        f.add_argument("--stiff-duration", type=float, default=None,
                       help="simulated time for the runs with E > 1e9 Pa, s (default: "
                            "--duration)")
        f.add_argument("--E-duration", action="append", default=None, metavar="E=SECONDS",
                       help="simulated time for the run at E (Pa), s, over --duration and "
                            "--stiff-duration; repeat for more, e.g. --E-duration 1e7=60")
    f8 = _add_study(sub, "fig8", "Figs. 8-9: triangular centre and first line, snapshots, GIF "
                    "and ParaView series")
    f8.add_argument("--snapshots", default="9.3,12.2", metavar="T1,T2,...",
                    help="times of the table snapshots, s (9.3,12.2; clipped to the run)")
    e = sub.add_parser("equivalence", help="spheres vs clumped vs exact cartridges on one table")
    e.add_argument("--n", type=int, default=40, help="bodies on the reduced table (40)")
    _add_modulus(e, "Young's modulus, Pa (4.5e8)", type=float, default=45e7)
    e.add_argument("--duration", "--t-end", dest="duration", type=float, default=2.0,
                   help="simulated time, s (2.0)")
    e.add_argument("--out", default="demfem_out/equivalence", help="output directory")
    e.set_defaults(func=_cmd_equivalence)
    a = sub.add_parser("assess", help="the main job, breakage risk: calibration, DEM, "
                       "collision events, stresses, Weibull risk per passage and per hour "
                       "with its interval, HTML report")
    a.add_argument("scene", nargs="?", default=None, metavar="SCENE.toml",
                   help="table scene file (default: the built-in default table)")
    a.add_argument("--duration", type=float, default=None,
                   help="a fixed simulated time of the table, s, statistics over its second "
                        "half (default: " + duration_help().replace("%", "%%") + ")")
    a.add_argument("--out", default="demfem_out/assess", help="output directory "
                   "(demfem_out/assess); the same settings there resume from the last "
                   "completed stage, other settings are refused")
    a.add_argument("--quick", action="store_true", help="a smoke run (0.1 s simulated)")
    a.add_argument("--full", action="store_true", help=(
        "the full-accuracy run: the mean impacts per gate period known to "
        f"{100 * STEADY_FULL[1]:.0f} %% over at least {STEADY_FULL[0]} periods (default "
        f"{100 * STEADY_DEFAULT[1]:.0f} %%, {STEADY_DEFAULT[0]})"))
    a.add_argument("--strength", default=None, metavar="FILE",
                   help="a strength file of your own glass (demfem strength-fit); default: "
                        "the planning assumptions of demfem.risk")
    a.add_argument("--csv", action="store_true", help="also write events.csv and "
                   "passages.csv (the tables are Parquet with units in the schema)")
    a.add_argument("--no-refeed", action="store_true", help="run the scene as a batch that "
                   "drains (default: cartridges leaving are re-fed upstream, so the table "
                   "reaches a steady state)")
    a.add_argument("--throughput", type=float, default=None, metavar="PER_HOUR",
                   help="cartridges per hour of your line; default: the table's own "
                        "discharge in the simulation (given, the report shows both)")
    a.add_argument("--threads", type=int, default=min(2, os.cpu_count() or 1),
                   help="DEM engine threads (results are the same on any number)")
    a.add_argument("--fresh", "--overwrite", dest="fresh", action="store_true",
                   help="replace the assessment in --out (its outputs are removed)")
    a.add_argument("--stress-model", default=None, metavar="contact|shell|MODEL.json",
                   help="contact (default: the contact field with friction on top of the "
                        "shell's bending, demfem.stress), shell (the former shell-only closed "
                        "form) or a shell-model file (demfem stress-model)")
    a.add_argument("--pair-geometry", default="crossed", choices=("crossed", "parallel"),
                   help="how two cartridges touch: crossed at 90 degrees (default, a point "
                        "contact) or parallel along the body (a line contact)")
    a.add_argument("--place", default="mix", choices=("mix", "body", "rim", "shoulder"),
                   help="where on the cartridge the events land: mix (default: weighted over "
                        "body, rim and shoulder by the full-shape table's counts, "
                        "docs/cartridge-places.md) or every event at one place")
    a.add_argument("--flaw-depth", default="characteristic", metavar="characteristic|none|M",
                   help="depth of the outer surface's flaws at which the contact tension is "
                        "felt: characteristic (default: the flaw that fails at sigma_0), none "
                        "(the surface value), or a depth in m")
    a.add_argument("--replicas", type=int, default=None, metavar="N",
                   help="run N independent replicas of the table (perturbed starts, seeds "
                        "--seed ... --seed+N-1) on Dask and merge them: the hourly number "
                        "with a 95%% interval from their scatter (--out/replica_<k>, "
                        "--out/replicas.json; docs/replicas.md)")
    a.add_argument("--precision", type=float, default=None, metavar="FRACTION",
                   help="with replicas: add replicas, a batch of the worker count at a "
                        "time, until the interval's half-width is at most this fraction of "
                        "the number (e.g. 0.2), or --max-replicas is reached")
    a.add_argument("--max-replicas", type=int, default=None, metavar="N",
                   help="most replicas --precision runs (64)")
    a.add_argument("--seed", type=int, default=None,
                   help="perturbed start: with replicas the first replica's seed (0); "
                        "alone, one run from the perturbed start of this seed (default: the "
                        "scene's own start)")
    a.add_argument("--scheduler", default=None,
                   help="with replicas: a Dask scheduler address (tcp://host:8786) or "
                        "'serial'; default: a LocalCluster on this machine")
    a.add_argument("--workers", type=int, default=None,
                   help="with replicas: LocalCluster worker processes (default: the cores)")
    a.add_argument("--no-reports", action="store_true",
                   help="with replicas: stop each replica after its risk stage (no "
                        "report.html per replica; the merge needs only risk.json)")
    a.set_defaults(func=_cmd_assess)
    sm = sub.add_parser("stress-model", help="refit the stress model of demfem assess from a "
                        "designed grid of FEM two-cartridge collisions, with held-back error")
    sm.add_argument("--out", default="demfem_out/stress_model", help="output directory; "
                    "finished FEM runs there are reused")
    sm.add_argument("--layers", type=int, default=2, help="tet layers through the wall (2)")
    _add_modulus(sm, "Young's modulus of the glass, Pa (4.5e10)", type=float, default=45e9)
    sm.add_argument("--quick", action="store_true", help="a 2 x 2 grid instead of 4 x 3")
    sm.add_argument("--scheduler", default=None, help="Dask scheduler address, or 'serial'; "
                    "default: a LocalCluster")
    sm.add_argument("--workers", type=int, default=None, help="LocalCluster worker processes")
    sm.set_defaults(func=_cmd_stress_model)
    cl = sub.add_parser("cluster", help="FEM of the seven-cartridge cluster (Figs. 10-13): "
                        "forces, sigma1, maps, VTK")
    cl.add_argument("--case", default="max", metavar="max|avg|SCENE.toml",
                    help="load case: max (V2 0.18, V3 0.12 m/s), avg (0.05, 0.025) or a "
                         "cluster scene file (default max)")
    cl.add_argument("--from", dest="from_run", default=None, metavar="RUN",
                    help="take the load case from a DEM run: a demfem run or assess folder "
                         "(its table_run.npz) or the .npz itself; the cluster gets the "
                         "run's cartridge and glass (replaces --case)")
    cl.add_argument("--pick", default="max", choices=("max", "typical"),
                    help="with --from: the run's hardest double impact (max) or the median "
                         "one (typical)")
    cl.add_argument("--springs", action="store_true",
                    help="hold 4-7 by no-tension springs to ghost neighbours")
    cl.add_argument("--elements", default=None, choices=("tet", "shell"),
                    help="element type: tet (layers through the wall) or shell (mid-surface, contact on both faces)")
    cl.add_argument("--layers", type=int, default=None,
                    help="tet layers through the wall, 1-4 (2)")
    cl.add_argument("--duration", type=float, default=3e-3, help="simulated time, s (3e-3)")
    cl.add_argument("--snapshots", type=int, default=40,
                    help="snapshots (sigma1, VTK) at regular times (40)")
    cl.add_argument("--out", default="demfem_out/cluster", help="output directory "
                    "(demfem_out/cluster); a finished run there with the same settings is "
                    "reused, other settings are refused")
    cl.add_argument("--fresh", "--overwrite", dest="fresh", action="store_true",
                    help="replace the cluster run in --out")
    cl.set_defaults(func=_cmd_cluster)
    sf = sub.add_parser("strength-fit", help="Weibull parameters of your own glass from "
                        "strength tests (ASTM C1239 fit, C1683 scaling): writes a strength file")
    sf.add_argument("data", metavar="DATA.csv", help="one specimen per row: strength_Pa or "
                    "failure_stress_MPa, optional censored (0/1); see docs/strength.md")
    sf.add_argument("--test", default="none",
                    choices=("ring-on-ring", "side-compression", "burst", "none"),
                    help="the strength test, for its effective area (none: --effective-area)")
    for opt, what in (("--load-ring-diameter", "ring-on-ring: load ring diameter, m"),
                      ("--support-ring-diameter", "ring-on-ring: support ring diameter, m"),
                      ("--specimen-diameter", "ring-on-ring: disc diameter, m"),
                      ("--outer-diameter", "side-compression, burst: tube outer diameter, m"),
                      ("--wall-thickness", "side-compression, burst: tube wall, m"),
                      ("--length", "side-compression, burst: loaded tube length, m"),
                      ("--effective-area", "none: the test's effective area, m^2 "
                       "(default: the reference area)")):
        sf.add_argument(opt, type=float, default=None, help=what,
                        metavar="M2" if opt == "--effective-area" else "METRES")
    sf.add_argument("--poisson-ratio", type=float, default=0.2, help="ring-on-ring (0.2)")
    sf.add_argument("--closed-ends", action="store_true", help="burst: closed tube ends")
    sf.add_argument("--surface", default="outer", choices=("outer", "inner"),
                    help="the cartridge surface whose flaws the specimens failed from (outer)")
    sf.add_argument("--criterion", default="max_principal", choices=("max_principal", "pia"),
                    help="effective-area criterion (max_principal, as demfem assess)")
    sf.add_argument("--modulus", default="unbiased", choices=("unbiased", "ml"),
                    help="m used for the scaling and the strength file (unbiased)")
    sf.add_argument("--reference-area", type=float, default=1e-4,
                    help="A_0 of the strength file, m^2 (1e-4)")
    sf.add_argument("--confidence", type=float, default=0.90, help="of the bounds (0.90)")
    sf.add_argument("--time-to-failure", type=float, default=None,
                    help="typical duration of a test to failure, s (recorded, for slow "
                         "crack growth)")
    sf.add_argument("--simulations", type=int, default=20000,
                    help="Monte Carlo samples of the bounds and the unbiasing factor (20000)")
    sf.add_argument("--seed", type=int, default=1239, help="their seed (1239)")
    sf.add_argument("--out", default="strength.json", help="strength file (strength.json)")
    sf.add_argument("--merge", action="store_true",
                    help="keep the other surface's fit already in --out")
    sf.set_defaults(func=_cmd_strength_fit)
    return p


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Entry point of the ``demfem`` command; returns the exit code: 0 done, 1 a failed run
    (a numerical failure, a damaged file, an i/o error), 2 bad arguments or settings, 130
    interrupted. Errors are one line ``demfem: error: ...`` on standard error, never a
    traceback."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a bad argument (already reported)
        return int(exc.code or 0) if not isinstance(exc.code, str) else 2
    fresh_hint = (f" (to start afresh: demfem {args.command} ... --fresh)"
                  if args.command in ("run", "assess") else "")
    try:
        return int(args.func(args))
    except SimulationInterrupted as exc:
        print(f"demfem: interrupted: {exc}", file=sys.stderr)
        return 130
    except KeyboardInterrupt:
        print("demfem: interrupted", file=sys.stderr)
        return 130
    except CheckpointError as exc:
        hint = "" if "--fresh" in str(exc) else fresh_hint
        print(f"demfem: error: {exc}{hint}", file=sys.stderr)
        return 1
    except MemoryError:
        print("demfem: error: out of memory (a smaller scene, a shorter run or fewer "
              "snapshots needs less)", file=sys.stderr)
        return 1
    except SettingsMismatchError as exc:
        print(f"demfem: error: {exc}", file=sys.stderr)
        return 2
    except (InvalidParameterError, ValueError) as exc:
        print(f"demfem: error: {exc}", file=sys.stderr)
        return 2
    except (DemfemError, OSError) as exc:
        print(f"demfem: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
