"""The compiled event loop over other physics: the same source compiled again, nothing in it edited.

- :func:`with_physics`: over another law of motion or collision law (modules of parts,
  ``docs/adding-physics.md``);
- :func:`with_laws`: with the loop's ``LAWS`` constant True, the loop every run under gravity, restitution or the
  TC model takes (one loop for every value of their numbers, cached on disk under its own names).

Each rebuilds the loop's functions of :data:`~discsim.engines.event_driven.numba.loop.PHYSICAL` from their very
source over a copy of the loop module's globals with some names replaced.
"""

from __future__ import annotations

from discsim.engines.event_driven.numba import loop

__all__ = ["with_laws", "with_physics"]

#: Loops compiled by :func:`with_physics`, by the identity of their laws (kept here, so the ids stay theirs).
_BUILT: dict[tuple[int, int, bool], tuple[object, object, dict]] = {}


def with_physics(law_of_motion=None, collision_law=None, *, interpreted: bool = False) -> dict:
    """This loop compiled over another law of motion or collision law: nothing above is edited.

    The parts (:func:`discsim.physics.compiled.compile_parts`) are compiled over the given laws, and the
    functions of the loop's ``PHYSICAL`` are compiled anew from their very source with those parts in place of free
    flight and the elastic law; the rest (queue, cells, prefetches) is shared. The new functions are compiled
    in this process, once per pair of laws, and not cached on disk (numba's cache knows a function by its own
    source file and name, not by the laws compiled into it): the first use takes about as long as the first
    compile of this module.

    ``interpreted=True`` (or no numba) rebuilds the same functions over the laws without compiling them: the
    very loop, run by the interpreter on its arrays, as the pure-Python backend runs a law that its own loop
    does not inline (about 5x slower than that loop on free flight; the same events, bit for bit, as the
    compiled loop over the same laws). The prefetches, which only a compiled loop can ask for, do nothing.

    Args:
        law_of_motion: a module with the functions of :data:`discsim.physics.compiled.DYNAMICS` (None: free
            flight).
        collision_law: a module with those of :data:`discsim.physics.compiled.LAWS` (None: elastic).
        interpreted: build the loop for the interpreter instead of compiling it.

    Returns:
        This module's namespace (a dict) with the new ``predict``, ``predict_all``, ``set_disc`` and
        ``run_events``; :class:`~discsim.engines.event_driven.numba.backend.NumbaBackend` runs it as it runs
        this module.
    """

    from discsim._numba import numba
    from discsim.physics.compiled import compile_parts

    nb = numba()
    interpreted = interpreted or nb is None
    key = (id(law_of_motion), id(collision_law), interpreted)
    if key in _BUILT:
        return _BUILT[key][2]
    namespace = dict(vars(loop))
    namespace.update(compile_parts(law_of_motion, collision_law, interpreted=interpreted))
    if interpreted:
        namespace.update(_prefetch_disc=_no_prefetch, _prefetch_cells=_no_prefetch)
    _rebuild(namespace, interpreted, suffix="", cache=False)
    _BUILT[key] = (law_of_motion, collision_law, namespace)
    return namespace


#: The loop of :func:`with_laws`, once built (per interpreted or not).
_LAWS_BUILT: dict[bool, dict] = {}


def with_laws(*, interpreted: bool = False) -> dict:
    """The loop compiled with its ``LAWS`` constant True: the loop that reads gravity, restitution, the TC time and the
    rest speed from the numbers after the cells' edges (one loop for every value of them).

    The functions of the loop's ``PHYSICAL`` are rebuilt from their very source over a copy of the loop module's globals
    in which ``LAWS`` is True (and each calls the others' rebuilt versions), and compiled under their own names
    (``run_events_laws`` ...), so that numba caches them on disk beside the default loop's without mixing the
    two: the first run under a non-default law on a machine compiles them once (about as long as the default
    loop's first compile), later processes load them. ``interpreted=True`` (or no numba): the same functions for
    the interpreter, the pure-Python backend's loop under the laws.

    Returns:
        This module's namespace (a dict) with the loop's functions replaced.
    """

    from discsim._numba import numba

    nb = numba()
    interpreted = interpreted or nb is None
    if interpreted in _LAWS_BUILT:
        return _LAWS_BUILT[interpreted]
    namespace = dict(vars(loop))
    namespace["LAWS"] = True
    if interpreted:
        namespace.update(_prefetch_disc=_no_prefetch, _prefetch_cells=_no_prefetch)
    _rebuild(namespace, interpreted, suffix="_laws", cache=True)  # its own names: its own cache files
    _LAWS_BUILT[interpreted] = namespace
    return namespace


def _rebuild(namespace: dict, interpreted: bool, *, suffix: str, cache: bool) -> None:
    """Rebuild the loop's :data:`~discsim.engines.event_driven.numba.loop.PHYSICAL` functions from their very
    source over ``namespace`` (each calling the others' rebuilt versions), named with ``suffix``, and put them
    in it: compiled (``cache``: on disk, under those names) or, ``interpreted``, as plain functions."""
    from types import FunctionType

    from discsim._numba import numba

    for name in loop.PHYSICAL:
        dispatcher = vars(loop)[name]
        source = getattr(dispatcher, "py_func", dispatcher)
        table = dict(source.__globals__)
        table.update({key: namespace[key] for key in table if key in namespace})
        rebuilt = FunctionType(source.__code__, table, f"{source.__name__}{suffix}", source.__defaults__)
        rebuilt.__qualname__ = f"{source.__qualname__}{suffix}"
        rebuilt.__module__ = source.__module__
        if interpreted:
            namespace[name] = rebuilt
        else:
            options = {key: value for key, value in dispatcher.targetoptions.items() if key != "nopython"}
            namespace[name] = numba().njit(cache=cache, **options)(rebuilt)


def _no_prefetch(*args) -> None:
    """The prefetches of an interpreted loop: nothing (the interpreter cannot ask the CPU for a cache line)."""
