"""A jammed start never hangs a fixed-step run either (issue 18, part 2).

The frame policies respond once per frame and always end; the sub-frame policies answer contacts inside a
frame, which on an exactly touching lattice never ran out: they now raise JammedError after a bounded
number of responses in one frame.
"""

from __future__ import annotations

import pytest
from jams import JAMS, watchdog

import discsim as ds


@pytest.mark.parametrize("name", sorted(JAMS))
@pytest.mark.parametrize("policy", ["resolve", "revert", "separate", "bisect", "swept"])
def test_a_jammed_start_ends_under_every_policy(name, policy):
    discs, box, _ = JAMS[name]()
    sim = ds.FixedStep(discs, box, frame_rate=30, policy=policy)  # the backend of this case
    with watchdog(60):
        try:
            sim.run(until=1.0)
        except ds.JammedError as exc:
            assert policy in ("bisect", "swept")
            assert "are jammed at time" in str(exc)
            assert "contacts" in str(exc)
        else:
            assert sim.time == 1.0


def test_the_hexagonal_lattice_jams_the_sub_frame_policies():
    discs, box, _ = JAMS["hexagonal_lattice"]()
    for policy in ("bisect", "swept"):
        with watchdog(60), pytest.raises(ds.JammedError, match=r"disc \d+ and disc \d+ are jammed"):
            ds.FixedStep(discs, box, frame_rate=30, policy=policy).run(until=1.0)
