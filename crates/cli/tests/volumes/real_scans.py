#!/usr/bin/env python3
"""Real scans for specula's volume tests, made and measured with independent tools only
(numpy, nibabel, pydicom; never specula).

    python real_scans.py ct-nifti OUT.nii.gz
    python real_scans.py ct-dicom OUT_DIR
    python real_scans.py bad-dicom OUT_DIR missing-slice|inconsistent-spacing
    python real_scans.py marker IN OUT --at R,A,S [--value V]
    python real_scans.py marker-dicom-series IN_DIR OUT_DIR --at R,A,S [--value V]
    python real_scans.py corner IN --fraction FX,FY,FZ
    python real_scans.py projection IN --axis A|P|L|R|S|I --above V [--size N] [--square M]
    python real_scans.py enhanced-path eCT_Supplemental.dcm|emri_small.dcm
    python real_scans.py mri-path
    python real_scans.py ct-path
    python real_scans.py selftest [--keep DIR]

The scans (Debian packages that `.ci/run` installs, and a PyPI wheel):

- CT: `invesalius-examples`' Cranium.inv3 (InVesalius 3 project: a tar.gz holding
  `<dir>/main.plist` and `<dir>/matrix.dat`, raw little-endian int16 Hounsfield units).
  Shape, dtype, file name and spacing are read from main.plist (`matrix.shape` is z, y, x;
  `spacing` is x, y, z). Orientation, established by looking at the slices (the CT table
  lies at low row index, the frontal sinus at high row index, the vertex at high slice
  index): column index increasing = the patient's Left, row index increasing = Anterior,
  slice index increasing = Superior. In RAS millimetres (NIfTI's world; +x Right,
  +y Anterior, +z Superior) the index -> world map is

      world = diag(-sx, +sy, +sz) (i, j, k) + CT_ORIGIN_RAS,  CT_ORIGIN_RAS = (122, -140, -60)

  (i = column, j = row, k = slice). The origin is an arbitrary, scanner-like one: voxel
  (0, 0, 0) is the patient's right-posterior-inferior corner at RAS (122, -140, -60) mm
  (LPS (-122, 140, -60)); the grid's centre is not at the world origin. The grid spans
  x in [-122.05, 122], y in [-140, 104.05], z in [-60, 100.5].
- MRI: `mricron-data`'s /usr/share/mricron/templates/ch2.nii.gz (Colin27 T1 with skull,
  181 x 217 x 181 uint8, 1 mm, RAS, sform code 4), read as shipped.
- Enhanced (multi-frame) DICOM: `pydicom-data`'s eCT_Supplemental.dcm (enhanced CT, 2
  frames of 512 x 512, per-frame Plane Position, shared Plane Orientation and Pixel
  Measures) and emri_small.dcm (enhanced MR, 10 frames of 64 x 64 with no functional
  groups at all: the "multi-frame object without geometry" a reader must refuse).

Subcommands:

ct-nifti OUT.nii.gz
    The CT as an int16 NIfTI-1 (nibabel): the affine above as sform and qform (code 1,
    scanner), xyzt units mm, no scaling (scl_slope 1, scl_inter 0), and NO hint of
    Hounsfield units (empty descrip, intent none, cal_min = cal_max = 0), as dcm2niix-like
    converters often leave it: a reader must recognise CT by its value range. The tar is
    read in memory; only OUT is written (through a temporary file beside it, renamed).
ct-dicom OUT_DIR
    The CT as a DICOM CT series (pydicom), one file per slice: CT Image Storage, explicit
    VR little endian, Modality CT, study/series/frame-of-reference UIDs from
    pydicom.uid.generate_uid with pydicom's prefix and fixed entropy (reruns give the same
    UIDs), Image Position (Patient) in LPS (= RAS with x and y negated), Image Orientation
    (Patient) 1\\0\\0\\0\\-1\\0 (rows run to the patient's left, columns anterior: the
    slice normal row x column points inferior, against the slices' order), Pixel Spacing
    (row spacing, column spacing), Slice Thickness, Instance Number 1..N in position order
    (inferior first), pixels stored unsigned (Pixel Representation 0) as HU + 1024 with
    Rescale Intercept -1024, Rescale Slope 1, Rescale Type HU, Bits Stored 12 (16 if the
    values need it). File names IMxxxx are in a fixed shuffled order (a reader must sort by
    position). Written into a temporary folder beside OUT_DIR, then renamed (OUT_DIR must
    not exist or be an empty folder).
bad-dicom OUT_DIR KIND
    The CT series spoiled: `missing-slice` drops the interior slice at position rank 54;
    `inconsistent-spacing` sets one slice's (rank 40) Pixel Spacing to 0.5\\0.5.
marker IN OUT --at R,A,S [--value V]
    A copy of a NIfTI file (nibabel) or of a single enhanced (multi-frame) DICOM file
    (pydicom) with a bright 5 x 5 x 5-voxel cube (clipped to the grid) centred at the voxel
    nearest the world point R,A,S (RAS mm). Its value, unless --value: CT (NIfTI whose
    minimum is <= -500, or DICOM Modality CT) max + 2000 (HU); otherwise 3 x max. A NIfTI
    whose on-disk type cannot hold the value is widened (uint8 -> int16 -> float32) and any
    scaling is dropped (values written as read). For DICOM the voxel comes from each frame's
    Plane Position, the (shared or per-frame) Plane Orientation and Pixel Measures, in LPS;
    the stored value is (value - intercept) / slope, Bits Stored raised to 16 if needed.
    Prints JSON: {"voxel": [i, j, k], "world_ras": [x, y, z], "value": v, "stored": s,
    "dtype": ..., "cube": 5, "clipped": bool}; for DICOM the voxel is (column, row, frame
    index in the file).
marker-dicom-series IN_DIR OUT_DIR --at R,A,S [--value V]
    The same for a series of single-frame slices: the slices are sorted along the slice
    normal (row direction x column direction) by Image Position, and the voxel printed is
    (column, row, rank along that normal); "slice_files" names the files touched. Other
    files are copied as they are. Written through a temporary folder, then renamed.
corner IN --fraction FX,FY,FZ
    The world RAS point at fractions FX, FY, FZ of the head's bounding box along R, A, S
    (0 = the box's minimum: the patient's left, posterior, inferior side; 1 = the right,
    anterior, superior side), the head being the largest 6-connected component of the voxels
    above a tissue threshold (-300 HU for CT, 20 % of the maximum otherwise; the component
    leaves out the CT's table and head-holder). IN is a NIfTI file, a DICOM series folder or
    an enhanced DICOM file. Prints JSON {"world_ras", "box_min", "box_max" (voxel centres),
    "threshold", "ct", "head_voxels"}.
projection IN --axis A|P|L|R|S|I --above V [--size N] [--square M]
    A coarse N x N (default 32) silhouette of the voxels whose value is above V, seen from
    that side, in the orientation a radiologist views it:
        A (from the front):    patient's left on image right, superior up
        P (from behind):       patient's left on image left, superior up
        L (camera at the patient's left): anterior on image left, superior up
        R (camera at the patient's right): anterior on image right, superior up
        S (from above):        anterior up, patient's right on image right
        I (from the feet):     anterior up, patient's left on image right
    framed to the volume's whole world bounding box (its 8 corners projected; each axis
    split into N bins), or with --square M to a square centred on that box with half-size
    M x the larger half-extent (specula frames its standard views that way with M = 1.05).
    Prints JSON: {"axis", "above", "size", "right", "up" (world directions of the image's
    +x and +y), "right_mm", "up_mm" (the framed world intervals), "count" (voxels above V),
    "rows" (N strings, top row first, '#' = some voxel above V projects there, '.' none),
    "silhouette" (the same as lists of booleans)}.
enhanced-path NAME
    The path of pydicom-data's NAME (pydicom.data.get_testdata_file), or one error line.
mri-path, ct-path
    The paths of ch2.nii.gz and Cranium.inv3, or one error line naming the Debian package.
selftest [--keep DIR]
    Converts the CT to NIfTI and DICOM in a temporary folder (or DIR), re-reads both with
    nibabel and pydicom (the series stacked by position) and compares them with the matrix
    exactly, checks the spoiled series, round-trips markers through NIfTI, the series and
    the enhanced CT, and prints where the face is (the frontal sinus: an air pocket in the
    anterior-superior part of the skull). Prints `ok ...` lines; exits 1 on any mismatch.

Any failure prints one line `real_scans.py: error: ...` on stderr and exits 1 (2 for bad
usage).
"""

