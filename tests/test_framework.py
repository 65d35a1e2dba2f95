"""Registry, generation, loading: generic over every registered model."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import legkin
from legkin import _generate
from legkin.__main__ import main
from legkin._registry import MODELS, get_spec

ROOT = Path(__file__).resolve().parents[1]
MODEL_NAMES = sorted(MODELS)


def test_list_models_matches_xacro_sources():
    sources = sorted(p.name[: -len(".urdf.xacro")] for p in (ROOT / "xacro").glob("*.urdf.xacro"))
    assert legkin.list_models() == sources


def test_unknown_model_lists_known_names():
    with pytest.raises(legkin.UnknownModelError) as info:
        legkin.load("no_such_robot")
    for name in MODEL_NAMES:
        assert name in str(info.value)
    assert isinstance(info.value, legkin.LegkinError)


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_registry_params_match_xacro_args(name):
    text = (ROOT / "xacro" / f"{name}.urdf.xacro").read_text()
    args = dict(re.findall(r'<xacro:arg\s+name="([^"]+)"\s+default="([^"]*)"', text))
    spec = get_spec(name)
    assert set(args) == set(spec.params)
    for key, param in spec.params.items():
        if isinstance(param.default, str):
            assert args[key] == param.default
        else:
            assert float(args[key]) == pytest.approx(param.default, abs=0, rel=1e-15)


def test_generate_check_passes_on_committed_urdf(capsys):
    assert main(["generate", "--check"]) == 0


def test_generate_is_deterministic():
    spec = get_spec(MODEL_NAMES[0])
    args = {k: p.default for k, p in spec.params.items()}
    assert _generate.render(spec, args) == _generate.render(spec, args)


def test_generate_check_detects_drift(tmp_path, monkeypatch, capsys):
    # A copy of the tree with one URDF altered: --check must fail and name the file, writing nothing.
    import shutil

    shutil.copytree(ROOT / "xacro", tmp_path / "xacro")
    shutil.copytree(ROOT / "urdf", tmp_path / "urdf")
    target = tmp_path / "urdf" / f"{MODEL_NAMES[0]}.urdf"
    target.write_text(target.read_text().replace("<robot", "<robot foo='bar'", 1))
    before = target.read_bytes()
    monkeypatch.setenv("LEGKIN_ROOT", str(tmp_path))
    assert main(["generate", "--check"]) == 1
    assert f"urdf/{MODEL_NAMES[0]}.urdf" in capsys.readouterr().err
    assert target.read_bytes() == before
    assert main(["generate"]) == 0
    assert main(["generate", "--check"]) == 0


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_unknown_param_refused_before_writing(name, tmp_path, monkeypatch):
    monkeypatch.setenv("LEGKIN_CACHE", str(tmp_path))
    with pytest.raises(legkin.InvalidParameterError) as info:
        legkin.load(name, no_such_param=1.0)
    assert "no_such_param" in str(info.value)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_out_of_range_params_refused_before_writing(name, tmp_path, monkeypatch):
    monkeypatch.setenv("LEGKIN_CACHE", str(tmp_path))
    for key, param in get_spec(name).params.items():
        bad = ["not-a-choice"] if param.choices else [v for v in (param.low, param.high) if v is not None]
        for value in bad:
            value = value - 1.0 if value == param.low and not param.choices else value
            value = value + 1.0 if not param.choices and value == param.high else value
            with pytest.raises(legkin.InvalidParameterError) as info:
                legkin.load(name, **{key: value})
            assert key in str(info.value)
        if not param.choices:
            with pytest.raises(legkin.InvalidParameterError):
                legkin.load(name, **{key: float("nan")})
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_load_builds_model_loops_and_poses(name):
    robot = legkin.load(name)
    assert robot.model.nq > 0 and robot.visual_model.ngeoms > 0
    assert len(robot.constraint_models) == len(robot.loops)
    assert set(robot.actuated_joints) <= set(robot.joint_names)
    assert robot.poses, "every model ships named poses in its SRDF"
    lo, hi = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    for pose, q in robot.poses.items():
        assert np.all(q >= lo - 1e-12) and np.all(q <= hi + 1e-12), pose
        res = robot.constraint_residual(q)
        assert res.size == 0 or np.linalg.norm(res) <= 1e-10, (pose, np.linalg.norm(res))
    root = ET.parse(robot.urdf_path).getroot()
    assert root.get("name") == name


@pytest.mark.parametrize("name", [n for n in MODEL_NAMES if get_spec(n).floating])
def test_floating_base_adds_free_flyer(name):
    fixed, floating = legkin.load(name), legkin.load(name, floating=True)
    assert floating.model.nq == fixed.model.nq + 7
    assert floating.model.nv == fixed.model.nv + 6
    assert floating.q0.shape == (floating.model.nq,)


def test_non_default_params_go_to_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("LEGKIN_CACHE", str(tmp_path))
    committed = (ROOT / "urdf" / "quadruped.urdf").read_bytes()
    robot = legkin.load("quadruped", foot_z=-0.015)
    assert tmp_path in robot.urdf_path.parents
    assert (ROOT / "urdf" / "quadruped.urdf").read_bytes() == committed
    f = robot.frame_placement(robot.q0, "LF_FOOT")
    base = legkin.load("quadruped")
    assert not np.allclose(f.translation, base.frame_placement(base.q0, "LF_FOOT").translation)


def test_robot_input_errors(quadruped):
    with pytest.raises(ValueError):
        quadruped.frame_placement(np.zeros(3), "LF_FOOT")
    with pytest.raises(ValueError):
        quadruped.frame_placement(np.full(quadruped.model.nq, np.nan), "LF_FOOT")
    with pytest.raises(legkin.LegkinError):
        quadruped.frame_placement(quadruped.q0, "NO_FRAME")
    with pytest.raises(legkin.LegkinError):
        quadruped.solve_loops(quadruped.q0, fixed={"NO_JOINT": 0.0})


def test_cli_list_and_errors(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for name in MODEL_NAMES:
        assert name in out
    assert main(["check", "no_such_robot"]) == 2
    assert "known models" in capsys.readouterr().err
    assert main(["view", "quadruped", "--pose", "no_such_pose", "--html", "/dev/null"]) == 2
    assert main(["view", "quadruped", "--q", "1", "2", "--html", "/dev/null"]) == 2
    with pytest.raises(SystemExit):
        main(["check", "--samples", "0"])


def test_check_json(tmp_path):
    import json

    out = tmp_path / "check.json"
    assert main(["check", "quadruped", "--samples", "50", "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["passed"] is True
    rows = doc["models"]["quadruped"]["checks"]
    assert rows and {"name", "samples", "max_error", "p99_error", "tolerance", "passed"} <= set(rows[0])


def test_readme_model_table_lists_every_model():
    text = (ROOT / "README.md").read_text()
    table = text[text.index("<!-- legkin:models -->") : text.index("<!-- /legkin:models -->")]
    for name in MODEL_NAMES:
        assert f"[`{name}`]" in table, f"README model table lacks {name}: run scripts/make_docs.py"
        assert (ROOT / "docs" / f"{name}.md").exists()


def test_readme_python_examples_run():
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "README.md", "exec"), namespace)  # noqa: S102 - the README's own examples
