"""Shader export: every language, and the text the CLI writes."""

import pytest

import specula


@pytest.mark.parametrize("language", specula.languages())
def test_every_language_is_written(language):
    # OSL takes no normalisation (its closure is GGX, normalised by construction), nor does
    # VTK's module (it replaces only the power of VTK's own Phong specular).
    normalisation = "none" if language in ("osl", "vtk") else "lobe"
    code = specula.Lobe("cosquad", 64, normalisation=normalisation).shader(language)
    if language == "spirv":
        assert isinstance(code, bytes) and code[:4] == b"\x03\x02\x23\x07"
    else:
        assert isinstance(code, str) and len(code) > 100


@pytest.mark.parametrize("language", ["wgsl", "glsl", "hlsl", "msl", "osl", "mtlx", "mitsuba"])
def test_the_text_is_the_clis(cli, language):
    lobe = specula.Lobe("schlick", 32, geometry="blinn")
    code, out, err = cli("shader", "--lobe", "schlick", "--n", "32", "--geometry", "blinn",
                         "--lang", language)
    assert code == 0, err
    assert lobe.shader(language) == out


def test_bad_languages_are_refused():
    lobe = specula.Lobe("pow", 8)
    with pytest.raises(ValueError, match=r"valid languages: wgsl, glsl, hlsl, msl, spirv, osl"):
        lobe.shader("cuda")
    with pytest.raises(ValueError, match=r"valid GLSL versions: 450, 300es, 100"):
        lobe.shader("glsl", glsl_version="330")


@pytest.mark.parametrize("language", ["osl", "vtk"])
def test_a_normalisation_is_refused_as_the_cli_does(cli, language):
    with pytest.raises(ValueError) as raised:
        specula.Lobe("pow", 8, normalisation="lobe").shader(language)
    code, _, err = cli("shader", "--lobe", "pow", "--n", "8", "--normalisation", "lobe",
                       "--lang", language)
    assert code != 0 and str(raised.value) in err
