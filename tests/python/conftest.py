"""Fixtures shared by the module's tests."""
import pytest

import scoleid


@pytest.fixture(scope="session")
def beam_record():
    """The Simbody truth of paper-beam-1 (about a minute): simulated once, read by every test that
    needs it. A test that changes a record changes a copy."""
    return scoleid.truth("paper-beam-1")
