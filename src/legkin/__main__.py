"""The ``legkin`` command line: list, generate, check, view."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from . import errors


def _cmd_list(args) -> int:
    from ._registry import MODELS

    for name in sorted(MODELS):
        spec = MODELS[name]
        print(f"{name:<12} seed {spec.seed:<10} {spec.title}")
    return 0


def _cmd_generate(args) -> int:
    from ._generate import check_all, generate_all

    if args.check:
        stale = check_all(args.models or None)
        if stale:
            print("out of date (run `legkin generate`): " + ", ".join(stale), file=sys.stderr)
            return 1
        print("urdf/ matches xacro/")
        return 0
    for path in generate_all(args.models or None):
        print(f"wrote {path}")
    return 0


def _cmd_check(args) -> int:
    from .validation import all_passed, format_table, run_checks, write_json

    results = run_checks(args.models or None, samples=args.samples, seed=args.seed)
    print(format_table(results))
    if args.json:
        write_json(results, args.json)
    if args.plots:
        from .plots import write_check_plots

        for path in write_check_plots(results, args.plots):
            print(f"wrote {path}")
    ok = all_passed(results)
    print("all checks passed" if ok else "SOME CHECKS FAILED")
    return 0 if ok else 1


def _cmd_view(args) -> int:
    from . import load
    from .viewer import show, write_html

    robot = load(args.model)
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
        from .animations import frames
        from .viewer import write_animation_html

        qs = frames(robot, args.animate)
        if args.html:
            print(f"wrote {write_animation_html(robot, qs, args.html)}")
            return 0
        show(robot, qs[0], animation=qs)
        return 0
    if args.html:
        print(f"wrote {write_html(robot, q, args.html)}")
        return 0
    show(robot, q)
    return 0


def _cmd_bench(args) -> int:
    from .bench import run_bench_cli

    return run_bench_cli(args)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="legkin", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("list", help="list the registered models")
    p.set_defaults(func=_cmd_list)

    p = sub.add_parser("generate", help="run xacro on xacro/*.urdf.xacro and write urdf/")
    p.add_argument("models", nargs="*", help="models (default: all)")
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 if urdf/ differs from xacro/")
    p.set_defaults(func=_cmd_generate)

    p = sub.add_parser("check", help="validate the analytic kinematics against Pinocchio")
    p.add_argument("models", nargs="*", help="models (default: all)")
    p.add_argument("--samples", type=int, default=10_000, help="random samples per check (default 10000)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    p.add_argument("--plots", metavar="DIR", help="also write PNG figures (needs matplotlib)")
    p.set_defaults(func=_cmd_check)

    p = sub.add_parser("view", help="show a model in meshcat")
    p.add_argument("model")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--pose", help="a named pose from the SRDF")
    g.add_argument("--q", type=float, nargs="+", help="a configuration vector")
    p.add_argument("--animate", metavar="NAME", help="play an animation clip (see legkin.animations)")
    p.add_argument("--html", metavar="PATH", help="write a static page and exit")
    p.set_defaults(func=_cmd_view)
    p = sub.add_parser("bench", help="time analytic kinematics against iterative solvers")
    p.add_argument("models", nargs="*", help="models (default: all)")
    p.add_argument("--n", type=int, default=None, help="targets per method (default: per model)")
    p.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    p.add_argument("--quick", action="store_true", help="small run for smoke tests (under a minute)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.set_defaults(func=_cmd_bench)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "samples", 1) is not None and getattr(args, "samples", 1) < 1:
        parser.error(f"--samples must be a positive integer, got {args.samples}")
    try:
        return args.func(args)
    except errors.LegkinError as exc:
        print(f"legkin: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
