import os
import sys

import matplotlib

matplotlib.use("Agg")
sys.path.insert(0, os.path.dirname(__file__))  # so tests can import the oracle module


import pytest

from discsim import _numba

#: The backends every engine test runs against (numba ones skip when numba is missing or hidden).
BACKENDS = ("python", "numba")

if _numba.available():
    # Import the compiled modules while numba is visible: a test that hides numba (every_backend's "python")
    # and runs the compiled loop's source interpreted (the laws) would otherwise import them first, as plain
    # functions, for the whole session.
    import discsim.engines.event_driven.numba.loop  # noqa: F401


@pytest.fixture(params=BACKENDS)
def every_backend(request, monkeypatch):
    """Run the test once per backend: ``backend="auto"`` (the default) then picks that backend.

    For ``"python"`` numba is hidden (as ``DISCSIM_NO_NUMBA=1`` does), so ``"auto"`` falls back to the
    pure-Python loop; ``"numba"`` is skipped when numba is not installed (the ``fast`` extra).
    """
    if request.param == "python":
        monkeypatch.setattr(_numba, "_module", None)
        monkeypatch.setattr(_numba, "_tried", True)
    elif not _numba.available():
        pytest.skip("numba is not installed or is hidden (the fast extra)")
    else:  # "auto" then runs even a short event-driven run compiled from its first event
        monkeypatch.setattr(_numba, "AUTO_PYTHON_EVENTS", 0)
    return request.param


@pytest.hookimpl(tryfirst=True)  # before -m deselects by the marks
def pytest_collection_modifyitems(items):
    """A test marked ``slow_on_python`` is slow in its pure-Python backend's case only: mark that case ``slow`` (under
    the laws both backends run one loop's source, the Python one interpreted, so its quick case is the compiled one)."""
    for item in items:
        callspec = getattr(item, "callspec", None)
        if item.get_closest_marker("slow_on_python") and callspec and callspec.params.get("every_backend") == "python":
            item.add_marker(pytest.mark.slow)
