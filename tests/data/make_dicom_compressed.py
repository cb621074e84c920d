"""Writes compressed twins of uncompressed DICOM test files: the same data set, only the
transfer syntax and the Pixel Data (encapsulated, one frame a fragment) change. Run from the
repository root with pydicom 3.0.2, numpy, python-gdcm 3.2.6 and Pillow; the files are committed,
and rerunning gives the same bytes:

    python tests/data/make_dicom_compressed.py

Outputs (each twin named as its original with a prefix, since the fuzz corpus takes files by
name):

- tests/data/dicom_series/oblique_rle/rle_*.dcm: every slice of oblique/ (signed 16-bit) as RLE
  Lossless (1.2.840.10008.1.2.5, pydicom's own encoder): two segments a frame, high bytes first.
- tests/data/dicom_series/oblique_jpeg/jpeg_*.dcm: the same slices as JPEG Lossless, first-order
  prediction (1.2.840.10008.1.2.4.70), the codestream GDCM's encoder writes.
- tests/data/dicom_series/oblique_j2k/j2k_*.dcm: the same slices as JPEG 2000 Lossless
  (1.2.840.10008.1.2.4.90), the codestream GDCM's encoder (OpenJPEG) writes: signed samples.
- tests/data/dicom_series/oblique_jls/jls_*.dcm: the same slices as JPEG-LS Lossless
  (1.2.840.10008.1.2.4.80), the codestream GDCM's encoder (CharLS) writes.
- tests/data/dicom_series/phantom_ct_jpeg/jpeg_*.dcm: the slices of phantom_ct/ (unsigned 8-bit)
  as JPEG Baseline (1.2.840.10008.1.2.4.50, lossy, Pillow at quality 95, no chroma: one grey
  component), marked Lossy Image Compression 01. Its values differ from the original's by a few
  stored units near edges.
- tests/data/dicom_series/phantom_ct_j2k/j2k_*.dcm: the same slices as JPEG 2000
  (1.2.840.10008.1.2.4.91, lossy: Pillow's OpenJPEG, the irreversible 9/7 wavelet at 20:1),
  marked Lossy Image Compression 01.
- tests/data/dicom_series/phantom_ct_jls/jls_*.dcm: the same slices as JPEG-LS near-lossless
  (1.2.840.10008.1.2.4.81, GDCM's encoder with an error bound of 2 stored units), marked Lossy
  Image Compression 01: every value within 2 of the original's.
- tests/data/dicom_seg/labelmap_rle.dcm, fractional_rle.dcm: labelmap.dcm (LABELMAP, 8-bit, 22
  frames) and fractional.dcm (FRACTIONAL, 8-bit, 10 frames) as RLE Lossless.
- tests/data/dicom_seg/fractional_jpeg.dcm: fractional.dcm as JPEG Lossless SV1 (GDCM's
  codestreams, one fragment a frame; GDCM does not read the LABELMAP SOP class).
- tests/data/dicom_seg/fractional_j2k.dcm: fractional.dcm as JPEG 2000 Lossless (GDCM's
  codestreams, one fragment a frame).
- tests/data/dicom_seg/fractional_jls.dcm: fractional.dcm as JPEG-LS Lossless (GDCM's
  codestreams, one fragment a frame).
- tests/data/dicom_seg/phantom_deflated.dcm and tests/data/dicom_series/oblique_deflated/
  deflated_*.dcm: phantom.dcm (BINARY) and the slices of oblique/ in Deflated Explicit VR Little
  Endian (1.2.840.10008.1.2.1.99): the whole data set after the file meta group one raw deflate
  stream, as pydicom writes it.

BINARY SEGs have no RLE twin: highdicom refuses RLE for 1-bit segmentations. Each lossless twin
is decoded back with pydicom (GDCM for JPEG) and compared with the original's pixels.
"""

import io
import os
import tempfile

import gdcm
import numpy as np
import pydicom
from PIL import Image
from pydicom.encaps import encapsulate, generate_frames
from pydicom.uid import (
    DeflatedExplicitVRLittleEndian,
    JPEG2000,
    JPEG2000Lossless,
    JPEGBaseline8Bit,
    JPEGLosslessSV1,
    JPEGLSLossless,
    JPEGLSNearLossless,
    RLELossless,
)

SERIES = "tests/data/dicom_series"


def rle_twin(source, target):
    ds = pydicom.dcmread(source)
    original = ds.pixel_array.copy()
    ds.compress(RLELossless, encoding_plugin="pydicom", generate_instance_uid=False)
    ds.save_as(target, enforce_file_format=True)
    check_same(target, original, RLELossless)


def check_same(target, original, syntax):
    back = pydicom.dcmread(target)
    assert back.file_meta.TransferSyntaxUID == syntax
    assert np.array_equal(back.pixel_array, original), f"{target} decodes differently"


