"""Structure of a configuration: the radial distribution function g(r) and bond-orientational order psi6.

Numpy in, numpy out. Pairs are found with a cell list (cells at least ``r_max`` a side, the pairs of a block
of discs at a time), so memory grows with the pairs within ``r_max`` of a block, never with ``N^2``; N = 10^4
is fine. Distances use :meth:`~discsim.model.Box.minimum_image`, the one minimum-image rule.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from discsim.cells import grid_shape
from discsim.errors import InvalidArgumentError
from discsim.model import Box

__all__ = ["RDF", "Psi6", "pairs_within", "psi6", "rdf"]

#: The default ``r_max`` of :func:`rdf`, in mean spacings ``sqrt(A / N)``: the first few shells at any density
#: (a dense fluid's g(r) is within a few per cent of 1 beyond); the pair search costs ``N r_max^2`` per frame.
_SHELLS = 5.0
#: Candidate pairs handled at once (bounds the memory of the pair search: about 40 bytes a pair).
_PAIR_BLOCK = 1 << 21


def _positions(positions, box: Box, what: str) -> np.ndarray:
    """``positions`` as a float array ``(T, N, 2)`` (one frame if ``(N, 2)``), finite, N >= 2."""
    try:
        pos = np.asarray(positions, dtype=float)
    except (TypeError, ValueError) as exc:
        msg = f"{what}: positions must be numbers of shape (N, 2) or (T, N, 2), got {type(positions).__name__}"
        raise InvalidArgumentError(msg) from exc
    if pos.ndim == 2:
        pos = pos[None]
    if pos.ndim != 3 or pos.shape[2] != 2:
        msg = f"{what}: positions must have shape (N, 2) or (T, N, 2), got shape {pos.shape}"
        raise InvalidArgumentError(msg)
    if pos.shape[0] == 0 or pos.shape[1] < 2:
        msg = f"{what} needs at least one frame of two discs, got positions of shape {pos.shape}"
        raise InvalidArgumentError(msg)
    if not np.isfinite(pos).all():
        msg = f"{what}: positions must be finite, got {pos[~np.isfinite(pos)][0]!r}"
        raise InvalidArgumentError(msg)
    if not isinstance(box, Box):
        msg = f"{what} needs a discsim Box, got {type(box).__name__}"
        raise InvalidArgumentError(msg)
    return box.wrap(pos)


def _positive(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise InvalidArgumentError(msg)
    if not (math.isfinite(value) and value > 0):
        msg = f"{name} must be a positive, finite number, got {value!r}"
        raise InvalidArgumentError(msg)
    return float(value)


def pairs_within(positions: np.ndarray, box: Box, r_max: float) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Every pair of points closer than ``r_max``, once each, in blocks: yields ``(i, j, d)``.

    ``i``, ``j``: ``(P,)`` indices, ``d``: ``(P, 2)`` the displacement from ``i`` to ``j`` (minimum image when
    periodic), ``|d| < r_max``. A cell list with cells at least ``r_max`` a side finds candidates in the same
    and the adjacent cells (a periodic box under 3 cells a side takes every pair as a candidate); candidates
    are produced for a block of discs at a time, about :data:`_PAIR_BLOCK` at once.

    Args:
        positions: ``(N, 2)`` points inside ``box``. box: the box. r_max: the cutoff (length units);
            at most half the shorter side of a periodic box.
    """
    n = len(positions)
    if n < 2:
        return
    nx, ny = grid_shape(box, r_max, max(4 * n, 1 << 16))
    cx = np.clip((positions[:, 0] * (nx / box.width)).astype(np.int64), 0, nx - 1)
    cy = np.clip((positions[:, 1] * (ny / box.height)).astype(np.int64), 0, ny - 1)
    cell = cx * ny + cy
    order = np.argsort(cell, kind="stable")
    cell_start = np.zeros(nx * ny + 1, dtype=np.int64)
    np.cumsum(np.bincount(cell, minlength=nx * ny), out=cell_start[1:])
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n)
    if nx * ny == 1:
        offsets = [(0, 0)]
    else:
        offsets = [(0, 0), (1, 0), (1, 1), (0, 1), (-1, 1)]
    r2 = r_max * r_max
    # Candidate counts per owner and offset, so that owners can be taken in blocks of bounded work.
    targets = []
    for dx, dy in offsets:
        ox, oy = cx + dx, cy + dy
        if box.periodic:
            ox, oy = ox % nx, oy % ny
            valid = np.ones(n, dtype=bool)
        else:
            valid = (ox >= 0) & (ox < nx) & (oy < ny)
        target = np.where(valid, ox * ny + oy, 0)
        start = cell_start[target]
        stop = cell_start[target + 1]
        if dx == 0 and dy == 0:
            start = rank + 1  # same cell: only later members
        count = np.where(valid, np.maximum(stop - start, 0), 0)
        targets.append((start, count))
    work = np.cumsum(sum(count for _, count in targets))
    lo = 0
    while lo < n:
        hi = int(np.searchsorted(work, (work[lo - 1] if lo else 0) + _PAIR_BLOCK, side="right"))
        hi = max(hi, lo + 1)
        owners = np.arange(lo, hi)
        for start, count in targets:
            c = count[lo:hi]
            total = int(c.sum())
            if total == 0:
                continue
            i = np.repeat(owners, c)
            first = np.repeat(start[lo:hi] - (np.cumsum(c) - c), c)
            j = order[first + np.arange(total)]
            d = box.minimum_image(positions[j] - positions[i])
            near = np.einsum("ij,ij->i", d, d) < r2
            yield i[near], j[near], d[near]
        lo = hi


