"""Hand-derived analytic kinematics, one module per mechanism (numpy only, vectorised)."""
