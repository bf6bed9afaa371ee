"""The kinds of event, each a part with its ``predict`` and ``resolve``: pairs, walls, segments, cell crossings.

Each is written over the law of motion (:mod:`discsim.physics.dynamics`) and the collision law
(:mod:`discsim.physics.laws`), in plain float functions that the compiled loops compile from this very source.
The event kinds are numbered once, in :class:`discsim.events.EventKind`.
"""
