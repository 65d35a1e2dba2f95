"""Per-mechanism validation: each module's ``run(samples, rng)`` returns ``CheckResult`` rows."""
