"""Writes the DICOM SEG test files with highdicom (0.28.2, on pydicom 3.0.2, numpy 2.4.6,
nibabel 5.4.2, Python 3.11), from the shared abdominal phantom and from synthetic shapes. Run
from the repository root (the shared data lives in ../shared/data); the files are committed:

    ~/.cache/meshsmooth/pyenv/bin/python tests/data/make_dicom_seg.py

Outputs, in tests/data/dicom_seg/ (README.md and expected.json there describe them):

- phantom.dcm: case_phantom_shared.nii.gz (160 x 140 x 48, labels 1..4) as one multi-frame
  BINARY SEG of 4 segments (liver, portal_vein, tumor, right_kidney: SCT codes, sRGB colours
  of case_phantom_shared_labels.txt as CIELab), empty frames omitted (highdicom's default), so
  each segment holds only the slices it occupies (53 frames, not 4 x 48). The NIfTI affine is
  float32 (-0.77999997); it is rounded to 6 decimals (0.78) for the DICOM and expected.json;
- labelmap.dcm: the same phantom as one LABELMAP SEG (8-bit, each pixel its segment's number;
  SOP class Label Map Segmentation Storage), one frame per slice the phantom occupies;
- gap.dcm + gap.nii.gz: 40 x 32 x 30 axis-aligned BINARY SEG of two segments (a box low, a
  sphere high, slices 3..9 and 20..26); slices 10..19 are empty for every segment, so no frame
  has their positions (nor those of 0..2 and 27..29);
- oblique.dcm + oblique.nii.gz: 35 x 29 x 24 BINARY SEG of one ellipsoid on a grid rotated 20
  degrees about z then 15 degrees about x (LPS); 35 x 29 = 1015 bits per frame, not a multiple
  of 8, so the frames' bits run on across byte boundaries (DICOM packs them without padding);
- fractional.dcm + fractional.nii.gz: 32 x 32 x 20 FRACTIONAL (PROBABILITY, maximum 255) SEG of
  one sphere with p = clip(0.5 + (r0 - r) / 2, 0, 1), r the distance from the centre in mm and
  r0 = 9 mm. highdicom stores round(p * 255) (numpy's round, half to even); the .nii.gz is the
  label map a reader should produce: 1 where the stored value >= 128, else 0 (the same as
  p >= 0.5 here up to that rounding; the rule is on the stored value).

Geometry. A NIfTI affine maps voxel (i, j, k) to RAS mm; DICOM is LPS, so LPS = diag(-1, -1, 1)
RAS. DICOM Columns run along i and Rows along j: pixel (row r, column c) of slice k is voxel
(i = c, j = r, k). ImageOrientationPatient = [unit i axis in LPS, unit j axis in LPS],
PixelSpacing = [j spacing, i spacing], ImagePositionPatient of slice k = LPS of voxel (0, 0, k),
and the k axis is the cross product of the two directions (every grid here is right-handed in
that sense). highdicom needs source images for this: a minimal CT series (one pydicom Dataset
per slice, zero pixels) with that geometry is built in memory and never written.

What highdicom does that a reader must cope with: frames run segment by segment and, within a
segment, from the highest k down (expected.json's frame_order); with a single segment the
SegmentIdentificationSequence sits in the shared functional groups, not per frame; it writes
SpacingBetweenSlices (from the source positions) in the shared PixelMeasuresSequence; 1-bit
pixels are packed little-endian bit order (pixel 0 = bit 0 of byte 0), uncompressed (Explicit
VR Little Endian). Colours: highdicom's CIELabColor.from_rgb (sRGB, D65, pixelmed's formulas),
checked to convert back (to_rgb) to the same sRGB integers.

Determinism: every UID is '2.25.' + the integer of a uuid5 of a fixed name; highdicom's own
random DimensionOrganizationUID and its clock dates and times (instance creation, content,
contributing equipment) are overwritten with fixed values after construction; the NIfTI files
are gzipped with mtime 0 and no file name. The script builds each SEG twice and checks the
bytes agree, then reads every file back (pydicom, plus an independent unpacking of the bits)
and checks each frame's position against the grid and the rebuilt label map against the
source voxels voxel for voxel.
"""

