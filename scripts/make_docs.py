#!/usr/bin/env python3
"""Regenerate the README's pictures and tables: ``python scripts/make_docs.py [--skip-bench] [--only NAME ...]
[--samples N]``.

Writes ``docs/img/<model>.png`` (a meshcat page of each model rendered by headless Chromium),
``docs/img/plots/*.png`` (``legkin check --plots``), ``docs/check.json`` and ``docs/bench.json``, then
rewrites the README sections between ``<!-- legkin:NAME -->`` and ``<!-- /legkin:NAME -->`` markers
(NAME = models, pictures, check, bench; ``--only`` picks some) and, with the bench, the single-call tables of
``docs/bench.md`` (its ``single-calls`` markers). Needs the ``plots`` and ``bench`` extras and Chromium.
"""

from __future__ import annotations

import argparse
import json
import re
import tempfile
from pathlib import Path

import legkin
from legkin._registry import get_spec
from legkin.validation import run_checks, write_json
from legkin.viewer import screenshot, write_html

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
IMG = DOCS / "img"


def _replace_section(text: str, name: str, body: str) -> str:
    pattern = re.compile(rf"(<!-- legkin:{name} -->\n).*?(<!-- /legkin:{name} -->)", re.S)
    if not pattern.search(text):
        raise SystemExit(f"README.md lacks the <!-- legkin:{name} --> ... <!-- /legkin:{name} --> markers")
    return pattern.sub(lambda m: m.group(1) + body + m.group(2), text)


def model_table() -> str:
    lines = ["| name | DOF | loops | actuated joints | source seed |", "| --- | --- | --- | --- | --- |"]
    for name in legkin.list_models("legkin"):
        spec = get_spec(name)
        robot = legkin.load(name)
        mobility = robot.mobility(robot.q0)
        dof = f"{mobility} (tree nv = {robot.model.nv})" if robot.loops else str(mobility)
        if spec.floating:
            dof += ", +6 with `floating=True`"
        joints = ", ".join(f"`{j}`" for j in spec.actuated_joints)
        if len(spec.actuated_joints) > 6:
            joints = ", ".join(f"`{j}`" for j in spec.actuated_joints[:4]) + f", ... ({len(spec.actuated_joints)})"
        lines.append(f"| [`{name}`](docs/{name}.md) | {dof} | {len(robot.loops)} | {joints} | {spec.seed} |")
    return "\n".join(lines) + "\n"


def pictures() -> str:
    IMG.mkdir(parents=True, exist_ok=True)
    cells = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in legkin.list_models("legkin"):
            robot = legkin.load(name)
            page = write_html(robot, robot.q0, Path(tmp) / f"{name}.html")
            screenshot(page, IMG / f"{name}.png", size=(480, 360))
            cells.append(f'<img src="docs/img/{name}.png" width="240" alt="{name}"/>')
    names = " | ".join(f"`{n}`" for n in legkin.list_models("legkin"))
    return f"| {names} |\n|{' --- |' * len(cells)}\n| {' | '.join(cells)} |\n"


def check_tables(samples: int) -> str:
    from legkin.figures import write_check_plots

    results = run_checks(samples=samples)
    write_json(results, DOCS / "check.json")
    write_check_plots(results, IMG / "plots")
    out = []
    for name, (rows, seconds) in results.items():
        out.append(f"**{name}** ({rows[0].samples if rows else 0}+ samples per row, {seconds:.1f} s)\n")
        out.append("| check | samples | max error | p99 error | tolerance | result |")
        out.append("| --- | ---: | ---: | ---: | ---: | --- |")
        for r in rows:
            out.append(
                f"| {r.name} | {r.samples} | {r.max_error:.1e} | {r.p99_error:.1e} | {r.tolerance:.0e} | "
                f"{'pass' if r.passed else '**FAIL**'} |"
            )
        out.append("")
    return "\n".join(out)


