"""The pure-Python backend's hot loop: pop, validate the counter, advance, resolve, record, re-predict, push.

:func:`process_events` runs over a :class:`~discsim.engines.event_driven.python.backend.PythonBackend`'s
state, aliased into locals (CPython reads locals fastest). Collisions and bounces go through the collision
law's parts (:func:`discsim.physics.laws.collide`, :func:`~discsim.physics.laws.reflect`,
:func:`discsim.physics.sources.segments.resolve`); free flight, the minimum image and the step into the next
cell are inlined (a Python call each cost this loop 5% at N = 10^3), and the cross-backend tests hold them to
the compiled loop, :func:`discsim.engines.event_driven.numba.loop.run_events`, which calls the parts, bit for
bit.
"""

from __future__ import annotations

import math

from discsim.engines.event_driven.python.layout import (
    _CELL_INDEX,
    _COLLISION,
    _GHOSTS,
    _MINUS_X,
    _PLUS_X,
    _PLUS_Y,
    _RECORD,
    _RECORD_BYTES,
    _SEGMENT,
    _SLOT,
    _WALL,
    INF,
)
from discsim.events import EventLog
from discsim.physics import laws
from discsim.physics.sources import segments

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
    collide, reflect, resolve_segment = laws.collide, laws.reflect, segments.resolve  # the collision law
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
            # pairs.resolve with its minimum image inlined (model.minimum_image_1d): two Python calls fewer per
            # collision; the collision law is the part itself.
            dx, dy = xj - xi, yj - yi
            if periodic:
                dx -= width * round(dx / width)
                dy -= height * round(dy / height)
            uxi, uyi, uxj, uyj = collide(dx, dy, vxi, vyi, vxj, vyj, mi, mj)
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
            # boundaries.cross, inlined (a Python call per crossing costs about 1% of this loop).
            cx, cy = divmod(here[_CELL_INDEX], ny)
            if other == _PLUS_X:
                cx += 1
                if cx == nx:
                    cx = 0
                    xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                    pack(disc, i * _RECORD_BYTES, xi - width, yi, vxi, vyi, ti, ri)
                    image_x[i] += 1
            elif other == _MINUS_X:
                cx -= 1
                if cx < 0:
                    cx = nx - 1
                    xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                    pack(disc, i * _RECORD_BYTES, xi + width, yi, vxi, vyi, ti, ri)
                    image_x[i] -= 1
            elif other == _PLUS_Y:
                cy += 1
                if cy == ny:
                    cy = 0
                    xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                    pack(disc, i * _RECORD_BYTES, xi, yi - height, vxi, vyi, ti, ri)
                    image_y[i] += 1
            else:
                cy -= 1
                if cy < 0:
                    cy = ny - 1
                    xi, yi, vxi, vyi, ti, ri = unpack(disc, i * _RECORD_BYTES)
                    pack(disc, i * _RECORD_BYTES, xi, yi + height, vxi, vyi, ti, ri)
                    image_y[i] -= 1
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
