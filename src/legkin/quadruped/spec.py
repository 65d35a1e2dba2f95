"""Registry entry of the 12-DOF quadruped (seeds 004 and 002)."""

from .._registry import ModelSpec, Param

LEGS = ("LF", "LH", "RF", "RH")

SPEC = ModelSpec(
    name="quadruped",
    title="12-DOF quadruped (POPI leg geometry), closed-form leg IK",
    seed="004 + 002",
    params={
        "foot_z": Param(0.0, "foot drop below the knee-foot axis (m)", -0.1, 0.1),
    },
    actuated_joints=tuple(f"{leg}_{j}" for leg in LEGS for j in ("HAA", "HFE", "KFE")),
    floating=True,
    yardstick_frame="LF_FOOT",  # the bench's Pinocchio yardstick calls (legkin.bench)
)
