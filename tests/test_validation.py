"""Bad input: a clear error naming the disc and the value, raised before any change."""

import numpy as np
import pytest

import discsim as ds


def _ok():
    return dict(positions=[[1.0, 1.0], [4.0, 1.0], [1.0, 4.0]], velocities=np.zeros((3, 2)), radii=0.5)


@pytest.mark.parametrize(
    ("change", "error", "match"),
    [
        ({"positions": [[1.0, 1.0, 0.0]]}, ds.InvalidDiscsError, r"shape \(N, 2\), got shape \(1, 3\)"),
        ({"velocities": np.zeros((2, 2))}, ds.InvalidDiscsError, r"velocities must have shape \(3, 2\)"),
        ({"radii": [0.5, 0.5]}, ds.InvalidDiscsError, r"radii must have shape \(3,\)"),
        (
            {"positions": [[1.0, 1.0], [np.nan, 1.0], [1.0, 4.0]]},
            ds.InvalidDiscsError,
            "disc 1 has a non-finite position",
        ),
        ({"velocities": [[0, 0], [0, 0], [np.inf, 0]]}, ds.InvalidDiscsError, "disc 2 has a non-finite velocity"),
        ({"radii": [0.5, -1.0, 0.5]}, ds.InvalidDiscsError, r"disc 1 has radius -1\.0"),
        ({"radii": [0.5, 0.5, 0.0]}, ds.InvalidDiscsError, r"disc 2 has radius 0\.0"),
        ({"masses": [1.0, 0.0, 1.0]}, ds.InvalidDiscsError, r"disc 1 has mass 0\.0"),
        ({"masses": [1.0, 1.0, np.nan]}, ds.InvalidDiscsError, r"disc 2 has mass nan"),
        (
            {"masses": [np.inf, 1.0, 1.0], "velocities": [[1.0, 0], [0, 0], [0, 0]]},
            ds.InvalidDiscsError,
            "disc 0 has infinite mass but velocity",
        ),
    ],
)
def test_bad_discs_are_refused_with_the_disc_and_value(change, error, match):
    kwargs = {**_ok(), **change}
    with pytest.raises(error, match=match):
        ds.Discs(**kwargs)


def test_errors_are_value_errors_and_discsim_errors():
    with pytest.raises(ValueError):
        ds.Discs([[0.0, 0.0]], [[0.0, 0.0]], -1.0)
    with pytest.raises(ds.DiscsimError):
        ds.Discs([[0.0, 0.0]], [[0.0, 0.0]], -1.0)


@pytest.mark.parametrize(("w", "h"), [(0.0, 1.0), (-2.0, 1.0), (1.0, np.nan), (np.inf, 1.0)])
def test_bad_box_is_refused(w, h):
    with pytest.raises(ds.InvalidArgumentError, match="box (width|height)"):
        ds.Box(w, h)


def test_disc_outside_the_box_or_cut_by_a_wall():
    discs = ds.Discs([[1.0, 1.0], [9.8, 5.0]], [[0, 0], [0, 0]], 0.5)
    with pytest.raises(ds.OutsideBoxError, match=r"disc 1 at \[9\.8, 5\.0\] with radius 0\.5 is outside the box"):
        ds.EventDriven(discs, ds.Box(10.0, 10.0))
    discs = ds.Discs([[1.0, 1.0], [10.5, 5.0]], [[0, 0], [0, 0]], 0.5)
    with pytest.raises(ds.OutsideBoxError, match="disc 1 .* outside the periodic box"):
        ds.EventDriven(discs, ds.Box(10.0, 10.0, periodic=True))


def test_overlap_names_the_pair_and_depth():
    discs = ds.Discs([[2.0, 2.0], [5.0, 5.0], [5.8, 5.0]], np.zeros((3, 2)), 0.5)
    with pytest.raises(ds.OverlapError, match=r"discs 1 and 2 overlap by 0\.2 "):
        ds.EventDriven(discs, ds.Box(10.0, 10.0))
    # across a periodic edge too
    discs = ds.Discs([[0.2, 5.0], [9.9, 5.0]], np.zeros((2, 2)), 0.5)
    with pytest.raises(ds.OverlapError, match="discs 0 and 1 overlap by 0.7"):
        ds.EventDriven(discs, ds.Box(10.0, 10.0, periodic=True))


def test_a_crowd_of_overlapping_discs_is_an_overlap_error_not_a_memory_error():
    """Issue 30, item 8: the overlap check of 10^5 discs at one spot asked numpy for 37 GiB (MemoryError)."""
    n = 10**5
    discs = ds.Discs(np.full((n, 2), 5.0), np.zeros((n, 2)), 0.01)
    with pytest.raises(ds.OverlapError, match=r"discs 0 and 1 overlap by 0\.02 \(distance 0,"):
        ds.EventDriven(discs, ds.Box(10.0, 10.0))
    # The same discs spread over a periodic box, one pair overlapping far down the candidate pairs.
    rng = np.random.default_rng(5)
    side = 400.0
    places = (np.stack(np.meshgrid(np.arange(316), np.arange(316)), -1).reshape(-1, 2) + 0.5) * (side / 316)
    places = places[rng.permutation(len(places))]
    places[-1] = places[-2] + [0.005, 0.0]
    discs = ds.Discs(places, np.zeros_like(places), 0.5)
    with pytest.raises(ds.OverlapError, match=f"discs {len(places) - 2} and {len(places) - 1} overlap by 0.995"):
        ds.EventDriven(discs, ds.Box(side, side, periodic=True))


