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
from legkin._registry import get_spec

ROOT = Path(__file__).resolve().parents[1]
MODEL_NAMES = legkin.list_models("legkin")


def test_list_models_matches_xacro_sources():
    sources = sorted(p.name[: -len(".urdf.xacro")] for p in (ROOT / "xacro").glob("*.urdf.xacro"))
    assert legkin.list_models("legkin") == sources


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
    assert main(["check", "--samples", "0"]) == 2


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


# ------------------------------------------------------------------------------ bad inputs to Robot and load
NAN, INF = float("nan"), float("inf")


@pytest.fixture(scope="module")
def tripod():
    return legkin.load("tripod")


def test_solve_loops_nan_held_value_names_the_joint(tripod):
    # Issue 10: this reached numpy's SVD ("SVD did not converge", LinAlgError).
    with pytest.raises(legkin.InvalidInputError, match="A_q1") as info:
        tripod.solve_loops(tripod.q0, fixed={"A_q1": NAN})
    assert isinstance(info.value, ValueError) and "finite" in str(info.value)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"fixed": {"A_q1": INF}}, ["A_q1", "finite"]),
        ({"fixed": {"A_q1": 1j}}, ["A_q1", "real"]),
        ({"fixed": {"A_q1": "x"}}, ["A_q1", "numeric"]),
        ({"fixed": {"A_q1": [0.1, 0.2]}}, ["A_q1", "nq = 1"]),
        ({"fixed": {"NO_JOINT": 0.0}}, ["NO_JOINT", "A_q1, A_q2"]),
        ({"fixed": ["NO_JOINT"]}, ["NO_JOINT", "A_q1, A_q2"]),
        ({"fixed": {3: 0.0}}, ["string", "3"]),
        ({"fixed": "A_q1"}, ["string", "['A_q1']"]),
        ({"fixed": 5}, ["collection of joint names", "5"]),
        ({"tol": NAN}, ["tol", "(0, inf)", "nan"]),
        ({"tol": -1e-9}, ["tol", "(0, inf)"]),
        ({"tol": 0.0}, ["tol", "(0, inf)"]),
        ({"tol": INF}, ["tol", "(0, inf)", "inf"]),
        ({"tol": "1e-9"}, ["tol", "real number"]),
        ({"tol": 1e-9 + 0j}, ["tol", "real number"]),
        ({"max_iter": -1}, ["max_iter", ">= 0", "-1"]),
        ({"max_iter": 2.5}, ["max_iter", "integer", "2.5"]),
        ({"max_iter": True}, ["max_iter", "integer"]),
        ({"max_iter": NAN}, ["max_iter", "integer"]),
        ({"damping": 0.0}, ["damping", "(0, inf)"]),
        ({"damping": NAN}, ["damping", "(0, inf)"]),
        ({"return_info": "yes"}, ["return_info", "True or False"]),
    ],
)
def test_solve_loops_refuses_bad_keywords(tripod, kwargs, words):
    with pytest.raises(legkin.InvalidInputError) as info:
        tripod.solve_loops(tripod.q0, **kwargs)
    for word in words:
        assert word in str(info.value), (kwargs, str(info.value))


def _q_cases(robot):
    nq = robot.model.nq
    q_nan = robot.q0.copy()
    q_nan[5] = NAN
    return [
        (np.zeros(nq - 1), [f"({nq},)", f"({nq - 1},)"]),
        (np.zeros((2, nq)), [f"({nq},)", f"(2, {nq})"]),
        (robot.q0 + 0j, ["real", "complex"]),
        (q_nan, ["finite", "[5] = nan", repr(robot.joint_names[5])]),
        (np.where(np.arange(nq) == 0, INF, robot.q0), ["finite", "[0] = inf"]),
        ("abc", ["numeric"]),
        ([[0.0, 1.0], [2.0]], ["numeric"]),
        (None, ["numeric"]),
    ]


@pytest.mark.parametrize("case", range(8))
@pytest.mark.parametrize(
    "method",
    ["constraint_residual", "constraint_jacobian", "mobility", "solve_loops", "frame_placement", "frame_jacobian"],
)
def test_robot_methods_refuse_bad_q(tripod, method, case):
    q, words = _q_cases(tripod)[case]
    if method == "solve_loops" and q is None:
        pytest.skip("solve_loops(None) starts from q0")
    call = {
        "frame_placement": lambda: tripod.frame_placement(q, "A_ee"),
        "frame_jacobian": lambda: tripod.frame_jacobian(q, "A_ee"),
    }.get(method, lambda: getattr(tripod, method)(q))
    with pytest.raises(legkin.InvalidInputError) as info:
        call()
    for word in words:
        assert word in str(info.value), (method, str(info.value))


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"tol": NAN}, ["tol", "[0, 1)"]),
        ({"tol": -1.0}, ["tol", "[0, 1)"]),
        ({"tol": 1.0}, ["tol", "[0, 1)"]),
        ({"locked": ["NO_JOINT"]}, ["NO_JOINT"]),
        ({"locked": "A_q1"}, ["string"]),
    ],
)
def test_mobility_refuses_bad_keywords(tripod, kwargs, words):
    with pytest.raises(legkin.InvalidInputError) as info:
        tripod.mobility(tripod.q0, **kwargs)
    for word in words:
        assert word in str(info.value)


