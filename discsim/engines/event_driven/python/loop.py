"""The pure-Python backend's hot loop: pop, validate the counter, advance, resolve, record, re-predict, push.

:func:`process_events` runs over a :class:`~discsim.engines.event_driven.python.backend.PythonBackend`'s
state, aliased into locals (CPython reads locals fastest). Events are resolved through the physics parts
(:mod:`discsim.physics.sources`, :mod:`discsim.physics.laws`); the same loop, compiled, is
:func:`discsim.engines.event_driven.numba.loop.run_events`.
"""

from __future__ import annotations

import math

from discsim.engines.event_driven.python.layout import (
    _CELL_INDEX,
    _COLLISION,
    _GHOSTS,
    _RECORD,
    _RECORD_BYTES,
    _SEGMENT,
    _SLOT,
    _WALL,
    INF,
)
from discsim.events import EventLog
from discsim.physics.laws import reflect
from discsim.physics.sources import boundaries, pairs, segments

__all__ = ["process_events"]


def process_events(backend, until: float, limit: int, crossings: int, log: EventLog | None, interrupted) -> int:
    """The hot loop of :meth:`PythonBackend.advance` (-1: no limit on ``limit`` or ``crossings``).

    Stops before the next event once ``interrupted[0]`` is true
    (see :func:`~discsim._interrupt.deferred_interrupt`).
    """
    queue = backend._queue
    pop_before = queue.pop_before
    predict = backend._predict
    disc, unpack, pack = backend._disc, _RECORD.unpack_from, _RECORD.pack_into
    count, mass, one_mass = backend._count, backend._mass, backend._one_mass
    image_x, image_y = backend._image_x, backend._image_y  # box lengths to unwrap, changed only at the edges
    where, info, grid = backend._where, backend._cell_info, backend.grid
    nx, ny = grid.nx, grid.ny
    width, height, periodic = backend.box.width, backend.box.height, backend.box.periodic
    caller = backend._caller_id  # the caller's numbering, for the log
    counts = backend._counts
    segment_ends = [(*seg.p0.tolist(), *seg.p1.tolist()) for seg in backend.segments]
    resolve_pair, resolve_segment, cross = pairs.resolve, segments.resolve, boundaries.cross
    n_coll = n_wall = n_cross = n_stale = 0
    done = 0
    max_queue = backend.max_queue
    now, last, virial = None, None, backend._virial
    sqrt, max_overlap = math.sqrt, backend.max_overlap
    # Internal times run from the epoch, which moves every _rebase_every physical events.
    epoch = backend._epoch
    horizon = until - epoch
    rebase_at = backend._rebase_every - backend._since_rebase
    while done != limit:
        if interrupted[0]:  # Ctrl-C: stop between two whole events
            break
        popped = pop_before(horizon)
        if popped is None:
            break
        t, i, (kind, other, stamp) = popped
        if kind == _COLLISION:
            j = other
            if count[j] != stamp:  # the partner has changed course since the prediction
                n_stale += 1
                predict(i, t, -1)
                continue
            # Advance the two discs to the contact.
            xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
            dt = t - ti
            xi += vxi * dt
            yi += vyi * dt
            xj, yj, vxj, vyj, tj, rj = unpack(disc, j * _RECORD_BYTES)
            dt = t - tj
            xj += vxj * dt
            yj += vyj * dt
            if one_mass is None:
                mi, mj = mass[i], mass[j]
            else:
                mi = mj = one_mass
            dx, dy, uxi, uyi, uxj, uyj = resolve_pair(
                xi, yi, vxi, vyi, mi, xj, yj, vxj, vyj, mj, width, height, periodic
            )
            overlap = 1.0 - sqrt(dx * dx + dy * dy) / (ri + rj)
            if overlap > max_overlap:
                max_overlap = overlap
            pack(disc, i * _RECORD_BYTES, xi, yi, uxi, uyi, t, ri)
            pack(disc, j * _RECORD_BYTES, xj, yj, uxj, uyj, t, rj)
            virial -= mi * ((uxi - vxi) * dx + (uyi - vyi) * dy)  # owners are never obstacles
            count[i] += 1
            n_coll += 1
            done += 1
            if log is not None:
                log.collision(t + epoch, caller[i], caller[j], xi, yi, uxi, uyi, xj, yj, uxj, uyj)
            predict(i, t, j)
            if mj != INF:  # obstacles never move, and their counter never changes
                count[j] += 1
                predict(j, t, i)
                # Only here can the queue grow (j's slot may have been empty); other
                # events pop their owner's event and push at most one back.
                size = len(queue)
                if size > max_queue:
                    max_queue = size
            last = (t + epoch, _COLLISION, i, j)
        elif kind == _WALL:
            xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
            dt = t - ti
            xi += vxi * dt
            yi += vyi * dt
            vxi, vyi = reflect(vxi, vyi, other)
            pack(disc, i * _RECORD_BYTES, xi, yi, vxi, vyi, t, ri)
            count[i] += 1
            n_wall += 1
            done += 1
            if log is not None:
                log.wall(t + epoch, caller[i], xi, yi, vxi, vyi)
            predict(i, t, -1)
            last = (t + epoch, _WALL, i, -1)
        elif kind == _SEGMENT:
            xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
            dt = t - ti
            xi += vxi * dt
            yi += vyi * dt
            vxi, vyi = resolve_segment(xi, yi, vxi, vyi, *segment_ends[other])
            pack(disc, i * _RECORD_BYTES, xi, yi, vxi, vyi, t, ri)
            count[i] += 1
            n_wall += 1
            done += 1
            if log is not None:
                log.wall(t + epoch, caller[i], xi, yi, vxi, vyi)
            predict(i, t, -2 - other)  # never the same segment again straight away
            last = (t + epoch, _WALL, i, -1)
        else:  # cell crossing: the trajectory is unchanged, only the neighbourhood
            here = where[i]
            tile, slot = here[1], here[_SLOT]
            others = tile[slot]
            if len(others) == 1:
                others = ()
            else:
                k = others.index(i)
                others = others[:k] + others[k + 1 :]
            tile[slot] = others
            for tile, slot in here[_GHOSTS]:  # the copies in the rings of neighbouring tiles
                tile[slot] = others
            cx, cy = divmod(here[_CELL_INDEX], ny)
            cx, cy, wrap_x, wrap_y = cross(cx, cy, other, nx, ny)
            if wrap_x or wrap_y:  # out through one edge of the box, in through the other
                xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                pack(disc, i * _RECORD_BYTES, xi - wrap_x * width, yi - wrap_y * height, vxi, vyi, ti, ri)
                image_x[i] += wrap_x
                image_y[i] += wrap_y
            here = where[i] = info[cx * ny + cy]
            tile, slot = here[1], here[_SLOT]
            others = tile[slot] + (i,)
            tile[slot] = others
            for tile, slot in here[_GHOSTS]:
                tile[slot] = others
            n_cross += 1
            predict(i, t, -1, other)
            if n_cross == crossings:
                now = t
                break
        now = t
        if done >= rebase_at:
            backend._rebase(now)
            epoch, now = backend._epoch, 0.0
            horizon = until - epoch
            rebase_at = done + backend._rebase_every
    backend._since_rebase = backend._rebase_every - (rebase_at - done)
    backend.max_queue = max_queue
    backend._virial, backend.max_overlap = virial, max_overlap
    if now is not None:
        backend.time = now + epoch
    if last is not None:
        backend._last = last
    counts["collisions"] += n_coll
    counts["wall_hits"] += n_wall
    counts["cell_crossings"] += n_cross
    counts["stale"] += n_stale
    return done
