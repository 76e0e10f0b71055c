"""Time-delayed feedback (``controllers.detumbling.tdfc``) at the longest delay its symbolic form
holds: the documented bound is "longer than MAX_SYMBOLIC_DELAY samples runs in the Python loop", so
a delay of exactly that many samples has a symbolic law, and that law dissipates as the physics
says.

Oracle: a body spinning at a constant ``ω`` in a field fixed in inertial space sees
``B(t) = exp(−[ω×] t) B₀`` (SciPy's rotation); after the delay the law's power is
``ω · (m × B) = −K |ω| sin(|ω| τ) |B_⊥|²`` (module docstring, by hand), and nothing before it.

Mutation caught (a scratch mutation run on tdfc.py with test_detumbling, test_symbolic_laws,
test_logic_laws, test_limits_detumbling, which let it through): the symbolic bound taken as
``>=`` (a delay of exactly the bound refused a symbolic law).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from controllers import TDFC
from controllers.detumbling.tdfc import MAX_SYMBOLIC_DELAY
from ocp import Magnetorquers, Measurement, Spacecraft, quat
from ocp.dynamics.layout import measurement_vector

INERTIA = np.diag([0.0109, 0.05, 0.05])


def test_a_delay_of_exactly_the_symbolic_bound_has_a_symbolic_law_that_dissipates():
    gain, sample_time = 2.0e4, 0.05
    spacecraft = Spacecraft(INERTIA, magnetorquers=Magnetorquers(None))
    longer = TDFC({"gain": gain, "delay": (MAX_SYMBOLIC_DELAY + 1) * sample_time})
    longer.reset(spacecraft, sample_time)
    assert str(MAX_SYMBOLIC_DELAY + 1) in (longer.symbolic_error() or "")
    law = TDFC({"gain": gain, "delay": MAX_SYMBOLIC_DELAY * sample_time})
    law.reset(spacecraft, sample_time)
    assert law.symbolic_error() is None
    symbolic = law.symbolic_law()
    z = symbolic.state0
    omega = np.array([0.3, -0.5, 0.4])
    rate, tau = np.linalg.norm(omega), MAX_SYMBOLIC_DELAY * sample_time  # |ω| τ = 1.13 rad < π
    b0 = np.array([2e-5, -1e-5, 3e-5])
    for k in range(MAX_SYMBOLIC_DELAY + 3):
        t = k * sample_time
        field = Rotation.from_rotvec(-omega * t).apply(b0)
        y = measurement_vector(Measurement(t, quat.IDENTITY, omega, np.zeros(0), field))
        u, z = (v.full().ravel() for v in symbolic.function(t, y, z, np.zeros(26)))
        dipole = u[-3:]
        if k < MAX_SYMBOLIC_DELAY:
            np.testing.assert_array_equal(dipole, 0.0)
            continue
        normal = field - (field @ omega) * omega / rate**2
        expected = -gain * rate * np.sin(rate * tau) * (normal @ normal)
        assert expected < 0
        assert abs(omega @ np.cross(dipole, field) - expected) <= 1e-9 * gain * rate * (normal @ normal)
