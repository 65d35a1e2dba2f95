"""``legkin bench``: smoke runs through the CLI, the JSON schema, and the generic machinery (no timing assertions)."""

from __future__ import annotations

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
    assert set(doc["models"]) | set(doc["skipped"]) == set(legkin.list_models())
    for name in doc["models"]:
        _check_schema(doc, name)


def test_missing_peer_is_skipped_with_a_note(tmp_path, monkeypatch, capsys):
    import legkin.benches.quadruped as bq

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
