"""Evaluating lobes on NumPy arrays: values against NumPy's own t**n, the range rules, and the
array contracts (dtype, shape, order, NaN, out)."""

import subprocess
import sys

import numpy as np
import pytest

import specula

ALL = specula.lobe_ids()


def cosines(count=10_001, dtype=np.float64):
    return np.linspace(-0.25, 1.0, count, dtype=dtype)


@pytest.mark.parametrize("n", [1.0, 7.5, 64.0, 1000.0])
def test_pow_in_float64_is_numpys_t_to_the_n(n):
    t = cosines()
    expected = np.where(t > 0, np.maximum(t, 0) ** n, 0.0)
    np.testing.assert_allclose(specula.Lobe("pow", n)(t), expected, rtol=1e-13, atol=1e-300)


@pytest.mark.parametrize("n", [2.0, 64.0, 700.0])
def test_pow_in_float32_is_within_float32_rounding_of_numpy(n):
    t = cosines(dtype=np.float32)
    got = specula.Lobe("pow", n)(t)
    assert got.dtype == np.float32
    expected = np.where(t > 0, np.maximum(t.astype(np.float64), 0) ** n, 0.0)
    # Where the value is visible (above 1e-6 of the peak): a few float32 ulps of relative
    # error, carried by n through the logarithm (the fast pow's budget).
    visible = expected > 1e-6
    relative = np.abs(got[visible] - expected[visible]) / expected[visible]
    assert relative.max() < 2e-4, relative.max()


@pytest.mark.parametrize("lobe", ALL)
def test_every_lobe_obeys_the_range_rules_in_both_precisions(lobe):
    model = specula.Lobe(lobe, 64)
    for dtype in (np.float64, np.float32):
        t = cosines(dtype=dtype)
        values = model(t)
        assert values.dtype == dtype and values.shape == t.shape
        assert np.all(values[t <= 0] == 0)
        assert np.all((values >= 0) & (values <= 1))
        assert abs(float(model(np.array([1.0], dtype=dtype))[0]) - 1.0) < 1e-3
    # The two precisions agree to float32 accuracy where the lobe is visible.
    t64 = cosines()
    exact = model(t64)
    fast = model(t64.astype(np.float32)).astype(np.float64)
    assert np.max(np.abs(fast - exact)) < 2e-3


def test_any_shape_and_order_is_kept():
    lobe = specula.Lobe("cosquad", 32)
    block = np.linspace(0.5, 1.0, 4 * 5 * 6, dtype=np.float32).reshape(4, 5, 6)
    flat = lobe(block.ravel())
    np.testing.assert_array_equal(lobe(block), flat.reshape(4, 5, 6))
    # A strided (non-contiguous) view reads the view's elements, in order.
    view = block[:, ::2, 1:]
    np.testing.assert_array_equal(lobe(view), lobe(np.ascontiguousarray(view)))
    transposed = block.T
    np.testing.assert_array_equal(lobe(transposed), lobe(np.ascontiguousarray(transposed)))
    # Zero-dimensional and empty arrays.
    assert lobe(np.array(1.0, dtype=np.float32)).shape == ()
    assert lobe(np.zeros((0, 3))).shape == (0, 3)


def test_python_numbers_give_floats():
    lobe = specula.Lobe("pow", 2)
    value = lobe(0.5)
    assert isinstance(value, float) and value == 0.25
    assert lobe(1) == 1.0


def test_out_receives_the_values_without_allocating():
    lobe = specula.Lobe("schlick", 16)
    t = cosines(dtype=np.float32)
    out = np.empty_like(t)
    assert lobe(t, out=out) is out
    np.testing.assert_array_equal(out, lobe(t))
    with pytest.raises(ValueError, match=r"out has shape"):
        lobe(t, out=np.empty(3, dtype=np.float32))
    with pytest.raises(ValueError, match=r"writable float32"):
        lobe(t, out=np.empty_like(t, dtype=np.float64))


def test_out_must_be_a_separate_writable_contiguous_array():
    lobe = specula.Lobe("pow", 4)
    t = cosines(dtype=np.float32)
    with pytest.raises(ValueError, match=r"not t itself"):
        lobe(t, out=t)
    frozen = np.empty_like(t)
    frozen.setflags(write=False)
    with pytest.raises(ValueError, match=r"writable float32"):
        lobe(t, out=frozen)
    strided = np.empty(2 * t.size, dtype=np.float32)[::2]
    with pytest.raises(ValueError, match=r"not C-contiguous"):
        lobe(t, out=strided)
    with pytest.raises(ValueError, match=r"out is given but t is a number"):
        lobe(0.5, out=np.empty(1))