import gzip
import io
import json
import os
import uuid

import highdicom as hd
import nibabel as nib
import numpy as np
import pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.sr.codedict import codes
from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian
from pydicom.valuerep import format_number_as_ds

SHARED = "../shared/data/labelmaps"
OUT = "tests/data/dicom_seg"
LPS = np.diag([-1.0, -1.0, 1.0, 1.0])  # RAS <-> LPS, its own inverse

# Fixed date and time for every DA / TM / DT the files carry.
DATE, TIME = "20260101", "120000"


def uid(name):
    """A fixed UID under the 2.25 root: the integer of a uuid5 of a name."""
    return "2.25." + str(uuid.uuid5(uuid.NAMESPACE_URL, "meshsmooth/tests/dicom_seg/" + name).int)


def ds_number(value):
    """A decimal string short enough for DS (16 characters), near-exact for these values."""
    return float(format_number_as_ds(float(value)))


def ct_series(name, shape, affine_ras):
    """Minimal CT slices (zero pixels) on the grid of a NIfTI shape and RAS affine."""
    lps = LPS @ affine_ras
    ni, nj, nk = shape
    axes = lps[:3, :3]
    spacing = np.linalg.norm(axes, axis=0)
    row_dir, col_dir, slice_dir = (axes / spacing).T
    assert np.allclose(np.cross(row_dir, col_dir), slice_dir, atol=1e-6), "grid not right-handed"
    orientation = [ds_number(v) for v in (*row_dir, *col_dir)]
    pixel_spacing = [ds_number(spacing[1]), ds_number(spacing[0])]
    frame_of_reference = uid(f"{name}/frame-of-reference")
    series = uid(f"{name}/ct-series")
    slices = []
    for k in range(nk):
        ds = Dataset()
        ds.file_meta = FileMetaDataset()
        ds.file_meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds.SOPClassUID = CTImageStorage
        ds.SOPInstanceUID = uid(f"{name}/ct-slice/{k}")
        ds.StudyInstanceUID = uid(f"{name}/study")
        ds.SeriesInstanceUID = series
        ds.FrameOfReferenceUID = frame_of_reference
        ds.PositionReferenceIndicator = ""
        ds.Modality = "CT"
        ds.PatientName = "Phantom^Meshsmooth"
        ds.PatientID = f"MESHSMOOTH-{name.upper()}"
        ds.PatientBirthDate = ""
        ds.PatientSex = "O"
        ds.StudyID = "1"
        ds.AccessionNumber = ""
        ds.StudyDate = ds.SeriesDate = ds.ContentDate = DATE
        ds.StudyTime = ds.SeriesTime = ds.ContentTime = TIME
        ds.ReferringPhysicianName = ""
        ds.Manufacturer = "meshsmooth"
        ds.SeriesNumber = 1
        ds.InstanceNumber = k + 1
        ds.ImageType = ["DERIVED", "SECONDARY", "AXIAL"]
        ds.Rows, ds.Columns = nj, ni
        ds.PixelSpacing = pixel_spacing
        ds.SliceThickness = ds_number(spacing[2])
        ds.ImageOrientationPatient = orientation
        ds.ImagePositionPatient = [ds_number(v) for v in lps[:3, :3] @ [0, 0, k] + lps[:3, 3]]
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated = ds.BitsStored = 16
        ds.HighBit = 15
        ds.PixelRepresentation = 1
        ds.RescaleIntercept, ds.RescaleSlope = -1024, 1
        ds.PixelData = np.zeros((nj, ni), np.int16).tobytes()
        slices.append(ds)
    return slices


def frames_of(volume):
    """NIfTI voxels [i, j, k] -> highdicom frames [k, row = j, column = i]."""
    return np.ascontiguousarray(np.transpose(volume, (2, 1, 0)))


