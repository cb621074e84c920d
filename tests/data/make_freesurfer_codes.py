"""Writes src/segmentation/freesurfer_codes.tsv: the standard codes of FreeSurfer's aseg labels.

The codes are those fs2dicom (github.com/corticometrics/fs2dicom, the converter of FreeSurfer's
aseg into DICOM SEG) gives each label in `fs2dicom/templates/fs-aseg.json` (commit 611596a). That
file uses the SNOMED RT identifiers DICOM used before 2019 (scheme SRT, "T-A2570"); each is
replaced by its SNOMED CT concept id (scheme SCT) from DICOM PS3.16's table of the two
("SNOMED Concept ID to SNOMED ID Mapping"), as pydicom ships it in `pydicom/sr/_snomed_dict.py`.
Codes of other schemes (DCM) are kept. An SRT code without an SCT twin stops the script.

FreeSurfer 7 renamed labels 10 and 49 (`Left-Thalamus-Proper` -> `Left-Thalamus`); both names get
a row, so aseg files named by either table match. The colour is the file's recommended display
colour, FreeSurfer's own (the unit tests compare it with src/io/freesurfer_lut.rs).

    python tests/data/make_freesurfer_codes.py fs-aseg.json > src/segmentation/freesurfer_codes.tsv

with pydicom installed (3.0.2 wrote the committed file).
"""

import json
import sys

from pydicom.sr._snomed_dict import mapping

RENAMED = {"Left-Thalamus-Proper": "Left-Thalamus", "Right-Thalamus-Proper": "Right-Thalamus"}
SEQUENCES = [
    "SegmentedPropertyCategoryCodeSequence",
    "SegmentedPropertyTypeCodeSequence",
    "SegmentedPropertyTypeModifierCodeSequence",
]


def sct(code):
    """The code as a (scheme, value, meaning) triple in SNOMED CT where it was in SNOMED RT."""
    if code is None:
        return ("", "", "")
    scheme, value, meaning = code["CodingSchemeDesignator"], code["CodeValue"], code["CodeMeaning"]
    if scheme == "SRT":
        if value not in mapping["SRT"]:
            sys.exit(f"no SNOMED CT concept for SRT {value} ({meaning})")
        return ("SCT", mapping["SRT"][value], meaning)
    return (scheme, value, meaning)


def main(path):
    with open(path, encoding="utf-8") as f:
        segments = json.load(f)["segmentAttributes"][0]
    print("# FreeSurfer's aseg labels with the codes fs2dicom gives them "
          "(fs2dicom/templates/fs-aseg.json of github.com/corticometrics/fs2dicom, commit 611596a),")
    print("# its SNOMED RT identifiers replaced by their SNOMED CT concept ids from DICOM PS3.16's mapping table.")
    print("# Written by tests/data/make_freesurfer_codes.py; color: FreeSurfer's colour of the label.")
    print("class\tcategory_scheme\tcategory_value\tcategory_meaning\t"
          "type_scheme\ttype_value\ttype_meaning\t"
          "modifier_scheme\tmodifier_value\tmodifier_meaning\tcolor")
    for s in segments:
        fields = [field for seq in SEQUENCES for field in sct(s.get(seq))]
        color = ",".join(str(c) for c in s["recommendedDisplayRGBValue"])
        name = s["SegmentDescription"]
        for written in [name] + ([RENAMED[name]] if name in RENAMED else []):
            print("\t".join([written, *fields, color]))


if __name__ == "__main__":
    main(sys.argv[1])
