"""Physics as parts: the law of motion, the event sources and the collision law, each written once.

Every loop of discsim (the event-driven backends, the compression loop, the fixed-step frames, trajectories
and states) asks these modules, never its own copy:

- :mod:`.dynamics`: the law of free motion between events (today free flight, ``x + v t``): advance a disc,
  the time to leave a slab of space along x or y (a wall, a cell edge), the time of impact of a pair and of a
  disc with a segment.
- :mod:`.laws`: what an impact does to the velocities (today elastic and frictionless).
- :mod:`.sources`: the kinds of event, each with its ``predict`` and ``resolve`` written over the two above:
  pairs, walls, segments and cell crossings.
- :mod:`.polygons`: rotating convex polygons, the certified first contact of two (and of one with a line); no
  engine uses it yet.

Every function here is a plain function of floats that uses only arithmetic, comparisons and :mod:`math`, so
that the same source runs in CPython and, jitted by numba (``discsim._compiled.jit``), inside the compiled
loops: written once, compiled from the same source. ``docs/adding-physics.md`` shows how a new law of motion
or collision law is added.
"""
