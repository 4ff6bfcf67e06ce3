"""Shared fixtures: the paper's system (eq. 24) and its excitation."""

from __future__ import annotations

import pytest

from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem

#: Excitation amplitude q of the paper's example [N].
PAPER_AMPLITUDE = 10.0
#: Clearance of the paper's example [m].
PAPER_CLEARANCE = 3e-3


@pytest.fixture
def system() -> TwoDofSystem:
    """The paper's numerical example, eq. 24."""
    return PAPER_SYSTEM
