"""Writes the DICOM image series test files with pydicom (3.0.2, numpy, nibabel 5.4.2, Python
3.11): one CT slice a file, as scanners and PACS exports give a CT. Run from the repository root;
the files are committed:

    python tests/data/make_dicom_series.py

Outputs, in tests/data/dicom_series/:

- oblique/: 12 slices of 24 x 20 pixels on a grid rotated 20 degrees about z then 15 degrees
  about x (LPS), 1.0 mm between columns, 1.15 mm between rows and 2.5 mm between slices. Signed
  16-bit pixels; each slice has its own Rescale Intercept (-1024 on even slices, -1000 on odd
  ones), so a reader must scale slice by slice. File names are not in slice order (a hash of
  the slice number), nor are the Instance Numbers (reversed).
- oblique.nii.gz: the same grid's Hounsfield units as float32 in NIfTI (RAS), what a reader
  should produce from oblique/.
- gap/: oblique/ without its sixth slice (a different series UID): a slice missing.
- tilted/: oblique/'s slices each shifted 0.4 mm further along the row direction (a gantry
  tilt): positions that do not lie along the slices' normal.
- phantom_ct/: the first 24 slices (k 0..23) of tests/data/phantom_ct.nii.gz, the abdominal
  phantom's synthetic CT, on its segmentation's grid: unsigned 8-bit pixels with Rescale Slope 10
  and Intercept -150 (its five HU values -150, 60, 220, -60, 150 are stored as 0, 21, 37, 9,
  30). The NIfTI's float32 spacing (-0.77999997) is written to 6 decimals (0.78), as in
  make_dicom_seg.py.

Geometry as in make_dicom_seg.py: Columns run along i and Rows along j, ImageOrientationPatient
= [unit i axis in LPS, unit j axis in LPS], PixelSpacing = [j spacing, i spacing],
ImagePositionPatient of slice k = LPS of voxel (0, 0, k); RAS = diag(-1, -1, 1) LPS. Every UID
is '2.25.' + the integer of a uuid5 of a fixed name, so rerunning gives the same bytes.
"""

import gzip
import hashlib
import io
import os
import uuid

import nibabel as nib
import numpy as np
import pydicom
from pydicom.dataset import FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian

OUT = "tests/data/dicom_series"
CT_IMAGE_STORAGE = "1.2.840.10008.5.1.4.1.1.2"
DIMS = (24, 20, 12)
SPACING = (1.0, 1.15, 2.5)
ORIGIN_LPS = np.array([-14.0, -21.5, 37.0])


def uid(name):
    return "2.25." + str(uuid.uuid5(uuid.NAMESPACE_URL, "meshsmooth-series/" + name).int)


