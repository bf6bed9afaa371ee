"""What every engine reads from its event log: :class:`EventRecord` (``events``, the exact ``trajectory``) and
:func:`collision_virials`.

:class:`EventRecord` is a mixin of :class:`~discsim.engines.base.Engine`: it reads the engine's log
(``run_context.log``, an :class:`~discsim.events.EventLog` its loop fills while ``_logging``), its
``record`` setting, its clock and the discs where the log starts. :func:`collision_virials` takes records
only, so that an engine restoring an old checkpoint (``FixedStep``'s version 1 state) and the analyses
above (:mod:`discsim.analysis.thermo`) share one definition.
"""

from __future__ import annotations

import numpy as np

from discsim.engines.context import RunContext
from discsim.errors import InvalidArgumentError
from discsim.events import COLLISION, EVENT_DTYPE
from discsim.losses import event_losses
from discsim.model import Box, Discs
from discsim.trajectory import log_start, positions_from_log

__all__ = ["EventRecord", "collision_virials"]


class EventRecord:
    """The event log's readers every engine shares (see the module docstring)."""

    # What the engine gives these methods (declared for type checkers; Engine sets or defines each).
    discs: Discs
    box: Box
    record: bool
    start_time: float
    time: float
    run_context: RunContext

    @property
    def _logging(self) -> bool:
        """Whether the loop logs events now: ``record``, or an observer of the current run wants them."""
        return self.record or self.run_context.recording

    def _log_origin(self) -> tuple[Discs, np.ndarray | None]:
        """``(discs, ids)`` where the log starts, at ``start_time`` (ids None: their indices)."""
        return self.run_context.log_origin(self.discs)

    @property
    def events(self) -> np.ndarray:
        """The recorded event log: a structured array ``(E,)`` of :data:`~discsim.events.EVENT_DTYPE`.

        Empty when the engine was built with ``record=False``.

        Raises:
            InvalidArgumentError: if the log was streamed to disk (``run(record_to=...)``):
                read it with :func:`discsim.read_events`.
        """
        self._refuse_if_streamed("events")
        if not self.record:
            return np.zeros(0, dtype=EVENT_DTYPE)
        return self.run_context.log.to_array()

    def trajectory(self, times, *, unwrapped: bool = False) -> np.ndarray:
        """Exact positions ``(T, N, 2)`` at ``times`` ``(T,)``, rebuilt from the event log.

        Column ``k`` is the disc of id ``k`` (:attr:`ids`): the disc of index ``k`` unless discs were
        removed. After :meth:`add_discs` or :meth:`remove_discs` there is one column per disc the run ever
        held (``M >= N``: ``trajectory(t)[:, sim.ids]`` are the discs there now), NaN at times the disc was
        not there (before its ``ADD`` record, from its ``REMOVE`` record on). After such a change the engine
        restarts every disc's path from where it is, so positions rebuilt between that change and a
        disc's next event may differ from the engine's own in the last bits.

        Args:
            times: simulated times within ``[start_time, time]``, any order.
            unwrapped: in a periodic box, follow each disc across the edges
                instead of wrapping it into the box (as a mean-squared
                displacement needs); the same as wrapped in a walled box.

        Raises:
            InvalidArgumentError: if the engine does not hold its log
                (``record=False``, or streamed to disk: use
                :func:`discsim.trajectory_from_events`).
            TimeError: if a time is not finite or lies outside the simulated span.
        """
        self._refuse_if_streamed("trajectory()")
        if not self.record:
            msg = "trajectory() needs the event log; build the engine with record=True"
            raise InvalidArgumentError(msg)
        discs, ids = self._log_origin()
        return positions_from_log(
            self.run_context.log.to_array(),
            discs,
            self.box,
            self.start_time,
            self.time,
            times,
            span="simulated span",
            unwrapped=unwrapped,
            ids=ids,
            gravity=self._gravity(),
            drag=getattr(getattr(self, "laws", None), "drag", 0.0),
        )

    def event_losses(self) -> np.ndarray:
        """``(E,)`` the kinetic energy (mass length^2 / time^2) each record of :attr:`events` took: a collision or
        wall hit with restitution below 1, a rough one (its rotational part too, in an event-driven run), a bounce
        that ended in rest; 0 for elastic, smooth ones and for ``SET``, ``ADD`` and ``REMOVE`` records.

        Read from the log (:func:`discsim.losses.event_losses`): each disc's velocity just before an event is its
        previous record's carried along the law of motion. Summed, they are :attr:`dissipated` less what the drag
        took between events (all of it without drag), to rounding.

        Raises:
            InvalidArgumentError: if the engine does not hold its log (``record=False``, or streamed to disk).

        Example:
            >>> import discsim as ds
            >>> discs = ds.Discs([[5.0, 3.0]], [[0.0, 0.0]], radii=1.0)
            >>> sim = ds.EventDriven(discs, ds.Box(10.0, 10.0), gravity=(0.0, -1.0), restitution=0.5)
            >>> round(float(sim.run(until=2.5).event_losses()[0]), 12)  # lands at speed 2: 3/4 of 2 is lost
            1.5
        """
        self._refuse_if_streamed("event_losses()")
        if not self.record:
            msg = "event_losses() needs the event log; build the engine with record=True"
            raise InvalidArgumentError(msg)
        events = self.run_context.log.to_array()
        discs, ids = self._log_origin()
        _, velocities, radii, masses, _ = log_start(events, discs, ids)
        rows = np.arange(len(discs)) if ids is None else np.asarray(ids)
        spins0, inertia = np.zeros(len(masses)), 0.5 * masses * radii**2  # discs added later: a uniform disc
        spins0[rows], inertia[rows] = discs.spins, discs.inertia
        laws = getattr(self, "laws", None)
        spin_events = getattr(self, "spin_events", None) if laws is not None and laws.rough else None
        return event_losses(
            events,
            velocities,
            masses,
            self.start_time,
            laws.gravity if laws is not None else (0.0, 0.0),
            laws.drag if laws is not None else 0.0,
            spins0,
            inertia,
            spin_events,
        )

    def _gravity(self):
        """The run's gravity ``(gx, gy)``, or None (engines without laws, or none)."""
        laws = getattr(self, "laws", None)
        return laws.gravity if laws is not None and laws.falls else None

    def _refuse_if_streamed(self, what: str) -> None:
        stream = self.run_context.stream
        if stream is not None:
            path = stream["path"]
            msg = (
                f"{what} is not kept in memory: this run streamed its event log to {path!r}; "
                f"read it with ds.read_events({path!r}) and rebuild positions with "
                f"ds.trajectory_from_events({path!r}, times)"
            )
            raise InvalidArgumentError(msg)


