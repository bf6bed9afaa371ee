"""The kinetic energy each logged event took: :func:`event_losses`, read from an event log and the laws.

A collision with restitution below 1, a rough collision, a bounce that ends in rest: each takes kinetic energy,
which the engines sum in ``dissipated``. The log holds each disc's velocity (and, for rough discs, the spin log its
spin) after each event; its velocity just before is its previous record's, carried along the law of motion
(free flight, gravity while it falls, drag) to the event's time. The difference, summed over the one or two discs
of the event (discs of infinite mass and inertia left out), is what the event took.

Example:
    >>> import discsim as ds
    >>> discs = ds.Discs([[2.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [-1.0, 0.0]], radii=1.0)
    >>> sim = ds.EventDriven(discs, ds.Box(10.0, 10.0), restitution=0.5).run(until=3.0)
    >>> sim.event_losses().tolist()  # (1 - e^2) of the kinetic energy 1 of the head-on collision
    [0.75]
"""

from __future__ import annotations

import math

import numpy as np

from discsim.events import ADD, COLLISION, REMOVE, SENSED, WALL
from discsim.physics.dynamics import advance

__all__ = ["event_losses"]


def event_losses(
    events: np.ndarray,
    velocities0: np.ndarray,
    masses: np.ndarray,
    time0: float,
    gravity=(0.0, 0.0),
    drag: float = 0.0,
    spins0: np.ndarray | None = None,
    inertia: np.ndarray | None = None,
    spin_events: np.ndarray | None = None,
) -> np.ndarray:
    """``(E,)`` the kinetic energy (translation, and rotation for rough discs) each record of ``events`` took.

    Args:
        events: ``(E,)`` :data:`~discsim.events.EVENT_DTYPE` records in time order, discs named by id.
        velocities0: ``(M, 2)`` each disc id's velocity at ``time0`` (NaN rows: not there then; an ``ADD``
            record brings it).
        masses: ``(M,)`` each disc id's mass (inf: an obstacle, left out).
        time0: the time of ``velocities0``.
        gravity: ``(gx, gy)``, the run's gravity: a disc of finite mass falls between its records except after a
            collision or wall record that left it with velocity exactly zero (at rest), as
            :func:`discsim.trajectory.reconstruct` reads the log.
        drag: the run's drag ``gamma`` (its loss during the flights is not an event's: it is the rest of
            ``dissipated``).
        spins0, inertia: ``(M,)`` each id's spin at ``time0`` and moment of inertia (None: smooth discs).
        spin_events: the :data:`~discsim.events.SPIN_DTYPE` rows of a rough run, one per collision or wall record
            of ``events`` in order (None: smooth discs).

    Returns:
        ``(E,)`` float: each collision's or wall hit's loss (>= 0 up to roundoff; 0 when elastic and smooth), 0
        for ``SET``, ``ADD``, ``REMOVE``, ``ENTER`` and ``LEAVE`` records.
    """
    n = len(masses)
    gx, gy = float(gravity[0]), float(gravity[1])
    rough = spin_events is not None and spins0 is not None and inertia is not None
    spin_rows = spin_events if spin_events is not None else np.zeros(0)
    moments = inertia if inertia is not None else np.zeros(n)
    t_ref = np.full(n, float(time0))
    vel = np.array(velocities0, dtype=float).reshape(n, 2)
    falls = np.isfinite(masses) & ~np.isnan(vel[:, 0])
    spin = np.zeros(n) if spins0 is None else np.array(spins0, dtype=float)
    out = np.zeros(len(events))
    k_spin = 0
    for k, record in enumerate(events.tolist()):
        t, kind, i, j = record[0], record[1], record[2], record[3]
        if kind == ADD:
            t_ref[i], vel[i], falls[i] = t, (record[6], record[7]), math.isfinite(masses[i])
            continue
        if kind == REMOVE:
            continue
        physical = kind in (COLLISION, WALL)
        if kind in SENSED:  # j is a sensor, not a disc (and the motion does not change)
            j = -1
        lost = 0.0
        for d, vx, vy, w_slot in ((i, record[6], record[7], 3), (j, record[10], record[11], 4)):
            if d < 0:
                continue
            m = masses[d]
            if physical and math.isfinite(m):
                a = (gx, gy) if falls[d] else (0.0, 0.0)
                _, _, ux, uy = advance(0.0, 0.0, vel[d, 0], vel[d, 1], t - t_ref[d], a[0], a[1], drag)
                lost += 0.5 * m * ((ux * ux + uy * uy) - (vx * vx + vy * vy))
            if physical and rough:
                w = float(spin_rows[k_spin][w_slot])
                if math.isfinite(moments[d]):
                    lost += 0.5 * moments[d] * (spin[d] * spin[d] - w * w)
                spin[d] = w
            t_ref[d], vel[d] = t, (vx, vy)
            falls[d] = math.isfinite(m) and not (physical and vx == 0.0 and vy == 0.0)
        if physical and rough:
            k_spin += 1
        out[k] = lost
    return out