def _num(x, fmt: str = ".1e", missing: str = "-") -> str:
    """A JSON number for a table cell; ``missing`` for null, ``fail`` for NaN/inf."""
    if x is None:
        return missing
    return format(x, fmt) if x == x and abs(x) != float("inf") else "fail"


def _machine(mach: dict) -> str:
    return (f"{mach.get('cpu', '?')} ({mach.get('cpu_count', '?')} cores, {mach.get('numba_threads', '?')} numba "
            f"threads, 1-min load {mach.get('load_average_1min', float('nan')):.2f})")


def single_call_tables(doc: dict) -> str:
    """docs/bench.md's single-call tables, from the bench run's JSON (``models.<name>.single_calls``)."""
    out = [
        f"`python scripts/make_docs.py --only bench` (it runs `legkin bench --json docs/bench.json`), one run on "
        f"{_machine(doc['machine'])}, legkin {doc['machine'].get('legkin', '?')}, numba "
        f"{doc['machine'].get('numba', '?')}. Ratio = function / yardstick, both timed the same way in the same run "
        "(< 1 is faster than Pinocchio). The peer tables are in the README.\n"
    ]
    for name, entry in doc["models"].items():
        single = entry.get("single_calls")
        if not single:
            continue
        out += [f"**{name}**\n", "| function | time per call | yardstick | yardstick per call | ratio |",
                "| --- | ---: | --- | ---: | ---: |"]
        for r in single["rows"]:
            out.append(f"| `{r['name']}` | {r['time_per_call_s'] * 1e6:.2f} us | {r['yardstick']} | "
                       f"{r['yardstick_time_per_call_s'] * 1e6:.2f} us | {_num(r['ratio'], '.2f')} |")
        out.append("")
        out += [f"* {key}: {y['label']}" for key, y in single.get("yardsticks", {}).items()]
        out.append("")
    return "\n".join(out)


def bench_tables() -> str:
    from legkin.__main__ import main

    path = DOCS / "bench.json"
    main(["bench", "--json", str(path)])
    doc = json.loads(path.read_text())
    bench_md = DOCS / "bench.md"
    bench_md.write_text(_replace_section(bench_md.read_text(), "single-calls", single_call_tables(doc)))
    mach = doc["machine"]
    out = [
        f"Measured in one run on {_machine(mach)}, Python {mach.get('python', '?')}, numpy "
        f"{mach.get('numpy', '?')}, pin {mach.get('pin', '?')}. Ratios are within a group of methods solving "
        "the same problem; 'fail' in an error column means some targets were not solved.\n"
    ]
    for name, entry in doc["models"].items():
        out += [f"**{name}**\n",
                "| method | targets | solved | median error | max error | time per target | ratio to fastest |",
                "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
        out += [f"| {m['name']} | {m['targets']} | {m['solved']:.1f}% | {_num(m['median_error'])} | "
                f"{_num(m['max_error'], missing='fail')} | {_num(m['time_per_target_s'], '.2e')} s | "
                f"{_num(m.get('ratio_to_fastest'), '.3g')}x |" for m in entry["methods"]]
        out.append("")
    return "\n".join(out)


SECTIONS = ("models", "pictures", "check", "bench")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--samples", type=int, default=10_000)
    parser.add_argument("--skip-bench", action="store_true")
    parser.add_argument("--only", nargs="+", choices=SECTIONS, help="regenerate only these sections")
    args = parser.parse_args()
    names = args.only or [name for name in SECTIONS if not (name == "bench" and args.skip_bench)]
    readme = ROOT / "README.md"
    text = readme.read_text()
    makers = {"models": model_table, "pictures": pictures, "check": lambda: check_tables(args.samples),
              "bench": bench_tables}
    for name in names:
        text = _replace_section(text, name, makers[name]())
    readme.write_text(text)
    print(f"README.md sections updated: {', '.join(names)}")


if __name__ == "__main__":
    main()
