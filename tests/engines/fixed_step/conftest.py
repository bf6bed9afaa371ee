"""Every test of the fixed-step engine runs once per backend (see ``every_backend`` in tests/conftest.py).

Every policy has a compiled frame. A test that runs no frame of the engine (the bisection kernel alone,
the mark ``one_backend``) would run the same Python code twice, so its numba case is skipped.
"""

import pytest

from discsim.engines.fixed_step.engine import COMPILED_POLICIES


def pytest_configure(config):
    config.addinivalue_line("markers", "one_backend: a fixed-step test that runs no frame (python only)")


@pytest.fixture(autouse=True)
def _each_backend(request, every_backend):
    if every_backend == "numba":
        params = getattr(getattr(request.node, "callspec", None), "params", {})
        if params.get("policy", "resolve") not in COMPILED_POLICIES or request.node.get_closest_marker("one_backend"):
            pytest.skip("no frame of the engine runs in this test: its python case covers it")
    return every_backend