def segment(number, label, srgb, category, type_, description, modifier=None):
    color = hd.color.CIELabColor.from_rgb(*srgb)
    assert color.to_rgb() == tuple(srgb), (label, srgb, color.to_rgb())
    desc = hd.seg.SegmentDescription(
        segment_number=number,
        segment_label=label,
        segmented_property_category=hd.sr.CodedConcept(*category[1::-1], category[2]),
        segmented_property_type=hd.sr.CodedConcept(*type_[1::-1], type_[2]),
        algorithm_type=hd.seg.SegmentAlgorithmTypeValues.AUTOMATIC,
        algorithm_identification=hd.AlgorithmIdentificationSequence(
            name="meshsmooth make_dicom_seg.py",
            family=codes.cid7162.ArtificialIntelligence,
            version="1",
        ),
        tracking_uid=uid(f"segment/{label}"),
        tracking_id=label,
        display_color=color,
    )
    desc.SegmentDescription = description
    if modifier is not None:
        desc.SegmentedPropertyTypeCodeSequence[0].SegmentedPropertyTypeModifierCodeSequence = [
            hd.sr.CodedConcept(*modifier[1::-1], modifier[2])
        ]
    fact = {
        "number": number,
        "label": label,
        "description": description,
        "srgb": list(srgb),
        "cielab_dicom": list(color.value),
        "category": list(category),
        "type": list(type_),
        "modifier": list(modifier) if modifier else None,
    }
    return desc, fact


def build(name, volume, affine_ras, segments, kind="BINARY"):
    """The SEG dataset of a NIfTI-shaped volume (label map, or probabilities for FRACTIONAL)."""
    sources = ct_series(name, volume.shape, affine_ras)
    extra = {}
    if kind == "FRACTIONAL":
        extra = dict(fractional_type="PROBABILITY", max_fractional_value=255)
    seg = hd.seg.Segmentation(
        source_images=sources,
        pixel_array=frames_of(volume),
        segmentation_type=kind,
        segment_descriptions=segments,
        series_instance_uid=uid(f"{name}/seg-series"),
        series_number=100,
        sop_instance_uid=uid(f"{name}/seg-instance"),
        instance_number=1,
        manufacturer="meshsmooth",
        manufacturer_model_name="make_dicom_seg.py",
        software_versions=f"highdicom {hd.__version__}, pydicom {pydicom.__version__}",
        device_serial_number="1",
        content_description=f"meshsmooth test segmentation: {name}",
        content_creator_name="Meshsmooth^Tests",
        content_label=name.upper(),
        series_description=f"meshsmooth {name} SEG",
        **extra,
    )
    # highdicom's random and clock-dependent values, fixed.
    dim_uid = uid(f"{name}/dimension-organization")
    seg.DimensionOrganizationSequence[0].DimensionOrganizationUID = dim_uid
    for item in seg.DimensionIndexSequence:
        item.DimensionOrganizationUID = dim_uid
    seg.InstanceCreationDate, seg.InstanceCreationTime = DATE, TIME
    seg.ContentDate, seg.ContentTime = DATE, TIME
    seg.SeriesDate, seg.SeriesTime = DATE, TIME
    for item in seg.get("ContributingEquipmentSequence", []):
        item.ContributionDateTime = DATE + TIME
    return seg


def to_bytes(ds):
    buffer = io.BytesIO()
    ds.save_as(buffer, enforce_file_format=True)
    return buffer.getvalue()


def check_fixed(ds):
    """Every date/time is the fixed one; fail loudly if highdicom added a new clock value."""
    for elem in ds.iterall():
        if elem.VR in ("DA", "TM", "DT") and elem.value not in ("", None):
            assert str(elem.value) in (DATE, TIME, DATE + TIME), (elem.keyword, elem.value)


def write_seg(name, volume, affine_ras, segments, kind="BINARY"):
    data = to_bytes(build(name, volume, affine_ras, segments, kind))
    again = build(name, volume, affine_ras, segments, kind)
    check_fixed(again)
    assert to_bytes(again) == data, f"{name}.dcm is not deterministic"
    with open(f"{OUT}/{name}.dcm", "wb") as f:
        f.write(data)


