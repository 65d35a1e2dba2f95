"""``legkin study MODEL --param NAME=START:STOP:N ... --samples N [--scheduler ADDRESS|local[:K]] --out FILE
--plot PNG``: the command line of :func:`legkin.study.study`."""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
from typing import TYPE_CHECKING, Any, Callable, Iterator

from ..errors import LegkinError

if TYPE_CHECKING:
    import numpy as np

__all__ = ["add_study_command", "parse_param", "run_study_cli"]


def parse_param(text: str) -> tuple[str, np.ndarray]:
    """``NAME=START:STOP:N`` (N values, ends included) or ``NAME=V1,V2,...``.

    Args:
        text: the command-line word.

    Returns:
        (name, values).

    Raises:
        argparse.ArgumentTypeError: malformed.
    """
    import numpy as np

    name, sep, spec = text.partition("=")
    try:
        if not sep or not name:
            raise ValueError
        if ":" in spec:
            start, stop, n = spec.split(":")
            if int(n) < 1:
                raise ValueError
            return name, np.linspace(float(start), float(stop), int(n))
        return name, np.array([float(v) for v in spec.split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be NAME=START:STOP:N (N >= 1) or NAME=V1,V2,..., got {text!r}") from None


def _need(modules: tuple[str, ...], what: str) -> None:
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if missing:
        raise LegkinError(f'{what} needs {", ".join(missing)}: pip install -e ".[study]"')


@contextlib.contextmanager
def scheduler_client(spec: str | None) -> Iterator[Any]:
    """None (in-process), a LocalCluster (``local`` or ``local:K``: :func:`~legkin.study.cluster.local_cluster`, K
    worker processes of one core each) or a connection to a running scheduler (its address).

    Args:
        spec: the ``--scheduler`` value.

    Yields:
        A ``distributed.Client`` or None.
    """
    if spec is None:
        yield None
        return
    _need(("distributed",), "--scheduler")
    if spec == "local" or spec.startswith("local:"):
        k = spec.partition(":")[2] or "2"
        if not k.isdigit() or int(k) < 1:
            raise LegkinError(f"--scheduler local:K needs K >= 1 workers, got {spec!r}")
        from .cluster import local_cluster

        with local_cluster(int(k)) as client:
            yield client
        return
    from distributed import Client

    with Client(spec) as client:
        yield client


def run_study_cli(args: argparse.Namespace) -> int:
    """Run ``legkin study``: print the table, write ``--out`` (.parquet or .csv) and ``--plot``.

    Args:
        args: the parsed command line.

    Returns:
        The exit status (0).
    """
    _need(("pandas",) + (("pyarrow",) if args.out and not args.out.endswith(".csv") else ()), "legkin study")
    import pandas as pd

    from .plot import plot_study
    from .run import plan, study

    params = dict(args.param)
    metrics = tuple(args.metrics.split(",")) if args.metrics else None
    kw: dict[str, Any] = {"seed": args.seed, "chunk_blocks": args.chunk_blocks}
    if metrics:
        kw["metrics"] = metrics
    plan(args.model, params, args.samples, **kw)  # every parameter checked before a cluster starts
    with scheduler_client(args.scheduler) as client:
        frame = study(args.model, params, args.samples, client=client, progress=args.progress, **kw)
    with pd.option_context("display.width", 200, "display.max_columns", 40):
        print(frame.to_string(index=False, float_format=lambda v: f"{v:.6g}"))
    if args.out:
        if args.out.endswith(".csv"):
            frame.to_csv(args.out, index=False)
        else:
            frame.to_parquet(args.out)
        print(f"wrote {args.out}")
    if args.plot:
        _need(("matplotlib",), "--plot")
        title = f"{args.model}: {args.samples} samples a point, seed {args.seed}"
        print(f"wrote {plot_study(frame, list(params), args.plot, title)}")
    return 0


def add_study_command(sub: Any, output_file: Callable[[str], str], positive_int: Callable[[str], int],
                      nonnegative_int: Callable[[str], int], show_progress: Callable[[Any], bool]) -> None:
    """Add ``legkin study`` to the CLI's sub-parsers (the CLI's own argument types passed in).

    Args:
        sub: the sub-parsers. output_file, positive_int, nonnegative_int: the CLI's argument types.
        show_progress: ``show_progress(args)``, whether to draw a progress bar.
    """
    p = sub.add_parser("study", help="workspace, dexterity and singularity metrics over geometry parameters")
    p.add_argument("model", help="planar_2link, quadruped, tripod or wheel_leg")
    p.add_argument("--param", type=parse_param, action="append", required=True, metavar="NAME=START:STOP:N",
                   help="a swept parameter (repeat for a grid); NAME=V1,V2,... for a list")
    p.add_argument("--samples", type=positive_int, default=10**6, help="Monte-Carlo samples a point (default 1e6)")
    p.add_argument("--metrics", default=None,
                   help="comma-separated: reach,conditioning,singularity (default) and the model's own (tripod: "
                        "cv_error, wheel_leg: rim_contact)")
    p.add_argument("--seed", type=nonnegative_int, default=0, help="root seed (default 0)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS|local[:K]",
                   help="run on dask: a scheduler's address, or a LocalCluster of K processes (default 2)")
    p.add_argument("--chunk-blocks", type=positive_int, default=None, help="blocks of 65536 samples a dask task")
    p.add_argument("--out", type=output_file, default=None, help="write the table (.parquet, or .csv)")
    p.add_argument("--plot", type=output_file, default=None, help="write the picture (PNG)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar on stderr")

    def run(args: argparse.Namespace) -> int:
        args.progress = show_progress(args)
        return run_study_cli(args)

    p.set_defaults(func=run)


