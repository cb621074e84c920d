//! FreeSurfer's colour table for the labels of `aseg.mgz` and `aparc+aseg.mgz` (the subcortical
//! structures and the Desikan-Killiany cortical parcels, `ctx-lh-*` and `ctx-rh-*`): names and
//! colours as FreeSurfer 7 publishes them in `distribution/FreeSurferColorLUT.txt` of
//! github.com/freesurfer/freesurfer (commit 62228baedd5c5914333d31211e3e02759faed287). Older
//! tables call labels 10 and 49 `Left-Thalamus-Proper` and `Right-Thalamus-Proper`.

/// Value, name and sRGB colour, by value.
const TABLE: &[(i64, &str, [u8; 3])] = &[
    (1, "Left-Cerebral-Exterior", [70, 130, 180]),
    (2, "Left-Cerebral-White-Matter", [245, 245, 245]),
    (3, "Left-Cerebral-Cortex", [205, 62, 78]),
    (4, "Left-Lateral-Ventricle", [120, 18, 134]),
    (5, "Left-Inf-Lat-Vent", [196, 58, 250]),
    (6, "Left-Cerebellum-Exterior", [0, 148, 0]),
    (7, "Left-Cerebellum-White-Matter", [220, 248, 164]),
    (8, "Left-Cerebellum-Cortex", [230, 148, 34]),
    (9, "Left-Thalamus-unused", [0, 118, 14]),
    (10, "Left-Thalamus", [0, 118, 14]),
    (11, "Left-Caudate", [122, 186, 220]),
    (12, "Left-Putamen", [236, 13, 176]),
    (13, "Left-Pallidum", [12, 48, 255]),
    (14, "3rd-Ventricle", [204, 182, 142]),
    (15, "4th-Ventricle", [42, 204, 164]),
    (16, "Brain-Stem", [119, 159, 176]),
    (17, "Left-Hippocampus", [220, 216, 20]),
    (18, "Left-Amygdala", [103, 255, 255]),
    (19, "Left-Insula", [80, 196, 98]),
    (20, "Left-Operculum", [60, 58, 210]),
    (21, "Line-1", [60, 58, 210]),
    (22, "Line-2", [60, 58, 210]),
    (23, "Line-3", [60, 58, 210]),
    (24, "CSF", [60, 60, 60]),
    (25, "Left-Lesion", [255, 165, 0]),
    (26, "Left-Accumbens-area", [255, 165, 0]),
    (27, "Left-Substancia-Nigra", [0, 255, 127]),
    (28, "Left-VentralDC", [165, 42, 42]),
    (29, "Left-undetermined", [135, 206, 235]),
    (30, "Left-vessel", [160, 32, 240]),
    (31, "Left-choroid-plexus", [0, 200, 200]),
    (32, "Left-F3orb", [100, 50, 100]),
    (33, "Left-aOg", [122, 135, 50]),
    (34, "Left-WMCrowns", [123, 135, 50]),
    (35, "Left-mOg", [51, 50, 135]),
    (36, "Left-pOg", [74, 155, 60]),
    (37, "Left-Stellate", [120, 62, 43]),
    (38, "Left-Porg", [74, 155, 60]),
    (39, "Left-Aorg", [122, 135, 50]),
    (40, "Right-Cerebral-Exterior", [70, 130, 180]),
    (41, "Right-Cerebral-White-Matter", [245, 245, 245]),
    (42, "Right-Cerebral-Cortex", [205, 62, 78]),
    (43, "Right-Lateral-Ventricle", [120, 18, 134]),
    (44, "Right-Inf-Lat-Vent", [196, 58, 250]),
    (45, "Right-Cerebellum-Exterior", [0, 148, 0]),
    (46, "Right-Cerebellum-White-Matter", [220, 248, 164]),
    (47, "Right-Cerebellum-Cortex", [230, 148, 34]),
    (48, "Right-Thalamus-unused", [0, 118, 14]),
    (49, "Right-Thalamus", [0, 118, 14]),
    (50, "Right-Caudate", [122, 186, 220]),
    (51, "Right-Putamen", [236, 13, 176]),
    (52, "Right-Pallidum", [13, 48, 255]),
    (53, "Right-Hippocampus", [220, 216, 20]),
    (54, "Right-Amygdala", [103, 255, 255]),
    (55, "Right-Insula", [80, 196, 98]),
    (56, "Right-Operculum", [60, 58, 210]),
    (57, "Right-Lesion", [255, 165, 0]),
    (58, "Right-Accumbens-area", [255, 165, 0]),
    (59, "Right-Substancia-Nigra", [0, 255, 127]),
    (60, "Right-VentralDC", [165, 42, 42]),
    (61, "Right-undetermined", [135, 206, 235]),
    (62, "Right-vessel", [160, 32, 240]),
    (63, "Right-choroid-plexus", [0, 200, 221]),
    (64, "Right-F3orb", [100, 50, 100]),
    (65, "Right-lOg", [135, 50, 74]),
    (66, "Right-WMCrowns", [122, 135, 50]),
    (67, "Right-mOg", [51, 50, 135]),
    (68, "Right-pOg", [74, 155, 60]),
    (69, "Right-Stellate", [120, 62, 43]),
    (70, "Right-Porg", [74, 155, 60]),
    (71, "Right-Aorg", [122, 135, 50]),
    (72, "5th-Ventricle", [120, 190, 150]),
    (73, "Left-Interior", [122, 135, 50]),
    (74, "Right-Interior", [122, 135, 50]),
    (75, "Left-Locus-Coeruleus", [91, 97, 255]),
    (76, "Right-Locus-Coeruleus", [0, 7, 218]),
    (77, "WM-hypointensities", [200, 70, 255]),
    (78, "Left-WM-hypointensities", [255, 148, 10]),
    (79, "Right-WM-hypointensities", [255, 148, 10]),
    (80, "non-WM-hypointensities", [164, 108, 226]),
    (81, "Left-non-WM-hypointensities", [164, 108, 226]),
    (82, "Right-non-WM-hypointensities", [164, 108, 226]),
    (83, "Left-F1", [255, 218, 185]),
    (84, "Right-F1", [255, 218, 185]),
    (85, "Optic-Chiasm", [234, 169, 30]),
    (251, "CC_Posterior", [0, 0, 64]),
    (252, "CC_Mid_Posterior", [0, 0, 112]),
    (253, "CC_Central", [0, 0, 160]),
    (254, "CC_Mid_Anterior", [0, 0, 208]),
    (255, "CC_Anterior", [0, 0, 255]),
    (1000, "ctx-lh-unknown", [25, 5, 25]),
    (1001, "ctx-lh-bankssts", [25, 100, 40]),
    (1002, "ctx-lh-caudalanteriorcingulate", [125, 100, 160]),
    (1003, "ctx-lh-caudalmiddlefrontal", [100, 25, 0]),
    (1004, "ctx-lh-corpuscallosum", [120, 70, 50]),
    (1005, "ctx-lh-cuneus", [220, 20, 100]),
    (1006, "ctx-lh-entorhinal", [220, 20, 10]),
    (1007, "ctx-lh-fusiform", [180, 220, 140]),
    (1008, "ctx-lh-inferiorparietal", [220, 60, 220]),
    (1009, "ctx-lh-inferiortemporal", [180, 40, 120]),
    (1010, "ctx-lh-isthmuscingulate", [140, 20, 140]),
    (1011, "ctx-lh-lateraloccipital", [20, 30, 140]),
    (1012, "ctx-lh-lateralorbitofrontal", [35, 75, 50]),
    (1013, "ctx-lh-lingual", [225, 140, 140]),
    (1014, "ctx-lh-medialorbitofrontal", [200, 35, 75]),
    (1015, "ctx-lh-middletemporal", [160, 100, 50]),
    (1016, "ctx-lh-parahippocampal", [20, 220, 60]),
    (1017, "ctx-lh-paracentral", [60, 220, 60]),
    (1018, "ctx-lh-parsopercularis", [220, 180, 140]),
    (1019, "ctx-lh-parsorbitalis", [20, 100, 50]),
    (1020, "ctx-lh-parstriangularis", [220, 60, 20]),
    (1021, "ctx-lh-pericalcarine", [120, 100, 60]),
    (1022, "ctx-lh-postcentral", [220, 20, 20]),
    (1023, "ctx-lh-posteriorcingulate", [220, 180, 220]),
    (1024, "ctx-lh-precentral", [60, 20, 220]),
    (1025, "ctx-lh-precuneus", [160, 140, 180]),
    (1026, "ctx-lh-rostralanteriorcingulate", [80, 20, 140]),
    (1027, "ctx-lh-rostralmiddlefrontal", [75, 50, 125]),
    (1028, "ctx-lh-superiorfrontal", [20, 220, 160]),
    (1029, "ctx-lh-superiorparietal", [20, 180, 140]),
    (1030, "ctx-lh-superiortemporal", [140, 220, 220]),
    (1031, "ctx-lh-supramarginal", [80, 160, 20]),
    (1032, "ctx-lh-frontalpole", [100, 0, 100]),
    (1033, "ctx-lh-temporalpole", [70, 70, 70]),
    (1034, "ctx-lh-transversetemporal", [150, 150, 200]),
    (1035, "ctx-lh-insula", [255, 192, 32]),
    (2000, "ctx-rh-unknown", [25, 5, 25]),
    (2001, "ctx-rh-bankssts", [25, 100, 40]),
    (2002, "ctx-rh-caudalanteriorcingulate", [125, 100, 160]),
    (2003, "ctx-rh-caudalmiddlefrontal", [100, 25, 0]),
    (2004, "ctx-rh-corpuscallosum", [120, 70, 50]),
    (2005, "ctx-rh-cuneus", [220, 20, 100]),
    (2006, "ctx-rh-entorhinal", [220, 20, 10]),
    (2007, "ctx-rh-fusiform", [180, 220, 140]),
    (2008, "ctx-rh-inferiorparietal", [220, 60, 220]),
    (2009, "ctx-rh-inferiortemporal", [180, 40, 120]),
    (2010, "ctx-rh-isthmuscingulate", [140, 20, 140]),
    (2011, "ctx-rh-lateraloccipital", [20, 30, 140]),
    (2012, "ctx-rh-lateralorbitofrontal", [35, 75, 50]),
    (2013, "ctx-rh-lingual", [225, 140, 140]),
    (2014, "ctx-rh-medialorbitofrontal", [200, 35, 75]),
    (2015, "ctx-rh-middletemporal", [160, 100, 50]),
    (2016, "ctx-rh-parahippocampal", [20, 220, 60]),
    (2017, "ctx-rh-paracentral", [60, 220, 60]),
    (2018, "ctx-rh-parsopercularis", [220, 180, 140]),
    (2019, "ctx-rh-parsorbitalis", [20, 100, 50]),
    (2020, "ctx-rh-parstriangularis", [220, 60, 20]),
    (2021, "ctx-rh-pericalcarine", [120, 100, 60]),
    (2022, "ctx-rh-postcentral", [220, 20, 20]),
    (2023, "ctx-rh-posteriorcingulate", [220, 180, 220]),
    (2024, "ctx-rh-precentral", [60, 20, 220]),
    (2025, "ctx-rh-precuneus", [160, 140, 180]),
    (2026, "ctx-rh-rostralanteriorcingulate", [80, 20, 140]),
    (2027, "ctx-rh-rostralmiddlefrontal", [75, 50, 125]),
    (2028, "ctx-rh-superiorfrontal", [20, 220, 160]),
    (2029, "ctx-rh-superiorparietal", [20, 180, 140]),
    (2030, "ctx-rh-superiortemporal", [140, 220, 220]),
    (2031, "ctx-rh-supramarginal", [80, 160, 20]),
    (2032, "ctx-rh-frontalpole", [100, 0, 100]),
    (2033, "ctx-rh-temporalpole", [70, 70, 70]),
    (2034, "ctx-rh-transversetemporal", [150, 150, 200]),
    (2035, "ctx-rh-insula", [255, 192, 32]),
];

/// The name and colour FreeSurfer gives `value`, if its table for these volumes lists it.
pub(super) fn entry(value: i64) -> Option<(&'static str, [u8; 3])> {
    let i = TABLE.binary_search_by_key(&value, |e| e.0).ok()?;
    Some((TABLE[i].1, TABLE[i].2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_sorted_and_names_what_aseg_and_aparc_use() {
        assert!(TABLE.windows(2).all(|w| w[0].0 < w[1].0));
        assert_eq!(entry(17), Some(("Left-Hippocampus", [220, 216, 20])));
        assert_eq!(entry(2035), Some(("ctx-rh-insula", [255, 192, 32])));
        assert_eq!(entry(0), None);
        assert_eq!(entry(3000), None);
    }

    #[test]
    fn the_standard_codes_give_freesurfers_labels_freesurfers_colours() {
        let mut coded = 0;
        for &(_, name, rgb) in TABLE {
            if let Some(class) = crate::segmentation::standard_class(name) {
                assert_eq!(
                    class.color.map(|c| (c * 255.0).round() as u8),
                    rgb,
                    "{name}"
                );
                coded += 1;
            }
        }
        // fs2dicom's 49 aseg labels, under FreeSurfer 7's names.
        assert_eq!(coded, 49);
    }
}
