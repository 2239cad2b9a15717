"""The float Dormand-Prince integrator: accuracy, events, dense output, failure."""

import math

import pytest

from reduced.ode import IntegrationError, dopri5


def test_event_time_of_tan():
    """y' = 1 + y^2, y(0) = 0 is tan t: the event y = 1 fires at pi/4."""
    sol = dopri5(lambda t, y: [1 + y[0] ** 2], 0.0, [0.0], 10.0, 1e-10, [1e-14],
                 events=[lambda t, y: y[0] - 1.0])
    assert sol.event == 0
    assert sol.t[-1] == pytest.approx(math.pi / 4, rel=1e-9)      # event refined with real steps
    assert sol.y[-1][0] == pytest.approx(1.0, rel=1e-9)


def test_dense_output_is_fourth_order_accurate():
    sol = dopri5(lambda t, y: [-y[0], y[0] - y[1]], 0.0, [1.0, 0.0], 5.0, 1e-9, [1e-14, 1e-14],
                 dense_output=True)
    assert sol.event is None and sol.t[-1] == pytest.approx(5.0)
    for i, dense in enumerate(sol.dense):
        tm = 0.5 * (sol.t[i] + sol.t[i + 1])
        y = dense(tm)
        assert y[0] == pytest.approx(math.exp(-tm), rel=1e-7)
        assert y[1] == pytest.approx(tm * math.exp(-tm), abs=1e-8)


def test_singular_right_hand_side_raises():
    """y' = 1/(1-t) blows up at t = 1: the integrator says where instead of returning garbage."""
    with pytest.raises(IntegrationError, match="step size underflow|steps reached"):
        dopri5(lambda t, y: [1.0 / (1.0 - t) ** 2], 0.0, [0.0], 2.0, 1e-8, [1e-12], max_steps=5000)
