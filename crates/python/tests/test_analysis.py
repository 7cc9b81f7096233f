"""Analysis against values derived without specula: closed forms, SciPy quadrature, NumPy on
dense grids; and the rows against the CLI's own JSON."""

import math

import numpy as np
import pytest
from scipy import integrate

import specula

ALL = specula.lobe_ids()


@pytest.mark.parametrize("n", [1.0, 10.0, 300.0])
def test_zones_are_where_t_to_the_n_crosses_its_levels(n):
    zones = specula.zones(n)
    assert zones["epicentre_cos"] ** n == pytest.approx(0.5, rel=1e-12)
    assert zones["bloom_cos"] ** n == pytest.approx(1 / 256, rel=1e-12)
    assert math.cos(zones["epicentre_angle"]) == pytest.approx(zones["epicentre_cos"], rel=1e-12)


def energy_by_scipy(lobe):
    """(n + 1) int_0^{pi/2} lobe(cos g) sin g dg = (n + 1) int_0^1 lobe(t) dt, by SciPy's
    trapezoid rule on 2^22 + 1 points: the bit-trick lobes have kinks (their float
    exponent's steps) that adaptive quadrature cannot see, and the rule's error on this grid
    is below 1e-9 either way."""
    t = np.linspace(0.0, 1.0, (1 << 22) + 1)
    return (lobe.n + 1) * integrate.trapezoid(lobe(t), t)


@pytest.mark.parametrize("lobe", ALL)
@pytest.mark.parametrize("n", [8.0, 100.0])
def test_energy_ratio_is_scipys_quadrature(lobe, n):
    model = specula.Lobe(lobe, n)
    assert model.energy_ratio() == pytest.approx(energy_by_scipy(model), rel=1e-7)


def test_pows_energy_ratio_is_one():
    assert specula.Lobe("pow", 37).energy_ratio() == pytest.approx(1.0, rel=1e-10)


@pytest.mark.parametrize("n", [1.0, 20.0, 500.0])
def test_albedo_at_normal_incidence_is_the_closed_form(n):
    # Phong geometry, wo along the normal: t = cos(theta_i), so
    # int (n+1)/(2 pi) t^n cos(theta) dw = (n + 1) / (n + 2).
    lobe = specula.Lobe("pow", n, normalisation="lobe")
    assert lobe.albedo(0.0) == pytest.approx((n + 1) / (n + 2), rel=1e-9)


@pytest.mark.parametrize("geometry", ["phong", "blinn"])
@pytest.mark.parametrize("lobe", ["pow", "cosquad", "schlick"])
def test_albedo_off_normal_is_scipys_double_integral(geometry, lobe):
    model = specula.Lobe(lobe, 16, geometry=geometry, normalisation="lobe")
    theta_o = 0.7
    wo = np.array([math.sin(theta_o), 0.0, math.cos(theta_o)])

    def integrand(theta, phi):
        wi = np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi),
                       math.cos(theta)])
        if geometry == "phong":
            t = float(np.dot(2 * wo[2] * np.array([0, 0, 1.0]) - wo, wi))
        else:
            h = (wo + wi) / np.linalg.norm(wo + wi)
            t = h[2]
        return model.constant * model(t) * math.cos(theta) * math.sin(theta)

    expected, _ = integrate.dblquad(integrand, 0, 2 * math.pi, 0, math.pi / 2,
                                    epsabs=1e-9, epsrel=1e-7)
    assert model.albedo(theta_o) == pytest.approx(expected, rel=1e-5)


@pytest.mark.parametrize("lobe", ALL)
def test_epicentre_error_is_numpys_on_a_dense_grid(lobe):
    n = 64.0
    model = specula.Lobe(lobe, n)
    figures = specula.errors(model)
    t = np.linspace(specula.zones(n)["epicentre_cos"], 1.0, 400_001)
    reference = t**n
    dense = np.max(np.abs(model(t) - reference) / reference)
    # The library samples each zone (100,001 points); the dense grid can only find more.
    assert figures["epicentre_max_rel"] <= dense * (1 + 1e-9) + 1e-15
    assert figures["epicentre_max_rel"] >= dense * 0.98 - 1e-12


def test_pow_has_no_error():
    figures = specula.errors(specula.Lobe("pow", 50))
    assert figures["epicentre_max_rel"] < 1e-12 and figures["tail_max_abs"] < 1e-12


@pytest.mark.parametrize("geometry", ["phong", "blinn"])
def test_the_specular_brdf_is_reciprocal(geometry):
    lobe = specula.Lobe("cosquad", 30, geometry=geometry, normalisation="lobe")
    assert lobe.reciprocity_error(pairs=20_000, seed=7) < 1e-12


def test_analyze_rows_are_the_clis(cli_json):
    ours = specula.analyze(["cosquad", "schlick"], [16, 64])
    theirs = cli_json("analyze", "--lobe", "cosquad,schlick", "--n", "16,64",
                      "--format", "json")
    assert ours == theirs


def test_errors_are_analyzes_figures_and_numpy_scalars_are_exponents():
    # errors() samples as `specula analyze` does by default, so the figures are its row's;
    # a NumPy scalar is one exponent, as a Python number is.
    for n in [np.int64(64), np.float32(16.0), 64]:
        rows = specula.analyze("cosquad", n)
        assert len(rows) == 1 and rows[0]["n"] == float(n)
        figures = specula.errors(specula.Lobe("cosquad", float(n)))
        assert figures and figures == {key: rows[0][key] for key in figures}


VERDICTS = {"holds", "holds with qualification", "does not hold"}


def test_claims_give_verdicts():
    rows = specula.claims(exponent_steps=4, samples_per_zone=2_001, reciprocity_pairs=2_000)
    assert len(rows) >= 6
    for row in rows:
        assert row["verdict"] in VERDICTS, row["verdict"]
        assert row["claim"] and row["measured"]


def test_bad_analysis_arguments_are_refused():
    with pytest.raises(ValueError, match=r"valid precisions: f64, f32, simd"):
        specula.analyze(["pow"], [8], precision="f16")
    with pytest.raises(ValueError, match=r"\[1, 1000\]"):
        specula.zones(0)
    with pytest.raises(ValueError, match=r"theta_o"):
        specula.Lobe("pow", 8).albedo(float("nan"))