def write_nifti(name, labels, affine_ras):
    image = nib.Nifti1Image(labels.astype(np.uint8), affine_ras)
    image.set_qform(affine_ras, code=1)
    image.set_sform(affine_ras, code=1)
    with open(f"{OUT}/{name}.nii.gz", "wb") as f:
        with gzip.GzipFile(filename="", mode="wb", fileobj=f, mtime=0, compresslevel=9) as z:
            z.write(image.to_bytes())


def unpack_bits(ds):
    """All frames of a 1-bit SEG, unpacked independently of pydicom: bit 0 of byte 0 is the
    first pixel, frames follow each other with no padding to a byte boundary."""
    n, rows, cols = int(ds.NumberOfFrames), int(ds.Rows), int(ds.Columns)
    bits = np.unpackbits(np.frombuffer(ds.PixelData, np.uint8), bitorder="little")
    assert len(ds.PixelData) == (n * rows * cols + 7) // 8 + ((n * rows * cols + 7) // 8) % 2
    return bits[: n * rows * cols].reshape(n, rows, cols)


def read_back(name, shape, affine_ras):
    """Rebuilds the per-segment voxel arrays [segment][i, j, k] from the file, checking every
    frame's position against the grid. Returns (dataset, arrays by segment number,
    [segment, k] of every frame in file order)."""
    ds = pydicom.dcmread(f"{OUT}/{name}.dcm")
    lps = LPS @ affine_ras
    axes = lps[:3, :3]
    spacing = np.linalg.norm(axes, axis=0)
    sfg = ds.SharedFunctionalGroupsSequence[0]
    iop = np.array(sfg.PlaneOrientationSequence[0].ImageOrientationPatient, float)
    assert np.allclose(iop[:3], axes[:, 0] / spacing[0], atol=1e-6), iop
    assert np.allclose(iop[3:], axes[:, 1] / spacing[1], atol=1e-6), iop
    pm = sfg.PixelMeasuresSequence[0]
    assert np.allclose(np.array(pm.PixelSpacing, float), spacing[[1, 0]], atol=1e-6)
    assert (int(ds.Rows), int(ds.Columns)) == (shape[1], shape[0])
    if ds.SegmentationType == "BINARY":
        frames = ds.pixel_array.reshape(-1, ds.Rows, ds.Columns)
        assert np.array_equal(frames, unpack_bits(ds)), "pydicom and the bit unpacking disagree"
    else:
        count = int(ds.NumberOfFrames) * ds.Rows * ds.Columns
        frames = np.frombuffer(ds.PixelData, np.uint8)[:count].reshape(-1, ds.Rows, ds.Columns)
        assert np.array_equal(frames, ds.pixel_array.reshape(frames.shape))
    out = {int(s.SegmentNumber): np.zeros(shape, np.uint8) for s in ds.SegmentSequence}
    ks = []
    for f, item in enumerate(ds.PerFrameFunctionalGroupsSequence):
        # With one segment highdicom puts SegmentIdentificationSequence in the shared groups.
        ident = item if "SegmentIdentificationSequence" in item else sfg
        number = int(ident.SegmentIdentificationSequence[0].ReferencedSegmentNumber)
        position = np.array(item.PlanePositionSequence[0].ImagePositionPatient, float)
        k = float(np.dot(position - lps[:3, 3], axes[:, 2]) / spacing[2] ** 2)
        assert abs(k - round(k)) < 1e-4, (name, f, k)
        k = int(round(k))
        expected = lps[:3, :3] @ [0, 0, k] + lps[:3, 3]
        assert np.allclose(position, expected, atol=1e-4), (name, f, position, expected)
        assert 0 <= k < shape[2]
        assert not out[number][:, :, k].any(), f"slice {k} of segment {number} twice"
        out[number][:, :, k] = frames[f].T
        ks.append([number, k])
    return ds, out, ks


def verify_labels(name, labels, affine_ras):
    ds, per_segment, ks = read_back(name, labels.shape, affine_ras)
    rebuilt = np.zeros(labels.shape, np.uint8)
    for number, mask in per_segment.items():
        assert not (rebuilt[mask > 0]).any(), "segments overlap"
        rebuilt[mask > 0] = number
    assert np.array_equal(rebuilt, labels), f"{name}: rebuilt label map differs"
    report(name, ds, ks)
    return ds, ks


