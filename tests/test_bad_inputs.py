"""The bad-input catalogue: every entry must raise the legkin error it names (docs/robustness.md lists them).

``python scripts/robustness.py`` prints the table of docs/robustness.md from this catalogue, with the class
and the message each entry actually gets. A new mechanism adds its rows here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import legkin
from legkin.hybrid_leg import kinematics as hl
from legkin.quadruped import kinematics as aq
from legkin.tripod import kinematics as at
from legkin.wheel_leg import kinematics as wl

P_LF = aq.fk([0.1, 1.0, 1.0], "LF")
T_FL = wl.fk([1.0, 0.1, 0.0], "FL")
NAN = float("nan")

#: (mechanism, call as written, thunk, expected legkin error class)
CASES = [
    # ---- quadruped
    ("quadruped", "ik(zeros((2, 3)), 'LF', q_near=zeros((3, 3)))",
     lambda: aq.ik(np.zeros((2, 3)), "LF", q_near=np.zeros((3, 3))), legkin.InvalidInputError),
    ("quadruped", "within_limits('abc')", lambda: aq.within_limits("abc"), legkin.InvalidInputError),
    ("quadruped", "within_limits(q, tol=-1e-9)", lambda: aq.within_limits(np.zeros(3), tol=-1e-9),
     legkin.InvalidParameterError),
    ("quadruped", "Geometry(foot_z=nan)", lambda: aq.Geometry(foot_z=NAN), legkin.InvalidParameterError),
    ("quadruped", "Geometry(foot_z=5)", lambda: aq.Geometry(foot_z=5), legkin.InvalidParameterError),
    ("quadruped", "Geometry(foot_z='0.01')", lambda: aq.Geometry(foot_z="0.01"), legkin.InvalidParameterError),
    ("quadruped", "fk(q, 'LF', geometry=0.01)", lambda: aq.fk(np.zeros(3), "LF", geometry=0.01),
     legkin.InvalidParameterError),
    ("quadruped", "ik(p, 'LF', return_mask='yes')", lambda: aq.ik(P_LF, "LF", return_mask="yes"),
     legkin.InvalidParameterError),
    ("quadruped", "ik(p + 0j, 'LF')", lambda: aq.ik(P_LF + 0j, "LF"), legkin.InvalidInputError),
    ("quadruped", "ik([[0.1], [0.2, 0.3]], 'LF')", lambda: aq.ik([[0.1], [0.2, 0.3]], "LF"),
     legkin.InvalidInputError),
    ("quadruped", "ik(p, 'XX')", lambda: aq.ik(P_LF, "XX"), legkin.InvalidParameterError),
    ("quadruped", "ik(full(3, 1e300), 'LF')", lambda: aq.ik(np.full(3, 1e300), "LF"),
     legkin.UnreachableError),
    ("quadruped", "textbook_ik(p, Y12, 0, L2)", lambda: aq.textbook_ik(P_LF, aq.Y12, 0.0, 0.3),
     legkin.InvalidParameterError),
    # ---- tripod
    ("tripod", "Geometry(d=nan)", lambda: at.Geometry(d=NAN), legkin.InvalidParameterError),
    ("tripod", "Geometry(alpha='pi')", lambda: at.Geometry(alpha="pi"), legkin.InvalidParameterError),
    ("tripod", "Geometry(eta=(0, nan, 1))", lambda: at.Geometry(eta=(0.0, NAN, 1.0)), legkin.InvalidParameterError),
    ("tripod", "ik(u, geometry={'d': 0.05})", lambda: at.ik(np.array([0.2, -0.1]), geometry={"d": 0.05}),
     legkin.InvalidParameterError),
    ("tripod", "ik(u, mode='-+')", lambda: at.ik(np.array([0.2, -0.1]), mode="-+"), legkin.InvalidParameterError),
    ("tripod", "fk(q, tol=nan)", lambda: at.fk(np.array([0.1, 0.2, 0.3]), tol=NAN), legkin.InvalidParameterError),
    ("tripod", "fk(q, max_iter=2.5)", lambda: at.fk(np.array([0.1, 0.2, 0.3]), max_iter=2.5),
     legkin.InvalidParameterError),
    ("tripod", "leg_transform(q, 'D')", lambda: at.leg_transform(np.zeros(4), "D"), legkin.InvalidParameterError),
    ("tripod", "orientation_from_axis(zeros(3))", lambda: at.orientation_from_axis(np.zeros(3)),
     legkin.InvalidInputError),
    ("tripod", "ik((0, pi))  (the flip)", lambda: at.ik(np.array([0.0, math.pi])), legkin.SingularityError),
    ("tripod", "ik((0.2 + 1j, 0))", lambda: at.ik(np.array([0.2 + 1j, 0.0])), legkin.InvalidInputError),
    ("tripod", "ik(u, return_mask='yes')", lambda: at.ik(np.array([0.2, -0.1]), return_mask="yes"),
     legkin.InvalidParameterError),
    # ---- wheel_leg
    ("wheel_leg", "IKOptions(tol=nan)", lambda: wl.IKOptions(tol=NAN), legkin.InvalidParameterError),
    ("wheel_leg", "IKOptions(max_iter=0)", lambda: wl.IKOptions(max_iter=0), legkin.InvalidParameterError),
    ("wheel_leg", "ik(t, 'FL', options={'tol': 1e-9})", lambda: wl.ik(T_FL, "FL", options={"tol": 1e-9}),
     legkin.InvalidParameterError),
    ("wheel_leg", "ik(t, 'FL', method=array(['radial']))",
     lambda: wl.ik(T_FL, "FL", method=np.array(["radial"])), legkin.InvalidParameterError),
    ("wheel_leg", "ik(t, 'FL', q_start=q)  (radial takes q_near)",
     lambda: wl.ik(T_FL, "FL", q_start=[1.0, 0.1, 0.0]), legkin.InvalidParameterError),
    ("wheel_leg", "fk(q, 'FL', radius=nan)",
     lambda: wl.fk([1.0, 0.1, 0.0], "FL", radius=NAN), legkin.InvalidParameterError),
    ("wheel_leg", "fk(q, 'FL', rim='five_arcs')",
     lambda: wl.fk([1.0, 0.1, 0.0], "FL", rim="five_arcs"), legkin.InvalidParameterError),
    ("wheel_leg", "Geometry(R=-0.1)", lambda: wl.Geometry(R=-0.1), legkin.InvalidParameterError),
    ("wheel_leg", "ik(t, 'FL', geometry={'R': 0.1})", lambda: wl.ik(T_FL, "FL", geometry={"R": 0.1}),
     legkin.InvalidParameterError),
    ("wheel_leg", "ik(zeros((3, 3)), 'FL', q_near=zeros((2, 3)))",
     lambda: wl.ik(np.zeros((3, 3)), "FL", q_near=np.zeros((2, 3))), legkin.InvalidInputError),
    ("wheel_leg", "ik([1+1j, 0.2, -0.2], 'FL')", lambda: wl.ik([1 + 1j, 0.2, -0.2], "FL"),
     legkin.InvalidInputError),
    ("wheel_leg", "ik(t, 'FL', w=0.05)  (w beyond T/2)", lambda: wl.ik(T_FL, "FL", w=0.05),
     legkin.InvalidInputError),
    ("wheel_leg", "fk([0.2, 0, 0], 'FL')  (theta below 17 deg)", lambda: wl.fk([0.2, 0.0, 0.0], "FL"),
     legkin.InvalidInputError),
    ("wheel_leg", "ik(t, 'FL') for a foot turned up (gamma ~ 162 deg)",
     lambda: wl.ik(wl.fk([0.39896854737191256, 2.6257815016632486, 2.829530947384123], "FL"), "FL"),
     legkin.JointLimitError),
    ("wheel_leg", "ik([0.3, 0.2, -0.6], 'FL')  (too far)", lambda: wl.ik([0.3, 0.2, -0.6], "FL"),
     legkin.UnreachableError),
    ("wheel_leg", "ik_all([0.3, 0.2, -0.6], 'FL')  (too far)", lambda: wl.ik_all([0.3, 0.2, -0.6], "FL"),
     legkin.UnreachableError),
    # ---- hybrid_leg
    ("hybrid_leg", "ik(p, ll_branch=array([1, -1]))",
     lambda: hl.ik(np.array([0.0, 0.0, -0.3]), ll_branch=np.array([1, -1])), legkin.InvalidParameterError),
    ("hybrid_leg", "ik([nan, 0, -0.3])", lambda: hl.ik([NAN, 0.0, -0.3]), legkin.InvalidInputError),
    ("hybrid_leg", "Geometry(starting_value=4)", lambda: hl.Geometry(starting_value=4.0), legkin.InvalidParameterError),
    ("hybrid_leg", "fk(q, geometry={'center': 'universal'})",
     lambda: hl.fk(np.zeros(3), geometry={"center": "universal"}), legkin.InvalidParameterError),
    ("hybrid_leg", "fk(q, geometry=Geometry(center='spherical'))",
     lambda: hl.fk(np.zeros(3), geometry=hl.Geometry(center="spherical")), legkin.InvalidParameterError),
    ("hybrid_leg", "ik(p, q_near=zeros(2))", lambda: hl.ik(np.array([0.4, 0.0, -0.2]), q_near=np.zeros(2)),
     legkin.InvalidInputError),
    # ---- framework
    ("framework", "load('nope')", lambda: legkin.load("nope"), legkin.UnknownModelError),
    ("framework", "load('tripod', alpha=nan)", lambda: legkin.load("tripod", alpha=NAN), legkin.InvalidParameterError),
    ("framework", "load('tripod').solve_loops(q0, fixed={'A_q1': nan})",
     lambda: legkin.load("tripod").solve_loops(legkin.load("tripod").q0, fixed={"A_q1": NAN}),
     legkin.InvalidInputError),
]


@pytest.mark.parametrize("mechanism, text, call, expected", CASES, ids=[f"{c[0]}: {c[1]}" for c in CASES])
def test_bad_input_gets_its_legkin_error(mechanism, text, call, expected):
    with pytest.raises(expected) as info:
        call()
    assert isinstance(info.value, legkin.LegkinError)
    if issubclass(expected, (legkin.InvalidInputError, legkin.InvalidParameterError)):
        assert isinstance(info.value, ValueError)
    assert str(info.value)  # a message, naming the value
