"""Reference physics: the hard-disc virial series against its exact low orders and Henderson's equation."""

from __future__ import annotations

import math

import numpy as np
import pytest

import discsim as ds
from discsim.analysis.theory import DISC_VIRIAL_COEFFICIENTS


def test_virial_series_low_orders_are_exact():
    eta = np.linspace(0.0, 0.6, 7)
    np.testing.assert_allclose(ds.virial_z(eta, order=2), 1.0 + 2.0 * eta, rtol=0, atol=1e-15)
    b3 = (16.0 / 3.0 - 4.0 * math.sqrt(3.0) / math.pi) / 4.0  # B_3 / B_2^2, exact
    b4 = (16.0 - 36.0 * math.sqrt(3.0) / math.pi + 80.0 / math.pi**2) / 8.0  # B_4 / B_2^3, exact
    assert DISC_VIRIAL_COEFFICIENTS[1] == pytest.approx(b3, abs=5e-9)
    assert DISC_VIRIAL_COEFFICIENTS[2] == pytest.approx(b4, abs=5e-9)
    x = 2.0 * eta
    np.testing.assert_allclose(ds.virial_z(eta, order=4), 1 + x + b3 * x**2 + b4 * x**3, rtol=1e-8)


def test_virial_series_meets_henderson_in_the_dilute_fluid_and_falls_below_it_dense():
    assert float(ds.virial_z(0.1)) == pytest.approx(float(ds.henderson_z(0.1)), rel=1e-4)
    assert float(ds.virial_z(0.3)) == pytest.approx(float(ds.henderson_z(0.3)), rel=1e-3)
    dense = np.array([0.5, 0.6, 0.7])
    assert np.all(ds.virial_z(dense) < ds.henderson_z(dense))
    orders = [float(ds.virial_z(0.5, order=k)) for k in range(2, 11)]
    assert orders == sorted(orders)  # every coefficient is positive: each order adds


@pytest.mark.parametrize("order", [1, 11, 2.0, True])
def test_virial_series_refuses_orders_it_has_no_coefficients_for(order):
    with pytest.raises(ds.InvalidArgumentError, match="order must be an integer from 2 to 10"):
        ds.virial_z(0.2, order=order)
