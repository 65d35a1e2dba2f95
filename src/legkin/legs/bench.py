"""Foot IK on go2's FL leg (measured from example-robot-data): legkin's closed form vs Pinocchio CLIK and peers.

Targets: Pinocchio's ``FL_foot`` for FL joint values drawn uniformly inside the URDF limits (the base at its
neutral pose, the other legs at zero), so every target is reachable inside the limits. Every method's answer
is scored the same way: Pinocchio's foot at the returned joints against the target; solved = error
<= :data:`SOLVE_TOL` and the joints inside the URDF limits. Peers (ikpy, roboticstoolbox ``ik_LM``) are
optional: a row says why it is skipped when one is not installed or cannot be set up. Their URDF is go2's with
the visual/collision/gazebo elements removed (their loaders try to resolve the ``package://`` meshes).
"""

from __future__ import annotations

import os
import tempfile
import time
import warnings
import xml.etree.ElementTree as ET

import numpy as np

__all__ = ["bench_go2", "SOLVE_TOL", "CLIK_MAX_ITER", "CLIK_DAMPING", "PEER_TARGETS"]

#: A target is solved when the foot at the answer is within this distance (m) of it, inside the limits.
SOLVE_TOL = 1e-10
#: Pinocchio CLIK: iteration cap and damping (m^2) of the damped Newton steps.
CLIK_MAX_ITER = 100
CLIK_DAMPING = 1e-12
#: At most this many targets go to the iterative methods (CLIK gets 10x as many).
PEER_TARGETS = 200
LEG = "FL"


def _stripped_urdf(urdf) -> str:
    """A temporary copy of ``urdf`` without visual, collision and gazebo elements; returns its path."""
    tree = ET.parse(urdf)
    root = tree.getroot()
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
    for g in root.findall("gazebo"):
        root.remove(g)
    fd, path = tempfile.mkstemp(suffix=".urdf", prefix="legkin_go2_")
    os.close(fd)
    tree.write(path)
    return path


def _row(method: str, p: np.ndarray, q: np.ndarray, seconds: float, score, note: str = "") -> dict:
    err, inside = score(p, q)
    solved = inside & (err <= SOLVE_TOL)
    return {
        "method": method,
        "targets": int(len(p)),
        "solved": int(solved.sum()),
        "success_rate": float(solved.mean()) if len(p) else float("nan"),
        "us_per_target": 1e6 * seconds / max(len(p), 1),
        "max_error": float(np.max(np.where(solved, err, 0.0))) if solved.any() else float("nan"),
        "note": note,
    }


def _skip(method: str, reason: str) -> dict:
    return {"method": method, "targets": 0, "solved": 0, "success_rate": float("nan"),
            "us_per_target": float("nan"), "max_error": float("nan"), "note": f"skipped: {reason}"}


