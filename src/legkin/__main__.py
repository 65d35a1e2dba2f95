"""The ``legkin`` command line: list, generate, check, view, bench, study, sim, export, convert.

Every error ends the command with one line on stderr (``legkin: error: ...``) and a non-zero exit status:
1 when checks fail or files are stale, 2 for a bad command line or a legkin error, 3 for an unexpected
internal error (set ``LEGKIN_DEBUG=1`` to see its traceback), 130 when interrupted (Ctrl-C), 143 on SIGTERM,
129 on SIGHUP (128 + the signal's number, as a shell reports a process the signal killed; ``legkin check``'s
worker processes are killed first), and 141 when the reader of its output went away (a broken pipe, as in
``legkin check | head -1``: quietly, nothing on stderr).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

from . import errors
from ._signals import signals_raise

#: Unsolved IK targets ``legkin check`` classifies per model unless ``--classify-all``.
CLASSIFY_DEFAULT = 2000


class UsageError(Exception):
    """A bad command line (printed as one line, exit status 2)."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (argparse prints the usage first, on several lines)."""

    def error(self, message):  # noqa: D102 - argparse API
        raise UsageError(f"{self.prog}: error: {message} (see `{self.prog} --help`)")


# ------------------------------------------------------------------------------------------ argument types
def _int(text: str, low: int, what: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}") from None
    if value < low:
        raise argparse.ArgumentTypeError(f"must be {what}, got {value}")
    return value


def positive_int(text: str) -> int:
    return _int(text, 1, "a positive integer")


def nonnegative_int(text: str) -> int:
    return _int(text, 0, "an integer >= 0")


def finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def positive_float(text: str) -> float:
    value = finite_float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be a number > 0, got {text!r}")
    return value


def output_file(text: str) -> str:
    """A path a file can be written to: its directory exists, and the path is not a directory."""
    path = Path(text)
    parent = path.parent
    if text == "" or path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a directory, not a file name")
    if not parent.is_dir():
        why = "is not a directory" if parent.exists() else "does not exist"
        raise argparse.ArgumentTypeError(f"cannot write {text!r}: directory {str(parent)!r} {why}")
    if not os.access(parent, os.W_OK):
        raise argparse.ArgumentTypeError(f"cannot write {text!r}: directory {str(parent)!r} is not writable")
    return text