def test_a_broadcast_view_of_terabytes_is_a_memory_error_not_a_crash():
    huge = np.broadcast_to(np.float32(0.5), (1 << 40,))
    with pytest.raises(MemoryError):
        specula.Lobe("pow", 8)(huge)


def test_sizes_and_seeds_are_refused_as_values_not_overflows():
    lobe = specula.Lobe("pow", 8)
    with pytest.raises(ValueError, match=r"pairs -1 is out of range; give 1 to 10000000"):
        lobe.reciprocity_error(pairs=-1)
    with pytest.raises(ValueError, match=r"seed -5 is negative"):
        lobe.reciprocity_error(pairs=10, seed=-5)
    with pytest.raises(ValueError, match=r"samples_per_zone 10000000000 is out of range"):
        specula.errors(lobe, samples_per_zone=10**10)
    with pytest.raises(ValueError, match=r"exponent_steps 100000 is out of range"):
        specula.claims(exponent_steps=100_000)


def test_other_dtypes_are_refused_by_name_not_converted():
    lobe = specula.Lobe("pow", 8)
    with pytest.raises(ValueError, match=r"t has dtype int64; specula takes float32"):
        lobe(np.arange(3, dtype=np.int64))
    with pytest.raises(ValueError, match=r"t has dtype float16"):
        lobe(np.ones(3, dtype=np.float16))
    with pytest.raises(TypeError, match=r"t is a list"):
        lobe([0.5, 0.6])


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_non_finite_cosines_are_refused_with_their_index(dtype):
    lobe = specula.Lobe("cosquad", 64)
    t = np.full(100_000, 0.9, dtype=dtype)
    t[70_123] = np.nan
    with pytest.raises(ValueError, match=r"non-finite value .* at flat index 70123"):
        lobe(t)
    t[70_123] = np.inf
    with pytest.raises(ValueError, match=r"flat index 70123"):
        lobe(t)
    with pytest.raises(ValueError, match=r"non-finite"):
        lobe(float("nan"))


def test_properties_and_normalisation():
    lobe = specula.Lobe("pow", 10, geometry="blinn", normalisation="lobe")
    assert (lobe.id, lobe.n, lobe.geometry, lobe.normalisation) == ("pow", 10, "blinn", "lobe")
    # The lobe normalisation of t^n: (n + 1) / (2 pi).
    assert lobe.constant == pytest.approx(11 / (2 * np.pi), rel=1e-12)
    assert "Lobe('pow', n=10" in repr(lobe)


def test_parameters_and_formulas_spell_lobes_as_the_cli_does():
    t = cosines()
    spelled = specula.Lobe("=t^n", 40)
    np.testing.assert_allclose(spelled(t), specula.Lobe("pow", 40)(t), rtol=1e-12, atol=1e-300)
    assert specula.Lobe("cosquad:v=5", 40).id == "cosquad:v=5"


@pytest.mark.parametrize(
    "args, cli_args",
    [
        (("bogus", 64), ["--lobe", "bogus", "--n", "64"]),
        (("pow", 2000), ["--lobe", "pow", "--n", "2000"]),
        (("pow", 0.5), ["--lobe", "pow", "--n", "0.5"]),
        (("=t^", 8), ["--lobe", "=t^", "--n", "8"]),
    ],
)
def test_bad_lobes_raise_the_clis_message(cli, args, cli_args):
    # In a fresh interpreter, as the CLI is a fresh process: the lobes a process has defined
    # are part of some messages (the valid ids, a formula's number).
    script = (
        "import specula\n"
        "try:\n"
        f"    specula.Lobe(*{args!r})\n"
        "except ValueError as error:\n"
        "    print(error)\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          check=True)
    message = done.stdout.rstrip("\n")
    assert message and "\n" not in message
    code, _, err = cli("eval", *cli_args, "--cos", "0.5")
    assert code != 0 and message in err, (message, err)


def test_bad_geometry_and_normalisation_name_the_valid_ones():
    with pytest.raises(ValueError, match=r"phong.*blinn"):
        specula.Lobe("pow", 8, geometry="ward")
    with pytest.raises(ValueError, match=r"lafortune"):
        specula.Lobe("pow", 8, normalisation="bogus")