def bench_go2(n: int = 10_000, seed: int = 0) -> list[dict]:
    """Success rate and time per target of each IK method on ``n`` go2 FL foot targets.

    Rows: ``legkin Leg.ik`` as one batch and as single calls (all ``n`` targets), Pinocchio CLIK (damped Newton
    ``dq = J^T (J J^T + lambda I)^-1 e`` on the leg's three joints from the mid-limit configuration, clipped into
    the limits, <= :data:`CLIK_MAX_ITER` iterations; ``10 * PEER_TARGETS`` targets), ikpy and roboticstoolbox
    ``ik_LM`` (:data:`PEER_TARGETS` targets each) when importable.

    Returns:
        one dict per method: ``method, targets, solved, success_rate, us_per_target, max_error`` (m, over the
        solved targets), ``note``.
    """
    import pinocchio as pin

    from .erd import erd_files, load_erd
    from .extract import from_model

    model, urdf, _ = load_erd("go2")
    leg = from_model(model, LEG)
    data = model.createData()
    fid = model.getFrameId(leg.foot_frame)
    iq, iv = list(leg.idx_q), list(leg.idx_v)
    q0 = pin.neutral(model)
    rng = np.random.default_rng(seed)
    q_true = rng.uniform(leg.lower, leg.upper, (n, 3))

    def pin_foot(qleg: np.ndarray) -> np.ndarray:
        out = np.empty((len(qleg), 3))
        q = q0.copy()
        for k, row in enumerate(qleg):
            q[iq] = row
            pin.forwardKinematics(model, data, q)
            out[k] = pin.updateFramePlacement(model, data, fid).translation
        return out

    p = pin_foot(q_true)

    def score(pt: np.ndarray, q: np.ndarray):
        ok = np.isfinite(q).all(axis=-1)
        err = np.full(len(pt), np.inf)
        if ok.any():
            err[ok] = np.linalg.norm(pin_foot(q[ok]) - pt[ok], axis=-1)
        inside = ok & np.all((np.nan_to_num(q) >= leg.lower) & (np.nan_to_num(q) <= leg.upper), axis=-1)
        return err, inside

    rows = []
    # ---------------------------------------------------------------- legkin, batch and single calls
    leg.ik(p[:2])
    leg.ik(p[0])  # compiled / loaded from the cache before timing
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        q = leg.ik(p)
        best = min(best, time.perf_counter() - t0)
    rows.append(_row("legkin Leg.ik (batch)", p, q, best, score, "closed form, compiled prange loop"))
    q = np.full((n, 3), np.nan)
    t0 = time.perf_counter()
    for k in range(n):
        try:
            q[k] = leg.ik(p[k])
        except Exception:  # noqa: BLE001 - an unsolved target stays NaN
            pass
    rows.append(_row("legkin Leg.ik (single calls)", p, q, time.perf_counter() - t0, score))

    # ---------------------------------------------------------------- Pinocchio CLIK
    m = min(n, 10 * PEER_TARGETS)
    q = np.empty((m, 3))
    t0 = time.perf_counter()
    for k in range(m):
        qk = q0.copy()
        qk[iq] = leg.q_ref
        for _ in range(CLIK_MAX_ITER):
            pin.forwardKinematics(model, data, qk)
            e = p[k] - pin.updateFramePlacement(model, data, fid).translation
            if np.linalg.norm(e) <= 0.1 * SOLVE_TOL:
                break
            jac = pin.computeFrameJacobian(model, data, qk, fid, pin.LOCAL_WORLD_ALIGNED)[:3, iv]
            dq = jac.T @ np.linalg.solve(jac @ jac.T + CLIK_DAMPING * np.eye(3), e)
            qk[iq] = np.clip(qk[iq] + dq, leg.lower, leg.upper)
        q[k] = qk[iq]
    rows.append(_row("Pinocchio CLIK (damped Newton, 3 leg joints)", p[:m], q, time.perf_counter() - t0, score,
                     f"from mid-limit, damping {CLIK_DAMPING:g}, <= {CLIK_MAX_ITER} iterations, clipped into limits"))

    m = min(n, PEER_TARGETS)
    path = None
    try:
        path = _stripped_urdf(erd_files("go2")[0])
        # ---------------------------------------------------------------- ikpy
        try:
            import ikpy.chain

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                chain = ikpy.chain.Chain.from_urdf_file(path, base_elements=["base", leg.joint_names[0]])
                mask = [link.joint_type != "fixed" for link in chain.links]
                chain = ikpy.chain.Chain.from_urdf_file(path, base_elements=["base", leg.joint_names[0]],
                                                        active_links_mask=mask)
            active = np.flatnonzero(mask)
            init = np.zeros(len(chain.links))
            init[active] = leg.q_ref
            q = np.empty((m, 3))
            t0 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                for k in range(m):
                    q[k] = chain.inverse_kinematics(p[k], initial_position=init)[active]
            rows.append(_row("ikpy inverse_kinematics (position)", p[:m], q, time.perf_counter() - t0, score,
                             "from mid-limit, ikpy defaults"))
        except ImportError as exc:
            rows.append(_skip("ikpy inverse_kinematics (position)", f"not installed ({exc})"))
        except Exception as exc:  # noqa: BLE001 - a peer that cannot be set up is a skipped row
            rows.append(_skip("ikpy inverse_kinematics (position)", f"{type(exc).__name__}: {exc}"))
        # ---------------------------------------------------------------- roboticstoolbox
        try:
            import roboticstoolbox as rtb

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                rob = rtb.Robot.URDF(path)
            ets = rob.ets(start="base", end=leg.foot_frame)
            tol = 0.5 * (0.1 * SOLVE_TOL) ** 2  # ik_LM's tol bounds 1/2 |e|^2
            wmask = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
            tep = np.eye(4)
            q = np.empty((m, 3))
            t0 = time.perf_counter()
            for k in range(m):
                tep[:3, 3] = p[k]
                q[k] = ets.ik_LM(tep, q0=np.array(leg.q_ref), mask=wmask, tol=tol, joint_limits=True)[0]
            rows.append(_row("roboticstoolbox ik_LM (position mask)", p[:m], q, time.perf_counter() - t0, score,
                             "from mid-limit, joint_limits=True, defaults otherwise"))
        except ImportError as exc:
            rows.append(_skip("roboticstoolbox ik_LM (position mask)", f"not installed ({exc})"))
        except Exception as exc:  # noqa: BLE001
            rows.append(_skip("roboticstoolbox ik_LM (position mask)", f"{type(exc).__name__}: {exc}"))
    finally:
        if path is not None:
            os.unlink(path)
    return rows


def format_rows(rows: list[dict]) -> str:
    """A Markdown table of :func:`bench_go2`'s rows."""
    lines = ["| method | targets | solved | success | us / target | max error (m) | note |",
             "|---|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        lines.append(
            f"| {r['method']} | {r['targets']} | {r['solved']} | {r['success_rate']:.1%} | {r['us_per_target']:.3g} | "
            f"{r['max_error']:.2e} | {r['note']} |"
        )
    return "\n".join(lines)
