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
