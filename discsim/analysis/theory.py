"""Physical reference values for hard-disc systems.

Closed forms to compare simulations against: the Henderson equation of state
and the Enskog collision rate. Units: lengths in disc radii or diameters as
stated, energies in kT.
"""

from __future__ import annotations

import math

import numpy as np

from discsim.errors import InvalidArgumentError

__all__ = [
    "DISC_VIRIAL_COEFFICIENTS",
    "contact_value",
    "enskog_collision_rate",
    "enskog_diffusion",
    "henderson_z",
    "speed_cdf",
    "speed_pdf",
    "virial_z",
]


def _packing(value) -> np.ndarray:
    """``value`` as a float array of packing fractions, each finite and in ``[0, 1)``.

    Raises:
        InvalidArgumentError: naming the first value outside.
    """
    try:
        eta = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        msg = f"packing_fraction must be a number or an array of numbers, got {value!r}"
        raise InvalidArgumentError(msg) from exc
    bad = ~((eta >= 0.0) & (eta < 1.0))  # NaN included
    if bad.any():
        msg = f"packing_fraction must lie in [0, 1), got {float(eta[bad].flat[0])!r}"
        raise InvalidArgumentError(msg)
    return eta


def henderson_z(packing_fraction):
    """Henderson's hard-disc equation of state, ``Z = P A / (N kT)``.

    ``Z = (1 + eta^2 / 8) / (1 - eta)^2`` (D. Henderson, Mol. Phys. 30, 971
    (1975)); within about 0.5% of simulation data for ``eta <= 0.5``.

    Example:
        >>> round(float(henderson_z(0.5)), 4)
        4.125
    """
    eta = _packing(packing_fraction)
    return (1.0 + eta**2 / 8.0) / (1.0 - eta) ** 2


#: Reduced virial coefficients ``B_k / B_2^(k-1)`` of hard discs, k = 2..10: B_3 and B_4 exact, B_5..B_10 from
#: N. Clisby and B. M. McCoy, J. Stat. Phys. 122, 15 (2006), Table 1 (their last digits uncertain).
DISC_VIRIAL_COEFFICIENTS = (
    1.0,
    4.0 / 3.0 - math.sqrt(3.0) / math.pi,  # 0.7820044...
    2.0 - 9.0 * math.sqrt(3.0) / (2.0 * math.pi) + 10.0 / math.pi**2,  # 0.5322318...
    0.33355604,
    0.1988425,
    0.1148728,
    0.0649930,
    0.0362193,
    0.0199537,
)


def virial_z(packing_fraction, order: int = 10):
    """The virial series of the hard-disc ``Z``, summed to ``B_order``.

    ``Z = 1 + sum_{k=2}^{order} (B_k / B_2^(k-1)) (2 eta)^(k-1)`` (``B_2 rho = 2 eta`` in 2D), with the
    coefficients of :data:`DISC_VIRIAL_COEFFICIENTS`. Truncated series lie below the true ``Z`` and part
    from it as the fluid densifies (at ``eta = 0.6`` the tenth order is 4% below Henderson's equation).

    Args:
        packing_fraction: ``eta`` (a number or an array), in ``[0, 1)``.
        order: the last coefficient summed, 2 to 10.

    Example:
        >>> round(float(virial_z(0.1, order=2)), 6), round(float(virial_z(0.5)), 3)
        (1.2, 4.083)
    """
    eta = _packing(packing_fraction)
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 2 <= order <= 10:
        msg = f"order must be an integer from 2 to 10 (the last virial coefficient summed), got {order!r}"
        raise InvalidArgumentError(msg)
    x = 2.0 * eta
    z = np.ones_like(x)
    for k, b in enumerate(DISC_VIRIAL_COEFFICIENTS[: order - 1], start=1):
        z = z + b * x**k
    return z


def contact_value(packing_fraction):
    """Pair distribution at contact ``g(sigma) = (Z - 1) / (2 eta)`` from :func:`henderson_z`.

    In closed form ``g = (1 - 7 eta / 16) / (1 - eta)^2``, which is 1 at ``eta = 0``.

    Example:
        >>> float(contact_value(0.0)), round(float(contact_value(0.3)), 6)
        (1.0, 1.772959)
    """
    eta = _packing(packing_fraction)
    return (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2


def speed_pdf(speed, kT: float = 1.0, mass: float = 1.0):
    """The 2D Maxwell-Boltzmann (Rayleigh) density of speeds, per unit speed.

    ``p(v) = (m v / kT) exp(-m v^2 / (2 kT))``.

    Example:
        >>> round(float(speed_pdf(1.0)), 6)
        0.606531
    """
    v = np.asarray(speed, dtype=float)
    return (mass * v / kT) * np.exp(-mass * v**2 / (2.0 * kT))


def speed_cdf(speed, kT: float = 1.0, mass: float = 1.0):
    """The 2D Maxwell-Boltzmann (Rayleigh) cumulative distribution of speeds, ``1 - exp(-m v^2 / (2 kT))``."""
    v = np.asarray(speed, dtype=float)
    return 1.0 - np.exp(-mass * v**2 / (2.0 * kT))


def enskog_collision_rate(packing_fraction, radius: float = 1.0, kT: float = 1.0, mass: float = 1.0):
    """Enskog's mean collision rate per disc (collisions per unit time, per disc).

    ``rate = 2 sigma n g(sigma) sqrt(pi kT / m)`` in 2D, with ``sigma = 2 r``
    and number density ``n = eta / (pi r^2)``. Each collision involves two
    discs, so the total rate of collisions is ``N rate / 2``.
    """
    eta = _packing(packing_fraction)
    sigma = 2.0 * radius
    density = eta / (math.pi * radius**2)
    return 2.0 * sigma * density * contact_value(eta) * np.sqrt(math.pi * kT / mass)


def enskog_diffusion(packing_fraction, radius: float = 1.0, kT: float = 1.0, mass: float = 1.0):
    """Enskog's self-diffusion coefficient of hard discs (length^2 per time), first Sonine approximation.

    ``D_E = sqrt(kT / (pi m)) / (2 n sigma g(sigma))`` in 2D, with ``sigma = 2 r``, ``n = eta / (pi r^2)`` and
    ``g(sigma)`` from :func:`contact_value`; equivalently ``D_E = (kT / m) / rate`` with the
    :func:`enskog_collision_rate` (in 2D the velocity decorrelates at exactly the collision rate). Dilute
    discs diffuse within a few percent of it; dense ones deviate (correlated collisions, the long-time tail).

    Example:
        >>> d = enskog_diffusion(0.05)
        >>> bool(abs(d - 1.0 / float(enskog_collision_rate(0.05))) < 1e-12), round(float(d), 4)
        (True, 8.1771)
    """
    eta = _packing(packing_fraction)
    sigma = 2.0 * radius
    density = eta / (math.pi * radius**2)
    with np.errstate(divide="ignore"):
        return np.sqrt(kT / (math.pi * mass)) / (2.0 * density * sigma * contact_value(eta))
