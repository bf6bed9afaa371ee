"""Moving segments in the event-driven engine, attacked (issue 28 review). Every test runs on both backends (the
directory's conftest)."""

import pytest

import discsim as ds
from discsim.errors import JammedError


@pytest.mark.slow_on_python
@pytest.mark.xfail(
    strict=True,
    raises=AssertionError,
    reason="a paddle squeezing a disc against a wall: the disc bounces between them faster and faster while the "
    "clock creeps towards the instant they meet (7 - c / n after n bounces) and never gets there; the jam check "
    "keeps the time scale it took at the start (0.0: the disc was at rest; moving segments change the energy) "
    "and its window (1e-8 of it) is far below the creep anyway, so run(until=20) never returns (found in the "
    "issue 28 review; not fixed)",
)
def test_a_paddle_squeezing_a_disc_against_a_wall_raises_jammed_instead_of_running_for_ever():
    # The paddle x = 8 - t meets the disc (radius 0.5) against the wall x = 0 at t = 7: there is no room left.
    paddle = ds.Segment((8.0, 4.0), (8.0, 6.0), velocity=(-1.0, 0.0))
    sim = ds.EventDriven(ds.Discs([[5.0, 5.0]], [[0.0, 0.0]], radii=0.5), ds.Box(10.0, 10.0), segments=[paddle])
    try:
        sim.run(until=20.0, events=3 * (sim.jam_events + sim.jam_events_per_disc))  # a bound: today it never ends
    except JammedError as error:
        assert "disc" in str(error)
        return
    raise AssertionError(f"no JammedError: {sim.counts['wall_hits']} bounces, the clock at {sim.time!r} < 7")
