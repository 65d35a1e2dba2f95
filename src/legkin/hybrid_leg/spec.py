"""Registry entry of the hybrid leg: 2-RSS + centre platform, extension joint and foot (seed 003)."""

from .._registry import ModelSpec, Param

SPEC = ModelSpec(
    name="hybrid_leg",
    title="hybrid leg: 2-RSS platform (universal or spherical centre) + extension joint, closed-form IK",
    seed="003",
    params={
        "center": Param(
            "universal",
            "central joint LCS: 'universal' (physical 2-DOF platform, R_P = Rx Ry) or 'spherical' (as the seed)",
            choices=("universal", "spherical"),
        ),
        "starting_value": Param(
            0.0,
            "LL zero offset of eq 19, theta_LL = -theta0 * 0.07 / (2 pi 1.5) + starting_value (rad)",
            -3.141592653589793,
            3.141592653589793,
        ),
    },
    # LL is driven by the extension motor theta0 through eq 19 (see legkin.hybrid_leg.ll_angle).
    actuated_joints=("MCS1", "MCS2", "LL"),
    floating=False,
    reference_pose="neutral",
    yardstick_frame="FCS",  # the bench's Pinocchio yardstick calls (legkin.bench)
)
