"""The lobes as microfacet distributions against SciPy: the projected area by adaptive
quadrature, Beckmann's masking by its erfc closed form, pow's D by Walter's (n + 2) / (2 pi)."""

import math

import numpy as np
import pytest
from scipy import integrate, special

import specula


@pytest.mark.parametrize("lobe", ["pow", "cosquad", "sg-karis", "schlick-mod", "logexp"])
@pytest.mark.parametrize("n", [8.0, 200.0])
def test_the_projected_area_is_one(lobe, n):
    d = specula.Microfacet(specula.Lobe(lobe, n))
    width = math.sqrt(2.0 / (n + 2.0))
    points = [1.0 - (width * 2.0**k) ** 2 / 2.0 for k in range(-2, 6) if width * 2.0**k < 1.4]
    area, _ = integrate.quad(lambda t: 2.0 * math.pi * d.d(t) * t, 0.0, 1.0,
                             points=points, limit=400, epsabs=1e-12)
    assert area == pytest.approx(1.0, abs=1e-6)


def test_pow_is_walters_phong_distribution():
    n = 40.0
    t = np.linspace(0.5, 1.0, 101)
    d = specula.Microfacet(specula.Lobe("pow", n)).d(t)
    np.testing.assert_allclose(d, (n + 2.0) / (2.0 * math.pi) * t**n, rtol=1e-7)


@pytest.mark.parametrize("alpha", [0.1, 0.5])
def test_beckmann_masking_is_the_erfc_closed_form(alpha):
    cos = np.cos(np.radians(np.linspace(1.0, 89.0, 89)))
    a = cos / (alpha * np.sqrt(1.0 - cos**2))
    expected = 0.5 * (np.exp(-a * a) / (a * math.sqrt(math.pi)) - special.erfc(a))
    got = specula.Microfacet.beckmann(alpha).smith_lambda(cos)
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-15)
    g1 = specula.Microfacet.beckmann(alpha).g1(cos)
    np.testing.assert_allclose(g1, 1.0 / (1.0 + expected), rtol=1e-9)


def test_bad_values_are_refused_with_their_names():
    with pytest.raises(ValueError, match="alpha"):
        specula.Microfacet.ggx(0.0)
    with pytest.raises(ValueError, match="float64"):
        specula.Microfacet.ggx(0.2).d(np.ones(3, dtype=np.float32))
