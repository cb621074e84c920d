//! Files opened together, in the page's session and in the CLI, through the one path from
//! files to a case: a label map with its colour table, several masks, refusals.

#[path = "common/label_maps.rs"]
mod label_maps;

use label_maps::read;
use meshsmooth::session::Session;

/// Files dropped together in the page open as the CLI opens them, through the one path: a
/// colour table beside a label map names its labels; several masks are one structure each,
/// named by their files; two colour tables are refused by name.
#[test]
fn files_opened_together_make_the_case_the_cli_makes() {
    use meshsmooth::case;
    use meshsmooth::segmentation::NamedBytes;
    use meshsmooth::worker::NamedFile;

    let opened = |files: &[(&str, Vec<u8>)]| {
        let mut session = Session::default();
        let named = (files.iter())
            .map(|(name, bytes)| NamedFile {
                name: name.to_string(),
                bytes: bytes.clone(),
            })
            .collect();
        session.begin_open_files(named);
        let outcome = session.poll_opening().expect("done");
        (session, outcome)
    };
    let same = |session: &Session, expected: &case::Case| {
        let got = session.case().as_case().structures.as_slice();
        assert_eq!(got.len(), expected.structures.len());
        for (g, e) in got.iter().zip(&expected.structures) {
            assert_eq!(
                (&g.name, g.label, g.color, &g.source),
                (&e.name, e.label, e.color, &e.source)
            );
            assert_eq!(g.original, e.original, "{}", g.name);
        }
    };

    // A label map with its colour table, the table first as a drop may list it.
    let map = read("labelmaps/case_phantom_shared.nii.gz");
    let table = read("labelmaps/case_phantom_shared_labels.txt");
    let (session, outcome) = opened(&[
        ("case_phantom_shared_labels.txt", table.clone()),
        ("case_phantom_shared.nii.gz", map.clone()),
    ]);
    outcome.expect("opens");
    let cli = case::open(
        &[NamedBytes {
            name: "case_phantom_shared.nii.gz",
            bytes: &map,
        }],
        Some(NamedBytes {
            name: "case_phantom_shared_labels.txt",
            bytes: &table,
        }),
        &Default::default(),
    )
    .expect("the CLI's way");
    same(&session, &cli);
    let names: Vec<&str> = (session.case().as_case().structures.iter())
        .map(|s| s.name.as_str())
        .collect();
    assert!(!names.iter().any(|n| n.starts_with("label ")), "{names:?}");
    let model = session.case().model().expect("a model");
    assert_eq!(
        model.name,
        format!("case_phantom_shared.nii.gz: {}", names[0])
    );
    assert!(
        session.case().params().max_displacement.is_some(),
        "a label map's own bound"
    );

    // Four masks: one structure each, read and extracted one after another.
    let masks = [
        "sphere_r20_mask.nii.gz",
        "ellipsoid_30_20_12_mask.nii.gz",
        "torus_R24_r8_mask.nii.gz",
        "bent_tube_r3.5_mask.nii.gz",
    ];
    let bytes: Vec<Vec<u8>> = masks
        .iter()
        .map(|m| read(&format!("synthetic/{m}")))
        .collect();
    let files: Vec<(&str, Vec<u8>)> = masks.iter().copied().zip(bytes.iter().cloned()).collect();
    let (session, outcome) = opened(&files);
    outcome.expect("opens");
    let named: Vec<NamedBytes> = (masks.iter().zip(&bytes))
        .map(|(name, bytes)| NamedBytes { name, bytes })
        .collect();
    same(
        &session,
        &case::open(&named, None, &Default::default()).unwrap(),
    );
    let names: Vec<&str> = (session.case().as_case().structures.iter())
        .map(|s| s.name.as_str())
        .collect();
    assert_eq!(
        names,
        [
            "Sphere r20 mask",
            "Ellipsoid 30 20 12 mask",
            "Torus R24 r8 mask",
            "Bent tube r3.5 mask"
        ]
    );
    let stages: Vec<&str> = (session.open_stages().iter())
        .map(|(d, _)| d.as_str())
        .collect();
    let mut expected = ["reading a file", "extracting its structures"].repeat(4);
    expected.extend([
        "building the topology",
        "checking the mesh",
        "measuring the original",
    ]);
    assert_eq!(stages, expected);
    assert_eq!(
        session.case().case_file(),
        "sphere_r20_mask.nii.gz and 3 more files"
    );

    // Two tables: which one names the labels is not for the page to guess.
    let (session, outcome) = opened(&[
        ("case_phantom_shared.nii.gz", map),
        ("a.txt", table.clone()),
        ("b.txt", table),
    ]);
    let why = outcome.expect_err("refused");
    assert!(why.contains("a.txt") && why.contains("b.txt"), "{why}");
    assert!(session.case().model().is_none());
}

/// A surface opened after a segmentation keeps the filter and parameters the author was
/// trying, but not the displacement bound, which was half the last structure's voxel diagonal.
#[test]
fn a_surface_opened_after_a_segmentation_keeps_its_settings_but_not_its_voxel_bound() {
    let mut session = Session::default();
    let map = read("labelmaps/case_phantom_shared.seg.nrrd");
    session
        .open("case_phantom_shared.seg.nrrd", &map)
        .expect("opens");
    let mut liver = *session.case().params();
    assert_eq!(liver.max_displacement, Some(1.3662723), "the liver's bound");
    liver.iterations = 17;
    session.case_mut().set_params(liver).expect("set");
    let tube = read("synthetic/synthetic_bent_tube_r3.5.ply");
    session.open("tube.ply", &tube).expect("opens");
    let kept = *session.case().params();
    assert_eq!(kept.max_displacement, None);
    assert_eq!(
        (kept.filter, kept.alpha, kept.beta, kept.iterations),
        (liver.filter, liver.alpha, liver.beta, 17)
    );
    // A bound the author chose for a surface stays with the next one.
    let mut chosen = kept;
    chosen.max_displacement = Some(0.4);
    session.case_mut().set_params(chosen).expect("set");
    session.open("again.ply", &tube).expect("opens");
    assert_eq!(session.case().params().max_displacement, Some(0.4));
}
