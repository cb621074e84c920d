//! Standard codes for common structure names: the classes of TotalSegmentator's 'total' task
//! with the SNOMED CT codes TotalSegmentator publishes for them
//! (`totalsegmentator/resources/totalsegmentator_snomed_mapping.csv` of
//! github.com/wasserth/TotalSegmentator, last changed in d90ebaf4d8d5), so that a case built
//! from its output carries codes without the author typing them. A structure matches a class by
//! its name as TotalSegmentator writes it or as it reads ("kidney_right", "Right kidney"),
//! ignoring case.

use crate::io::{readable_class_name, Code, StructureCodes};

/// Category, type and modifier, each (scheme, value, meaning).
type Coded = (&'static str, &'static str, &'static str);

const ANATOMY: Coded = ("SCT", "123037004", "Anatomical Structure");
const ALTERED: Coded = ("SCT", "49755003", "Morphologically Altered Structure");
const LEFT: Option<Coded> = Some(("SCT", "7771000", "Left"));
const RIGHT: Option<Coded> = Some(("SCT", "24028007", "Right"));

/// Class name, category, type, modifier.
const TOTALSEGMENTATOR: &[(&str, Coded, Coded, Option<Coded>)] = &[
    (
        "adrenal_gland_left",
        ANATOMY,
        ("SCT", "23451007", "Adrenal gland"),
        LEFT,
    ),
    (
        "adrenal_gland_right",
        ANATOMY,
        ("SCT", "23451007", "Adrenal gland"),
        RIGHT,
    ),
    ("aorta", ANATOMY, ("SCT", "15825003", "Aorta"), None),
    (
        "autochthon_left",
        ANATOMY,
        ("SCT", "244849004", "Deep muscle of back"),
        LEFT,
    ),
    (
        "autochthon_right",
        ANATOMY,
        ("SCT", "244849004", "Deep muscle of back"),
        RIGHT,
    ),
    ("brain", ANATOMY, ("SCT", "12738006", "Brain"), None),
    (
        "clavicula_left",
        ANATOMY,
        ("SCT", "51299004", "Clavicle"),
        LEFT,
    ),
    (
        "clavicula_right",
        ANATOMY,
        ("SCT", "51299004", "Clavicle"),
        RIGHT,
    ),
    ("colon", ANATOMY, ("SCT", "71854001", "Colon"), None),
    ("duodenum", ANATOMY, ("SCT", "38848004", "Duodenum"), None),
    ("esophagus", ANATOMY, ("SCT", "32849002", "Esophagus"), None),
    ("femur_left", ANATOMY, ("SCT", "71341001", "Femur"), LEFT),
    ("femur_right", ANATOMY, ("SCT", "71341001", "Femur"), RIGHT),
    (
        "gallbladder",
        ANATOMY,
        ("SCT", "28231008", "Gallbladder"),
        None,
    ),
    (
        "gluteus_maximus_left",
        ANATOMY,
        ("SCT", "181674001", "Gluteus maximus muscle"),
        LEFT,
    ),
    (
        "gluteus_maximus_right",
        ANATOMY,
        ("SCT", "181674001", "Gluteus maximus muscle"),
        RIGHT,
    ),
    (
        "gluteus_medius_left",
        ANATOMY,
        ("SCT", "78333006", "Gluteus medius muscle"),
        LEFT,
    ),
    (
        "gluteus_medius_right",
        ANATOMY,
        ("SCT", "78333006", "Gluteus medius muscle"),
        RIGHT,
    ),
    (
        "gluteus_minimus_left",
        ANATOMY,
        ("SCT", "75297007", "Gluteus minius muscle"),
        LEFT,
    ),
    (
        "gluteus_minimus_right",
        ANATOMY,
        ("SCT", "75297007", "Gluteus minius muscle"),
        RIGHT,
    ),
    ("hip_left", ANATOMY, ("SCT", "29836001", "Hip"), LEFT),
    ("hip_right", ANATOMY, ("SCT", "29836001", "Hip"), RIGHT),
    (
        "humerus_left",
        ANATOMY,
        ("SCT", "85050009", "Humerus"),
        LEFT,
    ),
    (
        "humerus_right",
        ANATOMY,
        ("SCT", "85050009", "Humerus"),
        RIGHT,
    ),
    (
        "iliac_artery_left",
        ANATOMY,
        ("SCT", "73634005", "Common iliac artery"),
        LEFT,
    ),
    (
        "iliac_artery_right",
        ANATOMY,
        ("SCT", "73634005", "Common iliac artery"),
        RIGHT,
    ),
    (
        "iliac_vena_left",
        ANATOMY,
        ("SCT", "46027005", "Common iliac vein"),
        LEFT,
    ),
    (
        "iliac_vena_right",
        ANATOMY,
        ("SCT", "46027005", "Common iliac vein"),
        RIGHT,
    ),
    (
        "iliopsoas_left",
        ANATOMY,
        ("SCT", "68455001", "Iliopsoas muscle"),
        LEFT,
    ),
    (
        "iliopsoas_right",
        ANATOMY,
        ("SCT", "68455001", "Iliopsoas muscle"),
        RIGHT,
    ),
    (
        "inferior_vena_cava",
        ANATOMY,
        ("SCT", "64131007", "Inferior vena cava"),
        None,
    ),
    ("kidney_left", ANATOMY, ("SCT", "64033007", "Kidney"), LEFT),
    (
        "kidney_right",
        ANATOMY,
        ("SCT", "64033007", "Kidney"),
        RIGHT,
    ),
    ("liver", ANATOMY, ("SCT", "10200004", "Liver"), None),
    (
        "lung_lower_lobe_left",
        ANATOMY,
        ("SCT", "90572001", "Lower lobe of lung"),
        LEFT,
    ),
    (
        "lung_lower_lobe_right",
        ANATOMY,
        ("SCT", "90572001", "Lower lobe of lung"),
        RIGHT,
    ),
    (
        "lung_middle_lobe_right",
        ANATOMY,
        ("SCT", "72481006", "Middle lobe of right lung"),
        None,
    ),
    (
        "lung_upper_lobe_left",
        ANATOMY,
        ("SCT", "45653009", "Upper lobe of lung"),
        LEFT,
    ),
    (
        "lung_upper_lobe_right",
        ANATOMY,
        ("SCT", "45653009", "Upper lobe of lung"),
        RIGHT,
    ),
    ("pancreas", ANATOMY, ("SCT", "15776009", "Pancreas"), None),
    (
        "portal_vein_and_splenic_vein",
        ANATOMY,
        ("SCT", "110765007", "Portal vein and splenic vein"),
        None,
    ),
    (
        "rib_left_1",
        ANATOMY,
        ("SCT", "48535007", "First rib"),
        LEFT,
    ),
    (
        "rib_left_2",
        ANATOMY,
        ("SCT", "78247007", "Second rib"),
        LEFT,
    ),
    (
        "rib_left_3",
        ANATOMY,
        ("SCT", "25888004", "Third rib"),
        LEFT,
    ),
    (
        "rib_left_4",
        ANATOMY,
        ("SCT", "25523003", "Fourth rib"),
        LEFT,
    ),
    (
        "rib_left_5",
        ANATOMY,
        ("SCT", "15339008", "Fifth rib"),
        LEFT,
    ),
    (
        "rib_left_6",
        ANATOMY,
        ("SCT", "59558009", "Sixth rib"),
        LEFT,
    ),
    (
        "rib_left_7",
        ANATOMY,
        ("SCT", "24915002", "Seventh rib"),
        LEFT,
    ),
    (
        "rib_left_8",
        ANATOMY,
        ("SCT", "5953002", "Eighth rib"),
        LEFT,
    ),
    (
        "rib_left_9",
        ANATOMY,
        ("SCT", "22565002", "Ninth rib"),
        LEFT,
    ),
    (
        "rib_left_10",
        ANATOMY,
        ("SCT", "77644006", "Tenth rib"),
        LEFT,
    ),
    (
        "rib_left_11",
        ANATOMY,
        ("SCT", "58830002", "Eleventh rib"),
        LEFT,
    ),
    (
        "rib_left_12",
        ANATOMY,
        ("SCT", "43993008", "Twelfth rib"),
        LEFT,
    ),
    (
        "rib_right_1",
        ANATOMY,
        ("SCT", "48535007", "First rib"),
        RIGHT,
    ),
    (
        "rib_right_2",
        ANATOMY,
        ("SCT", "78247007", "Second rib"),
        RIGHT,
    ),
    (
        "rib_right_3",
        ANATOMY,
        ("SCT", "25888004", "Third rib"),
        RIGHT,
    ),
    (
        "rib_right_4",
        ANATOMY,
        ("SCT", "25523003", "Fourth rib"),
        RIGHT,
    ),
    (
        "rib_right_5",
        ANATOMY,
        ("SCT", "15339008", "Fifth rib"),
        RIGHT,
    ),
    (
        "rib_right_6",
        ANATOMY,
        ("SCT", "59558009", "Sixth rib"),
        RIGHT,
    ),
    (
        "rib_right_7",
        ANATOMY,
        ("SCT", "24915002", "Seventh rib"),
        RIGHT,
    ),
    (
        "rib_right_8",
        ANATOMY,
        ("SCT", "5953002", "Eighth rib"),
        RIGHT,
    ),
    (
        "rib_right_9",
        ANATOMY,
        ("SCT", "22565002", "Ninth rib"),
        RIGHT,
    ),
    (
        "rib_right_10",
        ANATOMY,
        ("SCT", "77644006", "Tenth rib"),
        RIGHT,
    ),
    (
        "rib_right_11",
        ANATOMY,
        ("SCT", "58830002", "Eleventh rib"),
        RIGHT,
    ),
    (
        "rib_right_12",
        ANATOMY,
        ("SCT", "43993008", "Twelfth rib"),
        RIGHT,
    ),
    ("sacrum", ANATOMY, ("SCT", "54735007", "Sacrum"), None),
    (
        "scapula_left",
        ANATOMY,
        ("SCT", "79601000", "Scapula"),
        LEFT,
    ),
    (
        "scapula_right",
        ANATOMY,
        ("SCT", "79601000", "Scapula"),
        RIGHT,
    ),
    (
        "small_bowel",
        ANATOMY,
        ("SCT", "30315005", "Small Intestine"),
        None,
    ),
    ("spleen", ANATOMY, ("SCT", "78961009", "Spleen"), None),
    ("stomach", ANATOMY, ("SCT", "69695003", "Stomach"), None),
    ("trachea", ANATOMY, ("SCT", "44567001", "Trachea"), None),
    (
        "urinary_bladder",
        ANATOMY,
        ("SCT", "89837001", "Urinary bladder"),
        None,
    ),
    (
        "vertebrae_S1",
        ANATOMY,
        ("SCT", "65985001", "S1 vertebra"),
        None,
    ),
    (
        "vertebrae_C1",
        ANATOMY,
        ("SCT", "14806007", "C1 vertebra"),
        None,
    ),
    (
        "vertebrae_C2",
        ANATOMY,
        ("SCT", "39976000", "C2 vertebra"),
        None,
    ),
    (
        "vertebrae_C3",
        ANATOMY,
        ("SCT", "113205007", "C3 vertebra"),
        None,
    ),
    (
        "vertebrae_C4",
        ANATOMY,
        ("SCT", "5329002", "C4 vertebra"),
        None,
    ),
    (
        "vertebrae_C5",
        ANATOMY,
        ("SCT", "36978003", "C5 vertebra"),
        None,
    ),
    (
        "vertebrae_C6",
        ANATOMY,
        ("SCT", "36054005", "C6 vertebra"),
        None,
    ),
    (
        "vertebrae_C7",
        ANATOMY,
        ("SCT", "87391001", "C7 vertebra"),
        None,
    ),
    (
        "vertebrae_L1",
        ANATOMY,
        ("SCT", "66794005", "L1 vertebra"),
        None,
    ),
    (
        "vertebrae_L2",
        ANATOMY,
        ("SCT", "14293000", "L2 vertebra"),
        None,
    ),
    (
        "vertebrae_L3",
        ANATOMY,
        ("SCT", "36470004", "L3 vertebra"),
        None,
    ),
    (
        "vertebrae_L4",
        ANATOMY,
        ("SCT", "11994002", "L4 vertebra"),
        None,
    ),
    (
        "vertebrae_L5",
        ANATOMY,
        ("SCT", "49668003", "L5 vertebra"),
        None,
    ),
    (
        "vertebrae_T1",
        ANATOMY,
        ("SCT", "64864005", "T1 vertebra"),
        None,
    ),
    (
        "vertebrae_T2",
        ANATOMY,
        ("SCT", "53733008", "T2 vertebra"),
        None,
    ),
    (
        "vertebrae_T3",
        ANATOMY,
        ("SCT", "1626008", "T3 vertebra"),
        None,
    ),
    (
        "vertebrae_T4",
        ANATOMY,
        ("SCT", "73071006", "T4 vertebra"),
        None,
    ),
    (
        "vertebrae_T5",
        ANATOMY,
        ("SCT", "56401006", "T5 vertebra"),
        None,
    ),
    (
        "vertebrae_T6",
        ANATOMY,
        ("SCT", "45296009", "T6 vertebra"),
        None,
    ),
    (
        "vertebrae_T7",
        ANATOMY,
        ("SCT", "62487009", "T7 vertebra"),
        None,
    ),
    (
        "vertebrae_T8",
        ANATOMY,
        ("SCT", "11068009", "T8 vertebra"),
        None,
    ),
    (
        "vertebrae_T9",
        ANATOMY,
        ("SCT", "82687006", "T9 vertebra"),
        None,
    ),
    (
        "vertebrae_T10",
        ANATOMY,
        ("SCT", "7610001", "T10 vertebra"),
        None,
    ),
    (
        "vertebrae_T11",
        ANATOMY,
        ("SCT", "12989004", "T11 vertebra"),
        None,
    ),
    (
        "vertebrae_T12",
        ANATOMY,
        ("SCT", "23215003", "T12 vertebra"),
        None,
    ),
    ("heart", ANATOMY, ("SCT", "80891009", "Heart"), None),
    (
        "pulmonary_vein",
        ANATOMY,
        ("SCT", "122972007", "Pulmonary vein"),
        None,
    ),
    (
        "brachiocephalic_trunk",
        ANATOMY,
        ("SCT", "12691009", "Brachiocephalic artery"),
        None,
    ),
    (
        "subclavian_artery_right",
        ANATOMY,
        ("SCT", "29700009", "Subclavian artery"),
        RIGHT,
    ),
    (
        "subclavian_artery_left",
        ANATOMY,
        ("SCT", "29700009", "Subclavian artery"),
        LEFT,
    ),
    (
        "common_carotid_artery_right",
        ANATOMY,
        ("SCT", "32062004", "Common carotid artery"),
        RIGHT,
    ),
    (
        "common_carotid_artery_left",
        ANATOMY,
        ("SCT", "32062004", "Common carotid artery"),
        LEFT,
    ),
    (
        "brachiocephalic_vein_left",
        ANATOMY,
        ("SCT", "8887007", "Brachiocephalic vein"),
        LEFT,
    ),
    (
        "brachiocephalic_vein_right",
        ANATOMY,
        ("SCT", "8887007", "Brachiocephalic vein"),
        RIGHT,
    ),
    (
        "atrial_appendage_left",
        ANATOMY,
        ("SCT", "68786006", "Auricular appendage"),
        LEFT,
    ),
    (
        "superior_vena_cava",
        ANATOMY,
        ("SCT", "48345005", "Superior vena cava"),
        None,
    ),
    (
        "kidney_cyst_left",
        ALTERED,
        ("SCT", "367643001", "Cyst"),
        None,
    ),
    (
        "kidney_cyst_right",
        ALTERED,
        ("SCT", "367643001", "Cyst"),
        None,
    ),
    ("prostate", ANATOMY, ("SCT", "41216001", "Prostate"), None),
    ("sternum", ANATOMY, ("SCT", "56873002", "Sternum"), None),
    ("skull", ANATOMY, ("SCT", "89546000", "Skull"), None),
    (
        "spinal_cord",
        ANATOMY,
        ("SCT", "2748008", "Spinal cord"),
        None,
    ),
    (
        "thyroid_gland",
        ANATOMY,
        ("SCT", "69748006", "Thyroid gland"),
        None,
    ),
    (
        "costal_cartilages",
        ANATOMY,
        ("SCT", "50016007", "Costal cartilage"),
        None,
    ),
];

/// The codes of a structure named `name`, when it is one of the classes above.
pub fn codes_for_name(name: &str) -> Option<StructureCodes> {
    let name = name.trim();
    let (_, category, kind, modifier) = (TOTALSEGMENTATOR.iter()).find(|(class, ..)| {
        class.eq_ignore_ascii_case(name) || readable_class_name(class).eq_ignore_ascii_case(name)
    })?;
    let code = |(scheme, value, meaning): &Coded| Code::new(scheme, value, meaning);
    Some(StructureCodes {
        category: code(category),
        kind: code(kind),
        modifier: modifier.as_ref().map(code),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn totalsegmentator_classes_have_their_published_codes() {
        assert_eq!(TOTALSEGMENTATOR.len(), 117);
        let kidney = codes_for_name("Right kidney").unwrap();
        assert_eq!(kidney.kind, Code::new("SCT", "64033007", "Kidney"));
        assert_eq!(kidney.modifier, Some(Code::new("SCT", "24028007", "Right")));
        assert_eq!(codes_for_name("kidney_right"), Some(kidney));
        let liver = codes_for_name("liver").unwrap();
        assert_eq!(
            liver.category,
            Code::new("SCT", "123037004", "Anatomical Structure")
        );
        assert_eq!(
            (liver.kind.value.as_str(), liver.modifier),
            ("10200004", None)
        );
        assert_eq!(
            codes_for_name("Left rib 1").unwrap().kind.meaning,
            "First rib"
        );
        assert_eq!(codes_for_name("tumor"), None);
    }
}