def report(name, ds, frames):
    pm = ds.SharedFunctionalGroupsSequence[0].PixelMeasuresSequence[0]
    sbs = pm.get("SpacingBetweenSlices")
    per = {}
    for n, _ in frames:
        per[n] = per.get(n, 0) + 1
    ks = [k for _, k in frames]
    size = os.path.getsize(f"{OUT}/{name}.dcm")
    print(
        f"{name}.dcm: {size} bytes, {ds.NumberOfFrames} frames {per}, slices "
        f"{sorted(set(ks))[0]}..{sorted(set(ks))[-1]} ({len(set(ks))} distinct), "
        f"SpacingBetweenSlices={sbs}, transfer syntax {ds.file_meta.TransferSyntaxUID.name}"
    )
    assert size < 250_000, f"{name}.dcm too big"


def affine_fact(affine_ras):
    return [[round(float(v), 9) for v in row] for row in affine_ras[:3]]


def grid(shape):
    return np.meshgrid(*(np.arange(n) for n in shape), indexing="ij")


TISSUE = ("SCT", "85756007", "Tissue")
ANATOMY = ("SCT", "123037004", "Anatomical Structure")
ALTERED = ("SCT", "49755003", "Morphologically Altered Structure")


def phantom(facts):
    image = nib.load(f"{SHARED}/case_phantom_shared.nii.gz")
    labels = np.asanyarray(image.dataobj).astype(np.uint8)
    # The affine is stored as float32 (-0.77999997); DICOM gets 0.78 (DS), so is this.
    affine = np.round(image.affine, 6)
    colours = {}
    with open(f"{SHARED}/case_phantom_shared_labels.txt") as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                index, name, r, g, b, _ = line.split()
                colours[name] = (int(r), int(g), int(b))
    specs = [
        (1, "liver", ANATOMY, ("SCT", "10200004", "Liver"), "Liver of the phantom", None),
        (2, "portal_vein", ANATOMY, ("SCT", "32764006", "Portal vein"),
         "Portal vein of the phantom", None),
        (3, "tumor", ALTERED, ("SCT", "108369006", "Neoplasm"), "Tumour in the phantom's liver",
         None),
        (4, "right_kidney", ANATOMY, ("SCT", "64033007", "Kidney"),
         "Right kidney of the phantom", ("SCT", "24028007", "Right")),
    ]
    descs, segs = zip(*(segment(n, l, colours[l], c, t, d, m) for n, l, c, t, d, m in specs))
    write_seg("phantom", labels, affine, list(descs))
    ds, frames = verify_labels("phantom", labels, affine)
    occupied = sum(int((labels == n).any(axis=(0, 1)).sum()) for n in range(1, 5))
    assert int(ds.NumberOfFrames) == occupied
    facts["phantom.dcm"] = {
        "source": "../shared/data/labelmaps/case_phantom_shared.nii.gz",
        "segmentation_type": "BINARY",
        "dims": list(labels.shape),
        "affine": affine_fact(affine),
        "frames": int(ds.NumberOfFrames),
        "frame_order": frames,
        "frames_if_not_omitted": 4 * labels.shape[2],
        "segments": list(segs),
    }


