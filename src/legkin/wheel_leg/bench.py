"""Wheel-leg rim-contact IK: legkin's ``ik`` (analytic Jacobian; radial) vs the seed's finite differences vs Pinocchio.

Targets: Pinocchio's contact point (the rim link's placement times the contact point's fixed local
coordinates, as in ``checks.wheel_leg``) for random (theta, beta, gamma) of leg FL, rim parameter alpha and
lateral coordinate w. Every answer is scored the same way: the Pinocchio configuration closing all loops for
the returned (theta, beta, gamma) (or Pinocchio's own configuration), its contact point against the target,
its loop residual, and theta inside [17, 160] deg.
"""

from __future__ import annotations

import numpy as np

from .._benchkit import SOLVE_TOL, Method, MethodResult, ModelBench, Score, levenberg_marquardt_rows, sizes
from .._single_call import SingleCall
from ..errors import UnreachableError
from ..robot import load
from . import kinematics as wl
from .configuration import SEGMENT_LINKS, configuration, ik_start, leg_joint_names, local_contact_point, sample_leg_q

LEG = "FL"
#: Every iterative method is asked for the same position tolerance (m) (wl.ik's default).
TOL = 1e-12
MAX_ITER = 100
OPTIONS = wl.IKOptions(tol=TOL)


def _sizes(n: int | None, quick: bool) -> tuple[int, int, int]:
    """(batch targets, scalar-loop targets, iterative-solver targets)."""
    return sizes(n, quick, full=(5_000, 300, 100), small=(300, 20, 5))


#: The single-call inputs: q = (theta, beta, gamma) of leg FL, rim parameter alpha, lateral coordinate w.
SINGLE_Q = np.array([1.2, 0.3, 0.2])
SINGLE_ALPHA, SINGLE_W = 0.5, 0.01


def single_calls() -> list[SingleCall]:
    """One single call per public function of :mod:`legkin.wheel_leg`, inputs bound (leg FL,
    :data:`SINGLE_Q`, :data:`SINGLE_ALPHA`, :data:`SINGLE_W`; the IK target is that configuration's contact point).

    Yardsticks: Pinocchio ``forwardKinematics`` + ``updateFramePlacement`` on the quadruped (``quadruped_fk``)
    for the closed forms; ``Robot.solve_loops`` on the wheel-leg (``solve_loops``, ``iterative=True``) for
    ``ik`` (every method) and the stance IK (root finding, its target the ground contact of :data:`SINGLE_Q`).
    """
    q = SINGLE_Q.copy()
    theta, beta, gamma = (float(v) for v in q)
    alpha, w = SINGLE_ALPHA, SINGLE_W
    phi_L, phi_R = (float(v) for v in wl.motor_angles(theta, beta))
    target = wl.fk(q, LEG, alpha=alpha, w=w)
    p_L = wl.rim_point(theta, beta, alpha, w)
    ground = wl.ground_contact(q, LEG).point
    cf, it = "quadruped_fk", "solve_loops"
    return [
        SingleCall("linkage_constants", lambda: wl.linkage_constants(), cf),
        SingleCall("linkage_points", lambda: wl.linkage_points(theta, beta), cf),
        SingleCall("passive_angles", lambda: wl.passive_angles(theta, beta), cf),
        SingleCall("motor_angles", lambda: wl.motor_angles(theta, beta), cf),
        SingleCall("theta_beta", lambda: wl.theta_beta(phi_L, phi_R), cf),
        SingleCall("rim_point", lambda: wl.rim_point(theta, beta, alpha, w), cf),
        SingleCall("rim_point_seed", lambda: wl.rim_point_seed(theta, beta, alpha, w), cf),
        SingleCall("rim_jump_seed", lambda: wl.rim_jump_seed(theta), cf),
        SingleCall("rim_segment", lambda: wl.rim_segment(alpha), cf),
        SingleCall("fk", lambda: wl.fk(q, LEG, alpha=alpha, w=w), cf),
        SingleCall("jacobian", lambda: wl.jacobian(q, LEG, alpha=alpha, w=w), cf),
        SingleCall("leg_frame_to_robot", lambda: wl.leg_frame_to_robot(p_L, gamma, LEG), cf),
        SingleCall("module_origin", lambda: wl.module_origin(LEG), cf),
        SingleCall("ik", lambda: wl.ik(target, LEG, alpha=alpha, w=w), it, iterative=True),
        SingleCall("ik_all", lambda: wl.ik_all(target, LEG, alpha=alpha, w=w), it, iterative=True),
        SingleCall("ik (method='damped')", lambda: wl.ik(target, LEG, alpha=alpha, w=w, method="damped"), it,
                   iterative=True),
        SingleCall("ik (method='gauss_newton_fd')",
                   lambda: wl.ik(target, LEG, alpha=alpha, w=w, method="gauss_newton_fd"), it, iterative=True),
        SingleCall("tyre_point", lambda: wl.tyre_point(theta, beta, alpha / (2 * np.pi) + 0.5, w), cf),
        SingleCall("tyre_pieces", lambda: wl.tyre_pieces(theta, beta), cf),
        SingleCall("tyre_length", lambda: wl.tyre_length(theta), cf),
        SingleCall("ground_contact", lambda: wl.ground_contact(q, LEG), cf),
        SingleCall("stance_ik", lambda: wl.stance_ik(ground, LEG), it, iterative=True),
        SingleCall("stance_ik_all", lambda: wl.stance_ik_all(ground, LEG), it, iterative=True),
    ]


