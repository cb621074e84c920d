//! The page's session on how a case's structures relate, as the author and the student see
//! it: the checks between them (and where the view marks their warnings), and the structure
//! under the pointer.

#[path = "common/label_maps.rs"]
mod label_maps;

use label_maps::{open_in_session, read};
use meshsmooth::session::{Session, StructureChange};
mod common_session;
use common_session::smooth_cpu;

/// The page's checks between structures report what the CLI's `case build` reports for the
/// case as it stands: the tumour lies inside the liver, until the liver is shrunk around it.
#[test]
fn the_session_checks_its_structures_as_they_stand() {
    use meshsmooth::smooth::{Filter, Params};
    let mut session = Session::default();
    let phantom = read("labelmaps/case_phantom_shared.seg.nrrd");
    open_in_session(&mut session, "case_phantom_shared.seg.nrrd", phantom);
    smooth_cpu(&mut session);
    session.start_checks().unwrap();
    assert!(
        session.step_checks(),
        "a worker on this thread answers at once"
    );
    assert!(!session.background().checking());
    let report = session.background().checks_report().unwrap();
    assert!(
        report["text"]
            .as_str()
            .unwrap()
            .contains("tumor lies inside liver"),
        "{report}"
    );
    assert_eq!(report["left_inside"], serde_json::json!([]));
    assert!(session.background().checks_current());
    assert!(session.background().flagged_structures().is_empty());
    // The same as the CLI's pipeline says of the same case.
    let case = session.case().to_case().unwrap();
    let before = meshsmooth::case::check(&case, false);
    let after = meshsmooth::case::check(&case, true);
    let changes = meshsmooth::case::relations::changes(&before, &after);
    let cli = meshsmooth::case::checks_json(&case, &after, &changes);
    assert_eq!(report["pairs"], cli["pairs"]);

    // A liver shrunk by heavy Laplace smoothing no longer holds the tumour.
    let shrink = Params {
        lambda: 0.9,
        iterations: 50,
        max_displacement: None,
        ..Params::defaults(Filter::Laplace)
    };
    session.case_mut().set_params(shrink).unwrap();
    assert!(!session.background().checks_current());
    smooth_cpu(&mut session);
    session.start_checks().unwrap();
    session.step_checks();
    let report = session.background().checks_report().unwrap();
    assert_eq!(
        report["left_inside"],
        serde_json::json!([["tumor", "liver"]]),
        "{}",
        report["text"]
    );
    assert!(report["text"]
        .as_str()
        .unwrap()
        .contains("warning: tumor no longer lies inside liver"));
    // The shrunk liver now also crosses the portal vein, and the tumour.
    let crossings = &report["new_crossings"];
    assert_eq!(
        crossings,
        &serde_json::json!([["liver", "portal_vein"], ["liver", "tumor"]])
    );
    assert_eq!(session.background().flagged_structures(), [0, 1, 2]);

    // The view marks where: the tumour's vertices out of the liver, the liver's in the vein and
    // the tumour, the vein's and the tumour's in the liver; nothing of the kidney.
    let marked = report["marked_vertices"].as_array().unwrap();
    let counts: Vec<u64> = marked.iter().map(|n| n.as_u64().unwrap()).collect();
    assert!(counts[..3].iter().all(|&n| n > 0), "{counts:?}");
    assert_eq!(counts[3], 0, "{counts:?}");
    let key = session.background().marks_key().expect("marks to show");
    let patches = session.background().marked_surfaces();
    assert_eq!(patches.len(), 3);
    let liver = &session.case().as_case().structures[0];
    assert!(patches[0].triangle_count() < liver.original.triangle_count() / 2);
    // Hiding or recolouring a structure leaves the surfaces as checked; a hidden one's marks
    // are not drawn.
    let hide = StructureChange {
        visible: Some(false),
        color: Some([0.2, 0.3, 0.4]),
        ..Default::default()
    };
    session.case_mut().set_structure(1, hide).unwrap();
    assert!(session.background().checks_current());
    assert_eq!(session.background().marks_key(), Some(key));
    assert_eq!(session.background().marked_surfaces().len(), 2);
    // Smoothing anew does not: the marks go.
    session
        .case_mut()
        .set_params(Params::defaults(Filter::Hc))
        .unwrap();
    smooth_cpu(&mut session);
    assert!(!session.background().checks_current());
    assert_eq!(session.background().marks_key(), None);
    assert!(session.background().marked_surfaces().is_empty());
    // Back to the checked parameters, the same surface again: the marks are current again.
    session.case_mut().set_params(shrink).unwrap();
    smooth_cpu(&mut session);
    assert_eq!(session.background().marks_key(), Some(key));
}

/// The structure under the pointer, as drawn: the nearest visible one along the ray, looking
/// through hidden and transparent ones and past what the clipping plane cuts away.
#[test]
fn the_structure_under_the_pointer_is_the_nearest_drawn() {
    use meshsmooth::view::Ray;
    let mut session = Session::default();
    let phantom = read("labelmaps/case_phantom_shared.seg.nrrd");
    open_in_session(&mut session, "case_phantom_shared.seg.nrrd", phantom);
    let tumour = &session.case().as_case().structures[2].original.positions;
    let centre = tumour
        .iter()
        .fold(glam::Vec3::ZERO, |sum, &p| sum + glam::Vec3::from(p))
        / tumour.len() as f32;
    // From the patient's left, level with the tumour: the liver holds it.
    let ray = Ray {
        origin: centre - glam::Vec3::X * 500.0,
        direction: glam::Vec3::X,
    };
    let none = [0.0; 4];
    let (first, hit) =
        meshsmooth::view::structure_at(&session.case().as_case().structures, &ray, none)
            .expect("the case in the way");
    assert_eq!(first, 0, "the liver first");
    let clear = StructureChange {
        opacity: Some(0.0),
        ..Default::default()
    };
    session.case_mut().set_structure(0, clear).unwrap();
    let (seen, deeper) =
        meshsmooth::view::structure_at(&session.case().as_case().structures, &ray, none).unwrap();
    assert_eq!(seen, 2, "through the transparent liver, the tumour");
    assert!(deeper.distance > hit.distance);
    session.case_mut().solo_structure(2).unwrap();
    let (alone, near) =
        meshsmooth::view::structure_at(&session.case().as_case().structures, &ray, none).unwrap();
    assert_eq!(alone, 2);
    // A plane through the tumour's centre cutting away its near half (x below the centre):
    // the pointer meets its far half.
    let cut_near = [-1.0, 0.0, 0.0, -centre.x];
    let (_, far) =
        meshsmooth::view::structure_at(&session.case().as_case().structures, &ray, cut_near)
            .unwrap();
    assert!(
        far.point.x > centre.x && far.distance > near.distance,
        "{far:?}"
    );
    // Cutting everything away leaves nothing to name.
    assert!(meshsmooth::view::structure_at(
        &session.case().as_case().structures,
        &ray,
        [0.0, 0.0, 0.0, -1.0]
    )
    .is_none());
    session.case_mut().solo_structure(2).unwrap();
    let hide = StructureChange {
        visible: Some(false),
        ..Default::default()
    };
    session.case_mut().set_structure(2, hide).unwrap();
    assert_ne!(
        meshsmooth::view::structure_at(&session.case().as_case().structures, &ray, none)
            .map(|(i, _)| i),
        Some(2),
        "hidden"
    );
}
