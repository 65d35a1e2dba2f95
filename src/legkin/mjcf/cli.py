"""``legkin mjcf``: the command-line entry points (:func:`add_export_command`, :func:`run_export`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import LegkinError
from ._base import DEFAULTS, unavailable_reason
from .floating import GROUND_DEFAULTS, to_ground_mjcf
from .ground import has_ground_model
from .mechanism import load_mujoco
from .render import render_png
from .writer import to_mjcf

if TYPE_CHECKING:  # pragma: no cover
    import argparse



# ------------------------------------------------------------------------------------------ command line
def add_export_command(subparsers: "argparse._SubParsersAction") -> "argparse.ArgumentParser":
    """Add ``legkin mjcf MODEL [-o FILE] [--floating] [--timestep S] [--png FILE]`` to ``legkin``'s parser."""
    p = subparsers.add_parser("mjcf", help="write a MuJoCo MJCF of a model, loops as equality constraints")
    p.add_argument("model")
    p.add_argument("-o", "--output", metavar="PATH", help="write the MJCF to PATH (default: stdout)")
    p.add_argument("--floating", action="store_true",
                   help="a free base standing on a floor, with contacts (models with a ground model: docs/mujoco.md; "
                        "the hybrid leg, a fixed mechanism: its base fixed, a floor under its foot)")
    p.add_argument(
        "--timestep", type=float, default=None,
        help=f"simulation step, s (default {DEFAULTS['timestep']:g}; {GROUND_DEFAULTS['timestep']:g} with --floating)",
    )
    p.add_argument("--png", metavar="PATH", help="also render q0 with MuJoCo to PATH (needs MUJOCO_GL=egl headless)")
    p.set_defaults(func=run_export)
    return p


def run_export(args: "argparse.Namespace") -> int:
    """Run ``legkin mjcf``: write the MJCF (compiled once by MuJoCo first, when it is installed); with
    ``--floating`` and a model that has a ground model, the ground export
    (:func:`~legkin.mjcf.floating.to_ground_mjcf`)."""
    from .._registry import get_spec
    from ..robot import load

    robot = load(args.model, floating=bool(args.floating) and get_spec(args.model).floating)
    step = {} if args.timestep is None else {"timestep": args.timestep}
    if args.floating and has_ground_model(robot):
        xml = to_ground_mjcf(robot, **step)  # contacts, a floor that collides, keyframes standing on it
    else:
        xml = to_mjcf(robot, **step)
    if unavailable_reason() is None:
        mech = load_mujoco(robot, xml=xml)  # MuJoCo accepts it, or a LegkinError says why
        if args.png:
            print(f"wrote {render_png(mech, args.png, robot.q0)}")
    elif args.png:
        raise LegkinError(unavailable_reason())
    if args.output:
        Path(args.output).write_text(xml)
        print(f"wrote {args.output}")
    else:
        print(xml, end="")
    return 0