def gdcm_frames(source, syntax, codec=None):
    """The codestreams GDCM writes for `source`'s frames in the transfer syntax `syntax`, with
    `codec` when given."""
    reader = gdcm.ImageReader()
    reader.SetFileName(source)
    assert reader.Read(), source
    change = gdcm.ImageChangeTransferSyntax()
    change.SetTransferSyntax(gdcm.TransferSyntax(syntax))
    if codec is not None:
        change.SetUserCodec(codec)
    change.SetInput(reader.GetImage())
    assert change.Change(), source
    with tempfile.TemporaryDirectory() as folder:
        out = os.path.join(folder, "out.dcm")
        writer = gdcm.ImageWriter()
        writer.SetFileName(out)
        writer.SetFile(reader.GetFile())
        writer.SetImage(change.GetOutput())
        assert writer.Write(), source
        written = pydicom.dcmread(out)
        count = int(written.get("NumberOfFrames", 1))
        return list(generate_frames(written.PixelData, number_of_frames=count))


def pillow_jpeg_baseline(ds):
    out = io.BytesIO()
    Image.fromarray(ds.pixel_array.astype(np.uint8), mode="L").save(
        out, format="JPEG", quality=95, optimize=False
    )
    return [out.getvalue()]


def gdcm_jpeg_lossless(source):
    return gdcm_frames(source, gdcm.TransferSyntax.JPEGLosslessProcess14_1)


def gdcm_jpeg_ls_near(source, error):
    codec = gdcm.JPEGLSCodec()
    codec.SetLossless(False)
    codec.SetLossyError(error)
    return gdcm_frames(source, gdcm.TransferSyntax.JPEGLSNearLossless, codec)


def pillow_jpeg_2000(ds):
    out = io.BytesIO()
    Image.fromarray(ds.pixel_array.astype(np.uint8), mode="L").save(
        out, format="JPEG2000", no_jp2=True, irreversible=True,
        quality_mode="rates", quality_layers=[20],
    )
    return [out.getvalue()]


def encapsulated_twin(source, target, syntax, frames, lossy=None):
    ds = pydicom.dcmread(source)
    original = ds.pixel_array.copy()
    ds.file_meta.TransferSyntaxUID = syntax
    ds.PixelData = encapsulate(frames)
    ds["PixelData"].VR = "OB"
    ds["PixelData"].is_undefined_length = True
    if lossy:
        ds.LossyImageCompression = "01"
        ds.LossyImageCompressionMethod = lossy
    ds.save_as(target, enforce_file_format=True)
    if not lossy:
        check_same(target, original, syntax)


def deflated_twin(source, target):
    ds = pydicom.dcmread(source)
    original = ds.pixel_array.copy()
    ds.file_meta.TransferSyntaxUID = DeflatedExplicitVRLittleEndian
    ds.save_as(target, enforce_file_format=True)
    check_same(target, original, DeflatedExplicitVRLittleEndian)


def twins_of(folder, prefix, make):
    os.makedirs(f"{SERIES}/{folder}_{prefix}", exist_ok=True)
    for name in sorted(os.listdir(f"{SERIES}/{folder}")):
        make(f"{SERIES}/{folder}/{name}", f"{SERIES}/{folder}_{prefix}/{prefix}_{name}")


def main():
    twins_of("oblique", "rle", rle_twin)
    twins_of(
        "oblique",
        "jpeg",
        lambda s, t: encapsulated_twin(s, t, JPEGLosslessSV1, gdcm_jpeg_lossless(s)),
    )
    twins_of(
        "phantom_ct",
        "jpeg",
        lambda s, t: encapsulated_twin(
            s, t, JPEGBaseline8Bit, pillow_jpeg_baseline(pydicom.dcmread(s)), "ISO_10918_1"
        ),
    )
    twins_of(
        "oblique",
        "j2k",
        lambda s, t: encapsulated_twin(
            s, t, JPEG2000Lossless, gdcm_frames(s, gdcm.TransferSyntax.JPEG2000Lossless)
        ),
    )
    twins_of(
        "phantom_ct",
        "j2k",
        lambda s, t: encapsulated_twin(
            s, t, JPEG2000, pillow_jpeg_2000(pydicom.dcmread(s)), "ISO_15444_1"
        ),
    )
    twins_of(
        "oblique",
        "jls",
        lambda s, t: encapsulated_twin(
            s, t, JPEGLSLossless, gdcm_frames(s, gdcm.TransferSyntax.JPEGLSLossless)
        ),
    )
    twins_of(
        "phantom_ct",
        "jls",
        lambda s, t: encapsulated_twin(
            s, t, JPEGLSNearLossless, gdcm_jpeg_ls_near(s, 2), "ISO_14495_1"
        ),
    )
    twins_of("oblique", "deflated", deflated_twin)
    seg = "tests/data/dicom_seg"
    deflated_twin(f"{seg}/phantom.dcm", f"{seg}/phantom_deflated.dcm")
    for name in ("labelmap", "fractional"):
        rle_twin(f"{seg}/{name}.dcm", f"{seg}/{name}_rle.dcm")
    fractional = f"{seg}/fractional.dcm"
    encapsulated_twin(
        fractional, f"{seg}/fractional_jpeg.dcm", JPEGLosslessSV1, gdcm_jpeg_lossless(fractional)
    )
    encapsulated_twin(
        fractional,
        f"{seg}/fractional_j2k.dcm",
        JPEG2000Lossless,
        gdcm_frames(fractional, gdcm.TransferSyntax.JPEG2000Lossless),
    )
    encapsulated_twin(
        fractional,
        f"{seg}/fractional_jls.dcm",
        JPEGLSLossless,
        gdcm_frames(fractional, gdcm.TransferSyntax.JPEGLSLossless),
    )


if __name__ == "__main__":
    main()
