"""Writes a synthetic CT of the abdominal phantom with nibabel (run from the repository root,
nibabel installed; the file is committed):

    python tests/data/make_phantom_ct.py

- phantom_ct.nii.gz: each voxel its label's Hounsfield units (background -150, liver 60, portal
  vein 220, tumour -60, kidney 150: far apart in the soft-tissue window, so every boundary is an
  edge), int16, on the label map's grid: what a segmentation's image is to its case. The same
  values as tests/case_image.rs makes in memory.
"""

import nibabel as nib
import numpy as np

DATA = "../shared/data/labelmaps"
HU = [-150, 60, 220, -60, 150]

image = nib.load(f"{DATA}/case_phantom_shared.nii.gz")
labels = np.asanyarray(image.dataobj).astype(np.int64)
ct = np.take(np.array(HU, dtype=np.int16), labels)
out = nib.Nifti1Image(ct, image.affine)
out.header.set_sform(image.affine, code=1)
out.header.set_qform(image.affine, code=1)
nib.save(out, "tests/data/phantom_ct.nii.gz")