import argparse
import io
import json
import os
import plistlib
import random
import shutil
import sys
import tarfile
import tempfile

import numpy as np

CRANIUM = "/usr/share/doc/invesalius-examples/examples/Cranium.inv3"
CH2 = "/usr/share/mricron/templates/ch2.nii.gz"
# Voxel (0, 0, 0) of the CT in RAS millimetres (see the module's description).
CT_ORIGIN_RAS = (122.0, -140.0, -60.0)
# pydicom's UID root; the entropy sources make the UIDs the same on every run.
UID_PREFIX = "1.2.826.0.1.3680043.8.498."
# Stored value = HU - intercept.
CT_INTERCEPT = -1024
MARKER_SIDE = 5
LPS = np.array([-1.0, -1.0, 1.0])  # LPS <-> RAS: x and y change sign


class Failure(Exception):
    """An error reported in one line."""


# --------------------------------------------------------------------------------------
# The CT: Cranium.inv3


def read_cranium(path=CRANIUM):
    """(matrix z,y,x as stored, spacing (sx, sy, sz), main.plist as a dict), read in memory."""
    if not os.path.exists(path):
        raise Failure(f"{path} is missing: install Debian's invesalius-examples")
    with tarfile.open(path, "r:*") as tar:
        members = {m.name: m for m in tar.getmembers() if m.isfile()}
        mains = [n for n in members if n.split("/")[-1] == "main.plist"]
        if len(mains) != 1:
            raise Failure(f"{path}: expected one main.plist, found {len(mains)}")
        main = mains[0]
        folder = main[: -len("main.plist")]
        plist = plistlib.loads(tar.extractfile(members[main]).read())
        matrix = plist["matrix"]
        shape = tuple(int(n) for n in matrix["shape"])
        dtype = np.dtype(matrix["dtype"]).newbyteorder("<")
        name = folder + matrix["filename"]
        if name not in members:
            raise Failure(f"{path}: {name} named by main.plist is not in the archive")
        raw = tar.extractfile(members[name]).read()
    expected = int(np.prod(shape)) * dtype.itemsize
    if len(raw) != expected:
        raise Failure(f"{path}: {name} holds {len(raw)} bytes, {shape} {dtype} needs {expected}")
    data = np.frombuffer(raw, dtype=dtype).reshape(shape)
    spacing = tuple(float(s) for s in plist["spacing"])
    if len(spacing) != 3 or len(shape) != 3:
        raise Failure(f"{path}: expected a 3-D matrix and 3 spacings")
    return data, spacing, plist


def ct_affine(spacing):
    """The CT's index (i = column, j = row, k = slice) -> RAS world map, 4 x 4."""
    sx, sy, sz = spacing
    affine = np.diag([-sx, sy, sz, 1.0])
    affine[:3, 3] = CT_ORIGIN_RAS
    return affine


def ct_volume():
    """(values indexed [i, j, k] as int16 HU, RAS affine, spacing)."""
    data, spacing, _ = read_cranium()
    return np.ascontiguousarray(data.transpose(2, 1, 0)).astype(np.int16), ct_affine(spacing), spacing


# --------------------------------------------------------------------------------------
# Writing atomically