class _Setup:
    """The bench's model, targets' contact frames and scoring, shared by every method."""

    def __init__(self, rng: np.random.Generator, n_batch: int):
        self.robot = robot = load("wheel_leg")
        self.model, self.data = robot.model, robot.data
        self.geo = wl.Geometry.from_params(robot.params)
        self.k_leg = wl.LEGS.index(LEG)
        q_leg = sample_leg_q(n_batch, rng)
        alpha = rng.uniform(-np.pi, np.pi, n_batch)
        w = rng.uniform(-self.geo.T / 2, self.geo.T / 2, n_batch)
        self.local, seg = local_contact_point(alpha, w, self.geo)
        self.frame_ids = np.array([robot.frame_id(f"{LEG}_{SEGMENT_LINKS[s][0]}") for s in range(4)])[seg]
        self.i_theta = (robot.idx_q(f"{LEG}_phi_L"), robot.idx_q(f"{LEG}_phi_R"))
        targets, _ = self.contact_and_residual(self.full_config(q_leg), np.arange(n_batch))
        self.inputs = (targets, alpha, w)

    def full_config(self, leg_q: np.ndarray) -> np.ndarray:
        """Configurations closing every loop: leg FL at ``leg_q``, the other legs in wheel mode."""
        all_q = np.tile(np.array([wl.THETA0, 0.0, 0.0]), (len(leg_q), 4, 1))
        all_q[:, self.k_leg] = leg_q
        return configuration(self.robot, all_q)

    def contact_and_residual(self, qs: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pinocchio's contact point and loop residual of configurations ``qs`` (the targets' rows)."""
        import pinocchio as pin

        pos = np.full((len(qs), 3), np.nan)
        res = np.full(len(qs), np.nan)
        for i, q in zip(rows, qs):
            if np.all(np.isfinite(q)):
                pin.framesForwardKinematics(self.model, self.data, q)
                M = self.data.oMf[int(self.frame_ids[i])]
                pos[i] = M.translation + M.rotation @ self.local[i]
                res[i] = np.linalg.norm(self.robot.constraint_residual(q))
        return pos, res

    def score_configs(self, inp, qs, theta, iters, evals) -> Score:
        pos, res = self.contact_and_residual(qs, np.arange(len(inp[0])))
        err = np.linalg.norm(pos - inp[0], axis=-1)
        with np.errstate(invalid="ignore"):
            theta_ok = (theta >= wl.THETA_MIN - 1e-12) & (theta <= wl.THETA_MAX + 1e-12)
        ok = (err <= SOLVE_TOL) & (res <= SOLVE_TOL) & theta_ok
        return Score(error=err, solved=ok, orientation=res, iterations=iters, fk_evals=evals, reached=err <= SOLVE_TOL)

    # ---------------------------------------------------------------- legkin
    def analytic(self, method: str, scalar: bool = False):
        """(run, score) of ``wl.ik(method=method)``: one batch call, or single calls in a Python loop."""
        geo = self.geo

        def run(inp):
            t, a, ww = inp
            if not scalar:
                return wl.ik(t, LEG, alpha=a, w=ww, method=method, options=OPTIONS, geometry=geo,  # type: ignore[call-overload]
                             return_info=True)
            q, its = np.full((len(t), 3), np.nan), np.zeros(len(t), dtype=int)
            evals = np.full(len(t), np.nan)
            for i in range(len(t)):
                try:
                    q[i], info = wl.ik(t[i], LEG, alpha=a[i], w=ww[i], method=method, options=OPTIONS,  # type: ignore[call-overload]
                                       geometry=geo, return_info=True)
                    its[i], evals[i] = info.iterations, info.evaluations
                except UnreachableError:
                    pass
            return q, wl.IKInfo(its, np.full(len(t), np.nan), None, evals)

        def score(inp, out) -> Score:
            q, info = out
            k = len(q)
            evals = np.full(k, np.nanmean(info.evaluations))  # IKInfo.evaluations: linkage evaluations per target
            finite = np.all(np.isfinite(q), axis=-1)
            qs = np.full((k, self.model.nq), np.nan)
            if finite.any():
                qs[finite] = self.full_config(q[finite])
            return self.score_configs(inp, qs, q[:, 0], info.iterations.astype(float), evals)

        return run, score

    def answer_only(self):
        """(run, score) of a batch ``wl.ik`` (radial) without ``return_info``: the answer alone, which a batch of
        more than ``legkin._batch.CHUNK`` targets computes by chunks (its bytes per target: issue 25)."""
        geo = self.geo

        def run(inp):
            t, a, ww = inp
            return wl.ik(t, LEG, alpha=a, w=ww, options=OPTIONS, geometry=geo)

        def score(inp, q) -> Score:
            finite = np.all(np.isfinite(q), axis=-1)
            qs = np.full((len(q), self.model.nq), np.nan)
            if finite.any():
                qs[finite] = self.full_config(q[finite])
            return self.score_configs(inp, qs, q[:, 0], None, None)

        return run, score

    # ---------------------------------------------------------------- Pinocchio closed-loop IK
    def pin_ik(self, inp):
        """The Levenberg-Marquardt of Robot.solve_loops on [16 loop residuals; contact point - target], the 11
        joints of leg FL free, from the analytic IK's first start."""
        import pinocchio as pin

        model = self.model
        free = np.zeros(model.nv, dtype=bool)
        for j in leg_joint_names(LEG):
            free[self.robot.idx_v(j)] = True
        loopset = self.robot._loopset
        ldata = loopset.data
        t, a, ww = inp
        k = len(t)
        starts = ik_start(t, LEG, alpha=a, w=ww, geometry=self.geo)
        q_start = self.full_config(np.column_stack([np.clip(starts[:, 0], wl.THETA_MIN, wl.THETA_MAX), starts[:, 1:]]))

        def problems():
            for i in range(k):
                fid, loc, target = int(self.frame_ids[i]), self.local[i], t[i]

                def residual_and_jacobian(q, fid=fid, loc=loc, target=target):
                    r, jc = loopset.residual_and_jacobian(q)  # forwardKinematics + computeJointJacobians in ldata
                    pin.updateFramePlacement(model, ldata, fid)
                    M = ldata.oMf[fid]
                    rr = M.rotation @ loc
                    j6 = pin.getFrameJacobian(model, ldata, fid, pin.LOCAL_WORLD_ALIGNED)
                    jp = j6[:3] - np.cross(rr, j6[3:].T).T  # velocity of the contact point: v + w x r
                    return np.concatenate([r, M.translation + rr - target]), np.vstack([jc, jp])

                yield residual_and_jacobian, q_start[i]

        return levenberg_marquardt_rows(model, problems(), k, free, TOL, MAX_ITER)

    def pin_score(self, inp, out) -> Score:
        qs, iters, evals = out
        theta = (qs[:, self.i_theta[0]] - qs[:, self.i_theta[1]]) / 2 + wl.THETA0
        return self.score_configs(inp, qs, theta, iters, evals)