def test_touching_discs_are_allowed():
    discs = ds.Discs([[2.0, 2.0], [3.0, 2.0]], [[1.0, 0.0], [0.0, 0.0]], 0.5)
    sim = ds.EventDriven(discs, ds.Box(10.0, 10.0))
    assert sim.step().time == 0.0  # touching and approaching: they collide at once


def test_periodic_box_too_small_for_its_grid():
    discs = ds.Discs([[1.0, 1.0]], [[1.0, 0.0]], 1.0)
    with pytest.raises(ds.BoxTooSmallError, match="at least 3 cells"):
        ds.EventDriven(discs, ds.Box(5.0, 10.0, periodic=True))


def test_cell_size_below_the_diameter_is_refused():
    discs = ds.Discs([[1.0, 1.0]], [[1.0, 0.0]], 1.0)
    with pytest.raises(ValueError, match="below the largest disc diameter"):
        ds.EventDriven(discs, ds.Box(10.0, 10.0), cell_size=1.5)


def test_unreachable_packing_fraction():
    with pytest.raises(ds.PackingError, match="cannot be reached"):
        ds.random_gas(100, 0.95)
    with pytest.raises(ds.PackingError, match="cannot be reached"):
        ds.random_gas(100, 0.0)
    with pytest.raises(ds.PackingError, match="cannot be reached"):
        ds.random_gas(7, 0.84, periodic=False)


def test_errors_leave_the_simulation_untouched():
    discs, box = ds.random_gas(50, 0.3, seed=0)
    sim = ds.EventDriven(discs, box).run(until=2.0)
    before = (sim.time, sim.positions, sim.velocities, dict(sim.counts), sim.events.tobytes())
    for bad in (1.0, float("nan"), "soon"):
        with pytest.raises(ds.TimeError):
            sim.run(until=bad)
    with pytest.raises(ValueError, match="events must be a non-negative integer"):
        sim.run(events=-3)
    after = (sim.time, sim.positions, sim.velocities, dict(sim.counts), sim.events.tobytes())
    assert before[0] == after[0] and before[3] == after[3] and before[4] == after[4]
    assert np.array_equal(before[1], after[1]) and np.array_equal(before[2], after[2])


def test_input_arrays_are_copied_and_read_only():
    pos = np.array([[1.0, 1.0], [4.0, 1.0]])
    discs = ds.Discs(pos, np.zeros((2, 2)), 0.5)
    pos[0, 0] = 99.0
    assert discs.positions[0, 0] == 1.0
    with pytest.raises(ValueError):
        discs.positions[0, 0] = 5.0


# --- arguments other than the discs: every error is a DiscsimError --------------------------------------


def _one_disc(periodic=False):
    return ds.EventDriven(ds.Discs([[5.0, 5.0]], [[1.0, 0.3]], 0.5), ds.Box(10.0, 10.0, periodic=periodic))


@pytest.mark.parametrize("events", [-1, 1.5, float("nan"), True, "3"])
def test_run_refuses_an_event_count_that_is_not_a_whole_number(events):
    sim = _one_disc()
    with pytest.raises(ds.InvalidArgumentError, match="events must be a non-negative integer"):
        sim.run(events=events)
    assert sim.time == 0.0 and sim.counts["predictions"] == 1


def test_run_refuses_an_endless_run_before_it_starts():
    sim = _one_disc()
    with pytest.raises(ds.TimeError, match="never ends"):
        sim.run(until=np.inf)
    with pytest.raises(ds.InvalidArgumentError, match="needs until"):
        sim.run()
    assert sim.time == 0.0
    assert sim.run(until=np.inf, events=3).counts["wall_hits"] == 3  # a count bounds it


def test_time_error_prints_plain_numbers():
    sim = _one_disc().run(until=2.0)
    with pytest.raises(ds.TimeError, match=r"until=1\.0 is before the current time 2\.0$"):
        sim.run(until=1.0)


