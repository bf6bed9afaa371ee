"""The engine registry and the services the layers above hand down to the engines (engines/base.py)."""

from __future__ import annotations

import importlib
import inspect
import subprocess
import sys
import textwrap

import pytest
from paths import PACKAGE

import discsim as ds
from discsim.engines import base


def _engine_classes() -> dict[str, type]:
    """Every concrete Engine subclass defined in a module under discsim/engines/."""
    found = {}
    for path in sorted((PACKAGE / "engines").rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        try:
            module = importlib.import_module(name)
        except ImportError:  # a compiled part without numba: it defines no engine (every other test imports it)
            continue
        for value in vars(module).values():
            if (
                inspect.isclass(value)
                and issubclass(value, base.Engine)
                and not inspect.isabstract(value)
                and value.__module__ == name
            ):
                found[value.__name__] = value
    return found


def test_the_registry_knows_every_engine():
    defined = _engine_classes()
    assert set(defined) >= {"Compression", "EventChain", "EventDriven", "FixedStep"}
    assert base.registered_engines() == defined
    for name, cls in defined.items():
        assert base.engine_class(name) is cls


def test_an_unknown_name_is_refused_naming_the_known_ones():
    known = r"'Nope' \(known: \['Compression', 'EventChain', 'EventDriven', 'FixedStep'\]\)"
    with pytest.raises(ds.InvalidArgumentError, match=known):
        base.engine_class("Nope")


def test_register_engine_refuses_a_non_engine_and_a_second_class_of_the_same_name():
    with pytest.raises(ds.WrongTypeError, match="subclass of discsim.engines.base.Engine"):
        base.register_engine(dict)

    class EventDriven(ds.EventDriven):  # another class under a registered name
        pass

    with pytest.raises(ds.InvalidArgumentError, match="registered already"):
        base.register_engine(EventDriven)
    assert base.engine_class("EventDriven") is ds.EventDriven
    assert base.register_engine(ds.EventDriven) is ds.EventDriven  # the same class again changes nothing
    copy = type("EventDriven", (ds.EventDriven,), {"__module__": ds.EventDriven.__module__})  # its file run again
    copy.__qualname__ = ds.EventDriven.__qualname__
    assert base.register_engine(copy) is copy and base.engine_class("EventDriven") is ds.EventDriven


def test_provide_refuses_an_unknown_service():
    with pytest.raises(ds.InvalidArgumentError, match="provide"):
        base.provide("fly", print)
    with pytest.raises(ds.InvalidArgumentError, match="provide"):
        base.provide("run", 42)


def test_an_engine_without_its_services_says_what_to_import(monkeypatch):
    monkeypatch.setattr(base, "_SERVICES", {})
    sim = ds.EventDriven(ds.Discs([[2.0, 5.0]], [[1.0, 0.0]], 1.0), ds.Box(10, 10))
    with pytest.raises(ds.DiscsimError, match=r"Engine.run\(\) needs discsim.run.driver"):
        sim.run(until=1.0)
    with pytest.raises(ds.DiscsimError, match=r"Engine.save\(\) needs discsim.io.checkpoints"):
        sim.save("unused.dsc")
    assert sim.time == 0.0


def test_the_old_table_of_engines_still_answers_with_a_warning():
    from discsim.io import checkpoints

    with pytest.warns(DeprecationWarning, match="registered_engines"):
        engines = checkpoints.ENGINES
    assert engines == {
        "Compression": ds.Compression, "EventChain": ds.EventChain, "EventDriven": ds.EventDriven,
        "FixedStep": ds.FixedStep,
    }  # fmt: skip


def test_an_engine_module_imported_alone_runs_and_saves(tmp_path):
    """``import discsim.engines.<engine>`` imports the package first, and with it the driver and io."""
    code = textwrap.dedent(
        f"""
        import sys
        from discsim.engines.event_driven import EventDriven
        from discsim.engines.fixed_step import FixedStep
        from discsim.model import Box, Discs
        discs = Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], 1.0)
        for cls in (EventDriven, FixedStep):
            sim = cls(discs, Box(10.0, 10.0)).run(until=2.5)
            path = sim.save({str(tmp_path)!r} + "/" + cls.__name__ + ".dsc")
            print(cls.__name__, sim.velocities.tolist(), path.name)
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split("\n")[:2] == [
        "EventDriven [[-1.0, 0.0], [1.0, 0.0]] EventDriven.dsc",
        "FixedStep [[-1.0, 0.0], [1.0, 0.0]] FixedStep.dsc",
    ]
