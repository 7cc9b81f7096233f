"""Sampling from given uniforms: the drawn cosines against the lobe's CDF (SciPy's KS test),
the density against quadrature, and the array contracts."""

import math

import numpy as np
import pytest
from scipy import integrate, stats

import specula

NORMAL = np.array([0.0, 0.0, 1.0])


def uniforms(count, seed):
    return np.random.default_rng(seed).random((count, 2))


def lobe_cdf(lobe):
    """P(T <= x) for the lobe as a distribution of its cosine about its axis (solid angle
    dw = dt dphi, so the density is lobe(t) / int_0^1 lobe), by SciPy quadrature."""
    zones = specula.zones(lobe.n)
    points = sorted({zones["bloom_cos"], zones["epicentre_cos"]})

    def integral(x):
        inside = [p for p in points if p < x]
        return integrate.quad(lambda t: lobe(t), 0.0, x, points=inside or None, limit=500,
                              epsabs=1e-14, epsrel=1e-11)[0]

    total = integral(1.0)
    grid = np.linspace(0.0, 1.0, 4001)
    table = np.array([integral(x) for x in grid]) / total
    return lambda x: np.interp(x, grid, table)


@pytest.mark.parametrize("lobe", ["pow", "cosquad", "schlick", "sg"])
@pytest.mark.parametrize("geometry", ["phong", "blinn"])
def test_drawn_cosines_follow_the_lobe(lobe, geometry):
    model = specula.Lobe(lobe, 24, geometry=geometry)
    wi, pdf = model.sample(NORMAL, uniforms(20_000, seed=1))
    assert wi.shape == (20_000, 3) and pdf.shape == (20_000,)
    drawn = pdf > 0
    if lobe == "pow":
        cdf = lambda x: np.clip(x, 0, 1) ** (model.n + 1)  # closed form
    else:
        cdf = lobe_cdf(model)
    if geometry == "phong":
        # About the mirror direction of the normal, the normal: nothing is cut.
        assert drawn.all()
        t = wi[:, 2]
    else:
        # Blinn draws the half vector about the normal; its reflection of the normal falls
        # below the horizon where h.z < 1/sqrt(2), so the kept cosines follow the lobe's
        # distribution above that cut.
        h = wi[drawn] + NORMAL
        t = h[:, 2] / np.linalg.norm(h, axis=1)
        cut = 1 / math.sqrt(2)
        assert np.all(t >= cut - 1e-12)
        assert (~drawn).sum() <= 20_000 * cdf(cut) * 3 + 10
        below = cdf(cut)
        full = cdf
        cdf = lambda x: (full(np.maximum(x, cut)) - below) / (1 - below)
    result = stats.kstest(t, cdf)
    assert result.pvalue > 1e-3, result


@pytest.mark.parametrize("geometry", ["phong", "blinn"])
def test_the_density_integrates_to_one_and_matches_the_draws(geometry):
    model = specula.Lobe("cosquad", 40, geometry=geometry)
    theta_o = 0.3
    wo = np.array([math.sin(theta_o), 0.0, math.cos(theta_o)])

    def density(theta, phi):
        wi = np.array([[math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi),
                        math.cos(theta)]])
        return float(model.pdf(wo, wi)[0]) * math.sin(theta)

    total, _ = integrate.dblquad(density, 0, 2 * math.pi, 0, math.pi / 2,
                                 epsabs=1e-7, epsrel=1e-6)
    # Off normal a little of the lobe is cut by the horizon: at most 1, and close to it.
    assert 0.98 < total <= 1.0 + 1e-5
    wi, pdf = model.sample(wo, uniforms(2_000, seed=3))
    kept = pdf > 0
    np.testing.assert_allclose(model.pdf(wo, wi[kept]), pdf[kept], rtol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(wi[kept], axis=1), 1.0, rtol=1e-12)
    assert np.all(wi[kept][:, 2] > 0) and np.all(wi[~kept] == 0)


def test_pow_density_is_the_closed_form():
    n = 12.0
    model = specula.Lobe("pow", n)
    wi, pdf = model.sample(NORMAL, uniforms(1_000, seed=5))
    # (n + 1) / (2 pi) t^n about the mirror direction.
    np.testing.assert_allclose(pdf, (n + 1) / (2 * math.pi) * wi[:, 2] ** n, rtol=1e-9)


def test_shapes_broadcast_over_leading_axes():
    model = specula.Lobe("pow", 8)
    u = uniforms(24, seed=9).reshape(2, 3, 4, 2)
    wi, pdf = model.sample(NORMAL, u)
    assert wi.shape == (2, 3, 4, 3) and pdf.shape == (2, 3, 4)
    per_row = np.broadcast_to(NORMAL, (2, 3, 4, 3)).copy()
    wi_each, pdf_each = model.sample(per_row, u)
    np.testing.assert_array_equal(wi, wi_each)
    np.testing.assert_array_equal(pdf, pdf_each)
    assert model.value(NORMAL, wi).shape == (2, 3, 4)


def test_below_the_horizon_there_is_no_sample():
    model = specula.Lobe("pow", 8)
    wi, pdf = model.sample(np.array([0.0, 0.0, -1.0]), uniforms(10, seed=2))
    assert np.all(pdf == 0) and np.all(wi == 0)


def test_bad_sampling_arrays_are_refused_by_name():
    model = specula.Lobe("pow", 8)
    with pytest.raises(ValueError, match=r"u holds 1 at flat index 3; uniform numbers must be in \[0, 1\)"):
        model.sample(NORMAL, np.array([[0.1, 0.2], [0.3, 1.0]]))
    with pytest.raises(ValueError, match=r"u has dtype float32; it must be float64"):
        model.sample(NORMAL, np.zeros((3, 2), dtype=np.float32))
    with pytest.raises(ValueError, match=r"u has shape \(3, 3\); it must be \(\.\.\., 2\)"):
        model.sample(NORMAL, np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"wo has shape \(2, 3\)"):
        model.sample(np.tile(NORMAL, (2, 1)), np.zeros((3, 2)))
    with pytest.raises(ValueError, match=r"wi\[1\] has zero length"):
        model.pdf(NORMAL, np.array([[0, 0, 1.0], [0, 0, 0]]))
    with pytest.raises(ValueError, match=r"wo holds a non-finite value"):
        model.pdf(np.array([np.nan, 0, 1]), np.array([[0, 0, 1.0]]))
