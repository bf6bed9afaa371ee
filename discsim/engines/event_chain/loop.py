"""The event chains of straight ECMC (Bernard, Krauth & Wilson 2009), written once for two runtimes.

Every function here uses only indexing, arithmetic and :mod:`math`, so the same source runs in pure Python on
plain lists and compiled by numba on numpy arrays (:mod:`.compiled` jits these very functions), as the
compression loop does.

A chain moves one disc along +x (or +y) until it would touch another disc ahead; that disc moves on for what is
left of the chain's length ``ell``, and so on (a *lift* at each contact). Each chain alternates the direction
(``dir0 + k`` even: +x, odd: +y). A disc is found ahead within the 3x3 cells around the moving disc's cell
(cells at least the largest contact distance wide, so none farther can be touched before the disc leaves its
cell), each cell of the block at its own periodic image (at least 3 cells a side: the nearest image is not
enough, a disc behind may also be ahead through the edge); when it leaves its cell it is moved to the edge and
relinked (a crossing), wrapped through the periodic
edge with its image count.

Data (per disc ``i``): ``x, y`` (in the box), ``r``, images ``ix, iy``, ``cell`` and the cell lists ``head``
(per cell), ``nxt``, ``prv`` (doubly linked). ``starts``: the first disc of each chain. ``par`` (floats): width,
height, cell width, cell height, ``ell``. ``ipar`` (ints): nx, ny, ``dir0``. ``out`` (floats): the running sum over
the lifts of the separation of the two discs along the chain's direction (the pressure's estimator).
``iout`` (ints): lifts, crossings, lifts logged. The lift log (when its arrays have room: ``len(lc)``): per lift,
the chain's number ``lc`` (``ipar[3]`` is the first's), the discs ``li`` (stopping) and ``lj`` (taking over),
``li``'s centre at the contact ``lx, ly`` and the separation ``lq``; lifts past the room are counted in
``iout[2]``, not written, so that the caller can run the same chains again with room for all.
"""

from __future__ import annotations

import math

from discsim.cells import link, unlink

INF = math.inf


def ahead(i, along_x, x, y, r, cell, head, nxt, par, ipar):
    """The first disc that disc ``i`` touches moving along +x (``along_x``) or +y while in its cell.

    Returns:
        ``(s, j, q)``: the distance to the contact (``inf``: none in reach), the disc, and the two centres'
        separation along the direction at contact (``q = sqrt(sigma^2 - h^2)``, ``h`` across it).
    """
    width = par[0]
    height = par[1]
    ncx = ipar[0]
    ncy = ipar[1]
    c = cell[i]
    cx = c // ncy
    cy = c - cx * ncy
    best = INF
    partner = -1
    sep = 0.0
    xi = x[i]
    yi = y[i]
    ri = r[i]
    for ox in range(-1, 2):
        gx = cx + ox
        sx = 0.0  # the image of the block's column: each of the 3 columns is its own (3 cells a side at least)
        if gx < 0:
            gx += ncx
            sx = -width
        elif gx >= ncx:
            gx -= ncx
            sx = width
        for oy in range(-1, 2):
            gy = cy + oy
            sy = 0.0
            if gy < 0:
                gy += ncy
                sy = -height
            elif gy >= ncy:
                gy -= ncy
                sy = height
            j = head[gx * ncy + gy]
            while j >= 0:
                if j != i:
                    dx = x[j] + sx - xi
                    dy = y[j] + sy - yi
                    if along_x:
                        b = dx
                        h = dy
                    else:
                        b = dy
                        h = dx
                    sigma = ri + r[j]
                    if b > 0.0 and h * h < sigma * sigma:
                        q = math.sqrt(sigma * sigma - h * h)
                        s = b - q
                        if s < 0.0:  # touching already (roundoff): the lift comes at once
                            s = 0.0
                        if s < best or (s == best and j < partner):
                            best = s
                            partner = j
                            sep = q
                j = nxt[j]
    return best, partner, sep


def run_chains(x, y, r, ix, iy, cell, head, nxt, prv, starts, par, ipar, out, iout, lc, li, lj, lx, ly, lq):
    """Run one chain from each disc of ``starts``; see the module's docstring. Returns the chains run."""
    cw = par[2]
    ch = par[3]
    ell = par[4]
    ncx = ipar[0]
    ncy = ipar[1]
    dir0 = ipar[2]
    lifts = 0
    crossings = 0
    room = len(lc)
    logged = iout[2]
    first = ipar[3]
    total = out[0]  # the running sum goes on lift by lift, however the chains are cut into calls
    for k in range(len(starts)):
        i = starts[k]
        along_x = (dir0 + k) % 2 == 0
        remaining = ell
        while remaining > 0.0:
            c = cell[i]
            cx = c // ncy
            cy = c - cx * ncy
            if along_x:
                edge = (cx + 1) * cw - x[i]
            else:
                edge = (cy + 1) * ch - y[i]
            if edge < 0.0:
                edge = 0.0
            s, j, q = ahead(i, along_x, x, y, r, cell, head, nxt, par, ipar)
            if s <= edge and s < remaining:  # a lift: j moves on
                if along_x:
                    x[i] += s
                else:
                    y[i] += s
                remaining -= s
                total += q
                lifts += 1
                if logged < room:
                    lc[logged] = first + k
                    li[logged] = i
                    lj[logged] = j
                    lx[logged] = x[i]
                    ly[logged] = y[i]
                    lq[logged] = q
                logged += 1
                i = j
            elif edge <= remaining:  # to the cell's edge, into the next cell
                remaining -= edge
                unlink(i, c, head, nxt, prv)
                if along_x:
                    cx += 1
                    x[i] = cx * cw
                    if cx == ncx:
                        cx = 0
                        x[i] = 0.0
                        ix[i] += 1
                else:
                    cy += 1
                    y[i] = cy * ch
                    if cy == ncy:
                        cy = 0
                        y[i] = 0.0
                        iy[i] += 1
                c = cx * ncy + cy
                link(i, c, head, nxt, prv)
                cell[i] = c
                crossings += 1
            else:  # the chain ends here
                if along_x:
                    x[i] += remaining
                else:
                    y[i] += remaining
                remaining = 0.0
    out[0] = total
    iout[0] += lifts
    iout[1] += crossings
    iout[2] = logged
    return len(starts)


#: The functions, callees before callers, in the order :mod:`.compiled` compiles them.
ORDER = ("unlink", "link", "ahead", "run_chains")
