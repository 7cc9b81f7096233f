"""Rendering scenes and volumes to arrays; a real MRI against nibabel's reading of it."""

import numpy as np
import pytest

import specula
from conftest import required


def test_the_default_scene_renders_to_linear_radiance():
    image = specula.render(width=64, height=48, samples=1)
    assert image.shape == (48, 64, 3) and image.dtype == np.float32
    assert np.isfinite(image).all() and (image >= 0).all() and image.max() > 0


def test_a_lobe_spelled_as_a_formula_renders_as_the_built_in():
    built_in = specula.render(width=48, height=32, samples=1, lobe="pow", n=40)
    spelled = specula.render(width=48, height=32, samples=1, lobe="=t^n", n=40)
    np.testing.assert_allclose(spelled, built_in, rtol=1e-4, atol=1e-5)
    # Another lobe changes the highlights, not the whole picture.
    other = specula.render(width=48, height=32, samples=1, lobe="sg", n=40)
    assert 0 < np.mean(np.abs(other - built_in)) < 0.1 * np.mean(built_in)


def test_a_scene_file_renders(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(specula.default_scene())
    np.testing.assert_array_equal(
        specula.render(scene, width=32, height=24, samples=1),
        specula.render(width=32, height=24, samples=1),
    )


def test_an_environment_is_path_traced():
    image = specula.render(environment="sky", width=32, height=24, spp=4, seed=1)
    assert image.shape == (24, 32, 3) and np.isfinite(image).all()


def test_bad_render_requests_are_refused(tmp_path):
    with pytest.raises(OSError, match=r"missing\.toml"):
        specula.render(tmp_path / "missing.toml")
    with pytest.raises(OSError):
        specula.render(tmp_path)  # a folder, not a scene file
    bad = tmp_path / "bad.toml"
    bad.write_text("[camera\n")
    with pytest.raises(ValueError, match=r"bad\.toml"):
        specula.render(bad)
    with pytest.raises(ValueError, match=r"valid shadings: flat, gouraud, phong"):
        specula.render(shading="toon")
    # The renderer's own refusal, naming its limits.
    with pytest.raises(ValueError, match=r"cannot render 0x\d+ pixels .*width and height must "
                       r"be at least 1"):
        specula.render(width=0)
    with pytest.raises(ValueError, match=r"samples in \[1, 8\]"):
        specula.render(samples=9)
    with pytest.raises(ValueError, match=r"spp must be in \[1, 65536\]"):
        specula.render(environment="sky", spp=0)
    with pytest.raises(ValueError, match=r"width -3 is negative"):
        specula.render(width=-3)
    with pytest.raises(ValueError, match=r"width 4294967296 is out of range; give at most "
                       r"4294967295"):
        specula.render(width=2**32)
    with pytest.raises(ValueError, match=r"seed -1 is negative"):
        specula.render(environment="sky", seed=-1)


def test_a_real_mri_reads_as_nibabel_reads_it(mri):
    try:
        import nibabel
    except ImportError:
        required("nibabel", "pip install nibabel (crates/cli/tests/renderers/requirements.txt)")
    volume = specula.Volume.load(mri)
    theirs = nibabel.load(str(mri))
    assert volume.shape == theirs.shape
    np.testing.assert_allclose(volume.data, theirs.get_fdata(dtype=np.float32), rtol=1e-6)
    np.testing.assert_allclose(volume.affine, theirs.affine, atol=1e-4)
    image = specula.render_volume(volume, lobe="cosquad", n=64, width=48, height=40)
    assert image.shape == (40, 48, 3) and np.isfinite(image).all() and image.max() > 0


def test_phantoms_render_and_bad_volumes_are_refused(tmp_path):
    phantom = specula.Volume.phantom("phantom", 32)
    assert phantom.shape == (32, 32, 32) and phantom.units == "arbitrary"
    assert phantom.affine.shape == (4, 4)
    image = specula.render_volume(phantom, width=32, height=32, view="superior")
    assert np.isfinite(image).all()
    with pytest.raises(ValueError, match=r"valid phantoms: phantom, marschner-lobb"):
        specula.Volume.phantom("teapot")
    for side in [0, 7, 513]:
        with pytest.raises(ValueError, match=rf"side {side}: the side must be 8 to 512 voxels"):
            specula.Volume.phantom("phantom", side)
    with pytest.raises(ValueError, match=r"side -1 is negative"):
        specula.Volume.phantom("phantom", -1)
    with pytest.raises(OSError):
        specula.Volume.load(tmp_path / "absent.nii")
    junk = tmp_path / "junk.nii"
    junk.write_bytes(b"not a nifti file")
    with pytest.raises(ValueError):
        specula.Volume.load(junk)
    with pytest.raises(ValueError, match=r"ct-bone"):
        specula.render_volume(phantom, transfer="bogus")