def test_robot_names_and_references_checked(tripod):
    with pytest.raises(legkin.InvalidInputError, match="did you mean A_ee"):
        tripod.frame_placement(tripod.q0, "A_ee_")
    with pytest.raises(legkin.InvalidInputError, match="string"):
        tripod.frame_placement(tripod.q0, 3)
    with pytest.raises(legkin.InvalidInputError, match="ReferenceFrame"):
        tripod.frame_jacobian(tripod.q0, "A_ee", reference=5)
    assert np.array_equal(
        tripod.frame_jacobian(tripod.q0, "A_ee", reference="WORLD"),
        tripod.frame_jacobian(tripod.q0, "A_ee", reference=pin_world()),
    )
    with pytest.raises(legkin.InvalidInputError, match="string"):
        tripod.joint_id(None)
    with pytest.raises(legkin.InvalidInputError, match="A_q1"):
        tripod.configuration({"A_q1": NAN})
    with pytest.raises(legkin.InvalidInputError, match="mapping"):
        tripod.configuration([0.1])
    with pytest.raises(legkin.InvalidInputError, match="base"):
        tripod.configuration({"A_q1": 0.1}, base=np.zeros(2))
    assert tripod.configuration({"A_q1": 0.25})[tripod.idx_q("A_q1")] == 0.25


def pin_world():
    import pinocchio as pin

    return pin.WORLD


def test_solve_loops_accepts_its_documented_forms(tripod):
    q, info = tripod.solve_loops(tripod.q0, fixed={"A_q1": np.float64(-0.4), "B_q1": np.array(-0.5)}, return_info=True)
    assert q[tripod.idx_q("A_q1")] == -0.4 and info.residual <= 1e-12
    tripod.solve_loops(q, fixed=("A_q1", "B_q1"), max_iter=np.int64(0))  # already closed: zero iterations
    tripod.solve_loops(fixed=None, damping=1e-3)


@pytest.mark.parametrize(
    "name, kwargs, words",
    [
        ("tripod", {"floating": "yes"}, ["floating", "True or False"]),
        ("tripod", {"d": True}, ["d=True", "(0, inf)"]),
        ("tripod", {"d": 0.05 + 0j}, ["d=", "not a number"]),
        ("tripod", {"d": np.array([0.05])}, ["d=", "not a number"]),
        ("tripod", {"d": NAN}, ["d=nan", "(0, inf)"]),
        ("hybrid_leg", {"center": np.array([1, 2])}, ["center", "'universal'"]),
        ("hybrid_leg", {"center": 1}, ["center", "'universal'"]),
    ],
)
def test_load_refuses_bad_kinds(name, kwargs, words, tmp_path, monkeypatch):
    monkeypatch.setenv("LEGKIN_CACHE", str(tmp_path))
    with pytest.raises(legkin.InvalidParameterError) as info:
        legkin.load(name, **kwargs)
    for word in words:
        assert word in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_no_foreign_exception_from_robot_methods(tripod):
    """Random junk into every Robot method: only legkin errors (or a result) may come out."""
    junk = [NAN, INF, -1, 0, 1e308, 2.5, True, None, "x", 1j, [], [1, 2], {"A_q1": NAN}, np.zeros(3), object()]
    q = tripod.q0
    calls = []
    for x in junk:
        calls += [
            lambda x=x: tripod.solve_loops(x),
            lambda x=x: tripod.solve_loops(q, fixed=x),
            lambda x=x: tripod.solve_loops(q, tol=x),
            lambda x=x: tripod.solve_loops(q, max_iter=x),
            lambda x=x: tripod.solve_loops(q, damping=x),
            lambda x=x: tripod.solve_loops(q, fixed={"A_q1": x}),
            lambda x=x: tripod.mobility(q, locked=x),
            lambda x=x: tripod.mobility(q, tol=x),
            lambda x=x: tripod.mobility(x),
            lambda x=x: tripod.constraint_residual(x),
            lambda x=x: tripod.frame_placement(q, x),
            lambda x=x: tripod.frame_jacobian(q, "A_ee", x),
            lambda x=x: tripod.configuration(x),
            lambda x=x: tripod.configuration({"A_q1": x}),
            lambda x=x: tripod.joint_id(x),
            lambda x=x: tripod.idx_q(x),
            lambda x=x: legkin.load(x),
            lambda x=x: legkin.load("tripod", floating=x),
        ]
    for call in calls:
        try:
            call()
        except legkin.LegkinError:
            pass


# ---------------------------------------------------------------------- external robots (legkin.legs)
def test_the_nine_example_robot_data_quadrupeds_are_registered_and_load():
    from legkin.legs import ERD_ALL, ERD_ROBOTS

    assert legkin.list_models("example-robot-data") == sorted(ERD_ALL)  # with the bipeds (tests/test_legs6.py)
    assert len(ERD_ROBOTS) == 9
    assert set(legkin.list_models()) == set(ERD_ALL) | set(legkin.list_models("legkin"))
    with pytest.raises(legkin.InvalidParameterError, match="source"):
        legkin.list_models("ros")
    for name in ERD_ROBOTS:
        robot = legkin.load(name)
        assert robot.model.nq == 12 and len(robot.actuated_joints) == 12, name
        assert "site-packages" in str(robot.urdf_path) or "dist-packages" in str(robot.urdf_path), robot.urdf_path
        legs = robot.geometry  # the legs measured from the model
        assert len(legs) == 4, (name, list(legs))
        floating = legkin.load(name, floating=True)
        assert floating.model.nq == 19 and floating.q0.shape == (19,)


def test_generate_refuses_an_external_robot():
    from legkin._generate import check_all

    with pytest.raises(legkin.LegkinError, match="example-robot-data"):
        check_all(["go2"])