@pytest.mark.parametrize(
    ("call", "error"),
    [
        (lambda: ds.EventDriven(*ds.random_gas(20, 0.3), queue="x"), ds.InvalidArgumentError),
        (lambda: ds.EventDriven(*ds.random_gas(20, 0.3), cell_size=0.5), ds.InvalidArgumentError),
        (lambda: ds.EventDriven(*ds.random_gas(20, 0.3), cell_size=np.inf), ds.InvalidArgumentError),
        (lambda: ds.FixedStep(*ds.random_gas(20, 0.3), dt=0.0), ds.InvalidArgumentError),
        (lambda: ds.random_gas(0, 0.3), ds.InvalidArgumentError),
        (lambda: _one_disc().pressure(), ds.InvalidArgumentError),
        (lambda: ds.EventDriven(*ds.random_gas(20, 0.3), record=False).run(until=1).trajectory([0.5]), ds.DiscsimError),
    ],
)
def test_bad_arguments_raise_discsim_errors(call, error):
    with pytest.raises(error):
        call()


def test_a_box_too_small_for_an_asked_cell_size_names_the_cell_size():
    discs = ds.Discs([[1.0, 1.0]], [[1.0, 0.0]], 0.5)
    with pytest.raises(ds.BoxTooSmallError, match=r"side >= 4 \(the cell_size asked for\)"):
        ds.EventDriven(discs, ds.Box(10.0, 10.0, periodic=True), cell_size=4.0)


@pytest.mark.parametrize("flag", ["no", "False", None, 2])
def test_box_periodic_must_be_a_flag(flag):
    with pytest.raises(ds.InvalidArgumentError, match="periodic must be True or False"):
        ds.Box(10.0, 10.0, periodic=flag)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"mass": 0}, "mass must be positive and finite, got 0"),
        ({"mass": -1.0}, r"mass must be positive and finite, got -1\.0"),
        ({"mass": np.inf}, "mass must be positive and finite, got inf"),
        ({"radius": 0.0}, r"radius must be positive and finite, got 0\.0"),
        ({"temperature": 0}, "temperature must be positive and finite, got 0"),
    ],
)
def test_random_gas_checks_its_parameters(kwargs, match):
    with pytest.raises(ds.InvalidArgumentError, match=match):
        ds.random_gas(20, 0.3, **kwargs)


@pytest.mark.parametrize(("n", "phi"), [(1, 0.3), (2, 0.2), (3, 0.4), (8, 0.7)])
def test_random_gas_refuses_periodic_boxes_the_engines_cannot_grid(n, phi):
    with pytest.raises(ds.PackingError, match=r"diameters wide, and the engines need at least 3: use n >= \d+"):
        ds.random_gas(n, phi)


@pytest.mark.parametrize(("n", "phi", "periodic"), [(1, 0.3, False), (1, 0.05, True), (2, 0.2, False), (4, 0.3, True)])
def test_small_random_gases_run(n, phi, periodic):
    discs, box = ds.random_gas(n, phi, periodic=periodic, seed=3)
    assert len(discs) == n
    assert discs.kinetic_energy() == pytest.approx(n * 1.0)
    for engine in (ds.EventDriven(discs, box), ds.FixedStep(discs, box, dt=0.01)):
        engine.run(until=1.0)


def test_discs_repr_shows_the_radius_range():
    assert repr(ds.Discs([[1, 1], [3, 1]], [[0, 0], [0, 0]], [0.5, 0.7])) == "Discs(n=2, radii in [0.5, 0.7])"
    assert repr(ds.Discs(np.zeros((0, 2)), np.zeros((0, 2)), 1.0)) == "Discs(n=0)"


# --- more bad arguments, each named before anything changes (issue 18, part 5) -------------------------
@pytest.mark.parametrize(
    ("call", "error", "named"),
    [
        (lambda d, b: ds.EventDriven(d, b, record="False"), ds.InvalidArgumentError, "'False'"),
        (lambda d, b: ds.FixedStep(d, b, record="no"), ds.InvalidArgumentError, "'no'"),
        (lambda d, b: ds.EventDriven(d, b, queue=["heap"]), ds.InvalidArgumentError, "['heap']"),
        (lambda d, b: ds.henderson_z(1.2), ds.InvalidArgumentError, "1.2"),
        (lambda d, b: ds.henderson_z([0.1, float("nan")]), ds.InvalidArgumentError, "nan"),
        (lambda d, b: ds.enskog_collision_rate(-0.1), ds.InvalidArgumentError, "-0.1"),
        (lambda d, b: ds.henderson_z("dense"), ds.InvalidArgumentError, "'dense'"),
        (lambda d, b: ds.compressibility_factor(d), ds.InvalidArgumentError, "Discs"),  # not an engine
        (lambda d, b: ds.FixedStep(d, b, dt=0.1).pressure(), ds.InvalidArgumentError, "positive duration"),
        (
            lambda d, b: ds.compressibility_factor(
                ds.EventDriven(ds.Discs(d.positions, np.zeros_like(d.velocities), d.radii), b).run(until=1.0)
            ),
            ds.InvalidArgumentError,
            "kinetic energy is 0",
        ),
    ],
)
def test_more_bad_arguments_are_named(call, error, named):
    discs, box = ds.random_gas(20, 0.3, seed=1)
    with pytest.raises(error) as caught:
        call(discs, box)
    assert named in str(caught.value)
