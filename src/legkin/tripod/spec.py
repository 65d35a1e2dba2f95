"""Registry entry of the parallel tripod: 2-DOF constant-velocity orientation mechanism (seed 000)."""

from .._registry import ModelSpec, Param

LEGS = ("A", "B", "C")

SPEC = ModelSpec(
    name="tripod",
    title="2-DOF parallel tripod (double-spherical CV wrist), 3 legs x 4 revolute, closed loops",
    seed="000",
    params={
        "d": Param(
            0.05, "distance |OD| = |DE| from the leg's middle joint point D to O and to E (m)", 0.0, None, low_open=True
        ),
        "alpha": Param(
            1.0471975511965976, "angle between the axes of joints 2 and 3 of each leg (rad)", 0.0, 3.141592653589793,
            low_open=True, high_open=True,
        ),
        "eta_A": Param(0.0, "placement angle of leg A about the x axis (rad)"),
        "eta_B": Param(2.0943951023931953, "placement angle of leg B about the x axis (rad)"),
        "eta_C": Param(4.1887902047863905, "placement angle of leg C about the x axis (rad)"),
    },
    actuated_joints=tuple(f"{leg}_q1" for leg in LEGS),
    floating=False,
    reference_pose="home",
    yardstick_frame="platform",  # the bench's Pinocchio yardstick calls (legkin.bench)
)