def _notes(n_batch: int, n_scalar: int, n_iter: int) -> list[str]:
    return [
        f"targets: Pinocchio contact point of leg {LEG} for {n_batch} random (theta in [17, 160] deg, "
        "beta in [-pi, pi], "
        f"|gamma| <= 0.6), alpha in [-pi, pi], |w| <= T/2; scalar loops solve the first {n_scalar}, Pinocchio the "
        f"first {n_iter}",
        "err = Pinocchio contact point of the answer vs target (m); loop |r| = Pinocchio loop residual; "
        "solved also needs theta in [17, 160] deg; iters = median; FK/solve = mean forward-kinematics "
        "evaluations per target (legkin: IKInfo.evaluations, rows passed to the contact FK; the damped "
        "method's FK also returns the Jacobian; radial: rows of its leg-plane closed form with theta-derivative "
        "(Newton steps) plus the final contact FK that checks the answer, its 17-node grid and start table "
        "look-ups are not counted; Pinocchio: residual + Jacobian evaluations)",
        f"every method is given tolerance {TOL:g} m; the legkin methods are compiled per target; damped "
        "and gauss_newton_fd start from the same geometric guess, the damped method restarts failures from two more "
        "guesses and takes one polishing step; radial solves gamma and beta in closed form and theta by a "
        "bracketed 1-D Newton (no start needed, every root found, the first returned); the Pinocchio IK starts "
        "from the configuration of the damped/gauss_newton_fd first guess (configuration.ik_start)",
        "pinocchio closed-loop IK: the Levenberg-Marquardt of Robot.solve_loops on [16 loop residuals; contact "
        "point - target] with the 11 joints of the leg free, contact Jacobian from getFrameJacobian",
    ]


