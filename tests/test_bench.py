"""``legkin bench``: smoke runs through the CLI, the JSON schema, and the generic machinery (no timing assertions)."""

from __future__ import annotations

import importlib
import json

import numpy as np
import pytest

import legkin
from legkin import bench
from legkin.__main__ import main

REQUIRED = {"name", "targets", "solved", "median_error", "max_error", "time_per_target_s"}


def _run(tmp_path, *args):
    out = tmp_path / "bench.json"
    code = main(["bench", "--quick", "--json", str(out), *args])
    return code, json.loads(out.read_text())


def _check_schema(doc, model):
    methods = doc["models"][model]["methods"]
    assert methods
    for m in methods:
        assert REQUIRED <= set(m), m
        assert m["targets"] >= 1
        assert 0.0 <= m["solved"] <= 100.0
        assert m["time_per_target_s"] > 0
    names = [m["name"] for m in methods]
    assert any("batch" in n for n in names), names
    assert any("pinocchio" in n.lower() for n in names), names
    return {m["name"]: m for m in methods}


def test_quick_quadruped_cli_and_json(tmp_path, capsys):
    code, doc = _run(tmp_path, "quadruped")
    assert code == 0
    text = capsys.readouterr().out
    assert "quadruped" in text and "time/target" in text
    machine = doc["machine"]
    for key in ("cpu", "python", "numpy", "pin"):
        assert machine[key], key
    import pinocchio

    assert machine["pin"] == pinocchio.__version__
    methods = _check_schema(doc, "quadruped")
    batch = next(m for n, m in methods.items() if "batch closed form" in n)
    # the closed form solves every reachable target to rounding error
    assert batch["solved"] == 100.0
    assert batch["max_error"] < 1e-12
    fk = next(m for n, m in methods.items() if "batch FK" in n)
    assert fk["max_error"] < 1e-12
    clik = [m for n, m in methods.items() if n.startswith("pinocchio CLIK")]
    assert len(clik) == 2
    # every iterative method solves a prefix of the same targets
    assert all(m["targets"] <= batch["targets"] for m in methods.values())
    # JSON is strict (no NaN/Infinity tokens)
    json.loads((tmp_path / "bench.json").read_text(), parse_constant=lambda c: pytest.fail(f"non-strict {c}"))


def test_quick_all_models_covers_the_registry(tmp_path):
    code, doc = _run(tmp_path)
    assert code == 0
    assert set(doc["models"]) | set(doc["skipped"]) == set(legkin.list_models("legkin"))
    for name in doc["models"]:
        _check_schema(doc, name)


def test_missing_peer_is_skipped_with_a_note(tmp_path, monkeypatch, capsys):
    import legkin.quadruped.bench as bq

    monkeypatch.setattr(bq, "missing", lambda dist, module=None: f"{dist} is not installed (test)")
    code, doc = _run(tmp_path, "quadruped")
    assert code == 0
    skipped = doc["models"]["quadruped"]["skipped_methods"]
    assert any("ikpy" in k for k in skipped) and any("TRAC-IK" in k for k in skipped)
    names = [m["name"] for m in doc["models"]["quadruped"]["methods"]]
    assert not any("ikpy" in n or "TRAC-IK" in n for n in names)
    assert "skipped: ikpy is not installed (test)" in capsys.readouterr().out


def test_model_without_bench_module_is_skipped(tmp_path, monkeypatch, capsys):
    assert bench._load_bench_module("no_such_model_xyz") is None
    real = bench._load_bench_module
    monkeypatch.setattr(bench, "_load_bench_module", lambda name: None if name == "quadruped" else real(name))
    code, doc = _run(tmp_path, "quadruped")
    assert code == 0
    assert doc["models"] == {}
    assert "quadruped" in doc["skipped"]
    assert "quadruped: skipped" in capsys.readouterr().out


def test_bad_arguments_exit_2(capsys):
    assert main(["bench", "no_such_model", "--quick"]) == 2
    assert "unknown model" in capsys.readouterr().err
    assert main(["bench", "quadruped", "--n", "0"]) == 2


def test_run_model_statistics_and_ratio():
    x = np.arange(10.0)

    def score(inputs, out):
        err = np.asarray(out, dtype=float)
        return bench.Score(error=err, solved=np.isfinite(err) & (err <= 1e-9), iterations=np.full(len(err), 3.0))

    slow_out = np.where(x < 5, 0.0, np.nan)  # half the targets give no answer

    def slow(inputs):
        s = 0.0
        for _ in range(20_000):
            s += 1.0
        return slow_out[: len(inputs)]

    mb = bench.ModelBench(
        methods=[
            bench.Method("fast batch", x, lambda i: np.zeros(len(i)), score, repeats=3),
            bench.Method("slow loop", x, slow, score, max_targets=8, repeats=2),
            bench.Method("absent peer", skip="not installed"),
        ],
        units={"ik": "m"},
        tolerance="error <= 1e-9",
    )
    rows = bench.run_model(mb)
    assert [r.name for r in rows] == ["fast batch", "slow loop"]
    fast, slow_row = rows
    assert fast.targets == 10 and slow_row.targets == 8
    assert fast.solved == 100.0 and slow_row.solved == pytest.approx(62.5)
    assert slow_row.max_error == float("inf")  # a target without an answer is a failure, not dropped
    assert min(r.ratio for r in rows) == 1.0 and all(r.ratio >= 1.0 for r in rows)
    assert fast.iterations_median == 3.0
    table = bench.format_table("toy", mb, rows)
    assert "absent peer" in table and "skipped: not installed" in table and "fail" in table


