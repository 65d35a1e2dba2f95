"""Deprecated: the kinematics moved to one package per mechanism (``from legkin import quadruped``).

``legkin.analytic.<name>`` keeps working, with a DeprecationWarning, for one release.
"""