def output_dir(text: str) -> str:
    """A directory that exists or can be made (its first existing ancestor is a writable directory)."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} exists and is not a directory")
    ancestor = path
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise argparse.ArgumentTypeError(f"cannot create {text!r}: {str(ancestor)!r} is not a directory")
    if not os.access(ancestor, os.W_OK):
        raise argparse.ArgumentTypeError(f"cannot write into {text!r}: {str(ancestor)!r} is not writable")
    return text


def _check_models(names) -> list[str] | None:
    """The model names of the command line, every one checked before any work starts."""
    from ._registry import get_spec
    from .robot import _is_path

    for name in names:
        if _is_path(name):
            continue  # a robot file: read by legkin.load
        get_spec(name)  # UnknownModelError lists the known names
    return list(names) or None


def _show_progress(args) -> bool:
    """Progress bars go to stderr, only when it is a terminal and ``--quiet`` was not given."""
    return not getattr(args, "quiet", False) and sys.stderr.isatty()


# ------------------------------------------------------------------------------------------ commands
def _cmd_list(args) -> int:
    from ._registry import MODELS

    for name in sorted(MODELS):
        spec = MODELS[name]
        origin = f"seed {spec.seed}" if spec.generated else f"from {spec.source}"
        print(f"{name:<12} {origin:<24} {spec.title}")
    return 0


def _cmd_generate(args) -> int:
    from ._generate import check_all, generate_all

    models = _check_models(args.models)
    if args.check:
        stale = check_all(models)
        if stale:
            print("out of date (run `legkin generate`): " + ", ".join(stale), file=sys.stderr)
            return 1
        print("urdf/ matches xacro/")
        return 0
    for path in generate_all(models, out_dir=args.out):
        print(f"wrote {path}")
    return 0


def _cmd_check(args) -> int:
    import importlib.util

    from .validation import all_passed, format_table, run_checks, write_json

    models = _check_models(args.models)
    files = [m for m in models or [] if _is_file(m)]
    if files:
        if len(files) != len(models or []):
            raise UsageError("legkin check: error: give either model names or robot files, not both")
        return _check_files(files, args)
    if args.jobs is None:
        args.jobs = min(4, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)
    if args.plots and importlib.util.find_spec("matplotlib") is None:
        raise errors.LegkinError('--plots needs matplotlib: pip install -e ".[plots]"')
    if not getattr(args, "quiet", False):
        note = _first_run_note(models)
        if note:
            print(note, file=sys.stderr, flush=True)
    results = run_checks(
        models,
        samples=args.samples,
        seed=args.seed,
        ik_targets=args.ik_targets,
        classify=None if args.classify_all else CLASSIFY_DEFAULT,
        progress=_show_progress(args),
        jobs=args.jobs,
    )
    print(format_table(results))
    from .validation import mujoco_note

    if mujoco_note() is not None:
        print(mujoco_note())
    if args.json:
        write_json(results, args.json)
    if args.plots:
        from .figures import write_check_plots

        for path in write_check_plots(results, args.plots):
            print(f"wrote {path}")
    ok = all_passed(results)
    print("all checks passed" if ok else "SOME CHECKS FAILED")
    return 0 if ok else 1


def _is_file(name: str) -> bool:
    from .robot import _is_path

    return _is_path(name)


def _check_files(paths: list[str], args) -> int:
    """``legkin check PATH...``: the rows of :func:`legkin.loaders.checks.check_rows` per robot file."""
    import time

    import numpy as np

    from .loaders import load_file
    from .loaders.checks import check_rows
    from .validation import all_passed, format_table, write_json

    results = {}
    for path in paths:
        t0 = time.perf_counter()
        robot = load_file(path)
        results[path] = (check_rows(robot, args.samples, np.random.default_rng(args.seed)), time.perf_counter() - t0)
    print(format_table(results))
    if args.json:
        write_json(results, args.json)
    ok = all_passed(results)
    print("all checks passed" if ok else "SOME CHECKS FAILED")
    return 0 if ok else 1


def _first_run_note(models: list[str] | None) -> str | None:
    """The note of a first run after an install (most of the models' kernels, default all, not in numba's cache
    yet), or None."""
    from . import _kernels
    from ._registry import get_spec, list_models
    from .validation import _checks_module

    for name in models or list_models():
        _checks_module(get_spec(name))  # imports the model's kernels
    cached, total = _kernels.cache_status()
    if total == 0 or cached >= total / 2:
        return None
    return (f"legkin check: {total - cached} of {total} kernels are not in numba's cache yet (a first run after an "
            "install): numba compiles them once (1-2 minutes of CPU for all of legkin's, by machine); later runs load "
            "them from the cache")


def _cmd_view(args) -> int:
    import numpy as np

    from .robot import load
    from .viewer import show, write_html

    if args.animate and (args.q is not None or args.pose is not None):
        raise UsageError("legkin view: error: --animate plays a clip: it takes no --pose or --q")
    robot = load(args.model, floating=args.floating)
    missing = getattr(robot, "missing_meshes", [])
    if missing:
        print(f"legkin view: {len(missing)} mesh file(s) not found, left out of the view: {', '.join(missing)}",
              file=sys.stderr)
    if args.q is not None:
        if len(args.q) != robot.model.nq:
            raise errors.InvalidInputError(
                f"--q takes {robot.model.nq} values for {args.model!r} (joints {', '.join(robot.joint_names)}), "
                f"got {len(args.q)}"
            )
        q = np.array(args.q)
    elif args.pose is not None:
        if args.pose not in robot.poses:
            raise errors.LegkinError(
                f"model {args.model!r} has no pose {args.pose!r}; poses: {', '.join(sorted(robot.poses)) or 'none'}"
            )
        q = robot.poses[args.pose]
    else:
        q = robot.q0
    if args.animate:
        from .clips import frames
        from .viewer import write_animation_html

        qs = frames(robot, args.animate)
        if args.html:
            print(f"wrote {write_animation_html(robot, qs, args.html, ground=not args.no_ground)}")
            return 0
        return _stopped_by(show(robot, qs[0], animation=qs, ground=not args.no_ground, host=args.host))
    if args.html:
        print(f"wrote {write_html(robot, q, args.html, ground=not args.no_ground)}")
        return 0
    return _stopped_by(show(robot, q, ground=not args.no_ground, host=args.host))


def _stopped_by(signum: int) -> int:
    """The viewer stopped by signal ``signum`` (its server stopped): raised as :func:`main` reports a signal,
    which exits with 128 + ``signum`` (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP)."""
    import signal

    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated(signum)


def _cmd_export(args) -> int:
    from .mjcf.cli import run_export

    args.output = str(args.mjcf)
    return run_export(args)


def _cmd_convert(args) -> int:
    from .loaders.convert import convert

    print(f"wrote {convert(args.input, args.output, loops=args.loops)}")
    return 0


def _cmd_bench(args) -> int:
    from .bench import run_bench_cli

    args.models = _check_models(args.models) or []
    return run_bench_cli(args)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="legkin", description="Kinematic models of legged and parallel mechanisms.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("list", help="list the registered models")
    p.set_defaults(func=_cmd_list)

    p = sub.add_parser("generate", help="run xacro on xacro/*.urdf.xacro and write urdf/")
    p.add_argument("models", nargs="*", help="models (default: all)")
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 if urdf/ differs from xacro/")
    p.add_argument("--out", metavar="DIR", default=None,
                   help="write into DIR instead of the source tree's urdf/ (required for an installed legkin)")
    p.set_defaults(func=_cmd_generate)

    p = sub.add_parser("check", help="validate the analytic kinematics against Pinocchio")
    p.add_argument("models", nargs="*", help="models (default: all)")
    p.add_argument("--samples", type=positive_int, default=10_000, help="random samples per check (default 10000)")
    p.add_argument("--jobs", "-j", type=positive_int, default=None, metavar="N",
                   help="worker processes, one mechanism each (default: the CPUs available, at most 4)")
    p.add_argument("--random-seed", dest="seed", type=nonnegative_int, default=0, metavar="S",
                   help="seed of the random samples, an integer >= 0 (default 0)")
    p.add_argument(
        "--ik-targets", type=positive_int, default=None, metavar="N",
        help="random targets of each model's IK robustness row (default: --samples)",
    )
    p.add_argument(
        "--classify-all", action="store_true",
        help=f"classify every unsolved IK target by a single call (default: at most {CLASSIFY_DEFAULT} per model)",
    )
    p.add_argument("--json", metavar="PATH", type=output_file, help="also write the results as JSON")
    p.add_argument("--plots", metavar="DIR", type=output_dir, help="also write PNG figures (needs matplotlib)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=_cmd_check)

    p = sub.add_parser("view", help="show a model in meshcat")
    p.add_argument("model")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--pose", help="a named pose from the SRDF")
    g.add_argument("--q", type=finite_float, nargs="+", help="a configuration vector")
    p.add_argument("--animate", metavar="NAME", help="play an animation clip (the clips of legkin.<model>.clips)")
    p.add_argument("--floating", action="store_true",
                   help="a free-flyer base (walking robots): the standing poses put the feet on the ground z = 0")
    p.add_argument("--no-ground", action="store_true", help="no ground plane under a walking robot")
    p.add_argument("--html", metavar="PATH", type=output_file, help="write a static page and exit")
    p.add_argument("--host", default="127.0.0.1", metavar="ADDRESS",
                   help="serve the page on this address (default 127.0.0.1: this machine only; 0.0.0.0 opens it "
                        "to every network interface, where anyone who reaches the machine sees the scene)")
    p.set_defaults(func=_cmd_view)

    p = sub.add_parser("bench", help="time analytic kinematics against iterative solvers")
    p.add_argument("models", nargs="*", help="models (default: all)")
    p.add_argument("--n", type=positive_int, default=None, help="targets per method (default: per model)")
    p.add_argument("--json", metavar="PATH", type=output_file, help="also write the results as JSON")
    p.add_argument("--quick", action="store_true", help="small run for smoke tests (under a minute)")
    p.add_argument("--random-seed", dest="seed", type=nonnegative_int, default=0, metavar="S",
                   help="seed of the random samples, an integer >= 0 (default 0)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=_cmd_bench)

    from .mjcf.cli import add_export_command

    add_export_command(sub)  # legkin mjcf MODEL [-o FILE] [--floating] [--timestep S] [--png FILE]
    from .mjcf.sim_cli import add_sim_command

    add_sim_command(sub)  # legkin sim MODEL --scenario stand|roll|squat|press [--video PATH | --html PATH]
    from .study.cli import add_study_command

    add_study_command(sub, output_file, positive_int, nonnegative_int, _show_progress)  # legkin study (docs/study.md)
    p = sub.add_parser("export", help="export a model to another format: --mjcf PATH (MuJoCo, loops as equalities)")
    p.add_argument("model")
    p.add_argument("--mjcf", metavar="PATH", type=output_file, required=True, help="write a MuJoCo MJCF to PATH")
    p.add_argument("--floating", action="store_true", help="a free base (models that walk only)")
    p.add_argument("--timestep", type=positive_float, default=None,
                   help="simulation step, s (default 0.0002; 0.001 with --floating)")
    p.add_argument("--png", metavar="PATH", type=output_file, help="also render q0 with MuJoCo (MUJOCO_GL=egl)")
    p.set_defaults(func=_cmd_export)

    p = sub.add_parser("convert",
                       help="convert a robot file's loops: YAML sidecar, URDF <loop_closure>, MJCF equalities")
    p.add_argument("input", help="a URDF (+ robot.yaml), xacro or MJCF")
    p.add_argument("output", type=output_file, help="OUT.yaml (sidecar), OUT.urdf (<loop_closure>) or OUT.xml (MJCF)")
    p.add_argument("--loops", metavar="YAML", help="the input URDF's sidecar, if not robot.yaml beside it")
    p.set_defaults(func=_cmd_convert)
    return parser


def _fail(message: str, status: int) -> int:
    print(message.replace("\n", " "), file=sys.stderr)
    return status


#: The exit status after a broken pipe (128 + SIGPIPE, as a shell reports a process that SIGPIPE killed).
BROKEN_PIPE = 141


class Terminated(BaseException):
    """SIGTERM or SIGHUP, raised in the main thread so that clean-up runs (``legkin check`` kills its workers)."""

    def __init__(self, signum: int):
        super().__init__(f"signal {signum}")
        self.signum = signum


def _stop(argv: list[str] | None, status: int) -> int:
    """After a signal, the command line (``argv`` None: ``sys.argv``) exits at once with ``status``: the clean-up
    that matters has run (``legkin check``'s workers killed, ``legkin view``'s server stopped), and the interpreter's
    teardown took 0.4 s idle, 4 s on a loaded machine. A call of :func:`main` with ``argv`` returns ``status``."""
    if argv is not None:
        return status
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(status)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (never raises, except SystemExit from --help)."""
    parser = build_parser()
    try:
        with signals_raise(Terminated):
            args = parser.parse_args(argv)
            return args.func(args)
    except Terminated as exc:
        return _stop(argv, _fail("legkin: terminated", 128 + exc.signum))
    except UsageError as exc:
        return _fail(str(exc), 2)
    except errors.LegkinError as exc:
        return _fail(f"legkin: error: {exc}", 2)
    except KeyboardInterrupt as exc:  # Ctrl-C; or SIGTERM, SIGHUP in the viewer (legkin._signals.SignalInterrupt)
        signum = getattr(exc, "signum", 2)
        return _stop(argv, _fail("legkin: interrupted" if signum == 2 else "legkin: terminated", 128 + signum))
    except BrokenPipeError:  # e.g. `legkin list | head -1`: stop quietly
        try:
            sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - Python flushes stdout at exit
        except OSError:
            pass
        return BROKEN_PIPE
    except OSError as exc:
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        return _fail(f"legkin: error: {where}{exc.strerror or exc}", 2)
    except MemoryError:
        return _fail("legkin: error: out of memory (try a smaller --samples / --n)", 2)
    except Exception as exc:  # noqa: BLE001 - a defect; the user still gets one line, not a traceback
        if os.environ.get("LEGKIN_DEBUG"):
            raise
        return _fail(
            f"legkin: internal error (a bug, please report it): {type(exc).__name__}: {exc} "
            "(LEGKIN_DEBUG=1 shows the traceback)",
            3,
        )


if __name__ == "__main__":
    sys.exit(main())
