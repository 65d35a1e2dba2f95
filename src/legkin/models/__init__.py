"""Registry entries: one module per mechanism, each defining ``SPEC``."""