@dataclass(frozen=True)
class RDF:
    """A radial distribution function ``g(r)`` (see :func:`rdf`).

    Attributes:
        edges: ``(B + 1,)`` bin edges (length units), from 0. r: ``(B,)`` bin centres.
        g: ``(B,)`` g(r). counts: ``(B,)`` pairs counted in each bin (over all frames, each pair once).
        ideal: ``(B,)`` pairs an ideal gas of the same N in the same box would put in each bin.
        n, frames: discs and frames averaged. periodic: the box's kind.
    """

    edges: np.ndarray
    r: np.ndarray
    g: np.ndarray
    counts: np.ndarray
    ideal: np.ndarray
    n: int
    frames: int
    periodic: bool

    def contact_value(self, sigma: float, width: float | None = None, degree: int = 2) -> float:
        """``g(sigma+)``, the contact value, extrapolated from the bins just beyond ``sigma``.

        A polynomial of ``degree`` in ``r`` is fitted by least squares to the bins lying wholly in
        ``[sigma, sigma + width]``, each weighted by its Poisson error (``sqrt(counts)``), and evaluated at
        ``sigma``. For monodisperse hard discs the pressure follows: ``Z = 1 + 2 eta g(sigma+)``.

        Args:
            sigma: the contact distance (the diameter of monodisperse discs). Best on a bin edge
                (``dr = sigma / k``); a bin cut by ``sigma`` is left out.
            width: the fit window (default ``0.15 sigma``). degree: the polynomial's degree (default 2).

        Raises:
            InvalidArgumentError: if the window holds fewer than ``degree + 2`` bins with counts.
        """
        sigma = _positive("sigma", sigma)
        width = 0.15 * sigma if width is None else _positive("width", width)
        tol = 1e-9 * sigma
        use = (self.edges[:-1] >= sigma - tol) & (self.edges[1:] <= sigma + width + tol) & (self.counts > 0)
        if use.sum() < degree + 2:
            msg = (
                f"contact_value: only {int(use.sum())} bin(s) with counts lie in [sigma, sigma + width] = "
                f"[{sigma!r}, {sigma + width!r}]; a fit of degree {degree} needs {degree + 2}: use finer bins "
                "(dr) or a wider window"
            )
            raise InvalidArgumentError(msg)
        x = self.r[use] - sigma
        weights = np.sqrt(self.counts[use]) / self.g[use]  # 1 / (the Poisson error of g)
        coeffs = np.polynomial.polynomial.polyfit(x, self.g[use], degree, w=weights)
        return float(coeffs[0])

    def plot(self, ax=None):
        """``g(r)`` against ``r``, with the ideal gas's 1. Returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        ax.plot(self.r, self.g, lw=1.2)
        ax.axhline(1.0, color="0.6", lw=0.8, ls="--")
        ax.set_xlabel("r")
        ax.set_ylabel("g(r)")
        ax.set_xlim(0, self.edges[-1])
        return ax


def _ideal_pairs(edges: np.ndarray, box: Box, n: int, margin: float) -> np.ndarray:
    """Pairs an ideal gas of ``n`` points puts in each bin of ``edges``, per frame.

    Periodic: ``n (n - 1) / 2`` times the shell's area over the box's. Walled: the same times the exact
    probability that two points uniform in the rectangle ``(W - 2 margin) x (H - 2 margin)`` lie a distance in
    the bin apart, from the rectangle's set covariance ``(a - |x|)(b - |y|)``:
    ``P(r < s) = (pi a b s^2 - 4/3 (a + b) s^3 + s^4 / 2) / (a b)^2`` for ``s <= min(a, b)``.
    """
    pairs = n * (n - 1) / 2.0
    if box.periodic:
        return pairs * math.pi * np.diff(edges**2) / box.area
    a, b = box.width - 2.0 * margin, box.height - 2.0 * margin
    s = edges
    cdf = (math.pi * a * b * s**2 - 4.0 / 3.0 * (a + b) * s**3 + 0.5 * s**4) / (a * b) ** 2
    return pairs * np.diff(cdf)


def rdf(positions, box: Box, r_max: float | None = None, dr: float | None = None, *, radii=0.0) -> RDF:
    """The radial distribution function ``g(r)`` of one frame ``(N, 2)`` or averaged over frames ``(T, N, 2)``.

    ``g(r) = counts(r) / ideal(r)``: pairs at a distance in each bin (each pair once), over the pairs an
    ideal gas of the same ``N`` in the same box puts there, so ``g`` tends to 1 at large ``r`` even for a
    small system (freud's ``normalization_mode="finite_size"``).

    - **Periodic box**: distances by the minimum image; ``ideal = N (N - 1) / 2 * pi (r2^2 - r1^2) / A``.
    - **Walls** (edge correction): pairs near a wall have fewer partners in the box; the ideal count is that of
      points spread uniformly over the rectangle the centres can reach, the box shrunk by the mean radius on
      every side (``radii``), from the rectangle's exact distance distribution (see :func:`_ideal_pairs`).
      So an ideal gas gives ``g = 1`` at every ``r`` up to the shorter side; a dense fluid keeps the layering
      at the walls (a real effect, not an artefact of the normalisation).

    Args:
        positions: ``(N, 2)`` or ``(T, N, 2)`` centres (length units).
        box: the box.
        r_max: largest distance (default: the smaller of the limit below and 5 mean spacings
            ``sqrt(A / N)``, a few shells of neighbours at any density); at most half the shorter side of a
            periodic box, the shorter side with walls. The cost grows as ``N r_max^2`` per frame.
        dr: bin width (default: the contact distance ``2 * mean(radii)`` over 50 when ``radii`` are given, so
            that it falls on a bin edge; else the mean spacing over 200, fine enough for
            :meth:`RDF.contact_value` at any packing fraction above about 0.03; at least 20 bins); the bins are
            ``[0, dr), [dr, 2 dr), ...`` up to ``r_max`` (rounded down to whole bins). Choose ``dr = sigma / k``
            to read the contact value.
        radii: ``(N,)`` or one radius (default 0: points): the disc size for the default ``dr``, and with
            walls the centres' margin from the walls.

    Returns:
        :class:`RDF` (``r``, ``g``, ``counts``, ``contact_value(sigma)``, ``plot()``).

    Raises:
        InvalidArgumentError: on positions of the wrong shape or not finite, fewer than 2 discs, a bin
            width larger than half the box (or not positive), or an ``r_max`` beyond the limits above.

    Example:
        >>> import numpy as np, discsim as ds
        >>> box = ds.Box(10.0, 10.0, periodic=True)
        >>> points = np.random.default_rng(0).uniform(0, 10, size=(10, 1000, 2))  # an ideal gas, 10 frames
        >>> g = ds.rdf(points, box, r_max=2.0, dr=0.5).g
        >>> bool(np.all(np.abs(g - 1) < 0.05))
        True
    """
    pos = _positions(positions, box, "rdf()")
    frames_, n = pos.shape[0], pos.shape[1]
    half = 0.5 * min(box.width, box.height)
    if dr is not None:
        dr = _positive("dr", dr)
        if dr > half:
            msg = f"the bin width dr={dr!r} is larger than half the box ({half!r}): no bin would fit"
            raise InvalidArgumentError(msg)
    radius = float(np.mean(radii))
    if not (math.isfinite(radius) and radius >= 0.0) or 2 * radius >= min(box.width, box.height):
        msg = f"radii must be >= 0 and leave room in the box, got a mean radius of {radius!r}"
        raise InvalidArgumentError(msg)
    margin = 0.0 if box.periodic else radius
    limit = half if box.periodic else min(box.width, box.height) - 2.0 * margin
    spacing = math.sqrt(box.area / n)  # the mean distance between neighbours
    if r_max is None:
        r_max = min(limit, _SHELLS * spacing)
        if dr is not None:
            r_max = max(r_max, min(dr, limit))
    else:
        r_max = _positive("r_max", r_max)
        if r_max > limit * (1 + 1e-12):
            where = "half the shorter side of a periodic box" if box.periodic else "the shorter side of the box"
            msg = f"r_max={r_max!r} is beyond {where} ({limit!r})"
            raise InvalidArgumentError(msg)
    if dr is None:
        dr = min(2.0 * radius / 50.0 if radius > 0.0 else spacing / 200.0, r_max / 20.0)  # 20 bins at least
    bins = max(1, math.floor(r_max / dr * (1 + 1e-12)))
    edges = dr * np.arange(bins + 1)
    top = float(edges[-1])
    counts = np.zeros(bins, dtype=np.int64)
    for frame in pos:
        for _, _, d in pairs_within(frame, box, top):
            r = np.sqrt(np.einsum("ij,ij->i", d, d))
            k = np.minimum((r / dr).astype(np.int64), bins - 1)
            counts += np.bincount(k, minlength=bins)
    ideal = _ideal_pairs(edges, box, n, margin) * frames_
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.where(ideal > 0, counts / ideal, 0.0)
    return RDF(edges, 0.5 * (edges[1:] + edges[:-1]), g, counts, ideal, n, frames_, box.periodic)


@dataclass(frozen=True)
class Psi6:
    """Bond-orientational order ``psi6`` (see :func:`psi6`).

    Attributes:
        local: ``(N,)`` or ``(T, N)`` complex: each disc's ``psi6``.
        mean: complex, or ``(T,)``: the average of ``local`` over the discs (the global order parameter).
        order: ``|mean|``: 1 for a perfect triangular crystal, about ``1 / sqrt(N)`` for a fluid.
        neighbours: how the neighbours were chosen (``"6 nearest"`` or ``"within r < ..."``).
        counts: ``(N,)`` or ``(T, N)`` neighbours of each disc.
        positions: the positions analysed (for :meth:`plot`). box: the box.
    """

    local: np.ndarray
    mean: complex | np.ndarray
    order: float | np.ndarray
    neighbours: str
    counts: np.ndarray
    positions: np.ndarray
    box: Box

    def plot(self, ax=None, frame: int = -1):
        """The discs (of one frame) coloured by ``|psi6|``. Returns the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        pos = self.positions if self.positions.ndim == 2 else self.positions[frame]
        local = self.local if self.local.ndim == 1 else self.local[frame]
        points = ax.scatter(pos[:, 0], pos[:, 1], c=np.abs(local), s=4, cmap="viridis", vmin=0, vmax=1)
        ax.figure.colorbar(points, ax=ax, label="|psi6|")
        ax.set_xlim(0, self.box.width)
        ax.set_ylim(0, self.box.height)
        ax.set_aspect("equal")
        return ax


def psi6(positions, box: Box, *, k: int | None = 6, cutoff: float | None = None) -> Psi6:
    """Bond-orientational order ``psi6_j = (1 / n_j) sum_k exp(6 i theta_jk)`` per disc, and its average.

    ``theta_jk`` is the angle of the bond from disc ``j`` to neighbour ``k`` (minimum image when periodic).
    Neighbours are the ``k`` nearest discs (default 6; ties at equal distance are broken by index), or, with
    ``cutoff``, every disc closer than ``cutoff`` (then ``k`` is ignored; a disc with no neighbour has
    ``psi6 = 0``). Voronoi neighbours are not offered.

    Args:
        positions: ``(N, 2)`` or ``(T, N, 2)`` centres.
        box: the box.
        k: the number of nearest neighbours (an integer >= 1, below N).
        cutoff: a neighbour distance instead (length units; at most half the shorter side if periodic).

    Returns:
        :class:`Psi6`: ``local`` per disc, ``mean`` (complex) and ``order = |mean|``.

    Raises:
        InvalidArgumentError: on bad positions, ``k`` not in ``[1, N - 1]``, or a bad ``cutoff``.

    Example:
        >>> import numpy as np, discsim as ds
        >>> a, nx, ny = 1.0, 10, 6  # a perfect triangular lattice filling a periodic box
        >>> i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
        >>> pos = np.column_stack([(i + 0.5 * (j % 2)).ravel() * a, j.ravel() * a * np.sqrt(3) / 2])
        >>> p = ds.psi6(pos, ds.Box(nx * a, ny * a * np.sqrt(3) / 2, periodic=True))
        >>> round(p.order, 12), bool(np.allclose(np.abs(p.local), 1.0))
        (1.0, True)
    """
    pos = _positions(positions, box, "psi6()")
    n = pos.shape[1]
    limit = 0.5 * min(box.width, box.height) if box.periodic else math.hypot(box.width, box.height) * (1 + 1e-12)
    if cutoff is not None:
        cutoff = _positive("cutoff", cutoff)
        if cutoff > limit:
            msg = f"cutoff={cutoff!r} is beyond half the shorter side of the periodic box ({limit!r})"
            raise InvalidArgumentError(msg)
        label = f"within r < {cutoff:g}"
    else:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not (1 <= k <= n - 1):
            msg = f"k must be an integer in [1, N - 1] = [1, {n - 1}] (nearest neighbours), got {k!r}"
            raise InvalidArgumentError(msg)
        k = int(k)
        label = f"{k} nearest"
    local = np.zeros((pos.shape[0], n), dtype=complex)
    counts = np.zeros((pos.shape[0], n), dtype=np.int64)
    for f, frame in enumerate(pos):
        if cutoff is not None:
            i, _, d = _bonds(frame, box, cutoff)
        else:
            assert k is not None  # an int: checked above, when there is no cutoff
            i, _, d = _nearest(frame, box, k, limit)
        bond = np.exp(6j * np.arctan2(d[:, 1], d[:, 0]))
        counts[f] = np.bincount(i, minlength=n)
        sums = np.bincount(i, weights=bond.real, minlength=n) + 1j * np.bincount(i, weights=bond.imag, minlength=n)
        local[f] = np.where(counts[f] > 0, sums / np.maximum(counts[f], 1), 0.0)
    mean = local.mean(axis=1)
    if np.asarray(positions).ndim == 2:
        return Psi6(local[0], complex(mean[0]), float(abs(mean[0])), label, counts[0], pos[0], box)
    return Psi6(local, mean, np.abs(mean), label, counts, pos, box)


def _bonds(frame: np.ndarray, box: Box, cutoff: float):
    """Every bond shorter than ``cutoff``, in both directions: ``(i, j, d)`` with ``d`` from ``i`` to ``j``."""
    parts = list(pairs_within(frame, box, cutoff))
    if not parts:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 2))
    i = np.concatenate([p[0] for p in parts])
    j = np.concatenate([p[1] for p in parts])
    d = np.concatenate([p[2] for p in parts])
    return np.concatenate([i, j]), np.concatenate([j, i]), np.concatenate([d, -d])


