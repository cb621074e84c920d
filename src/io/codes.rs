//! Standard codes that say what a structure is, as DICOM segmentations code it: a coded concept
//! (scheme, value, meaning), and a structure's category, type and type modifier.

/// A coded concept: the coding scheme ("SCT" for SNOMED CT), the code and its meaning.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Code {
    pub scheme: String,
    pub value: String,
    pub meaning: String,
}

impl Code {
    pub fn new(scheme: &str, value: &str, meaning: &str) -> Self {
        Self {
            scheme: scheme.to_string(),
            value: value.to_string(),
            meaning: meaning.to_string(),
        }
    }
}

/// What a structure is, in codes: DICOM's segmented property category ("Anatomical
/// Structure"), type ("Kidney") and type modifier ("Right"), if any.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct StructureCodes {
    pub category: Code,
    #[serde(rename = "type")]
    pub kind: Code,
    /// Always written (null when none): the workers' messages are not self-describing.
    #[serde(default)]
    pub modifier: Option<Code>,
}

/// The codes of 3D Slicer's terminology entry in a segment's tags
/// (`SegmentN_Tags:=...|TerminologyEntry:context~category~type~modifier~...|`), where each code
/// is `scheme^value^meaning`; `None` without an entry or with an empty category or type.
pub(super) fn from_slicer_tags(tags: &str) -> Option<StructureCodes> {
    let entry = (tags.split('|')).find_map(|tag| tag.strip_prefix("TerminologyEntry:"))?;
    let mut fields = entry.split('~').skip(1);
    let mut next = || fields.next().and_then(slicer_code);
    let category = next()?;
    let kind = next()?;
    let modifier = next();
    Some(StructureCodes {
        category,
        kind,
        modifier,
    })
}

/// `scheme^value^meaning`, or `None` when the value is empty (Slicer writes `^^` for none).
fn slicer_code(text: &str) -> Option<Code> {
    let mut parts = text.splitn(3, '^');
    let (scheme, value, meaning) = (parts.next()?, parts.next()?, parts.next().unwrap_or(""));
    (!value.trim().is_empty()).then(|| Code::new(scheme.trim(), value.trim(), meaning.trim()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slicer_terminology_entries_give_codes() {
        let tags = "Segmentation.Status:inprogress|TerminologyEntry:Segmentation category and \
                    type - 3D Slicer General Anatomy list~SCT^123037004^Anatomical Structure~\
                    SCT^64033007^Kidney~SCT^24028007^Right~Anatomic codes - DICOM master list~^^~^^|";
        let codes = from_slicer_tags(tags).unwrap();
        assert_eq!(
            codes.category,
            Code::new("SCT", "123037004", "Anatomical Structure")
        );
        assert_eq!(codes.kind, Code::new("SCT", "64033007", "Kidney"));
        assert_eq!(codes.modifier, Some(Code::new("SCT", "24028007", "Right")));
        let plain = "TerminologyEntry:list~SCT^123037004^Anatomical Structure~SCT^10200004^Liver~^^~x~^^~^^";
        assert_eq!(from_slicer_tags(plain).unwrap().modifier, None);
        assert_eq!(from_slicer_tags("|"), None);
        assert_eq!(from_slicer_tags("TerminologyEntry:list~^^~^^~^^"), None);
    }
}
