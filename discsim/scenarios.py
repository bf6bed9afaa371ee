"""Ready-made initial conditions.

:func:`random_gas` makes seeded, non-overlapping gases at a chosen packing
fraction. The study's four PIT failure cases, the cases under the laws of motion of issue 27
(:func:`law_cases`: a ball bouncing to rest, and a paddle a fast disc tunnels through) and other set pieces live
here too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from discsim.errors import InvalidArgumentError, PackingError
from discsim.model import Box, Discs, Segment

__all__ = [
    "Scenario",
    "billiard_break",
    "bouncing_ball",
    "delay",
    "head_on",
    "law_cases",
    "missed_collision",
    "multiple_collisions",
    "newtons_cradle",
    "paddle_tunnel",
    "random_gas",
    "study_cases",
    "terminal_fall",
    "wrong_direction",
]

#: Densest packing fraction a triangular lattice reaches in a square box here.
_MAX_PACKING = 0.85


def _lattice(n: int, side: float, radius: float, periodic: bool, rng: np.random.Generator):
    """``n`` sites of a near-triangular lattice in a square of ``side``, and their spacing.

    The number of rows follows from ``n``; only when that lattice is too tight
    for the discs (small ``n``) are the other row counts tried, the widest
    spacing kept, so every gas that fitted before stays the same.
    """
    rows = max(2, math.ceil(math.sqrt(n * 2.0 / math.sqrt(3.0))))
    if periodic and rows % 2:
        rows += 1  # an even number of rows keeps the staggering consistent across the wrap
    sites, spacing = _sites(n, side, radius, periodic, rows)
    if spacing < 2.0 * radius * (1.0 + 1e-9) and n <= 1000:
        for other in range(2, n + 2, 2 if periodic else 1):
            more_sites, more_spacing = _sites(n, side, radius, periodic, other, exact=True)
            if more_spacing > spacing:
                sites, spacing = more_sites, more_spacing
    chosen = np.sort(rng.choice(len(sites), size=n, replace=False))
    return sites[chosen], spacing


def _sites(n: int, side: float, radius: float, periodic: bool, rows: int, exact: bool = False):
    """All sites of a lattice of ``rows`` rows holding at least ``n``, and its spacing.

    ``exact`` measures the nearest pair of sites (O(sites^2)); the default is
    the closed form the gases were always made with.
    """
    cols = max(1, math.ceil(n / rows))
    while cols * rows < n:
        cols += 1
    if periodic:
        ax, ay = side / cols, side / rows
        x0, y0 = 0.25 * ax, 0.5 * ay
    else:
        inner = side - 2.0 * radius
        ax = inner / (cols - 0.5) if cols > 1 else inner
        ay = inner / (rows - 1)
        x0 = y0 = radius
    jj, ii = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    x = x0 + (ii + 0.5 * (jj % 2)) * ax
    y = y0 + jj * ay
    sites = np.column_stack([x.ravel(), y.ravel()])
    if exact:  # the nearest pair of sites, images across a periodic edge included
        gap = Box(side, side, periodic).minimum_image(sites[:, None, :] - sites[None, :, :])
        distance = np.hypot(gap[..., 0], gap[..., 1])
        np.fill_diagonal(distance, np.inf)
        return sites, float(distance.min()) if len(sites) > 1 else math.inf
    spacing = min(ax, math.hypot(0.5 * ax, ay)) if cols > 1 else ay
    if not periodic and cols == 1:
        spacing = ay
    return sites, spacing


def random_gas(
    n: int,
    packing_fraction: float,
    periodic: bool = True,
    seed: int | None = 0,
    temperature: float = 1.0,
    radius: float = 1.0,
    mass: float = 1.0,
    radii=None,
    fractions=None,
    start: str = "lattice",
):
    """A gas of ``n`` discs (equal, or of several sizes) in a square box at a given packing fraction.

    Discs start on randomly occupied, randomly jittered sites of a triangular
    lattice (so even dense gases start without overlaps), with Gaussian
    velocities shifted to zero total momentum and scaled so that the kinetic
    energy is exactly ``n * temperature`` (2D equipartition, ``kT`` units).
    A dense start is a crystal; let it run a few collisions per disc to melt (at packing 0.70 that takes
    thousands of collisions per disc: check with ``ds.thermo``, or start disordered with ``start="random"``).

    Args:
        n: number of discs (>= 1).
        packing_fraction: ``n pi r^2 / area``, in ``(0, 0.85]``.
        periodic: periodic box (True) or reflecting walls.
        seed: seed of ``numpy.random.default_rng``; the same seed gives the same gas.
        temperature: ``kT`` in energy units (positive, finite).
        radius: disc radius (length units). mass: disc mass (positive, finite), the same for every disc.
        radii: None for equal discs of ``radius``; or the radii of several species, e.g. ``[1.0, 1.4]``,
            mixed in ``fractions`` (default equal; the counts are rounded to sum to ``n``) and shuffled, with
            each disc's species as its group; or an array of ``n`` radii; or a size distribution, a callable
            ``f(rng, n)`` returning ``n`` radii (e.g. ``lambda rng, n: rng.uniform(0.8, 1.2, n)``). The
            discs sit on a lattice spaced for the largest, so a mixture starts up to
            ``max(r)^2 / mean(r^2)`` times less dense than a monodisperse gas can: compress it from there
            (``ds.compress``).
        fractions: the share of each species in ``radii`` (positive, normalised here).
        start: ``"lattice"`` (the default, as above), or ``"random"``: a disordered start, the discs placed
            uniformly at random without overlap at packing ``min(packing_fraction, 0.1)`` (random sequential
            addition of discs shrunk in proportion) and then grown to ``packing_fraction`` by
            :func:`discsim.compress` (``growth_rate=0.1``, seeded from ``seed``), with fresh velocities as
            above. The radii come out within a relative 1e-9 of those asked (the compression's last
            correction); a dense target takes a while (about a million collisions for 10,000 discs at 0.70).

    Returns:
        ``(discs, box)``.

    Raises:
        PackingError: if the packing fraction is not in ``(0, 0.85]``, the
            lattice cannot hold ``n`` discs without overlap in that box, a
            periodic box would be under 3 diameters wide (the engines' cell grid),
            or (``start="random"``) the compression jammed below the target.
        InvalidArgumentError: if ``n``, ``temperature``, ``radius`` or ``mass``
            is not a positive (finite) number, or ``start`` is neither ``"lattice"`` nor ``"random"``.

    Example:
        >>> discs, box = random_gas(100, 0.3, seed=1)
        >>> len(discs), round(discs.kinetic_energy(), 9), bool(abs(discs.momentum()).max() < 1e-12)
        (100, 100.0, True)
    """
    if not _is_whole(n) or n < 1:
        msg = f"n must be a positive integer, got {n!r}"
        raise InvalidArgumentError(msg)
    n = int(n)
    if not isinstance(start, str) or start not in ("lattice", "random"):
        msg = f'start must be "lattice" or "random", got {start!r}'
        raise InvalidArgumentError(msg)
    if isinstance(packing_fraction, (bool, np.bool_)) or not isinstance(
        packing_fraction, (int, float, np.integer, np.floating)
    ):
        msg = f"packing_fraction must be a number in (0, {_MAX_PACKING}], got {packing_fraction!r}"
        raise InvalidArgumentError(msg)
    if not (0.0 < packing_fraction <= _MAX_PACKING):
        msg = f"packing fraction {packing_fraction!r} cannot be reached: it must lie in (0, {_MAX_PACKING}]"
        raise PackingError(msg)
    for name, value in (("temperature", temperature), ("radius", radius), ("mass", mass)):
        if not (isinstance(value, (int, float, np.integer, np.floating)) and 0 < value < math.inf):
            msg = f"{name} must be positive and finite, got {value!r}"
            raise InvalidArgumentError(msg)
    rng = np.random.default_rng(seed)
    groups = None
    if radii is not None:
        sizes, groups = _radii(n, radii, fractions, rng)
        radius = float(sizes.max())
        side = math.sqrt(math.pi * float(np.sum(sizes**2)) / packing_fraction)
    else:
        side = math.sqrt(n * math.pi * radius**2 / packing_fraction)
    if periodic and side < 6.0 * radius:  # the engines' cell grid needs 3 diameters a side
        need = math.ceil(36.0 * packing_fraction / math.pi)
        msg = (
            f"a periodic box of {n} disc(s) at packing fraction {packing_fraction!r} is {side / (2 * radius):.4g} "
            f"diameters wide, and the engines need at least 3: use n >= {need}, a lower packing fraction "
            "or periodic=False"
        )
        raise PackingError(msg)
    if not periodic and side < 2.0 * radius:
        msg = f"packing fraction {packing_fraction!r} cannot be reached with {n} disc(s) in a walled box"
        raise PackingError(msg)
    if start == "random":
        sizes = sizes if radii is not None else np.full(n, float(radius))
        return _random_start(sizes, groups, side, periodic, packing_fraction, temperature, mass, rng)
    if n == 1:  # no lattice needed: anywhere the disc fits
        low, high = (0.0, side) if periodic else (radius, side - radius)
        positions, spacing = rng.uniform(low, high, size=(1, 2)), math.inf
    else:
        positions, spacing = _lattice(n, side, radius, periodic, rng)
    slack = spacing - 2.0 * radius
    if slack < 1e-9 * radius:
        msg = (
            f"packing fraction {packing_fraction!r} cannot be reached for n={n} "
            f"({'periodic' if periodic else 'walled'} box): lattice spacing {spacing:.6g} < diameter {2 * radius:g}"
        )
        raise PackingError(msg)
    jitter = 0.0 if n == 1 else 0.49 * slack / math.sqrt(2.0)
    positions = positions + rng.uniform(-jitter, jitter, size=positions.shape)
    if periodic:
        positions = Box(side, side, periodic=True).wrap(positions)  # np.mod alone can give the far edge
    else:
        positions = np.clip(positions, radius, side - radius)
    if radii is not None:
        radius = sizes
    velocities = _velocities(n, temperature, mass, rng)
    return Discs(positions, velocities, radius, mass, groups), Box(side, side, periodic=periodic)


def _velocities(n: int, temperature: float, mass: float, rng: np.random.Generator) -> np.ndarray:
    """Gaussian velocities, zero total momentum, kinetic energy exactly ``n * temperature``."""
    velocities = rng.normal(0.0, math.sqrt(temperature / mass), size=(n, 2))
    if n > 1:
        velocities -= velocities.mean(axis=0)
    energy = 0.5 * mass * float(np.sum(velocities**2))
    if energy > 0:
        velocities *= math.sqrt(n * temperature / energy)
    return velocities


#: The packing at which ``random_gas(..., start="random")`` places its discs before compressing them.
DILUTE_PACKING = 0.1


def _random_start(sizes, groups, side, periodic, packing_fraction, temperature, mass, rng):
    """Random sequential addition at a dilute packing, then ``compress`` to ``packing_fraction``."""
    from discsim.engines.compress import compress

    n = len(sizes)
    dilute = min(packing_fraction, DILUTE_PACKING)
    small = sizes * math.sqrt(dilute / packing_fraction)
    box = Box(side, side, periodic=periodic)
    positions = np.empty((n, 2))
    for i in range(n):  # at packing <= 0.1 about two tries in three succeed
        low, high = (0.0, side) if periodic else (small[i], side - small[i])
        while True:
            trial = rng.uniform(low, high, size=2)
            d = box.minimum_image(positions[:i] - trial) if periodic else positions[:i] - trial
            if not i or np.min(np.einsum("ij,ij->i", d, d) - (small[:i] + small[i]) ** 2) > 0.0:
                positions[i] = trial
                break
    discs = Discs(positions, _velocities(n, temperature, mass, rng), small, mass, groups)
    if dilute < packing_fraction:
        seed = int(rng.integers(2**63))
        discs, _ = compress(discs, box, packing_fraction, growth_rate=0.1, seed=seed, temperature=temperature)
        reached = float(np.pi * np.sum(np.asarray(discs.radii) ** 2) / box.area)
        if reached < packing_fraction * (1.0 - 1e-9):
            msg = (
                f"start='random': the compression jammed at packing {reached:.6g}, below packing_fraction "
                f"{packing_fraction!r}: use the lattice start"
            )
            raise PackingError(msg)
    return Discs(discs.positions, _velocities(n, temperature, mass, rng), discs.radii, mass, groups), box


def _radii(n: int, radii, fractions, rng: np.random.Generator):
    """The ``(n,)`` radii of :func:`random_gas` and their groups (species index, or None), checked."""
    if callable(radii):
        sizes = np.asarray(radii(rng, n), dtype=float)
        if sizes.shape != (n,):
            msg = f"the size distribution radii(rng, n) must return {n} radii, got shape {sizes.shape}"
            raise InvalidArgumentError(msg)
        groups = None
    else:
        try:
            values = np.asarray(radii, dtype=float)
        except (TypeError, ValueError):
            msg = f"radii must be a list of species radii, an array of n radii or a callable, got {radii!r}"
            raise InvalidArgumentError(msg) from None
        if values.ndim != 1 or len(values) == 0:
            msg = f"radii must be a list of species radii, an array of n radii or a callable, got {radii!r}"
            raise InvalidArgumentError(msg)
        if fractions is None and len(values) == n and n > 1:
            sizes, groups = values, None  # one radius per disc
        else:
            shares = np.full(len(values), 1.0 / len(values)) if fractions is None else np.asarray(fractions, float)
            if (
                shares.shape != values.shape
                or not (np.isfinite(shares).all() and (shares >= 0).all())
                or not (shares.sum() > 0)
            ):
                msg = f"fractions must be {len(values)} non-negative numbers, not all 0, got {fractions!r}"
                raise InvalidArgumentError(msg)
            exact = shares / shares.sum() * n
            counts = np.floor(exact).astype(np.int64)
            order = np.argsort(-(exact - counts), kind="stable")  # largest remainders first
            counts[order[: n - int(counts.sum())]] += 1
            groups = rng.permutation(np.repeat(np.arange(len(values)), counts))
            sizes = values[groups]
    bad = ~(np.isfinite(sizes) & (sizes > 0))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        msg = f"radius {sizes[i]!r} (disc {i}) must be positive and finite"
        raise InvalidArgumentError(msg)
    return sizes, groups


# --- set pieces: the study's four PIT failures and classic demonstrations -------------------------------


def _is_whole(value) -> bool:
    """True for a finite whole number (an int, or a float such as 5.0), False for anything else."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        return False
    return math.isfinite(value) and int(value) == value


@dataclass(frozen=True)
class Scenario:
    """A ready-made initial condition with the frame rate and horizon to run it at.

    Attributes:
        discs: the discs at time 0.
        box: the box.
        frame_rate: frames per unit time for a fixed-step (PIT) run; the
            study's failures show at this rate.
        until: the horizon (time units); a whole number of frames.
        name: a short identifier, e.g. ``"missed_collision"``.
        description: one or two sentences on what happens and what PIT gets wrong.
        laws: the keywords of the laws of motion both engines take (``gravity=``, ``restitution=``, and
            ``segments=`` for a case with moving segments; pass them as ``**case.laws``); empty: free flight and
            elastic collisions off the box's walls.

    Example:
        >>> case = missed_collision()
        >>> case.name, len(case.discs), case.frame_rate, case.until
        ('missed_collision', 2, 10.0, 0.4)
    """

    discs: Discs
    box: Box
    frame_rate: float
    until: float
    name: str
    description: str
    laws: dict = field(default_factory=dict, hash=False)  # a scenario stays hashable, as before the laws

    @property
    def dt(self) -> float:
        """The frame interval ``1 / frame_rate`` (time units)."""
        return 1.0 / self.frame_rate


def missed_collision() -> Scenario:
    """Study case 1: a small fast disc passes through another between two frames.

    Two discs of radius 0.2 (contact distance 0.4) in a 20 x 10 box; disc 0
    flies at speed 30 along y = 5 towards disc 1, which drifts up slowly. At 10
    frames per unit time disc 0 moves 3 per frame: it is 1.5 short of disc 1 at
    one frame and 1.5 past it at the next, so PIT never sees them overlap. The
    exact contact is at t = 0.137 (disc 0 nearly stops, disc 1 takes its speed).

    Example:
        >>> case = missed_collision()
        >>> case.discs.velocities.tolist()
        [[30.0, 0.0], [0.0, 0.5]]
    """
    discs = Discs([[1.0, 5.0], [5.5, 4.95]], [[30.0, 0.0], [0.0, 0.5]], radii=0.2)
    return Scenario(
        discs,
        Box(20.0, 10.0),
        frame_rate=10.0,
        until=0.4,
        name="missed_collision",
        description="A small fast disc crosses another between two frames: PIT misses the collision.",
    )


def wrong_direction() -> Scenario:
    """Study case 2: an oblique collision found late, when the line of centres has turned.

    Disc 0 (radius 1, speed 6 along x) hits the resting disc 1 with an impact
    parameter of 1.2. At contact the line of centres makes
    ``atan(1.2 / 1.6) = 36.87`` degrees with x; at 5 frames per unit time PIT
    first sees the discs 0.6 apart in x, where the line makes
    ``atan(1.2 / 0.6) = 63.43`` degrees, so both discs leave about 26.6 degrees
    off their true directions.

    Example:
        >>> case = wrong_direction()
        >>> case.discs.positions.tolist()
        [[1.8, 3.0], [6.0, 4.2]]
    """
    discs = Discs([[1.8, 3.0], [6.0, 4.2]], [[6.0, 0.0], [0.0, 0.0]], radii=1.0)
    return Scenario(
        discs,
        Box(12.0, 10.0),
        frame_rate=5.0,
        until=1.0,
        name="wrong_direction",
        description=(
            "An oblique collision is detected late, with the discs deep in each other: "
            "the line of centres has turned, and both discs leave in wrong directions."
        ),
    )


def multiple_collisions() -> Scenario:
    """Study case 3: a chain A -> B -> static C whose second link PIT misses.

    The first collision is that of :func:`wrong_direction`: disc 0 hits disc 1,
    which should leave at 36.87 degrees with speed 4.8 and hit the static disc
    2 (infinite mass) 6 units along that line at t = 1.27. Under PIT the first
    contact is found late, disc 1 leaves at 63.43 degrees and passes disc 2 at
    a distance of 2.68 > 2 (the contact distance): the second collision never
    happens.

    Example:
        >>> case = multiple_collisions()
        >>> case.discs.masses.tolist()
        [1.0, 1.0, inf]
    """
    discs = Discs(
        [[1.8, 3.0], [6.0, 4.2], [10.8, 7.8]],
        [[6.0, 0.0], [0.0, 0.0], [0.0, 0.0]],
        radii=1.0,
        masses=[1.0, 1.0, np.inf],
    )
    return Scenario(
        discs,
        Box(14.0, 10.0),
        frame_rate=5.0,
        until=1.6,
        name="multiple_collisions",
        description=(
            "A disc should knock a second one into a static third; PIT finds the first contact "
            "late, sends the second disc off course, and misses the second collision."
        ),
    )


def delay() -> Scenario:
    """Study case 4: PIT responds only once the discs overlap, so all that follows is late.

    Two discs of radius 1 approach at speed 3 each along nearly the same line
    (offset 0.3). They touch at t = 4/3 - 0.0023 = 1.3311; at 5 frames per unit
    time PIT responds at t = 1.4, 0.069 late. The discs leave in almost the
    right directions (a few degrees off), but along paths shifted by about
    ``2 v delay = 0.4`` from the true ones.

    Example:
        >>> case = delay()
        >>> case.frame_rate, case.until
        (5.0, 2.4)
    """
    discs = Discs([[2.0, 5.0], [12.0, 5.3]], [[3.0, 0.0], [-3.0, 0.0]], radii=1.0)
    return Scenario(
        discs,
        Box(14.0, 10.0),
        frame_rate=5.0,
        until=2.4,
        name="delay",
        description=(
            "PIT responds only after the discs overlap: they leave in almost the right "
            "directions but late, so their paths are shifted."
        ),
    )


def study_cases() -> list[Scenario]:
    """The study's four PIT failure cases, in the study's order.

    Example:
        >>> [case.name for case in study_cases()]
        ['missed_collision', 'wrong_direction', 'multiple_collisions', 'delay']
    """
    return [missed_collision(), wrong_direction(), multiple_collisions(), delay()]


def bouncing_ball(restitution: float = 0.8, height: float = 4.0, gravity: float = 9.81) -> Scenario:
    """A ball dropped onto the floor, bouncing to rest under gravity with restitution (issue 27).

    One disc of radius 0.5, its bottom ``height`` above the floor of a 4 x 7 box, at rest, under
    ``gravity=(0, -gravity)`` with ``restitution``. Exactly (PIC), it hits the floor at
    ``t0 = sqrt(2 h / g)`` and bounce ``k`` rises ``e^(2k) h``, the flights ``2 e^k t0`` long: it comes to rest
    at ``t0 (1 + e) / (1 - e)`` (9 t0 = 8.13 at the defaults), after the infinitely many bounces a geometric
    series sums (EventDriven puts it to rest at the bounce below its rest speed). PIT (30 frames per unit
    time) answers each bounce at the first frame below the floor, so its bounce times and heights drift from
    the series, and once a bounce lasts less than a frame the ball jitters on the floor instead of resting.

    Example:
        >>> case = bouncing_ball()
        >>> case.laws, case.frame_rate, case.until
        ({'gravity': (0.0, -9.81), 'restitution': 0.8}, 30.0, 10.0)
    """
    r = 0.5
    discs = Discs([[2.0, r + height]], [[0.0, 0.0]], radii=r)
    return Scenario(
        discs,
        Box(4.0, 7.0),
        frame_rate=30.0,
        until=10.0,
        name="bouncing_ball",
        description=(
            "A ball bounces to rest under gravity with restitution: PIT answers each bounce below the floor, "
            "so its bounce times and heights drift from the exact geometric series, and it jitters on the "
            "floor instead of resting."
        ),
        laws={"gravity": (0.0, -float(gravity)), "restitution": float(restitution)},
    )


def terminal_fall(drag: float = 2.0, height: float = 8.0, gravity: float = 9.81, restitution: float = 0.5) -> Scenario:
    """A ball falling through a viscous fluid at its terminal velocity onto the floor, under linear drag (issue 27).

    One disc of radius 0.5, its bottom ``height`` above the floor of a 4 x 10 box, at rest, under
    ``gravity=(0, -gravity)``, ``drag`` and ``restitution``. Exactly (PIC), its speed relaxes to the terminal
    velocity ``g / gamma`` (4.905 at the defaults) within a few ``1 / gamma``, and it hits the floor when its drop
    ``(g / gamma) (t - tau(t))``, ``tau(t) = (1 - e^(-gamma t)) / gamma``, reaches ``height`` (``t = 2.124`` at the
    defaults); each bounce then rises less high than without drag. PIT (30 frames per unit time) follows the same
    exact flight between frames, but answers each bounce at the first frame below the floor.

    Example:
        >>> case = terminal_fall()
        >>> case.laws, case.frame_rate, case.until
        ({'gravity': (0.0, -9.81), 'drag': 2.0, 'restitution': 0.5}, 30.0, 5.0)
    """
    r = 0.5
    discs = Discs([[2.0, r + height]], [[0.0, 0.0]], radii=r)
    return Scenario(
        discs,
        Box(4.0, 10.0),
        frame_rate=30.0,
        until=5.0,
        name="terminal_fall",
        description=(
            "A ball falls at its terminal velocity under drag onto the floor and bounces: PIT follows the exact "
            "flight between frames but answers each bounce below the floor, a frame late at most."
        ),
        laws={"gravity": (0.0, -float(gravity)), "drag": float(drag), "restitution": float(restitution)},
    )


def paddle_tunnel(speed: float = 20.0, paddle_speed: float = 10.0) -> Scenario:
    """A fast disc and a thin paddle (a moving segment) head for each other; PIT's frames straddle the crossing
    (issue 28).

    One disc of radius ``r = 0.2`` at ``x_d = 2`` on the line y = 5 of a 20 x 10 box, moving at ``speed`` along
    x; a vertical paddle (the segment x = ``x_p = 14.5``, y from 3 to 7, ``laws["segments"]``) moving at
    ``-paddle_speed``. Exactly (PIC) the disc's edge meets the paddle at
    ``t_c = (x_p - x_d - r) / (speed + paddle_speed)`` (0.41 at the defaults), and the bounce in the paddle's
    frame sends the disc back at ``-(speed + 2 paddle_speed)`` (-40). PIT (30 frames per unit time) moves the two
    1 closer per frame (30 / 30), more than the disc's diameter: at the defaults the frame at 0.4 finds the centre
    0.5 short of the paddle and the one at 0.4333 0.5 past it, so the disc tunnels through and flies on (to x = 14
    at ``until``). A frame must find the centre less than ``r`` short of the paddle (a centre past a thin paddle
    moves away from it): with ``"resolve"`` at 150 frames per unit time (0.2 a frame) the frame at 0.41333 does,
    0.0033 late; ``"revert"``, which tests the disc where it was at the frame before, catches it from 60.

    Example:
        >>> case = paddle_tunnel()
        >>> case.laws["segments"], case.frame_rate, case.until
        ((Segment([14.5, 3.0], [14.5, 7.0], velocity=[-10.0, 0.0]),), 30.0, 0.6)
    """
    discs = Discs([[2.0, 5.0]], [[float(speed), 0.0]], radii=0.2)
    paddle = Segment((14.5, 3.0), (14.5, 7.0), velocity=(-float(paddle_speed), 0.0))
    return Scenario(
        discs, Box(20.0, 10.0), frame_rate=30.0, until=0.6, name="paddle_tunnel",
        description=(
            "A fast disc and a thin moving paddle close 1 per frame, more than the disc's diameter: PIT's frames "
            "straddle the crossing and the disc tunnels through the paddle, which PIC bounces it off at the exact "
            "time."
        ),
        laws={"segments": (paddle,)},
    )  # fmt: skip


def law_cases() -> list[Scenario]:
    """The cases that compare PIT against PIC under the laws of issues 27 and 28 (run both with ``**case.laws``).

    Example:
        >>> [case.name for case in law_cases()]
        ['bouncing_ball', 'terminal_fall', 'paddle_tunnel']
    """
    return [bouncing_ball(), terminal_fall(), paddle_tunnel()]


def head_on(m1: float = 1.0, m2: float = 1.0) -> Scenario:
    """A head-on collision of disc 0 (mass ``m1``, speed 1) with disc 1 (mass ``m2``, at rest).

    Radius 1, centres 4 apart on y = 5 in a 20 x 10 box; contact at t = 2.
    After it the velocities along x are exactly
    ``(m1 - m2) / (m1 + m2)`` and ``2 m1 / (m1 + m2)`` (or -1 and 0 when
    ``m2`` is ``numpy.inf``). A head-on line of centres does not turn, so PIT
    gets these velocities right too, only late.

    Args:
        m1: mass of the moving disc (positive, finite).
        m2: mass of the resting disc (positive; ``numpy.inf`` for a fixed one).

    Raises:
        InvalidDiscsError: if a mass is not positive, or ``m1`` is infinite.

    Example:
        >>> case = head_on(1.0, 3.0)
        >>> case.discs.masses.tolist(), case.until
        ([1.0, 3.0], 4.0)
    """
    discs = Discs([[4.0, 5.0], [8.0, 5.0]], [[1.0, 0.0], [0.0, 0.0]], radii=1.0, masses=[m1, m2])
    return Scenario(
        discs,
        Box(20.0, 10.0),
        frame_rate=10.0,
        until=4.0,
        name="head_on",
        description=f"Head-on collision of masses {m1:g} (moving) and {m2:g} (at rest).",
    )


def newtons_cradle(n: int = 5) -> Scenario:
    """Newton's cradle: a striker hits a row of ``n - 1`` touching discs at rest.

    Equal discs of radius 1 on y = 2; the striker starts at x = 2 with speed 1,
    the row starts at x = 6 with centres exactly 2 apart, so the contact is at
    t = 2. Exactly, the momentum passes down the row at once: the last disc
    leaves at speed 1 and the others stop. PIT passes it on one frame at a time.

    Args:
        n: number of discs, striker included (>= 2).

    Raises:
        ValueError: if ``n`` is not an integer >= 2.

    Example:
        >>> case = newtons_cradle(4)
        >>> case.discs.positions[:, 0].tolist()
        [2.0, 6.0, 8.0, 10.0]
    """
    if not _is_whole(n) or n < 2:
        msg = f"n must be an integer >= 2, got {n!r}"
        raise InvalidArgumentError(msg)
    n = int(n)
    x = np.concatenate([[2.0], 6.0 + 2.0 * np.arange(n - 1)])
    positions = np.column_stack([x, np.full(n, 2.0)])
    velocities = np.zeros((n, 2))
    velocities[0, 0] = 1.0
    discs = Discs(positions, velocities, radii=1.0)
    return Scenario(
        discs,
        Box(2.0 * n + 14.0, 4.0),
        frame_rate=10.0,
        until=8.0,
        name="newtons_cradle",
        description=f"Newton's cradle of {n} discs: a striker hits a row of touching discs.",
    )


def billiard_break(rows: int = 5, speed: float = 20.0) -> Scenario:
    """A triangle rack of ``rows * (rows + 1) / 2`` discs broken by a cue disc.

    Discs of radius 1 and mass 1 in a 60 x 30 box with walls. The rack's apex
    points at the cue disc (disc 0), which starts 20 to its left, 0.01 off the
    axis, at ``speed`` along x. Neighbours in the rack are 2 (1 + 1e-6) apart,
    so nothing overlaps at the start.

    Args:
        rows: rows of the rack (>= 1).
        speed: speed of the cue disc (positive).

    Raises:
        ValueError: if ``rows`` is not a positive integer or ``speed`` is not positive.

    Example:
        >>> case = billiard_break()
        >>> len(case.discs), case.discs.velocities[0].tolist()
        (16, [20.0, 0.0])
    """
    if not _is_whole(rows) or not 1 <= rows <= 12:
        msg = f"rows must be an integer in [1, 12], got {rows!r}"
        raise InvalidArgumentError(msg)
    if not isinstance(speed, (int, float, np.number)) or not (speed > 0 and math.isfinite(speed)):
        msg = f"speed must be positive and finite, got {speed!r}"
        raise InvalidArgumentError(msg)
    rows = int(rows)
    spacing = 2.0 * (1.0 + 1e-6)
    apex = np.array([30.0, 15.0])
    rack = [
        apex + np.array([row * spacing * math.sqrt(3.0) / 2.0, (k - row / 2.0) * spacing])
        for row in range(rows)
        for k in range(row + 1)
    ]
    positions = np.vstack([[apex[0] - 20.0, apex[1] + 0.01], *rack])
    velocities = np.zeros_like(positions)
    velocities[0, 0] = speed
    discs = Discs(positions, velocities, radii=1.0)
    return Scenario(
        discs,
        Box(60.0, 30.0),
        frame_rate=60.0,
        until=3.0,
        name="billiard_break",
        description=f"A cue disc at speed {speed:g} breaks a triangle rack of {len(rack)} discs.",
    )
