"""The single-call table of ``legkin bench`` (issue 16): one row per public analytic function.

Each bench module ``legkin.<model>.bench`` defines ``single_calls() -> list[SingleCall]``: one entry per
public function of its analytic module, with its inputs bound, and the Pinocchio call it is compared with
(its yardstick). The table reports, from one run, each function's time per single call next to the
yardstick's time per call on the same model, and their ratio.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

__all__ = ["SingleCall", "YARDSTICKS"]

#: Yardstick kinds: the Pinocchio call for the same quantity on the same model.
YARDSTICKS = {
    "fk": "forwardKinematics + updateFramePlacement (one frame)",
    "jacobian": "computeFrameJacobian (one frame, LOCAL_WORLD_ALIGNED)",
    "solve_loops": "Robot.solve_loops (closes every loop from the actuated joints)",
    "quadruped_fk": "forwardKinematics + updateFramePlacement on the 12-DOF quadruped",
}


@dataclass(frozen=True)
class SingleCall:
    """One public function, called once with bound inputs.

    Attributes:
        name: the function's public name, e.g. ``"foot_ik"``.
        call: makes one single call (inputs already bound, no argument).
        yardstick: key of :data:`YARDSTICKS`.
        iterative: the function iterates (tripod ``fk``, hybrid platform orientation, wheel-leg ``ik``):
            its target is >= 10x faster than the ``solve_loops``-based equivalent.
    """

    name: str
    call: Callable[[], object]
    yardstick: str
    iterative: bool = False