def _summary(results: list[MethodResult]) -> list[str]:
    d = next(r for r in results if "batch ik, analytic" in r.name)
    r = next(r for r in results if "batch ik, radial" in r.name)
    s = next(r for r in results if "forward differences" in r.name)
    d1 = next(r for r in results if "scalar ik (damped)" in r.name)
    r1 = next(r for r in results if "scalar ik (radial)" in r.name)
    s1 = next(r for r in results if "scalar calls" in r.name)
    p = next(r for r in results if "pinocchio" in r.name)

    def acc(x):
        if not np.isfinite(x.max_error):
            return f"{x.solved:.1f}% solved, some targets unsolved"
        return f"{x.solved:.1f}% solved, max error {x.max_error:.1e} m"

    return [
        "speed-up over the seed's finite-difference iteration (target >= 10x at equal or better accuracy): "
        f"damped (analytic Jacobian) {s.time_per_target_s / d.time_per_target_s:.2f}x batch, "
        f"{s1.time_per_target_s / d1.time_per_target_s:.2f}x scalar calls; radial "
        f"{s.time_per_target_s / r.time_per_target_s:.2f}x batch, "
        f"{s1.time_per_target_s / r1.time_per_target_s:.2f}x scalar calls",
        f"accuracy (batch): damped {acc(d)}; radial {acc(r)}; seed {acc(s)}",
        f"batch ik is {p.time_per_target_s / d.time_per_target_s:,.0f}x (damped) / "
        f"{p.time_per_target_s / r.time_per_target_s:,.0f}x (radial) and the scalar call "
        f"{p.time_per_target_s / d1.time_per_target_s:,.1f}x / {p.time_per_target_s / r1.time_per_target_s:,.1f}x "
        "faster than the Pinocchio closed-loop IK",
    ]


def build(n: int | None, rng: np.random.Generator, quick: bool) -> ModelBench:
    """The IK methods on the same Pinocchio-made targets of leg FL (see the module docstring)."""
    n_batch, n_scalar, n_iter = _sizes(n, quick)
    setup = _Setup(rng, n_batch)
    inputs = setup.inputs
    run_d, score_d = setup.analytic("damped")
    run_s, score_s = setup.analytic("gauss_newton_fd")
    run_r, score_r = setup.analytic("radial")
    run_a, score_a = setup.answer_only()
    run_d1, score_d1 = setup.analytic("damped", scalar=True)
    run_s1, score_s1 = setup.analytic("gauss_newton_fd", scalar=True)
    run_r1, score_r1 = setup.analytic("radial", scalar=True)
    methods = [
        Method(f"legkin batch ik, analytic Jacobian (method='damped'; {n_batch} at once)", inputs, run_d, score_d,
               repeats=5),
        Method(f"legkin batch ik, radial (method='radial'; {n_batch} at once)", inputs, run_r, score_r, repeats=5),
        Method(f"legkin batch ik, radial, answer only (no return_info; {n_batch} at once)", inputs, run_a, score_a,
               repeats=5),
        Method("seed Gauss-Newton, forward differences (method='gauss_newton_fd'; batch)", inputs, run_s, score_s,
               repeats=5),
        Method("legkin scalar ik (damped), Python loop", inputs, run_d1, score_d1, max_targets=n_scalar, repeats=3),
        Method("legkin scalar ik (radial), Python loop", inputs, run_r1, score_r1, max_targets=n_scalar, repeats=3),
        Method("seed forward-difference Gauss-Newton, scalar calls in a loop", inputs, run_s1, score_s1,
               max_targets=n_scalar, repeats=3),
        Method("pinocchio closed-loop IK (LM on loops + contact point)", inputs, setup.pin_ik, setup.pin_score,
               max_targets=n_iter, repeats=3),
    ]
    tolerance = f"contact error <= {SOLVE_TOL:g} m, loop |r| <= {SOLVE_TOL:g}, theta in [17, 160] deg"
    return ModelBench(methods=methods, units={"ik": "m"}, tolerance=tolerance, notes=_notes(n_batch, n_scalar, n_iter),
                      summary=_summary, secondary="loop |r|")
