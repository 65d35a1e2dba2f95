"""Shared fixtures."""

from __future__ import annotations

import numpy as np
import pytest

import legkin


@pytest.fixture(scope="session")
def quadruped():
    return legkin.load("quadruped")


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