def collision_virials(events: np.ndarray, masses: np.ndarray, box) -> tuple[np.ndarray, np.ndarray]:
    """``(times, W)`` of the disc-disc collisions in ``events``: each collision's virial ``dp_i . (r_i - r_j)``.

    From the state after the collision only: with ``mu`` the reduced mass (the finite one for an obstacle),
    ``W = 2 mu (u_i - u_j) . (r_i - r_j)``, ``u`` the velocities after and ``r_i - r_j`` the minimum image.
    Summed over a run, this is the engine's own virial (``pressure()``) to roundoff.

    Args:
        events: structured array ``(E,)`` of :data:`~discsim.events.EVENT_DTYPE`.
        masses: ``(N,)`` the discs' masses. box: the box.

    Returns:
        ``(C,)`` times and ``(C,)`` virials (energy units) of the ``C`` collisions.
    """
    rows = events[events["kind"] == COLLISION]
    mi = masses[rows["i"]]
    mj = masses[rows["j"]]
    with np.errstate(invalid="ignore"):
        mu = np.where(np.isinf(mj), mi, np.where(np.isinf(mi), mj, mi * mj / (mi + mj)))
    d = box.minimum_image(np.column_stack([rows["xi"] - rows["xj"], rows["yi"] - rows["yj"]]))
    w = 2.0 * mu * ((rows["vxi"] - rows["vxj"]) * d[:, 0] + (rows["vyi"] - rows["vyj"]) * d[:, 1])
    return rows["time"].astype(float), w
