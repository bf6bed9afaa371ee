"""Every test of the fixed-step engine runs once per backend (see ``every_backend`` in tests/conftest.py).

Only the frame policies have a compiled frame: a test of ``"bisect"`` or ``"swept"`` alone (its
``policy`` parameter, or the mark ``one_backend``) would run the same Python frames twice, so its numba
case is skipped.
"""

import pytest

from discsim.engines.fixed_step.engine import COMPILED_POLICIES


def pytest_configure(config):
    config.addinivalue_line("markers", "one_backend: a fixed-step test that no compiled frame runs (python only)")


@pytest.fixture(autouse=True)
def _each_backend(request, every_backend):
    if every_backend == "numba":
        params = getattr(getattr(request.node, "callspec", None), "params", {})
        if params.get("policy", "resolve") not in COMPILED_POLICIES or request.node.get_closest_marker("one_backend"):
            pytest.skip("no compiled frame runs this test: its python case covers it")
    return every_backend