def labelmap(facts):
    """The phantom again as one LABELMAP SEG: each frame a slice of segment numbers."""
    image = nib.load(f"{SHARED}/case_phantom_shared.nii.gz")
    labels = np.asanyarray(image.dataobj).astype(np.uint8)
    affine = np.round(image.affine, 6)
    phantom_facts = facts["phantom.dcm"]
    specs = [
        (s["number"], s["label"], tuple(s["srgb"]), tuple(s["category"]), tuple(s["type"]),
         s["description"], tuple(s["modifier"]) if s["modifier"] else None)
        for s in phantom_facts["segments"]
    ]
    descs, segs = zip(*(segment(n, l, c, cat, t, d, m) for n, l, c, cat, t, d, m in specs))
    write_seg("labelmap", labels, affine, list(descs), kind="LABELMAP")
    ds = pydicom.dcmread(f"{OUT}/labelmap.dcm")
    assert ds.SOPClassUID == "1.2.840.10008.5.1.4.1.1.66.7", ds.SOPClassUID
    frames = ds.pixel_array.reshape(int(ds.NumberOfFrames), ds.Rows, ds.Columns)
    occupied = [k for k in range(labels.shape[2]) if labels[:, :, k].any()]
    assert len(frames) == len(occupied), (len(frames), len(occupied))
    positions = [float(g.PlanePositionSequence[0].ImagePositionPatient[2])
                 for g in ds.PerFrameFunctionalGroupsSequence]
    for frame, z in zip(frames, positions):
        k = int(round((z - affine[2, 3]) / affine[2, 2]))
        assert np.array_equal(frame.T, labels[:, :, k]), k
    facts["labelmap.dcm"] = {
        "source": "../shared/data/labelmaps/case_phantom_shared.nii.gz",
        "segmentation_type": "LABELMAP",
        "dims": list(labels.shape),
        "affine": affine_fact(affine),
        "frames": int(ds.NumberOfFrames),
        "bits_allocated": int(ds.BitsAllocated),
        "photometric_interpretation": ds.PhotometricInterpretation,
        "segments": list(segs),
    }


def gap(facts):
    shape = (40, 32, 30)
    affine = np.array([[-0.9, 0, 0, 18.0], [0, -0.9, 0, 12.5], [0, 0, 1.5, -20.0], [0, 0, 0, 1]])
    i, j, k = grid(shape)
    labels = np.zeros(shape, np.uint8)
    labels[(i >= 5) & (i < 20) & (j >= 6) & (j < 18) & (k >= 3) & (k < 10)] = 1  # box, k 3..9
    sphere = (i - 26) ** 2 * 0.81 + (j - 16) ** 2 * 0.81 + ((k - 23) * 1.5) ** 2 <= 5.5**2
    labels[sphere] = 2  # k 19..27
    empty = [kk for kk in range(shape[2]) if not labels[:, :, kk].any()]
    descs, segs = zip(
        segment(1, "box", (241, 214, 145), TISSUE, TISSUE, "Box in the lower slices", None),
        segment(2, "sphere", (111, 184, 210), TISSUE, TISSUE, "Sphere in the upper slices", None),
    )
    write_seg("gap", labels, affine, list(descs))
    write_nifti("gap", labels, affine)
    ds, frames = verify_labels("gap", labels, affine)
    facts["gap.dcm"] = {
        "nifti": "gap.nii.gz",
        "segmentation_type": "BINARY",
        "dims": list(shape),
        "affine": affine_fact(affine),
        "frames": int(ds.NumberOfFrames),
        "frame_order": frames,
        "slices_per_segment": {
            str(n): [int(v) for v in np.where((labels == n).any(axis=(0, 1)))[0]] for n in (1, 2)
        },
        "empty_slices": empty,
        "spacing_between_slices": _sbs(ds),
        "segments": list(segs),
    }


def _sbs(ds):
    pm = ds.SharedFunctionalGroupsSequence[0].PixelMeasuresSequence[0]
    return float(pm.SpacingBetweenSlices) if "SpacingBetweenSlices" in pm else None