def rotation():
    z, x = np.radians(20.0), np.radians(15.0)
    rz = np.array([[np.cos(z), -np.sin(z), 0], [np.sin(z), np.cos(z), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
    return rx @ rz


def hounsfield():
    """Each voxel's HU: a sphere of 60 in -150 with a ramp along k, whole numbers."""
    i, j, k = np.meshgrid(*[np.arange(n) for n in DIMS], indexing="ij")
    r = np.sqrt(((i - 11.5) * SPACING[0]) ** 2 + ((j - 9.5) * SPACING[1]) ** 2
                + ((k - 5.5) * SPACING[2]) ** 2)
    hu = np.where(r < 9.0, 60, -150) + 7 * k - (i % 3)
    return hu.astype(np.int16)


def ct_slice(instance, study, series, frame, number):
    """A grey CT Image Storage slice's identity, each UID made from the name given."""
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = CT_IMAGE_STORAGE
    meta.MediaStorageSOPInstanceUID = uid(instance)
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    meta.ImplementationClassUID = uid("implementation")
    ds = pydicom.Dataset()
    ds.file_meta = meta
    ds.SOPClassUID = CT_IMAGE_STORAGE
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.StudyInstanceUID = uid(study)
    ds.SeriesInstanceUID = uid(series)
    ds.FrameOfReferenceUID = uid(frame)
    ds.Modality = "CT"
    ds.InstanceNumber = number
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    return ds


def write_series(folder, series_name, slices, shift_per_slice=0.0):
    os.makedirs(os.path.join(OUT, folder), exist_ok=True)
    rot = rotation()
    axis_i, axis_j = rot[:, 0], rot[:, 1]
    normal = np.cross(axis_i, axis_j)
    hu = hounsfield()
    for n, k in enumerate(slices):
        position = (ORIGIN_LPS + normal * SPACING[2] * k
                    + axis_i * shift_per_slice * k)
        intercept = -1024 if k % 2 == 0 else -1000
        stored = (hu[:, :, k].T.astype(np.int32) - intercept).astype(np.int16)
        ds = ct_slice(f"{series_name}/{k}", "study", series_name, "frame", len(slices) - n)
        ds.PatientName = "Phantom^Oblique"
        ds.PatientID = "meshsmooth-test"
        ds.ImagePositionPatient = [f"{v:.6f}" for v in position]
        ds.ImageOrientationPatient = [f"{v:.9f}" for v in (*axis_i, *axis_j)]
        ds.PixelSpacing = [f"{SPACING[1]}", f"{SPACING[0]}"]
        ds.SliceThickness = f"{SPACING[2]}"
        ds.Rows, ds.Columns = DIMS[1], DIMS[0]
        ds.BitsAllocated, ds.BitsStored, ds.HighBit = 16, 16, 15
        ds.PixelRepresentation = 1
        ds.RescaleIntercept = f"{intercept}"
        ds.RescaleSlope = "1"
        ds.PixelData = stored.tobytes()
        name = hashlib.sha1(f"{series_name}/{k}".encode()).hexdigest()[:10] + ".dcm"
        ds.save_as(os.path.join(OUT, folder, name), enforce_file_format=True)


def write_phantom():
    image = nib.load("tests/data/phantom_ct.nii.gz")
    hu = np.asanyarray(image.dataobj).astype(np.int32)
    lps = np.diag([-1.0, -1.0, 1.0, 1.0]) @ image.affine.astype(np.float64)
    spacing = np.linalg.norm(lps[:3, :3], axis=0)
    axes = lps[:3, :3] / spacing
    folder = os.path.join(OUT, "phantom_ct")
    os.makedirs(folder, exist_ok=True)
    for k in range(24):
        stored = (hu[:, :, k].T - (-150)) // 10
        assert np.array_equal(stored * 10 - 150, hu[:, :, k].T)
        ds = ct_slice(f"phantom/{k}", "phantom study", "phantom", "phantom frame", k + 1)
        ds.ImagePositionPatient = [f"{v:.6f}" for v in lps[:3, 3] + lps[:3, 2] * k]
        ds.ImageOrientationPatient = [f"{v:.6f}" for v in (*axes[:, 0], *axes[:, 1])]
        ds.PixelSpacing = [f"{spacing[1]:.6f}", f"{spacing[0]:.6f}"]
        ds.SliceThickness = f"{spacing[2]:.6f}"
        ds.Rows, ds.Columns = stored.shape
        ds.BitsAllocated, ds.BitsStored, ds.HighBit = 8, 8, 7
        ds.PixelRepresentation = 0
        ds.RescaleIntercept = "-150"
        ds.RescaleSlope = "10"
        ds.PixelData = stored.astype(np.uint8).tobytes()
        ds.save_as(os.path.join(folder, f"CT{k + 1:04d}.dcm"), enforce_file_format=True)


def write_nifti():
    rot = rotation()
    lps = np.eye(4)
    lps[:3, :3] = rot[:, :3] * np.array(SPACING)
    lps[:3, 3] = ORIGIN_LPS
    affine = np.diag([-1.0, -1.0, 1.0, 1.0]) @ lps
    image = nib.Nifti1Image(hounsfield().astype(np.float32), affine)
    image.header.set_sform(affine, code=1)
    image.header.set_qform(affine, code=1)
    raw = io.BytesIO()
    with gzip.GzipFile(fileobj=raw, mode="wb", mtime=0, filename="") as gz:
        gz.write(image.to_bytes())
    with open(os.path.join(OUT, "oblique.nii.gz"), "wb") as f:
        f.write(raw.getvalue())


def check(folder, count):
    """Reads the files back with pydicom: the HU of each slice, placed by its position."""
    hu = hounsfield()
    files = sorted(os.listdir(os.path.join(OUT, folder)))
    assert len(files) == count, files
    if folder != "oblique":
        return
    normal = np.cross(rotation()[:, 0], rotation()[:, 1])
    for name in files:
        ds = pydicom.dcmread(os.path.join(OUT, folder, name))
        height = np.dot(np.array(ds.ImagePositionPatient, dtype=float) - ORIGIN_LPS, normal)
        k = int(round(height / SPACING[2]))
        values = ds.pixel_array.astype(np.int32) * int(ds.RescaleSlope) + int(ds.RescaleIntercept)
        assert np.array_equal(values.T, hu[:, :, k]), name


def main():
    all_slices = list(range(DIMS[2]))
    write_series("oblique", "oblique", all_slices)
    write_series("gap", "gap", [k for k in all_slices if k != 5])
    write_series("tilted", "tilted", all_slices, shift_per_slice=0.4)
    write_nifti()
    write_phantom()
    check("oblique", 12)
    check("gap", 11)
    check("tilted", 12)


if __name__ == "__main__":
    main()