def replace_file(write, out):
    """Calls write(tmp) with a temporary path beside `out` (same suffix), then renames it."""
    out = os.path.abspath(out)
    parent = os.path.dirname(out)
    if not os.path.isdir(parent):
        raise Failure(f"{parent} is not a folder")
    base = os.path.basename(out)
    suffix = ".nii.gz" if base.endswith(".nii.gz") else os.path.splitext(base)[1]
    fd, tmp = tempfile.mkstemp(prefix="." + base + ".", suffix=suffix, dir=parent)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, out)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def replace_dir(write, out):
    """Calls write(tmp_dir) with a new folder beside `out`, then renames it to `out` (which
    must not exist, or be an empty folder)."""
    out = os.path.abspath(out)
    parent = os.path.dirname(out)
    if not os.path.isdir(parent):
        raise Failure(f"{parent} is not a folder")
    if os.path.lexists(out) and not (os.path.isdir(out) and not os.listdir(out)):
        raise Failure(f"{out} exists and is not an empty folder")
    tmp = tempfile.mkdtemp(prefix="." + os.path.basename(out) + ".", dir=parent)
    try:
        write(tmp)
        if os.path.isdir(out):
            os.rmdir(out)
        os.rename(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


# --------------------------------------------------------------------------------------
# NIfTI


def write_ct_nifti(out):
    import nibabel as nib

    values, affine, _ = ct_volume()
    header = nib.Nifti1Header()
    header.set_data_dtype(np.int16)
    image = nib.Nifti1Image(values, affine, header)
    image.set_sform(affine, code=1)
    image.set_qform(affine, code=1)
    image.header.set_xyzt_units(xyz="mm")
    image.header["descrip"] = b""
    image.header["intent_code"] = 0
    image.header["cal_min"] = 0
    image.header["cal_max"] = 0
    image.header.set_slope_inter(1.0, 0.0)

    def write(tmp):
        nib.save(image, tmp)

    replace_file(write, out)
    return values, affine


# --------------------------------------------------------------------------------------
# DICOM series


def ct_uids():
    from pydicom.uid import generate_uid

    def uid(what):
        return generate_uid(prefix=UID_PREFIX, entropy_srcs=["specula", "Cranium.inv3", what])

    return {w: uid(w) for w in ("study", "series", "frame-of-reference")}, uid


def ct_slices(spoil=None):
    """The CT's slices as pydicom datasets, in position order (inferior first), with the file
    name each is written to. `spoil` is None, "missing-slice" or "inconsistent-spacing"."""
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian, PYDICOM_IMPLEMENTATION_UID

    data, spacing, plist = read_cranium()
    sx, sy, sz = spacing
    slices, rows, columns = data.shape
    low, high = int(data.min()), int(data.max())
    if low < CT_INTERCEPT:
        raise Failure(f"the CT's minimum {low} HU is below the intercept {CT_INTERCEPT}")
    stored_max = high - CT_INTERCEPT
    bits = 12 if stored_max < 1 << 12 else 16
    if stored_max >= 1 << 16:
        raise Failure(f"the CT's maximum {high} HU does not fit 16 unsigned bits")
    uids, uid = ct_uids()
    order = list(range(slices))
    random.Random(32).shuffle(order)  # order[k] = the file number of slice k
    origin_lps = np.array(CT_ORIGIN_RAS) * LPS
    out = []
    for k in range(slices):
        if spoil == "missing-slice" and k == 54:
            continue
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = CTImageStorage
        meta.MediaStorageSOPInstanceUID = uid(f"instance {k}")
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        meta.ImplementationClassUID = PYDICOM_IMPLEMENTATION_UID
        ds = Dataset()
        ds.file_meta = meta
        ds.SpecificCharacterSet = "ISO_IR 100"
        ds.ImageType = ["ORIGINAL", "PRIMARY", "AXIAL"]
        ds.SOPClassUID = CTImageStorage
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.StudyDate = "20120914"
        ds.StudyTime = "151208"
        ds.Modality = "CT"
        ds.Manufacturer = "specula test set-up (from InVesalius' Cranium.inv3)"
        ds.StudyDescription = str(plist.get("name", "Cranium"))[:64]
        ds.SeriesDescription = "Cranium.inv3 as a CT series"
        ds.PatientName = "Anonymous^Cranium"
        ds.PatientID = "CRANIUM"
        ds.PatientPosition = "HFS"
        ds.SliceThickness = f"{sz:g}"
        ds.StudyInstanceUID = uids["study"]
        ds.SeriesInstanceUID = uids["series"]
        ds.FrameOfReferenceUID = uids["frame-of-reference"]
        ds.StudyID = "1"
        ds.SeriesNumber = 1
        ds.InstanceNumber = k + 1
        position = origin_lps + np.array([0.0, 0.0, k * sz])
        ds.ImagePositionPatient = [f"{v:.6g}" for v in position]
        # Along a row (increasing column) towards the patient's left (+x LPS); down a column
        # (increasing row) anterior (-y LPS).
        ds.ImageOrientationPatient = ["1", "0", "0", "0", "-1", "0"]
        ds.SliceLocation = f"{position[2]:.6g}"
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.Rows = rows
        ds.Columns = columns
        spacing_rc = [f"{sy:.7g}", f"{sx:.7g}"]
        if spoil == "inconsistent-spacing" and k == 40:
            spacing_rc = ["0.5", "0.5"]
        ds.PixelSpacing = spacing_rc
        ds.BitsAllocated = 16
        ds.BitsStored = bits
        ds.HighBit = bits - 1
        ds.PixelRepresentation = 0
        ds.RescaleIntercept = str(CT_INTERCEPT)
        ds.RescaleSlope = "1"
        ds.RescaleType = "HU"
        if "window_level" in plist and "window_width" in plist:
            ds.WindowCenter = f"{plist['window_level']:g}"
            ds.WindowWidth = f"{plist['window_width']:g}"
        ds.PixelData = (data[k].astype(np.int32) - CT_INTERCEPT).astype("<u2").tobytes()
        out.append((f"IM{order[k]:04d}", ds))
    return out


def save_dicom(ds, path):
    ds.save_as(path, enforce_file_format=True)


def write_ct_dicom(out, spoil=None):
    slices = ct_slices(spoil)

    def write(tmp):
        for name, ds in slices:
            save_dicom(ds, os.path.join(tmp, name))

    replace_dir(write, out)


def read_series(folder):
    """A folder of single-frame slices: (values [i, j, k] float64 after rescale, RAS affine,
    slice files in the k order, the datasets, modality). Slices are sorted along the normal
    row x column by position; uneven gaps or mixed geometry fail."""
    import pydicom

    items = []
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if not os.path.isfile(path):
            continue
        try:
            ds = pydicom.dcmread(path)
        except pydicom.errors.InvalidDicomError:
            continue
        items.append((path, ds))
    if not items:
        raise Failure(f"{folder}: no DICOM files")
    first = items[0][1]
    iop = np.array([float(v) for v in first.ImageOrientationPatient])
    row_dir, col_dir = iop[:3], iop[3:]
    normal = np.cross(row_dir, col_dir)
    rs, cs = (float(v) for v in first.PixelSpacing)
    for path, ds in items:
        if not np.allclose([float(v) for v in ds.ImageOrientationPatient], iop, atol=1e-4):
            raise Failure(f"{path}: a different orientation")
        if not np.allclose([float(v) for v in ds.PixelSpacing], [rs, cs], rtol=1e-4):
            raise Failure(f"{path}: a different pixel spacing")
    items.sort(key=lambda item: float(np.dot(normal, [float(v) for v in item[1].ImagePositionPatient])))
    positions = np.array([[float(v) for v in ds.ImagePositionPatient] for _, ds in items])
    if len(items) > 1:
        gaps = np.diff(positions @ normal)
        if gaps.min() <= 0 or gaps.max() - gaps.min() > 0.01 * gaps.mean():
            raise Failure(f"{folder}: uneven slice gaps ({gaps.min():g} to {gaps.max():g} mm)")
        step = (positions[-1] - positions[0]) / (len(items) - 1)
    else:
        step = normal * float(first.get("SliceThickness", 1.0))
    planes = []
    for _, ds in items:
        slope = float(ds.get("RescaleSlope", 1))
        intercept = float(ds.get("RescaleIntercept", 0))
        planes.append(ds.pixel_array.astype(np.float64) * slope + intercept)
    values = np.stack(planes).transpose(2, 1, 0)  # [column, row, slice]
    affine = np.eye(4)
    affine[:3, 0] = row_dir * cs * LPS
    affine[:3, 1] = col_dir * rs * LPS
    affine[:3, 2] = step * LPS
    affine[:3, 3] = positions[0] * LPS
    return values, affine, [p for p, _ in items], [ds for _, ds in items], str(first.get("Modality", ""))


# --------------------------------------------------------------------------------------
# Enhanced (multi-frame) DICOM


def frame_geometry(ds, path):
    """Per frame: (position LPS, row direction, column direction, (row spacing, column
    spacing)), from the per-frame or shared functional groups; one error line if absent."""
    shared = ds.get("SharedFunctionalGroupsSequence")
    shared = shared[0] if shared else None
    per_frame = ds.get("PerFrameFunctionalGroupsSequence")
    frames = int(ds.get("NumberOfFrames", 1))
    if per_frame is None or len(per_frame) != frames:
        raise Failure(
            f"{path}: a multi-frame object without per-frame functional groups: no geometry "
            "(Plane Position, Plane Orientation, Pixel Measures)"
        )

    def find(group, sequence, keyword):
        for source in (group, shared):
            if source is not None and sequence in source and len(source[sequence].value) > 0:
                item = source[sequence].value[0]
                if keyword in item:
                    return item[keyword].value
        return None

    out = []
    for f, group in enumerate(per_frame):
        position = find(group, "PlanePositionSequence", "ImagePositionPatient")
        orientation = find(group, "PlaneOrientationSequence", "ImageOrientationPatient")
        spacing = find(group, "PixelMeasuresSequence", "PixelSpacing")
        missing = [
            name
            for name, v in (("Plane Position", position), ("Plane Orientation", orientation), ("Pixel Measures", spacing))
            if v is None
        ]
        if missing:
            raise Failure(f"{path}: frame {f} has no {', '.join(missing)}: no geometry")
        o = np.array([float(v) for v in orientation])
        out.append((np.array([float(v) for v in position]), o[:3], o[3:], tuple(float(v) for v in spacing)))
    return out


def frame_rescale(ds):
    """(slope, intercept) of an enhanced object (shared Pixel Value Transformation, or the
    top-level attributes); per-frame differences are refused."""
    slope, intercept = float(ds.get("RescaleSlope", 1)), float(ds.get("RescaleIntercept", 0))
    shared = ds.get("SharedFunctionalGroupsSequence")
    if shared and "PixelValueTransformationSequence" in shared[0]:
        item = shared[0].PixelValueTransformationSequence[0]
        slope, intercept = float(item.get("RescaleSlope", 1)), float(item.get("RescaleIntercept", 0))
    for group in ds.get("PerFrameFunctionalGroupsSequence") or []:
        if "PixelValueTransformationSequence" in group:
            item = group.PixelValueTransformationSequence[0]
            if (float(item.get("RescaleSlope", 1)), float(item.get("RescaleIntercept", 0))) != (slope, intercept):
                raise Failure("frames with different rescales")
    return slope, intercept


def read_enhanced(path):
    """(values [column, row, frame-by-position], RAS affine, modality)."""
    import pydicom

    ds = pydicom.dcmread(path)
    geometry = frame_geometry(ds, path)
    _, row_dir, col_dir, (rs, cs) = geometry[0]
    normal = np.cross(row_dir, col_dir)
    order = sorted(range(len(geometry)), key=lambda f: float(np.dot(normal, geometry[f][0])))
    positions = np.array([geometry[f][0] for f in order])
    slope, intercept = frame_rescale(ds)
    pixels = ds.pixel_array
    if pixels.ndim == 2:
        pixels = pixels[None]
    values = pixels[order].astype(np.float64) * slope + intercept
    if len(order) > 1:
        step = (positions[-1] - positions[0]) / (len(order) - 1)
    else:
        step = normal * float(ds.get("SliceThickness", 1.0))
    affine = np.eye(4)
    affine[:3, 0] = row_dir * cs * LPS
    affine[:3, 1] = col_dir * rs * LPS
    affine[:3, 2] = step * LPS
    affine[:3, 3] = positions[0] * LPS
    return values.transpose(2, 1, 0), affine, str(ds.get("Modality", ""))


# --------------------------------------------------------------------------------------
# Any volume


def load(path):
    """(values [i, j, k] as float, RAS affine, is_ct) of a NIfTI file, a DICOM series folder
    or an enhanced DICOM file."""
    if os.path.isdir(path):
        values, affine, _, _, modality = read_series(path)
        return values, affine, modality == "CT"
    if path.endswith(".nii") or path.endswith(".nii.gz"):
        import nibabel as nib

        image = nib.load(path)
        values = np.asarray(image.get_fdata(dtype=np.float32))
        if values.ndim != 3:
            raise Failure(f"{path}: a {values.ndim}-D image; a volume is 3-D")
        return values, image.affine, float(values.min()) <= -500.0
    values, affine, modality = read_enhanced(path)
    return values, affine, modality == "CT"


def head_threshold(values, is_ct):
    return -300.0 if is_ct else 0.2 * float(values.max())


def _scatter_min(values, index, into):
    """into[index[n]] = min(into[index[n]], values[n]) for every n."""
    order = np.argsort(index, kind="stable")
    index, values = index[order], values[order]
    starts = np.flatnonzero(np.r_[True, index[1:] != index[:-1]])
    smallest = np.minimum.reduceat(values, starts)
    into[index[starts]] = np.minimum(into[index[starts]], smallest)


def largest_component(mask):
    """The largest 6-connected component of a 3-D boolean mask [i, j, k]: runs along i,
    joined where they overlap along j or k (label propagation with pointer jumping)."""
    m = np.ascontiguousarray(np.asarray(mask, dtype=bool).transpose(2, 1, 0))  # [k, j, i]
    rows = m.reshape(-1, m.shape[2])
    padded = np.zeros((rows.shape[0], rows.shape[1] + 1), dtype=np.int8)
    padded[:, 1:] = rows
    starts = np.diff(padded, axis=1) == 1
    runs = int(starts.sum())
    if runs == 0:
        return np.zeros(mask.shape, dtype=bool)
    run_id = np.where(rows, (np.cumsum(starts.ravel()) - 1).reshape(rows.shape), -1).reshape(m.shape)
    codes = []
    for a, b in ((run_id[:, :-1], run_id[:, 1:]), (run_id[:-1], run_id[1:])):
        both = (a >= 0) & (b >= 0)
        codes.append(a[both].astype(np.int64) * runs + b[both])
    codes = np.unique(np.concatenate(codes))
    first, second = codes // runs, codes % runs
    label = np.arange(runs)
    while True:
        low = np.minimum(label[first], label[second])
        new = label.copy()
        if len(codes):
            _scatter_min(low, first, new)
            _scatter_min(low, second, new)
        while True:
            jumped = new[new]
            if np.array_equal(jumped, new):
                break
            new = jumped
        if np.array_equal(new, label):
            break
        label = new
    run_sizes = np.bincount(run_id[run_id >= 0], minlength=runs)
    biggest = int(np.argmax(np.bincount(label, weights=run_sizes)))
    keep = (run_id >= 0) & (label[np.maximum(run_id, 0)] == biggest)
    return keep.transpose(2, 1, 0)


def head_mask(values, is_ct):
    """The head: the largest 6-connected component of the voxels above the tissue threshold
    (which leaves out a CT's table and head-holder)."""
    threshold = head_threshold(values, is_ct)
    return largest_component(values > threshold), threshold


def head_box(values, affine, is_ct):
    """(RAS minimum, RAS maximum, threshold, voxels) of the head's voxel centres."""
    mask, threshold = head_mask(values, is_ct)
    count = int(mask.sum())
    if count == 0:
        raise Failure(f"no voxel above {threshold:g}")
    world = world_of(affine, np.argwhere(mask))
    return world.min(axis=0), world.max(axis=0), threshold, count


def world_of(affine, index):
    return (affine[:3, :3] @ np.asarray(index, dtype=np.float64).T).T + affine[:3, 3]


def masked_world(values, affine, above):
    index = np.argwhere(values > above)
    return world_of(affine, index), len(index)


def parse_triple(text, what):
    try:
        parts = [float(v) for v in text.split(",")]
    except ValueError:
        parts = []
    if len(parts) != 3 or not all(np.isfinite(parts)):
        raise Failure(f"{what} must be three numbers X,Y,Z, not {text!r}")
    return np.array(parts)


def cmd_corner(args):
    values, affine, is_ct = load(args.input)
    fraction = parse_triple(args.fraction, "--fraction")
    try:
        lo, hi, threshold, count = head_box(values, affine, is_ct)
    except Failure as e:
        raise Failure(f"{args.input}: {e}")
    point = lo + fraction * (hi - lo)
    print(
        json.dumps(
            {
                "world_ras": [round(float(v), 3) for v in point],
                "box_min": [round(float(v), 3) for v in lo],
                "box_max": [round(float(v), 3) for v in hi],
                "threshold": threshold,
                "ct": bool(is_ct),
                "head_voxels": count,
            }
        )
    )


# Image right and up per view, in RAS.
VIEWS = {
    "A": ((-1, 0, 0), (0, 0, 1)),
    "P": ((1, 0, 0), (0, 0, 1)),
    "L": ((0, -1, 0), (0, 0, 1)),
    "R": ((0, 1, 0), (0, 0, 1)),
    "S": ((1, 0, 0), (0, 1, 0)),
    "I": ((-1, 0, 0), (0, 1, 0)),
}


def projection(values, affine, axis, above, size=32, square=None):
    right, up = (np.array(v, dtype=np.float64) for v in VIEWS[axis])
    dims = np.array(values.shape) - 1
    corners = world_of(affine, [[dims[0] * (c & 1), dims[1] * (c >> 1 & 1), dims[2] * (c >> 2 & 1)] for c in range(8)])
    cr, cu = corners @ right, corners @ up
    r_lo, r_hi, u_lo, u_hi = cr.min(), cr.max(), cu.min(), cu.max()
    if square is not None:
        half = square * max(r_hi - r_lo, u_hi - u_lo) / 2
        rc, uc = (r_lo + r_hi) / 2, (u_lo + u_hi) / 2
        r_lo, r_hi, u_lo, u_hi = rc - half, rc + half, uc - half, uc + half
    world, count = masked_world(values, affine, above)
    grid = np.zeros((size, size), dtype=bool)
    if count:
        x = np.floor((world @ right - r_lo) / (r_hi - r_lo) * size).astype(np.int64)
        y = np.floor((u_hi - world @ up) / (u_hi - u_lo) * size).astype(np.int64)
        np.clip(x, 0, size - 1, out=x)
        np.clip(y, 0, size - 1, out=y)
        grid[y, x] = True
    return {
        "axis": axis,
        "above": above,
        "size": size,
        "right": list(VIEWS[axis][0]),
        "up": list(VIEWS[axis][1]),
        "right_mm": [round(float(r_lo), 3), round(float(r_hi), 3)],
        "up_mm": [round(float(u_lo), 3), round(float(u_hi), 3)],
        "count": int(count),
        "rows": ["".join("#" if v else "." for v in row) for row in grid],
        "silhouette": grid.tolist(),
    }


def cmd_projection(args):
    values, affine, _ = load(args.input)
    if not 2 <= args.size <= 1024:
        raise Failure("--size must be 2 to 1024")
    print(json.dumps(projection(values, affine, args.axis, args.above, args.size, args.square)))


# --------------------------------------------------------------------------------------
# Markers


def cube(center, shape):
    """Index slices of the marker cube around `center`, clipped to `shape`, and whether it was."""
    half = MARKER_SIDE // 2
    lo = [max(0, int(c) - half) for c in center]
    hi = [min(int(n), int(c) + half + 1) for c, n in zip(center, shape)]
    clipped = any(h - l != MARKER_SIDE for l, h in zip(lo, hi))
    return tuple(slice(l, h) for l, h in zip(lo, hi)), clipped


def nearest_index(affine, point, shape, what):
    index = np.linalg.solve(affine[:3, :3], point - affine[:3, 3])
    voxel = np.rint(index).astype(np.int64)
    if np.any(voxel < 0) or np.any(voxel >= np.array(shape)):
        raise Failure(f"{what}: the point {point.tolist()} (voxel {index.round(2).tolist()}) is outside the grid {list(shape)}")
    return voxel


def marker_value(maximum, is_ct, value):
    if value is not None:
        return float(value)
    return maximum + 2000.0 if is_ct else 3.0 * maximum


def marker_nifti(args, point):
    import nibabel as nib

    image = nib.load(args.input)
    header = image.header.copy()
    values = np.asarray(image.get_fdata(dtype=np.float64))
    if values.ndim != 3:
        raise Failure(f"{args.input}: a {values.ndim}-D image; a volume is 3-D")
    is_ct = float(values.min()) <= -500.0
    value = marker_value(float(values.max()), is_ct, args.value)
    voxel = nearest_index(image.affine, point, values.shape, args.input)
    where, clipped = cube(voxel, values.shape)
    values[where] = value
    # The narrowest of the file's type, int16 and float32 that holds every value exactly.
    dtype = None
    for candidate in (header.get_data_dtype(), np.dtype(np.int16), np.dtype(np.float32)):
        if candidate.kind in "iu":
            info = np.iinfo(candidate)
            if np.all(values == np.rint(values)) and values.min() >= info.min and values.max() <= info.max:
                dtype = candidate
                break
        elif candidate.kind == "f":
            dtype = candidate
            break
    header.set_data_dtype(dtype)
    out = nib.Nifti1Image(values.astype(dtype), image.affine, header)
    out.header.set_slope_inter(1.0, 0.0)
    # Keep the codes the file had (set_* above keeps the matrices; nibabel may reset codes).
    out.set_sform(image.get_sform(), code=int(image.header["sform_code"]))
    out.set_qform(image.get_qform(), code=int(image.header["qform_code"]))
    replace_file(lambda tmp: nib.save(out, tmp), args.output)
    return {
        "voxel": [int(v) for v in voxel],
        "world_ras": [round(float(v), 3) for v in world_of(image.affine, [voxel])[0]],
        "value": value,
        "stored": value,
        "dtype": str(dtype),
        "cube": MARKER_SIDE,
        "clipped": clipped,
    }


def stored_marker(ds, maximum_stored, value, is_ct, slope, intercept):
    """(real value, stored value) and widen Bits Stored if needed."""
    real_max = maximum_stored * slope + intercept
    real = marker_value(real_max, is_ct, value)
    stored = int(round((real - intercept) / slope))
    unsigned = int(ds.get("PixelRepresentation", 0)) == 0
    allocated = int(ds.BitsAllocated)
    if allocated != 16:
        raise Failure(f"Bits Allocated {allocated}: only 16-bit pixels take a marker")
    top = (1 << 16) - 1 if unsigned else (1 << 15) - 1
    if stored > top or stored < (0 if unsigned else -(1 << 15)):
        raise Failure(f"the marker's stored value {stored} does not fit 16 bits")
    bits = int(ds.BitsStored)
    limit = (1 << bits) - 1 if unsigned else (1 << (bits - 1)) - 1
    if stored > limit:
        ds.BitsStored = 16
        ds.HighBit = 15
    return real, stored


def check_native(ds, path):
    if ds.file_meta.TransferSyntaxUID.is_compressed:
        raise Failure(f"{path}: compressed pixel data ({ds.file_meta.TransferSyntaxUID.name}); a marker needs native pixels")


def marker_enhanced(args, point):
    import pydicom

    ds = pydicom.dcmread(args.input)
    check_native(ds, args.input)
    geometry = frame_geometry(ds, args.input)
    slope, intercept = frame_rescale(ds)
    target = point * LPS
    # The frame whose plane is nearest, then the in-plane index.
    best = None
    for f, (position, row_dir, col_dir, (rs, cs)) in enumerate(geometry):
        normal = np.cross(row_dir, col_dir)
        distance = abs(float(np.dot(target - position, normal)))
        if best is None or distance < best[0]:
            best = (distance, f)
    _, frame = best
    position, row_dir, col_dir, (rs, cs) = geometry[frame]
    column = int(round(float(np.dot(target - position, row_dir)) / cs))
    row = int(round(float(np.dot(target - position, col_dir)) / rs))
    pixels = ds.pixel_array.copy()
    if pixels.ndim == 2:
        pixels = pixels[None]
    frames, rows, columns = pixels.shape
    if not (0 <= column < columns and 0 <= row < rows):
        raise Failure(f"{args.input}: the point {point.tolist()} falls outside frame {frame} (column {column}, row {row})")
    # The cube spans frames by their order along the normal.
    normal = np.cross(geometry[0][1], geometry[0][2])
    order = sorted(range(frames), key=lambda f: float(np.dot(normal, geometry[f][0])))
    rank = order.index(frame)
    ranks, clipped = cube((column, row, rank), (columns, rows, frames))
    is_ct = str(ds.get("Modality", "")) == "CT"
    real, stored = stored_marker(ds, int(pixels.max()), args.value, is_ct, slope, intercept)
    for r in range(ranks[2].start, ranks[2].stop):
        pixels[order[r], ranks[1], ranks[0]] = stored
    ds.PixelData = pixels.astype(pixels.dtype.newbyteorder("<")).tobytes()
    replace_file(lambda tmp: save_dicom(ds, tmp), args.output)
    world = position + column * cs * row_dir + row * rs * col_dir
    return {
        "voxel": [column, row, frame],
        "world_ras": [round(float(v), 3) for v in world * LPS],
        "value": real,
        "stored": stored,
        "dtype": str(pixels.dtype),
        "cube": MARKER_SIDE,
        "clipped": clipped,
    }


def cmd_marker(args):
    point = parse_triple(args.at, "--at")
    if args.input.endswith(".nii") or args.input.endswith(".nii.gz"):
        if not (args.output.endswith(".nii") or args.output.endswith(".nii.gz")):
            raise Failure("the output of a NIfTI marker must end in .nii or .nii.gz")
        result = marker_nifti(args, point)
    else:
        result = marker_enhanced(args, point)
    print(json.dumps(result))


def cmd_marker_series(args):
    import pydicom

    point = parse_triple(args.at, "--at")
    values, affine, paths, datasets, modality = read_series(args.input)
    voxel = nearest_index(affine, point, values.shape, args.input)
    where, clipped = cube(voxel, values.shape)
    first = datasets[0]
    slope = float(first.get("RescaleSlope", 1))
    intercept = float(first.get("RescaleIntercept", 0))
    stored_max = max(int(pydicom.dcmread(p).pixel_array.max()) for p in paths)
    touched = {}
    real = stored = None
    for k in range(where[2].start, where[2].stop):
        ds = pydicom.dcmread(paths[k])
        check_native(ds, paths[k])
        real, stored = stored_marker(ds, stored_max, args.value, modality == "CT", slope, intercept)
        pixels = ds.pixel_array.copy()
        pixels[where[1], where[0]] = stored
        ds.PixelData = pixels.astype(pixels.dtype.newbyteorder("<")).tobytes()
        touched[paths[k]] = ds

    def write(tmp):
        for name in sorted(os.listdir(args.input)):
            source = os.path.join(args.input, name)
            if not os.path.isfile(source):
                continue
            if source in touched:
                save_dicom(touched[source], os.path.join(tmp, name))
            else:
                shutil.copy2(source, os.path.join(tmp, name))

    replace_dir(write, args.output)
    print(
        json.dumps(
            {
                "voxel": [int(v) for v in voxel],
                "world_ras": [round(float(v), 3) for v in world_of(affine, [voxel])[0]],
                "value": real,
                "stored": stored,
                "cube": MARKER_SIDE,
                "clipped": clipped,
                "slice_files": [os.path.basename(p) for p in touched],
            }
        )
    )


# --------------------------------------------------------------------------------------
# Paths


def cmd_enhanced_path(args):
    try:
        from pydicom.data import get_testdata_file
    except ImportError as e:
        raise Failure(f"pydicom is not importable ({e}): pip install pydicom pydicom-data")
    try:
        path = get_testdata_file(args.name, download=False)
    except Exception as e:  # pydicom-data missing or the name unknown
        path = None
        reason = str(e)
    else:
        reason = "not found"
    if not path or not os.path.isfile(path):
        raise Failure(f"{args.name}: {reason} among pydicom's test files (pip install pydicom-data)")
    print(path)


def cmd_mri_path(_args):
    if not os.path.isfile(CH2):
        raise Failure(f"{CH2} is missing: install Debian's mricron-data")
    print(CH2)


def cmd_ct_path(_args):
    if not os.path.isfile(CRANIUM):
        raise Failure(f"{CRANIUM} is missing: install Debian's invesalius-examples")
    print(CRANIUM)


# --------------------------------------------------------------------------------------
# Self-test


def face(values, affine):
    """Orientation evidence on the CT: where the head's box is, where the rest above -300 HU
    (the table) lies, and where the air enclosed in the head (sinuses, nasal cavity,
    mastoids) is centred, as fractions of the head's box along R, A, S."""
    head, _ = head_mask(values, True)
    world = world_of(affine, np.argwhere(head))
    lo, hi = world.min(axis=0), world.max(axis=0)
    table = world_of(affine, np.argwhere((values > -300) & ~head)).mean(axis=0)
    # Enclosed: between the first and last head voxel along every grid line of every axis.
    inside = np.ones_like(head)
    for axis in range(3):
        idx = np.arange(values.shape[axis]).reshape([-1 if a == axis else 1 for a in range(3)])
        first = np.where(head, idx, values.shape[axis]).min(axis=axis, keepdims=True)
        last = np.where(head, idx, -1).max(axis=axis, keepdims=True)
        inside &= (idx > first) & (idx < last)
    air = world_of(affine, np.argwhere((values < -500) & inside))
    # The frontal sinus: the enclosed air above the head's mid-height.
    high = air[air[:, 2] > (lo[2] + hi[2]) / 2]
    return lo, hi, table, air.mean(axis=0), high.mean(axis=0), len(high)


def selftest(keep=None):
    import nibabel as nib
    import pydicom

    folder = keep or tempfile.mkdtemp(prefix="real_scans-")
    os.makedirs(folder, exist_ok=True)
    try:
        data, spacing, _ = read_cranium()
        expected = data.transpose(2, 1, 0)
        nii = os.path.join(folder, "ct.nii.gz")
        write_ct_nifti(nii)
        image = nib.load(nii)
        h = image.header
        assert h.get_data_dtype() == np.int16, h.get_data_dtype()
        assert int(h["sform_code"]) == 1 and int(h["qform_code"]) == 1
        assert h.get_xyzt_units()[0] == "mm"
        assert bytes(h["descrip"]).strip(b"\0") == b"" and int(h["intent_code"]) == 0
        assert np.array_equal(np.asanyarray(image.dataobj), expected)
        assert np.allclose(image.affine, ct_affine(spacing)) and np.allclose(image.get_qform(), ct_affine(spacing), atol=1e-4)
        assert nib.aff2axcodes(image.affine) == ("L", "A", "S")
        print(f"ok ct-nifti {list(image.shape)} int16, axes {''.join(nib.aff2axcodes(image.affine))}, exact")

        series = os.path.join(folder, "ct-dicom")
        write_ct_dicom(series)
        values, affine, paths, datasets, modality = read_series(series)
        assert modality == "CT"
        # Sorted along the slice normal (row x column = inferior here), the series runs from
        # the top slice down: the matrix's k reversed, the same world.
        assert np.array_equal(values[:, :, ::-1], expected.astype(np.float64)), "the series differs from the matrix"
        top = len(paths) - 1
        flipped = affine.copy()
        flipped[:3, 3] = world_of(affine, [[0, 0, top]])[0]
        flipped[:3, 2] = -affine[:3, 2]
        assert np.allclose(flipped, ct_affine(spacing), atol=1e-4), affine
        names = [os.path.basename(p) for p in paths]
        assert names != sorted(names), "the file names follow the positions"
        assert all(ds.file_meta.TransferSyntaxUID == pydicom.uid.ExplicitVRLittleEndian for ds in datasets)
        assert all(int(ds.BitsStored) == 12 and int(ds.PixelRepresentation) == 0 for ds in datasets)
        again = os.path.join(folder, "ct-dicom-again")
        write_ct_dicom(again)
        a, b = pydicom.dcmread(os.path.join(series, "IM0000")), pydicom.dcmread(os.path.join(again, "IM0000"))
        assert a.SeriesInstanceUID == b.SeriesInstanceUID and a.SOPInstanceUID == b.SOPInstanceUID
        print(f"ok ct-dicom {len(paths)} files, stacked by position equal the matrix, affine as the NIfTI's, UIDs repeat")

        for kind in ("missing-slice", "inconsistent-spacing"):
            bad = os.path.join(folder, "bad-" + kind)
            write_ct_dicom(bad, kind)
            try:
                read_series(bad)
            except Failure as e:
                print(f"ok bad-dicom {kind}: {e}")
            else:
                raise AssertionError(f"{kind} read without complaint")

        lo, hi, table, air, sinus, count = face(expected.astype(np.float64), ct_affine(spacing))
        frac = lambda p: ((p - lo) / (hi - lo)).round(2).tolist()  # noqa: E731
        print(f"ok head box RAS {lo.round(1).tolist()} .. {hi.round(1).tolist()} mm")
        print(f"ok table (above -300 HU, outside the head) centred at RAS fractions {frac(table)}: posterior")
        print(f"ok enclosed air centred at RAS fractions {frac(air)}: anterior")
        print(f"ok frontal sinus ({count} enclosed air voxels above mid-height) at RAS {sinus.round(1).tolist()}, fractions {frac(sinus)}: anterior-superior")
        assert frac(table)[1] < 0.25 and frac(air)[1] > 0.6 and frac(sinus)[1] > 0.75 and frac(sinus)[2] > 0.5

        # Markers: NIfTI CT, NIfTI MR, the series, the enhanced CT.
        class Args:
            pass

        cases = [("ct.nii.gz", nii, os.path.join(folder, "ct-marked.nii.gz"))]
        if os.path.isfile(CH2):
            cases.append(("ch2.nii.gz", CH2, os.path.join(folder, "ch2-marked.nii.gz")))
        for label, source, out in cases:
            values, affine, is_ct = load(source)
            lo = world_of(affine, [[0, 0, 0]])[0]
            point = world_of(affine, [np.array(values.shape) * [0.3, 0.7, 0.8]])[0]
            args = Args()
            args.input, args.output, args.value = source, out, None
            result = marker_nifti(args, point)
            marked, _, _ = load(out)
            i, j, k = result["voxel"]
            assert marked[i, j, k] == result["value"] > values.max()
            assert int(np.count_nonzero(marked != values)) <= MARKER_SIDE**3
            print(f"ok marker {label}: voxel {result['voxel']} at RAS {result['world_ras']}, value {result['value']:g} ({result['dtype']})")
        args = Args()
        args.input, args.output, args.value, args.at = series, os.path.join(folder, "ct-dicom-marked"), None, "-30,60,70"
        stdout = sys.stdout
        sys.stdout = io.StringIO()
        try:
            cmd_marker_series(args)
            result = json.loads(sys.stdout.getvalue())
        finally:
            sys.stdout = stdout
        marked, affine, _, _, _ = read_series(args.output)
        i, j, k = result["voxel"]
        assert marked[i, j, k] == result["value"] and np.allclose(world_of(affine, [[i, j, k]])[0], result["world_ras"], atol=1e-3)
        print(f"ok marker-dicom-series: voxel {result['voxel']} at RAS {result['world_ras']}, value {result['value']:g}")
        try:
            from pydicom.data import get_testdata_file

            ect = get_testdata_file("eCT_Supplemental.dcm", download=False)
        except Exception:
            ect = None
        if ect:
            values, affine, _ = read_enhanced(ect)
            point = world_of(affine, [[100, 300, 1]])[0]
            args = Args()
            args.input, args.output, args.value = ect, os.path.join(folder, "ect-marked.dcm"), None
            result = marker_enhanced(args, point)
            marked, _, _ = read_enhanced(args.output)
            assert marked[100, 300, 1] == result["value"] and np.allclose(result["world_ras"], point, atol=1e-3)
            print(f"ok marker eCT_Supplemental.dcm: voxel {result['voxel']} at RAS {result['world_ras']}, value {result['value']:g}")
            emri = get_testdata_file("emri_small.dcm", download=False)
            try:
                read_enhanced(emri)
            except Failure as e:
                print(f"ok emri_small.dcm refused: {e}")
            else:
                raise AssertionError("emri_small.dcm read with geometry")
    finally:
        if keep is None:
            shutil.rmtree(folder, ignore_errors=True)


# --------------------------------------------------------------------------------------


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("ct-nifti")
    p.add_argument("output")
    p = sub.add_parser("ct-dicom")
    p.add_argument("output")
    p = sub.add_parser("bad-dicom")
    p.add_argument("output")
    p.add_argument("kind", choices=["missing-slice", "inconsistent-spacing"])
    p = sub.add_parser("marker")
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--at", required=True, help="R,A,S in millimetres")
    p.add_argument("--value", type=float)
    p = sub.add_parser("marker-dicom-series")
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--at", required=True, help="R,A,S in millimetres")
    p.add_argument("--value", type=float)
    p = sub.add_parser("corner")
    p.add_argument("input")
    p.add_argument("--fraction", required=True, help="FX,FY,FZ along R, A, S")
    p = sub.add_parser("projection")
    p.add_argument("input")
    p.add_argument("--axis", required=True, choices=sorted(VIEWS))
    p.add_argument("--above", required=True, type=float)
    p.add_argument("--size", type=int, default=32)
    p.add_argument("--square", type=float, metavar="M")
    p = sub.add_parser("enhanced-path")
    p.add_argument("name")
    sub.add_parser("mri-path")
    sub.add_parser("ct-path")
    p = sub.add_parser("selftest")
    p.add_argument("--keep", metavar="DIR")
    # "--at -60,70,60": argparse would take the negative triple for an option.
    argv = sys.argv[1:]
    for n in range(len(argv) - 1):
        if argv[n] in ("--at", "--fraction", "--above") and argv[n + 1][:1] == "-":
            argv[n : n + 2] = [argv[n] + "=" + argv[n + 1], ""]
    args = parser.parse_args([a for a in argv if a != ""])
    try:
        if args.command == "ct-nifti":
            if not (args.output.endswith(".nii") or args.output.endswith(".nii.gz")):
                raise Failure("the output must end in .nii or .nii.gz")
            write_ct_nifti(args.output)
        elif args.command == "ct-dicom":
            write_ct_dicom(args.output)
        elif args.command == "bad-dicom":
            write_ct_dicom(args.output, args.kind)
        elif args.command == "marker":
            cmd_marker(args)
        elif args.command == "marker-dicom-series":
            cmd_marker_series(args)
        elif args.command == "corner":
            cmd_corner(args)
        elif args.command == "projection":
            cmd_projection(args)
        elif args.command == "enhanced-path":
            cmd_enhanced_path(args)
        elif args.command == "mri-path":
            cmd_mri_path(args)
        elif args.command == "ct-path":
            cmd_ct_path(args)
        elif args.command == "selftest":
            selftest(args.keep)
    except Failure as e:
        print(f"real_scans.py: error: {e}", file=sys.stderr)
        sys.exit(1)
    except AssertionError as e:
        print(f"real_scans.py: error: self-test failed: {e}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
