"""The inertial model: a solid box's tensor by its closed form and by integrating over its volume,
the parallel-axis theorem by that integral, and every unphysical value refused with one line."""
import dataclasses

import numpy as np
import pytest

import kin
from kin.dynamics import InertiaError, LinkInertia
from kin.errors import ChainError


def box(m, a, b, c):
    """A uniform solid box a × b × c (m) of mass m (kg): its tensor about its centre, closed form."""
    return (m / 12 * (b * b + c * c), m / 12 * (a * a + c * c), m / 12 * (a * a + b * b), 0.0, 0.0, 0.0)


def integrated_about_origin(m, sides, centre, k=40):
    """∫ ρ (|r|² I − r rᵀ) dV over the box centred at ``centre``, midpoint rule on a k³ grid."""
    axes = [c + s * ((np.arange(k) + 0.5) / k - 0.5) for c, s in zip(centre, sides)]
    P = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    w = m / len(P)
    return w * (np.sum(P * P) * np.eye(3) - P.T @ P)


def test_box_about_its_origin_equals_the_volume_integral():
    m, sides, c = 3.0, (0.4, 0.2, 0.1), (0.05, -0.1, 0.3)
    li = LinkInertia(m, c, box(m, *sides))
    np.testing.assert_allclose(li.about_origin(), integrated_about_origin(m, sides, c), rtol=2e-3, atol=1e-6)
    np.testing.assert_allclose(li.tensor, np.diag(box(m, *sides)[:3]))


def test_scaled_from_mm():
    li = LinkInertia(2.0, (0, 0, 100), (1e4, 1e4, 2e3, 0, 0, 0)).scaled(1e-3)      # kg·mm² → kg·m²
    assert li.com == pytest.approx((0, 0, 0.1)) and li.inertia[0] == pytest.approx(1e-2)


@pytest.mark.parametrize("kw,text", [
    (dict(mass=-1.0), "mass"), (dict(mass=float("nan")), "NaN"), (dict(mass=True), "mass"),
    (dict(mass=1.0, inertia=(1, 1, 3, 0, 0, 0)), "triangle"), (dict(mass=1.0, inertia=(-1, 1, 1, 0, 0, 0)),
                                                               "positive semi-definite"),
    (dict(mass=1.0, inertia=(1, 1, 1, 2, 0, 0)), "positive semi-definite"), (dict(mass=1.0, com=(0, 0)), "centre"),
    (dict(mass=1.0, inertia=(1, 1, 1)), "inertia"), (dict(mass=1.0, viscous=-0.1), "viscous"),
    (dict(mass=0.0, inertia=(1, 1, 1, 0, 0, 0)), "massless"), (dict(mass=1e9), "mass"),
])
def test_unphysical_values_are_refused(kw, text):
    with pytest.raises(InertiaError, match=text) as e:
        LinkInertia(body="link 2", **kw)
    assert "link 2" in str(e.value) and "\n" not in str(e.value)


def test_chain_takes_inertias_payload_and_gravity():
    chain = kin.load_chain("planar_2r")
    j = tuple(dataclasses.replace(x, inertia=LinkInertia(1.0, (0.5, 0, 0), box(1.0, 1.0, 0.05, 0.05)))
              for x in chain.joints)
    c = dataclasses.replace(chain, joints=j, payload=LinkInertia(0.5), gravity=(0, -9.81, 0))
    assert c.gravity == (0.0, -9.81, 0.0) and c.joints[0].inertia.mass == 1.0
    for bad in (dict(gravity=(0, 0, float("nan"))), dict(gravity=(0, 0)), dict(gravity="down"),
                dict(payload=2.0), dict(joints=(dataclasses.replace(chain.joints[0], inertia=1.0), chain.joints[1]))):
        with pytest.raises(ChainError):
            dataclasses.replace(chain, **bad)
