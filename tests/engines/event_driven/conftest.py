"""Every test of the event-driven engine runs once per backend (see ``every_backend`` in tests/conftest.py)."""

import pytest


@pytest.fixture(autouse=True)
def _each_backend(every_backend):
    return every_backend
