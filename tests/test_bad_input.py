"""Bad input, as a careless user gives it (issue 18, part 5): every public function and argument.

Each case asserts that the error is a :class:`discsim.DiscsimError`, that its message names the offending
value, and that the engines that already exist (an event-driven and a fixed-step run) are unchanged.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import discsim as ds

NAN, INF = math.nan, math.inf
POS = [[1.0, 1.0], [3.0, 1.0]]
VEL = [[1.0, 0.0], [0.0, 0.0]]


def _discs(**change):
    return ds.Discs(**{"positions": POS, "velocities": VEL, "radii": 0.5, **change})


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    discs, box = ds.random_gas(20, 0.3, seed=1)
    return {
        "discs": discs,
        "box": box,
        "walled": ds.Box(box.width, box.height),
        "sim": ds.EventDriven(discs, box, backend="python").run(until=1.0),
        "pit": ds.FixedStep(discs, box, dt=0.01, backend="python").run(until=1.0),
        "tmp": tmp_path_factory.mktemp("bad"),
    }


# (id, what to call with the world, text the message must hold)
CASES = [
    # --- Discs ---------------------------------------------------------------------------------------------
    ("positions complex", lambda w: _discs(positions=np.array(POS) + 1j), "complex"),
    ("positions string", lambda w: _discs(positions="abc"), "'abc'"),
    ("positions object None", lambda w: _discs(positions=np.array([[1.0, None], [3.0, 1.0]], dtype=object)), "None"),
    ("positions ragged", lambda w: _discs(positions=[[1.0, 1.0], [3.0]]), "ragged [[1.0, 1.0], [3.0]]"),
    ("positions booleans", lambda w: _discs(positions=[[True, False], [True, True]]), "booleans"),
    ("positions 1-D", lambda w: _discs(positions=[1.0, 2.0, 3.0]), "shape (3,)"),
    ("positions 3 columns", lambda w: _discs(positions=[[1.0, 1.0, 0.0], [3.0, 1.0, 0.0]]), "shape (2, 3)"),
    ("positions nan", lambda w: _discs(positions=[[1.0, 1.0], [NAN, 1.0]]), "[nan, 1.0]"),
    ("positions inf", lambda w: _discs(positions=[[INF, 1.0], [3.0, 1.0]]), "[inf, 1.0]"),
    ("positions strings in a list", lambda w: _discs(positions=[["1", "1"], ["3", "1"]]), "strings"),
    ("velocities complex", lambda w: _discs(velocities=np.array(VEL) * 1j), "complex"),
    ("velocities string", lambda w: _discs(velocities="fast"), "'fast'"),
    ("velocities shape", lambda w: _discs(velocities=[[1.0, 0.0]]), "shape (1, 2)"),
    ("velocities nan", lambda w: _discs(velocities=[[1.0, 0.0], [0.0, NAN]]), "[0.0, nan]"),
    ("velocities None", lambda w: _discs(velocities=None), "None"),
    ("radius negative", lambda w: _discs(radii=[0.5, -1.0]), "-1.0"),
    ("radius zero", lambda w: _discs(radii=0.0), "radius 0.0"),
    ("radius string", lambda w: _discs(radii="big"), "'big'"),
    ("radius nan", lambda w: _discs(radii=[NAN, 0.5]), "nan"),
    ("radius complex", lambda w: _discs(radii=0.5 + 0.1j), "complex"),
    ("radius shape", lambda w: _discs(radii=[0.5, 0.5, 0.5]), "shape (3,)"),
    ("mass zero", lambda w: _discs(masses=[1.0, 0.0]), "mass 0.0"),
    ("mass negative", lambda w: _discs(masses=-2.0), "-2.0"),
    ("mass string", lambda w: _discs(masses="heavy"), "'heavy'"),
    ("mass nan", lambda w: _discs(masses=[NAN, 1.0]), "nan"),
    ("moving obstacle", lambda w: _discs(masses=[INF, 1.0]), "[1.0, 0.0]"),
    ("groups float", lambda w: _discs(groups=[0.5, 1.0]), "float64"),
    ("groups strings", lambda w: _discs(groups=["a", "b"]), "['a', 'b']"),
    ("groups shape", lambda w: _discs(groups=[1, 2, 3]), "(3,)"),
    ("groups bool", lambda w: _discs(groups=[True, False]), "bool"),
    (
        "groups uint64 above 2**63",
        lambda w: _discs(groups=np.array([0, 2**63 + 5], dtype=np.uint64)),
        "9223372036854775813",
    ),
    ("groups ragged", lambda w: _discs(groups=[[1], [1, 2]]), "[[1], [1, 2]]"),
    ("radius above the units", lambda w: _discs(radii=1e60), "1e+60"),
    ("radius below the units", lambda w: _discs(radii=1e-60), "1e-60"),
    ("speed above the units", lambda w: _discs(velocities=[[1e60, 0.0], [0.0, 0.0]]), "1e+60"),
    ("speed below the units", lambda w: _discs(velocities=[[1e-60, 0.0], [0.0, 0.0]]), "1e-60"),
    ("mass above the units", lambda w: _discs(masses=1e200), "1e+200"),
    ("coordinate above the units", lambda w: _discs(positions=[[1e60, 1.0], [3.0, 1.0]]), "1e+60"),
    # --- Box -----------------------------------------------------------------------------------------------
    ("box negative", lambda w: ds.Box(-10, 10), "-10"),
    ("box zero", lambda w: ds.Box(10, 0), "got 0"),
    ("box nan", lambda w: ds.Box(NAN, 10), "nan"),
    ("box inf", lambda w: ds.Box(10, INF), "inf"),
    ("box string", lambda w: ds.Box("10", 10), "'10'"),
    ("box None", lambda w: ds.Box(None, 10), "None"),
    ("box list", lambda w: ds.Box([10], 10), "[10]"),
    ("box complex", lambda w: ds.Box(10 + 1j, 10), "(10+1j)"),
    ("box periodic string", lambda w: ds.Box(10, 10, periodic="no"), "'no'"),
    ("box periodic 2", lambda w: ds.Box(10, 10, periodic=2), "2"),
    ("box above the units", lambda w: ds.Box(1e60, 10), "1e+60"),
    # --- Segment and polygon -------------------------------------------------------------------------------
    ("segment string end", lambda w: ds.Segment((0, 0), ("a", 1)), "'a'"),
    ("segment zero length", lambda w: ds.Segment((1, 1), (1, 1)), "[1.0, 1.0]"),
    ("segment short point", lambda w: ds.Segment((0, 0), (1,)), "[1.0]"),
    ("segment nan", lambda w: ds.Segment((0, 0), (NAN, 1)), "nan"),
    ("segment complex", lambda w: ds.Segment((0, 0), (1j, 1)), "complex"),
    ("segment None", lambda w: ds.Segment(None, (1, 1)), "None"),
    ("polygon string", lambda w: ds.polygon("abc"), "'abc'"),
    ("polygon one vertex", lambda w: ds.polygon([(1, 1)]), "(1, 2)"),
    ("polygon ragged", lambda w: ds.polygon([(1, 1), (2,)]), "ragged"),
    # --- the scene an engine is given ----------------------------------------------------------------------
    ("discs as a list", lambda w: ds.EventDriven([[1, 1]], w["box"]), "list [[1, 1]]"),
    ("box as a tuple", lambda w: ds.EventDriven(w["discs"], (10, 10)), "tuple (10, 10)"),
    ("box as None", lambda w: ds.EventDriven(w["discs"], None), "NoneType None"),
    (
        "segment as points",
        lambda w: ds.EventDriven(w["discs"], w["walled"], segments=[((0, 0), (1, 1))]),
        "((0, 0), (1, 1))",
    ),
    ("segment as a string", lambda w: ds.EventDriven(w["discs"], w["walled"], segments=["wall"]), "'wall'"),
    (
        "segment outside the box",
        lambda w: ds.EventDriven(w["discs"], w["walled"], segments=[ds.Segment((100, 100), (120, 100))]),
        "[100.0, 100.0]",
    ),
    (
        "segments in a periodic box",
        lambda w: ds.EventDriven(w["discs"], w["box"], segments=[ds.Segment((1, 1), (2, 2))]),
        "periodic",
    ),
    ("pass_through string label", lambda w: ds.EventDriven(w["discs"], w["box"], pass_through=[("a", 0)]), "'a'"),
    ("pass_through None label", lambda w: ds.EventDriven(w["discs"], w["box"], pass_through=[(None, 0)]), "None"),
    ("pass_through single", lambda w: ds.EventDriven(w["discs"], w["box"], pass_through=[(1,)]), "(1,)"),
    ("pass_through fraction", lambda w: ds.EventDriven(w["discs"], w["box"], pass_through=[(1.5, 0)]), "1.5"),
    ("pass_through int", lambda w: ds.EventDriven(w["discs"], w["box"], pass_through=5), "5"),
    ("pass_through string", lambda w: ds.EventDriven(w["discs"], w["box"], pass_through="00"), "'00'"),
    ("record string", lambda w: ds.EventDriven(w["discs"], w["box"], record="False"), "'False'"),
    ("record None", lambda w: ds.EventDriven(w["discs"], w["box"], record=None), "None"),
    ("queue list", lambda w: ds.EventDriven(w["discs"], w["box"], queue=["heap"]), "['heap']"),
    ("queue unknown", lambda w: ds.EventDriven(w["discs"], w["box"], queue="fifo"), "'fifo'"),
    ("backend unknown", lambda w: ds.EventDriven(w["discs"], w["box"], backend="gpu"), "'gpu'"),
    ("cell_size negative", lambda w: ds.EventDriven(w["discs"], w["box"], cell_size=-1.0), "-1.0"),
    ("cell_size string", lambda w: ds.EventDriven(w["discs"], w["box"], cell_size="big"), "'big'"),
    ("cell_size nan", lambda w: ds.EventDriven(w["discs"], w["box"], cell_size=NAN), "nan"),
    ("overlapping discs", lambda w: ds.EventDriven(_discs(positions=[[1.0, 1.0], [1.5, 1.0]]), ds.Box(5, 5)), "0.5"),
    (
        "disc outside the box",
        lambda w: ds.EventDriven(_discs(positions=[[1.0, 1.0], [9.8, 1.0]]), ds.Box(5, 5)),
        "[9.8, 1.0]",
    ),
    ("radius too small for the box", lambda w: ds.EventDriven(_discs(radii=1e-12), ds.Box(100, 100)), "1e-12"),
    ("periodic box too small", lambda w: ds.EventDriven(_discs(), ds.Box(2.5, 2.5, periodic=True)), "2.5"),
    # --- FixedStep -----------------------------------------------------------------------------------------
    ("dt zero", lambda w: ds.FixedStep(w["discs"], w["box"], dt=0), "0"),
    ("dt negative", lambda w: ds.FixedStep(w["discs"], w["box"], dt=-1.0), "-1.0"),
    ("dt string", lambda w: ds.FixedStep(w["discs"], w["box"], dt="x"), "'x'"),
    ("frame_rate nan", lambda w: ds.FixedStep(w["discs"], w["box"], frame_rate=NAN), "nan"),
    ("policy unknown", lambda w: ds.FixedStep(w["discs"], w["box"], policy="magic"), "'magic'"),
    ("broad_phase unknown", lambda w: ds.FixedStep(w["discs"], w["box"], broad_phase="kd"), "'kd'"),
    ("fixed-step discs as a list", lambda w: ds.FixedStep([[1, 1]], w["box"]), "list"),
    ("fixed-step record string", lambda w: ds.FixedStep(w["discs"], w["box"], record="yes"), "'yes'"),
    # --- run -----------------------------------------------------------------------------------------------
    ("run with no limit", lambda w: w["sim"].run(), "until"),
    ("run until the past", lambda w: w["sim"].run(until=-1.0), "-1.0"),
    ("run until nan", lambda w: w["sim"].run(until=NAN), "NaN"),
    ("run until a string", lambda w: w["sim"].run(until="soon"), "'soon'"),
    ("run until inf", lambda w: w["sim"].run(until=INF), "inf"),
    ("run until a list", lambda w: w["sim"].run(until=[2.0]), "[2.0]"),
    ("run events negative", lambda w: w["sim"].run(events=-1), "-1"),
    ("run events fraction", lambda w: w["sim"].run(events=1.5), "1.5"),
    ("run events string", lambda w: w["sim"].run(events="many"), "'many'"),
    ("run events bool", lambda w: w["sim"].run(events=True), "True"),
    ("run events nan", lambda w: w["sim"].run(events=NAN), "nan"),
    ("run observers one observer", lambda w: w["sim"].run(until=2.0, observers=ds.Callback(print)), "Callback"),
    ("run observers a number", lambda w: w["sim"].run(until=2.0, observers=[5]), "int"),
    ("run observers a string", lambda w: w["sim"].run(until=2.0, observers="progress"), "str"),
    (
        "run checkpoint_every zero",
        lambda w: w["sim"].run(until=2.0, checkpoint=w["tmp"] / "c.dsc", checkpoint_every=0),
        "got 0",
    ),
    (
        "run checkpoint_every string",
        lambda w: w["sim"].run(until=2.0, checkpoint=w["tmp"] / "c.dsc", checkpoint_every="10"),
        "'10'",
    ),
    ("run checkpoint_every alone", lambda w: w["sim"].run(until=2.0, checkpoint_every=10), "checkpoint_every"),
    (
        "run stream and checkpoint in one file",
        lambda w: w["sim"].run(until=2.0, record_to=w["tmp"] / "x.dsc", checkpoint=w["tmp"] / "x.dsc"),
        "x.dsc",
    ),
    ("fixed-step frames negative", lambda w: w["pit"].run(frames=-1), "-1"),
    ("fixed-step frames and events differ", lambda w: w["pit"].run(frames=2, events=3), "frames=2"),
    ("fixed-step until the past", lambda w: w["pit"].run(until=-5.0), "-5.0"),
    ("fixed-step until a string", lambda w: w["pit"].run(until="x"), "'x'"),
    ("fixed-step until inf", lambda w: w["pit"].run(until=INF), "inf"),
    # --- trajectory ----------------------------------------------------------------------------------------
    ("trajectory a string", lambda w: w["sim"].trajectory("soon"), "'soon'"),
    ("trajectory 2-D times", lambda w: w["sim"].trajectory([[0.1, 0.2]]), "[[0.1, 0.2]]"),
    ("trajectory after the end", lambda w: w["sim"].trajectory([0.5, 5.0]), "5.0"),
    ("trajectory before the start", lambda w: w["sim"].trajectory(-0.5), "-0.5"),
    ("trajectory nan", lambda w: w["sim"].trajectory([NAN]), "nan"),
    ("trajectory None", lambda w: w["sim"].trajectory(None), "None"),
    ("trajectory complex", lambda w: w["sim"].trajectory([0.5j]), "0.5j"),
    ("trajectory ragged", lambda w: w["sim"].trajectory([[0.1], [0.2, 0.3]]), "[[0.1], [0.2, 0.3]]"),
    ("fixed-step trajectory a string", lambda w: w["pit"].trajectory("soon"), "'soon'"),
    ("fixed-step trajectory 2-D", lambda w: w["pit"].trajectory(np.zeros((2, 2))), "array"),
    # --- compare -------------------------------------------------------------------------------------------
    ("compare with a list", lambda w: ds.compare(w["sim"], [1, 2, 3]), "[1, 2, 3]"),
    ("compare a string", lambda w: ds.compare("pic", w["pit"]), "'pic'"),
    ("compare window string", lambda w: ds.compare(w["sim"], w["pit"], window="x"), "'x'"),
    ("compare window negative", lambda w: ds.compare(w["sim"], w["pit"], window=-1.0), "-1.0"),
    ("compare window nan", lambda w: ds.compare(w["sim"], w["pit"], window=NAN), "nan"),
    ("compare times outside both runs", lambda w: ds.compare(w["sim"], w["pit"], times=[5.0, 6.0]), "6.0"),
    ("compare times string", lambda w: ds.compare(w["sim"], w["pit"], times="soon"), "'soon'"),
    ("compare until outside", lambda w: ds.compare(w["sim"], w["pit"], until=50.0), "50.0"),
    # --- random_gas, scenarios, theory ---------------------------------------------------------------------
    ("random_gas packing string", lambda w: ds.random_gas(100, "dense"), "'dense'"),
    ("random_gas packing None", lambda w: ds.random_gas(100, None), "None"),
    ("random_gas packing too high", lambda w: ds.random_gas(100, 0.95), "0.95"),
    ("random_gas packing negative", lambda w: ds.random_gas(100, -0.1), "-0.1"),
    ("random_gas n zero", lambda w: ds.random_gas(0, 0.3), "0"),
    ("random_gas n fraction", lambda w: ds.random_gas(2.5, 0.3), "2.5"),
    ("random_gas n string", lambda w: ds.random_gas("ten", 0.3), "'ten'"),
    ("random_gas temperature negative", lambda w: ds.random_gas(100, 0.3, temperature=-1.0), "-1.0"),
    ("random_gas radius string", lambda w: ds.random_gas(100, 0.3, radius="r"), "'r'"),
    ("random_gas mass zero", lambda w: ds.random_gas(100, 0.3, mass=0.0), "0.0"),
    ("newtons_cradle one disc", lambda w: ds.newtons_cradle(1), "1"),
    ("newtons_cradle string", lambda w: ds.newtons_cradle("five"), "'five'"),
    ("henderson_z above 1", lambda w: ds.henderson_z(1.2), "1.2"),
    ("enskog_collision_rate negative", lambda w: ds.enskog_collision_rate(-0.1), "-0.1"),
    # --- add_discs, remove_discs (issue 19), on both engines: the new disc named by the index it would get ---
    *[
        case
        for engine in ("sim", "pit")
        for case in (
            (f"{engine} add_discs a list", lambda w, e=engine: w[e].add_discs([[1.0, 1.0]]), "list"),
            (
                f"{engine} add_discs on a disc",
                lambda w, e=engine: w[e].add_discs(ds.Discs([w[e].positions[3]], [[0.0, 0.0]], 0.2)),
                "new disc 20 at",
            ),
            (
                f"{engine} add_discs overlapping each other",
                lambda w, e=engine: w[e].add_discs(_free_pair(w[e], 0.05)),
                "new disc 21",
            ),
            (
                f"{engine} add_discs outside the box",
                lambda w, e=engine: w[e].add_discs(ds.Discs([[-1.0, 2.0]], [[0.0, 0.0]], 0.1)),
                "[-1.0, 2.0]",
            ),
            (
                f"{engine} add_discs too fast",
                lambda w, e=engine: w[e].add_discs(ds.Discs([_free_spot(w[e], 0.1)], [[1e60, 0.0]], 0.1)),
                "1e+60",
            ),
            (
                f"{engine} add_discs below the resolution",
                lambda w, e=engine: w[e].add_discs(ds.Discs([_free_spot(w[e], 0.1)], [[0.0, 0.0]], 1e-12)),
                "new disc 20 has radius 1e-12",
            ),
            (f"{engine} remove_discs out of range", lambda w, e=engine: w[e].remove_discs([3, 20]), "20"),
            (f"{engine} remove_discs negative", lambda w, e=engine: w[e].remove_discs(-1), "-1"),
            (f"{engine} remove_discs twice", lambda w, e=engine: w[e].remove_discs([4, 4]), "4 is given twice"),
            (f"{engine} remove_discs a float", lambda w, e=engine: w[e].remove_discs([1.5]), "[1.5]"),
            (f"{engine} remove_discs booleans", lambda w, e=engine: w[e].remove_discs([True]), "[True]"),
            (f"{engine} remove_discs a string", lambda w, e=engine: w[e].remove_discs("all"), "'all'"),
        )
    ],
    (
        "add_discs cut by a wall",
        lambda w: ds.EventDriven(ds.Discs([[5.0, 5.0]], [[0.0, 0.0]], 0.2), ds.Box(10, 10)).add_discs(
            ds.Discs([[0.05, 5.0]], [[0.0, 0.0]], 0.1)
        ),
        "new disc 1 at [0.05, 5.0] with radius 0.1 is outside the box or cut by a wall",
    ),
    (
        "add_discs cut by a segment",
        lambda w: ds.EventDriven(
            ds.Discs([[1.0, 1.0]], [[0.0, 0.0]], 0.2), ds.Box(10, 10), segments=[ds.Segment([5, 0], [5, 10])]
        ).add_discs(ds.Discs([[5.05, 5.0]], [[0.0, 0.0]], 0.2)),
        "new disc 1 at [5.05, 5.0] with radius 0.2 is cut by segment 0",
    ),
    # --- files ---------------------------------------------------------------------------------------------
    ("load a text file", lambda w: ds.load(_text_file(w)), "notes.txt"),
    ("read_events of a text file", lambda w: ds.read_events(_text_file(w)), "notes.txt"),
    ("resume a text file", lambda w: ds.resume(_text_file(w)), "notes.txt"),
]


def _free_spot(sim, r):
    """A place for a disc of radius ``r`` clear of every disc of ``sim`` (the first on a fine grid)."""
    box = sim.box
    for x in np.arange(r + 0.01, box.width - r, 0.05):
        for y in np.arange(r + 0.01, box.height - r, 0.05):
            d = box.minimum_image(sim.positions - [x, y])
            if (np.hypot(d[:, 0], d[:, 1]) > sim.discs.radii + 3 * r).all():
                return [x, y]
    raise AssertionError("no room")


def _free_pair(sim, r):
    """Two new discs of radius ``r`` that overlap each other, clear of every disc of ``sim``."""
    x, y = _free_spot(sim, r)
    return ds.Discs([[x, y], [x + r, y]], [[0.0, 0.0], [0.0, 0.0]], r)


def _text_file(w):
    path = w["tmp"] / "notes.txt"
    path.write_text("not a discsim file, but long enough to be read as one " * 4)
    return path


def _state(engine) -> list:
    scalars, arrays = engine.state().to_arrays()
    return [engine.time, engine.counts, scalars, {k: v.tobytes() for k, v in arrays.items()}, len(engine._log)]


def test_there_are_at_least_a_hundred_cases():
    assert len(CASES) >= 100
    assert len({name for name, _, _ in CASES}) == len(CASES)


@pytest.mark.parametrize(("call", "named"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_is_refused_by_name_and_changes_nothing(world, call, named):
    before = [_state(world["sim"]), _state(world["pit"])]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning is not an answer (numpy's ComplexWarning, say)
        with pytest.raises(ds.DiscsimError) as caught:
            call(world)
    assert named in str(caught.value), str(caught.value)
    assert [_state(world["sim"]), _state(world["pit"])] == before
    assert world["sim"]._broken is None and world["pit"]._broken is None


def test_pass_through_labels_no_disc_has_are_warned_about(world):
    with pytest.warns(UserWarning, match=r"group label\(s\) \[5, 7\] that no disc has"):
        ds.EventDriven(world["discs"], world["box"], pass_through=[(5, 7)])


def test_an_empty_periodic_box_runs_instead_of_blaming_the_largest_diameter():
    empty = ds.Discs(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))
    box = ds.Box(1.0, 1.0, periodic=True)
    assert ds.EventDriven(empty, box).run(until=1.0).time == 1.0
    assert ds.FixedStep(empty, box, dt=0.1, backend="python").run(until=1.0).time == 1.0