# ------------------------------------------------------------------------------------------- single calls
def _bench_modules():
    return {name: bench._load_bench_module(name) for name in legkin.list_models("legkin")}


def test_single_call_entries_run_and_name_known_yardsticks():
    from legkin._single_call import YARDSTICKS, SingleCall

    for name, module in _bench_modules().items():
        if module is None or not hasattr(module, "single_calls"):
            continue
        entries = module.single_calls()
        assert entries, name
        for e in entries:
            assert isinstance(e, SingleCall), (name, e)
            assert e.yardstick in YARDSTICKS, (name, e.name, e.yardstick)
            e.call()  # every entry's call runs


def test_single_call_table_covers_every_public_function():
    """Every public function of a mechanism (its kinematics module's ``__all__``) has a row in its bench's
    single-call table."""
    import inspect

    for name, module in _bench_modules().items():
        if module is None or not hasattr(module, "single_calls"):
            continue
        kin = importlib.import_module(f"legkin.{name}.kinematics")
        public = [n for n in kin.__all__ if inspect.isfunction(getattr(kin, n))]
        timed = {e.name.split(" ")[0] for e in module.single_calls()}
        assert [n for n in public if n not in timed] == [], name


def test_yardstick_calls_every_key_every_model():
    from legkin._single_call import YARDSTICKS

    for name in legkin.list_models("legkin"):
        calls = bench.yardstick_calls(name, list(YARDSTICKS))
        assert set(calls) == set(YARDSTICKS)
        for call, label in calls.values():
            call()
            assert label
    with pytest.raises(KeyError, match="unknown yardstick"):
        bench.yardstick_calls("quadruped", ["no_such_yardstick"])


def test_single_call_table_built_for_every_model_with_single_calls(monkeypatch):
    # no timing assertions: only that the table has one row per entry, with positive times
    monkeypatch.setattr(bench, "time_call", lambda call, repeats, min_time: (call(), 1e-6, 1)[1:])
    for name, module in _bench_modules().items():
        if module is None:
            continue
        table = bench.single_call_table(name, module, quick=True)
        if not hasattr(module, "single_calls"):
            assert table["rows"] == [] and table["skipped"] == "no single-call entries yet"
            assert "no single-call entries yet" in bench.format_single_table(name, table)
            continue
        entries = module.single_calls()
        assert [r.name for r in table["rows"]] == [e.name for e in entries]
        assert set(table["yardsticks"]) == {e.yardstick for e in entries}
        for r in table["rows"]:
            assert not r.error, (name, r.name, r.error)
            assert r.time_per_call_s > 0 and r.yardstick_time_s > 0
        assert name in bench.format_single_table(name, table)


def test_single_call_table_with_a_toy_module_and_json(tmp_path, monkeypatch):
    import types

    from legkin._single_call import SingleCall

    def boom():
        raise RuntimeError("broken entry")

    toy = types.SimpleNamespace(
        single_calls=lambda: [
            SingleCall("sum", lambda: sum(range(10)), "fk"),
            SingleCall("solver", lambda: sum(range(100)), "solve_loops", iterative=True),
            SingleCall("broken", boom, "jacobian"),
            SingleCall("unknown yardstick", lambda: None, "no_such_yardstick"),
        ]
    )
    table = bench.single_call_table("tripod", toy, quick=True)
    rows = {r.name: r for r in table["rows"]}
    assert set(rows) == {"sum", "solver", "broken", "unknown yardstick"}
    assert "unknown yardstick" in rows["unknown yardstick"].error
    assert rows["sum"].time_per_call_s > 0 and rows["sum"].number >= 1 and rows["sum"].repeats == 3
    assert np.isfinite(rows["solver"].ratio) and rows["solver"].iterative
    assert "broken entry" in rows["broken"].error and np.isnan(rows["broken"].time_per_call_s)
    assert set(table["yardsticks"]) == {"fk", "solve_loops", "jacobian"}
    text = bench.format_single_table("tripod", table)
    assert "failed: RuntimeError: broken entry" in text and "iterative" in text
    run = {"models": {}, "single": {"tripod": table}, "skipped": {}}
    run["models"]["tripod"] = (bench.ModelBench(methods=[]), [])
    doc = bench.to_json(run, machine={"cpu": "x"})
    rows_json = doc["models"]["tripod"]["single_calls"]["rows"]
    assert {"name", "yardstick", "time_per_call_s", "yardstick_time_per_call_s", "ratio"} <= set(rows_json[0])
    json.dumps(bench._finite(doc), allow_nan=False)


def test_time_call_counts_calls():
    calls = []
    per_call, number = bench.time_call(lambda: calls.append(1), repeats=3, min_time=1e-4)
    assert per_call > 0 and number >= 1
    assert len(calls) >= 1 + 3 * number  # the warm-up call, then 3 loops of `number`


def test_quick_cli_has_single_call_section_and_peer_rows(tmp_path, capsys):
    code, doc = _run(tmp_path, "quadruped")
    assert code == 0
    text = capsys.readouterr().out
    assert "single calls" in text
    single = doc["models"]["quadruped"]["single_calls"]
    assert "rows" in single and "yardsticks" in single
    from legkin import peers

    names = [m["name"] for m in doc["models"]["quadruped"]["methods"]]
    skipped = doc["models"]["quadruped"]["skipped_methods"]
    for peer_name, *_ in peers.PEERS:
        assert peer_name in names or peer_name in skipped, peer_name