def rotation(degrees_z, degrees_x):
    z, x = np.radians(degrees_z), np.radians(degrees_x)
    rz = np.array([[np.cos(z), -np.sin(z), 0], [np.sin(z), np.cos(z), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
    return rx @ rz  # 20 degrees about z first, then 15 degrees about x


def oblique(facts):
    shape = (35, 29, 24)
    spacing = np.array([1.0, 1.2, 2.0])
    lps = np.eye(4)
    lps[:3, :3] = rotation(20, 15) * spacing  # columns: i, j, k axes in LPS
    lps[:3, 3] = [-14.0, -21.5, 37.0]
    affine = LPS @ lps
    i, j, k = grid(shape)
    x, y, z = (i - 17.0) * 1.0, (j - 14.0) * 1.2, (k - 11.5) * 2.0
    labels = ((x / 13.0) ** 2 + (y / 10.0) ** 2 + (z / 19.0) ** 2 <= 1).astype(np.uint8)
    descs, segs = zip(
        segment(1, "ellipsoid", (128, 174, 128), TISSUE, TISSUE, "Ellipsoid on a rotated grid",
                None),
    )
    write_seg("oblique", labels, affine, list(descs))
    write_nifti("oblique", labels, affine)
    ds, frames = verify_labels("oblique", labels, affine)
    sfg = ds.SharedFunctionalGroupsSequence[0]
    facts["oblique.dcm"] = {
        "nifti": "oblique.nii.gz",
        "segmentation_type": "BINARY",
        "dims": list(shape),
        "affine": affine_fact(affine),
        "image_orientation_patient": [float(v) for v in
                                      sfg.PlaneOrientationSequence[0].ImageOrientationPatient],
        "frames": int(ds.NumberOfFrames),
        "frame_order": frames,
        "bits_per_frame": shape[0] * shape[1],
        "segments": list(segs),
    }


def fractional(facts):
    shape = (32, 32, 20)
    affine = np.array([[-1.0, 0, 0, 15.5], [0, -1.0, 0, 40.0], [0, 0, 2.0, -12.0], [0, 0, 0, 1]])
    i, j, k = grid(shape)
    r = np.sqrt((i - 15.3) ** 2 + (j - 16.6) ** 2 + ((k - 9.4) * 2.0) ** 2)
    p = np.clip(0.5 + (9.0 - r) / 2.0, 0.0, 1.0)
    stored = np.around(p * 255).astype(np.uint8)  # what highdicom stores
    labels = (stored >= 128).astype(np.uint8)
    descs, segs = zip(
        segment(1, "sphere", (216, 101, 79), TISSUE, TISSUE, "Probabilistic sphere", None),
    )
    write_seg("fractional", p, affine, list(descs), kind="FRACTIONAL")
    write_nifti("fractional", labels, affine)
    ds, per_segment, frames = read_back("fractional", shape, affine)
    assert ds.SegmentationType == "FRACTIONAL" and ds.SegmentationFractionalType == "PROBABILITY"
    assert int(ds.MaximumFractionalValue) == 255 and int(ds.BitsAllocated) == 8
    # Slices absent from the file are all zero; the rest must be the stored values exactly.
    assert np.array_equal(per_segment[1], stored), "fractional values differ"
    assert np.array_equal((per_segment[1] >= 128).astype(np.uint8), labels)
    report("fractional", ds, frames)
    values = per_segment[1]
    facts["fractional.dcm"] = {
        "nifti": "fractional.nii.gz",
        "segmentation_type": "FRACTIONAL",
        "fractional_type": "PROBABILITY",
        "max_fractional_value": 255,
        "threshold_rule": "label 1 where stored value >= 128 (of 255), else 0",
        "dims": list(shape),
        "affine": affine_fact(affine),
        "frames": int(ds.NumberOfFrames),
        "frame_order": frames,
        "voxels_inside": int(labels.sum()),
        "voxels_partial": int(((values > 0) & (values < 255)).sum()),
        "segments": list(segs),
    }


def main():
    os.makedirs(OUT, exist_ok=True)
    facts = {
        "_note": "dims [i, j, k] as the NIfTI has them; affine: 3x4 rows of the RAS affine "
        "(voxel (i, j, k) -> RAS mm); DICOM Columns run along i, Rows along j; codes as "
        "[scheme, value, meaning]; srgb the intended colour (0-255), cielab_dicom the stored "
        "RecommendedDisplayCIELabValue; made by tests/data/make_dicom_seg.py",
        "versions": {
            "highdicom": hd.__version__,
            "pydicom": pydicom.__version__,
            "numpy": np.__version__,
            "nibabel": nib.__version__,
        },
    }
    phantom(facts)
    labelmap(facts)
    gap(facts)
    oblique(facts)
    fractional(facts)
    for name in ("gap", "oblique", "fractional"):
        print(f"{name}.nii.gz: {os.path.getsize(f'{OUT}/{name}.nii.gz')} bytes")
    with open(f"{OUT}/expected.json", "w") as f:
        json.dump(facts, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
