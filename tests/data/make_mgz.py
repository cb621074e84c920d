"""Writes the MGZ test volumes with nibabel, FreeSurfer's reader and writer in Python, from the
shared label maps (run from the repository root, nibabel installed; the files are committed):

    python tests/data/make_mgz.py

- jhu_labels.mgz: the JHU white-matter atlas as an MGZ (int32 voxels), for the same surfaces as
  the NIfTI;
- phantom_aseg.mgz: the abdominal phantom with its labels renumbered to aseg values (1 -> 17
  Left-Hippocampus, 2 -> 10 Left-Thalamus, 3 -> 53 Right-Hippocampus, 4 -> 2035 ctx-rh-insula),
  uint8 voxels where they fit, for FreeSurfer's names.
"""

import nibabel as nib
import numpy as np

DATA = "../shared/data/labelmaps"


def write(source, target, remap=None, dtype=np.int32):
    image = nib.load(f"{DATA}/{source}")
    voxels = np.asanyarray(image.dataobj).astype(np.int64)
    if remap:
        out = np.zeros_like(voxels)
        for old, new in remap.items():
            out[voxels == old] = new
        voxels = out
    nib.save(nib.MGHImage(voxels.astype(dtype), image.affine), f"tests/data/{target}")


write("JHU-WhiteMatter-labels-1mm.nii.gz", "jhu_labels.mgz")
write("case_phantom_shared.nii.gz", "phantom_aseg.mgz", {1: 17, 2: 10, 3: 53, 4: 2035}, np.int16)