def _nearest(frame: np.ndarray, box: Box, k: int, limit: float):
    """The ``k`` nearest neighbours of every disc: ``(i, j, d)``, ``k`` rows per disc, nearest first."""
    n = len(frame)
    # A radius holding about 2.5 k discs at the mean density, grown until every disc has k neighbours.
    reach = min(limit, math.sqrt(2.5 * k * box.area / (math.pi * n)))
    while True:
        i, j, d = _bonds(frame, box, reach)
        if np.bincount(i, minlength=n).min() >= k or reach >= limit:
            break
        reach = min(limit, reach * 1.5)
    found = np.bincount(i, minlength=n)
    if found.min() < k:
        lonely = int(np.argmin(found))
        msg = (
            f"disc {lonely} has {int(found[lonely])} neighbour(s) within {reach:g} (half the periodic box), "
            f"fewer than k={k}: use a smaller k or a cutoff"
        )
        raise InvalidArgumentError(msg)
    dist = np.einsum("ij,ij->i", d, d)
    order = np.lexsort((j, dist, i))  # by disc, then distance, then index
    i, j, d = i[order], j[order], d[order]
    starts = np.searchsorted(i, np.arange(n))
    rank = np.arange(len(i)) - starts[i]
    keep = rank < k
    return i[keep], j[keep], d[keep]
