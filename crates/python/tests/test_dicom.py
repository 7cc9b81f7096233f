"""An enhanced (multi-frame) DICOM CT from pydicom-data, read by specula and by pydicom
alone: the values in Hounsfield units and the affine's placement of the corner voxels."""

import numpy as np
import pytest

import specula
from conftest import required


def test_the_enhanced_ct_reads_as_pydicom_reads_it():
    try:
        import pydicom
        from pydicom.data import get_testdata_file
    except ImportError:
        required("pydicom and pydicom-data", "pip install pydicom pydicom-data")
    path = get_testdata_file("eCT_Supplemental.dcm")
    ds = pydicom.dcmread(path)
    frames = int(ds.NumberOfFrames)
    shared = ds.SharedFunctionalGroupsSequence[0]
    per_frame = ds.PerFrameFunctionalGroupsSequence

    def group(f, name):
        own = per_frame[f]
        return (own if name in own else shared)[name][0]

    # Frames sorted along the slice normal, each rescaled by its own transformation to HU.
    stored = ds.pixel_array.astype(np.float64)
    positions = [np.array(per_frame[f].PlanePositionSequence[0].ImagePositionPatient, float)
                 for f in range(frames)]
    cosines = np.array(group(0, "PlaneOrientationSequence").ImageOrientationPatient, float)
    row, column = cosines[:3], cosines[3:]
    row_spacing, column_spacing = map(float, group(0, "PixelMeasuresSequence").PixelSpacing)
    normal = np.cross(row, column)
    order = sorted(range(frames), key=lambda f: positions[f] @ normal)
    hu = []
    for f in order:
        t = group(f, "PixelValueTransformationSequence")
        hu.append(stored[f] * float(t.RescaleSlope) + float(t.RescaleIntercept))
    expected = np.stack([h.T for h in hu], axis=-1)

    volume = specula.Volume.load(path)
    assert volume.units == "hounsfield"
    assert volume.data.shape == expected.shape == (512, 512, 2)
    # Stored integers rescaled by -1024 and held as float32: exact.
    np.testing.assert_array_equal(volume.data, expected)
    # Not vacuous: the frames differ, lie 10 mm apart, and hold air and tissue in HU.
    assert np.any(hu[0] != hu[-1])
    step = (positions[order[-1]] - positions[order[0]]) @ normal / (frames - 1)
    assert step == pytest.approx(10.0, abs=1e-6)
    assert expected.min() == -1024.0 and expected.max() > 0.0
    # Voxel (i, j, k) at slice k's LPS position plus i column spacings along the row and j
    # row spacings along the column, x and y negated for RAS.
    for k in (0, frames - 1):
        for i in (0, ds.Columns - 1):
            for j in (0, ds.Rows - 1):
                lps = positions[order[k]] + i * column_spacing * row + j * row_spacing * column
                ras = np.append(lps * np.array([-1.0, -1.0, 1.0]), 1.0)
                np.testing.assert_allclose(volume.affine @ [i, j, k, 1.0], ras, atol=1e-3)
    image = specula.render_volume(volume, lobe="sg", n=32, width=40, height=40,
                                  transfer="ct-bone")
    assert np.isfinite(image).all()
