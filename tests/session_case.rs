//! The page's session as a case: a label map's structures (each shown and smoothed its own
//! way, with Gibson's bound by default), files added to the case, and the case glTF it writes
//! reopened as the same case. "Suggest all" in the session: tests/session_suggest_all.rs.

#[path = "common/label_maps.rs"]
mod label_maps;

use label_maps::{open_in_session, read};

#[path = "common/vertex_match.rs"]
mod vertex_match;

use meshsmooth::export::CaseGltfOptions;
use meshsmooth::session::{Session, StructureChange};
use vertex_match::match_vertices;
mod common_session;
use common_session::smooth_cpu;

/// The open case's structures.
fn structures(session: &Session) -> &[meshsmooth::case::CaseStructure] {
    &session.case().as_case().structures
}

/// The page's case glTF: compressed, with the local error.
fn page_export() -> CaseGltfOptions {
    CaseGltfOptions {
        local_error: true,
        ..CaseGltfOptions::default()
    }
}

/// The page's session opens a label map in a worker (read, extract, then a mesh's stages), makes the
/// first structure the model with its voxel size, and opens another structure on request.
#[test]
fn a_session_opens_a_label_map_as_its_structures() {
    use meshsmooth::session::Session;
    let bytes = read("labelmaps/case_phantom_shared.seg.nrrd");
    let mut session = Session::default();
    session.begin_open("case_phantom_shared.seg.nrrd", bytes);
    session.poll_opening().expect("done").expect("opens");
    let stages: Vec<&str> = session
        .open_stages()
        .iter()
        .map(|(d, _)| d.as_str())
        .collect();
    assert_eq!(
        stages,
        [
            "reading the label map",
            "extracting the structures",
            "building the topology",
            "checking the mesh",
            "measuring the original"
        ]
    );
    let structures = session.case().as_case().structures.as_slice();
    assert_eq!(structures.len(), 4);
    assert_eq!(session.case().current_structure(), Some(0));
    let model = session.case().model().expect("a model");
    assert_eq!(model.name, "case_phantom_shared.seg.nrrd: liver");
    assert_eq!(model.mesh(), &structures[0].original);
    let vd = session
        .case()
        .voxel_diagonal()
        .expect("the voxel size comes with the structure");
    assert!((vd - (0.78f64 * 0.78 * 2.0 + 2.5 * 2.5).sqrt()).abs() < 1e-6);
    // Gibson's bound by default: half the voxel diagonal, with the case's filter.
    let params = session.case().params();
    assert_eq!(params.filter, meshsmooth::case::DEFAULT_FILTER);
    assert_eq!(params.max_displacement, Some((0.5 * vd) as f32));

    session.select_structure(2).expect("structure 2 exists");
    assert_eq!(session.case().current_structure(), Some(2));
    assert_eq!(
        session.case().model().expect("a model").name,
        "case_phantom_shared.seg.nrrd: tumor"
    );
    assert!(session
        .select_structure(4)
        .unwrap_err()
        .contains("4 does not exist"));

    // A broken label map keeps the open model and says what is wrong with which file.
    let mut broken = read("labelmaps/case_phantom_shared.nii.gz");
    broken.truncate(broken.len() / 2);
    session.begin_open("half.nii.gz", broken);
    let e = session.poll_opening().expect("finished").unwrap_err();
    assert!(e.starts_with("Cannot open half.nii.gz: "), "{e}");
    assert_eq!(
        session.case().model().expect("kept").name,
        "case_phantom_shared.seg.nrrd: tumor"
    );
}

/// The page's session shows a segmentation's structures each its own way: colours, opacity,
/// visibility and names as the author sets them, and each structure's smoothing kept while
/// another is the model, and restored when it is the model again.
#[test]
fn a_session_keeps_each_structures_look_and_smoothing() {
    use meshsmooth::smooth::{Filter, Params};
    let mut session = Session::default();
    session.begin_open(
        "case_phantom_shared.seg.nrrd",
        read("labelmaps/case_phantom_shared.seg.nrrd"),
    );
    session.poll_opening().expect("done").expect("opens");
    assert_eq!(session.case().as_case().structures.len(), 4);
    assert!(structures(&session)
        .iter()
        .all(|l| l.visible && l.color[3] == 1.0));
    // Three others around the liver, as extracted.
    let drawn = session.case().other_structures();
    let others: Vec<usize> = drawn.iter().map(|o| o.index).collect();
    assert_eq!(others, [1, 2, 3]);

    let change = StructureChange {
        name: Some(" tumour ".into()),
        color: Some([0.0, 1.0, 0.0]),
        opacity: Some(0.4),
        ..Default::default()
    };
    let version = session.case().case_version();
    session.case_mut().set_structure(2, change).unwrap();
    assert!(session.case().case_version() > version);
    let tumour = &session.case().as_case().structures[2];
    assert_eq!(
        (tumour.name.as_str(), tumour.color),
        ("tumour", [0.0, 1.0, 0.0, 0.4])
    );
    for bad in [
        StructureChange {
            opacity: Some(1.5),
            ..Default::default()
        },
        StructureChange {
            color: Some([0.0, 2.0, 0.0]),
            ..Default::default()
        },
        StructureChange {
            name: Some("  ".into()),
            ..Default::default()
        },
    ] {
        let refused = session.case_mut().set_structure(2, bad.clone());
        assert!(refused.is_err(), "{bad:?}");
    }
    assert!(session
        .case_mut()
        .set_structure(9, StructureChange::default())
        .is_err());
    assert_eq!(
        session.case().as_case().structures[2].name,
        "tumour",
        "a refusal changes nothing"
    );
    // Groups: set, trimmed, and taken away by null.
    let group = |g: Option<&str>| StructureChange {
        group: Some(g.map(str::to_string)),
        ..Default::default()
    };
    session
        .case_mut()
        .set_structure(1, group(Some(" Vessels ")))
        .unwrap();
    assert_eq!(
        session.case().as_case().structures[1].group.as_deref(),
        Some("Vessels")
    );
    session.case_mut().set_structure(1, group(None)).unwrap();
    assert_eq!(session.case().as_case().structures[1].group, None);
    session
        .case_mut()
        .set_structure(1, group(Some("Vessels")))
        .unwrap();

    // Solo shows one alone; again, every one.
    session.case_mut().solo_structure(3).unwrap();
    let visible: Vec<bool> = structures(&session).iter().map(|l| l.visible).collect();
    assert_eq!(visible, [false, false, false, true]);
    assert_eq!(session.case().other_structures().len(), 1);
    session.case_mut().solo_structure(3).unwrap();
    assert!(structures(&session).iter().all(|l| l.visible));

    // Smooth the liver, then work on the portal vein: the liver keeps its smoothing.
    let liver_params = Params {
        iterations: 7,
        ..Params::defaults(Filter::Taubin)
    };
    session.case_mut().set_params(liver_params).unwrap();
    smooth_cpu(&mut session);
    let liver = session.case().result().expect("smoothed").clone();
    session.select_structure(1).unwrap();
    let others = session.case().other_structures();
    let kept_liver = others
        .iter()
        .find(|o| o.index == 0)
        .expect("the liver is drawn");
    assert_eq!(kept_liver.positions, &liver.positions[..]);
    session
        .case_mut()
        .set_params(Params::defaults(Filter::Laplace))
        .unwrap();
    smooth_cpu(&mut session);
    let case = session.case();
    assert_eq!(case.current_structure(), Some(1));
    assert_eq!(case.as_case().structures[2].name, "tumour");
    assert_eq!(case.as_case().structures[2].color[3], 0.4);
    assert_eq!(case.structure_metrics(0), Some(&liver.metrics));
    assert!(case.structure_metrics(3).is_none(), "never smoothed");
    assert!(case.structure_metrics(1).is_some());

    // Back to the liver: a pointer moves. Nothing is opened or smoothed again: its
    // parameters and its result are where they were, in its structure.
    let model_before = session.case().model_id();
    session.select_structure(0).unwrap();
    assert!(
        session.loading().is_none(),
        "no worker opens a selected structure"
    );
    assert!(session.case().model_id() > model_before);
    assert_eq!(*session.case().params(), liver_params);
    assert_eq!(session.case().as_case().structures[0].params, liver_params);
    assert!(
        !session.case().needs_smoothing(),
        "its result is there at once"
    );
    assert_eq!(session.case().result().unwrap().positions, liver.positions);
    assert_eq!(session.case().result().unwrap().metrics, liver.metrics);
    assert!(smooth_cpu(&mut session).is_none(), "nothing to smooth");
    assert_eq!(
        session.case().as_case().structures[2].name,
        "tumour",
        "looks stay across switches"
    );

    // The case as arranged: the page's case glTF reads back with the same names, looks,
    // parameters and smoothed surfaces (the portal vein's kept, the liver's current).
    session
        .case_mut()
        .set_case_text(Some(" Abdomen "), Some("Liver with a tumour"));
    let glb = session
        .case()
        .export_case(&page_export())
        .expect("the case exports");
    let files = [meshsmooth::segmentation::NamedBytes {
        name: "case.glb",
        bytes: &glb,
    }];
    let back = meshsmooth::case::open(&files, None, &Default::default()).expect("reads back");
    assert_eq!(
        (back.title.as_str(), back.description.as_str()),
        ("Abdomen", "Liver with a tumour")
    );
    let names: Vec<&str> = back.structures.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["liver", "portal_vein", "tumour", "right_kidney"]);
    assert!((back.structures[2].color[3] - 0.4).abs() < 1e-6);
    assert_eq!(back.structures[0].params, liver_params);
    assert_eq!(back.structures[1].params.filter, Filter::Laplace);
    assert!(
        back.structures[1].smoothed.is_some(),
        "the portal vein's kept smoothing"
    );
    assert!(back.structures[3].smoothed.is_none(), "never smoothed");
    assert_eq!(back.structures[1].group.as_deref(), Some("Vessels"));
    let got = &back.structures[0]
        .smoothed
        .as_ref()
        .expect("smoothed")
        .positions;
    // Quantized: the file states how far a position may move. Vertices come back in the
    // codecs' order; the staircase says which is which.
    let stated = quantization_error(&glb);
    let matched = match_vertices(
        &session.case().as_case().structures[0].original.positions,
        &back.structures[0].original.positions,
        f64::from(stated) * 1.001,
    );
    let far = farthest(&liver.positions, got, &matched);
    assert!(
        far <= stated,
        "the liver moved {far} mm in the round trip, {stated} mm stated"
    );

    // A new file starts over.
    session.begin_open(
        "case_phantom_shared.seg.nrrd",
        read("labelmaps/case_phantom_shared.seg.nrrd"),
    );
    session.poll_opening().expect("done").expect("opens");
    assert_eq!(session.case().as_case().structures[2].name, "tumor");
}

/// The largest difference of two position lists, in mm.
/// The largest position quantization error (mm) a compressed case GLB's records state.
fn quantization_error(glb: &[u8]) -> f32 {
    let len = u32::from_le_bytes(glb[12..16].try_into().expect("4")) as usize;
    let doc: serde_json::Value = serde_json::from_slice(&glb[20..20 + len]).expect("JSON");
    let nodes = doc["nodes"].as_array().expect("nodes");
    let stated = nodes
        .iter()
        .filter_map(|n| n["extras"]["meshsmooth"]["quantization"]["max_error_mm"].as_f64())
        .fold(0.0, f64::max);
    assert!(stated > 0.0, "the page's case GLB is quantized");
    stated as f32
}

/// The farthest any of `b` lies from the vertex of `a` that `matched` names, on any axis.
fn farthest(a: &[[f32; 3]], b: &[[f32; 3]], matched: &[usize]) -> f32 {
    assert_eq!(a.len(), b.len());
    (b.iter().enumerate())
        .map(|(i, q)| {
            let p = a[matched[i]];
            (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0f32, f32::max)
        })
        .fold(0.0f32, f32::max)
}

/// #30's round trip in the page's session: export the case, open the file, export again; the
/// same structures, looks, groups, descriptions, parameters and positions (within the stated
/// quantization: the second smoothing starts from the quantized original), and the structure
/// that becomes the model takes up its own parameters.
#[test]
fn a_case_glb_reopens_in_the_session_and_exports_the_same_case() {
    use meshsmooth::session::StructureChange;
    use meshsmooth::smooth::{Filter, Params};
    let mut session = Session::default();
    let phantom = read("labelmaps/case_phantom_shared.seg.nrrd");
    open_in_session(&mut session, "case_phantom_shared.seg.nrrd", phantom);
    session
        .case_mut()
        .set_case_text(Some("Abdomen"), Some("Liver, tumour, vessels"));
    let vessels = StructureChange {
        group: Some(Some("Vessels".into())),
        description: Some("  Carries blood from the gut to the liver. ".into()),
        ..Default::default()
    };
    session.case_mut().set_structure(1, vessels).unwrap();
    let glassy = StructureChange {
        opacity: Some(0.3),
        ..Default::default()
    };
    session.case_mut().set_structure(0, glassy).unwrap();
    smooth_cpu(&mut session);
    let liver_params = *session.case().params();
    session.select_structure(3).unwrap();
    let kidney_params = Params {
        iterations: 9,
        ..Params::defaults(Filter::Taubin)
    };
    session.case_mut().set_params(kidney_params).unwrap();
    smooth_cpu(&mut session);
    let first = session.case().export_case(&page_export()).unwrap();

    let mut again = Session::default();
    open_in_session(&mut again, "abdomen_case.glb", first.clone());
    assert_eq!(again.case().current_structure(), Some(0));
    assert_eq!(
        again.case().model().unwrap().name,
        "abdomen_case.glb: liver"
    );
    assert_eq!(
        *again.case().params(),
        liver_params,
        "the liver's own parameters"
    );
    assert!(
        again.case().voxel_diagonal().is_some(),
        "its voxel size too"
    );
    assert_eq!(
        (
            again.case().as_case().title.as_str(),
            again.case().as_case().description.as_str()
        ),
        ("Abdomen", "Liver, tumour, vessels")
    );
    assert_eq!(again.case().as_case().structures[3].params, kidney_params);
    smooth_cpu(&mut again);
    let second = again.case().export_case(&page_export()).unwrap();

    let read_case = |bytes: &[u8]| {
        let files = [meshsmooth::segmentation::NamedBytes {
            name: "case.glb",
            bytes,
        }];
        meshsmooth::case::open(&files, None, &Default::default()).expect("reads back")
    };
    let (a, b) = (read_case(&first), read_case(&second));
    // Each file's quantization, and the second smoothing's start moved by the first's.
    let bound = 3.0 * quantization_error(&first).max(quantization_error(&second));
    assert_eq!((&a.title, &a.description), (&b.title, &b.description));
    assert_eq!(a.structures.len(), 4);
    assert_eq!(b.structures.len(), 4);
    for (x, y) in a.structures.iter().zip(&b.structures) {
        assert_eq!(
            (&x.name, x.color, x.visible, &x.group, &x.description),
            (&y.name, y.color, y.visible, &y.group, &y.description)
        );
        assert_eq!((&x.source, x.label), (&y.source, y.label));
        assert_eq!(
            (x.params, x.tau, x.voxel_size, x.voxels),
            (y.params, y.tau, y.voxel_size, y.voxels)
        );
        assert_eq!(x.smoothed.is_some(), y.smoothed.is_some(), "{}", x.name);
        let matched = match_vertices(
            &x.original.positions,
            &y.original.positions,
            f64::from(bound),
        );
        assert!(
            farthest(&x.original.positions, &y.original.positions, &matched) <= bound,
            "{}",
            x.name
        );
        assert!(
            farthest(x.positions(), y.positions(), &matched) <= bound,
            "{}: smoothed",
            x.name
        );
    }
    assert!(a.structures[0].smoothed.is_some() && a.structures[3].smoothed.is_some());
    assert_eq!(a.structures[1].group.as_deref(), Some("Vessels"));
    assert_eq!(
        a.structures[1].description,
        "Carries blood from the gut to the liver."
    );
    assert_eq!(a.structures[0].description, "", "none written, none read");
}

/// A structure left before its result came keeps the smoothed surface it had for its
/// parameters: a case glTF's liver stays smooth when the tumour is selected at once.
#[test]
fn a_structure_left_before_its_result_keeps_its_smoothed_surface() {
    let mut session = Session::default();
    let phantom = read("labelmaps/case_phantom_shared.seg.nrrd");
    open_in_session(&mut session, "case_phantom_shared.seg.nrrd", phantom);
    smooth_cpu(&mut session);
    let case = session.case().export_case(&page_export()).unwrap();

    let mut again = Session::default();
    open_in_session(&mut again, "case.glb", case);
    let kept = again.case().as_case().structures[0].smoothed.clone();
    assert!(kept.is_some(), "the case glTF holds the liver smoothed");
    assert!(
        again.case().last_result().is_none(),
        "nothing smoothed here yet"
    );
    again.select_structure(2).unwrap();
    assert_eq!(again.case().current_structure(), Some(2));
    assert_eq!(again.case().as_case().structures[0].smoothed, kept);
}

/// A case glTF's structure shows the surface the case holds for its parameters, before and
/// after the engine measures it; other parameters have none.
#[test]
fn a_case_glb_structure_keeps_its_surface_when_the_engine_measures_it() {
    let mut session = Session::default();
    let phantom = read("labelmaps/case_phantom_shared.seg.nrrd");
    open_in_session(&mut session, "case_phantom_shared.seg.nrrd", phantom);
    assert!(
        session.case().kept_surface().is_none(),
        "a label map holds no surfaces"
    );
    smooth_cpu(&mut session);
    let case = session.case().export_case(&page_export()).unwrap();
    let stated = quantization_error(&case);

    let mut again = Session::default();
    open_in_session(&mut again, "case.glb", case);
    let kept = again
        .case()
        .kept_surface()
        .expect("the liver's smoothed surface")
        .to_vec();
    let segmentation = &again.case().model().unwrap().mesh().positions;
    // One opened file: its vertices in one order.
    let same: Vec<usize> = (0..kept.len()).collect();
    assert!(
        farthest(&kept, segmentation, &same) > 0.1,
        "smoothed, not the segmentation"
    );
    smooth_cpu(&mut again);
    // The engine's recomputation lies within the quantization of the file's surface; the
    // structure keeps the file's, with the engine's per-vertex measures.
    let result = again.case().result().unwrap();
    assert!(result.vertex_measures().is_some());
    assert!(result.positions == kept, "the file's surface stays");
    assert!(stated > 0.0);
    let mut other = *again.case().params();
    other.iterations += 1;
    again.case_mut().set_params(other).unwrap();
    assert!(
        again.case().kept_surface().is_none(),
        "none for other parameters"
    );
}

/// Files added to an open case join it as structures (a surface coloured by its place, a label
/// map's with its bound) while the model stays; files added while one opens wait for it, and
/// are dropped when it fails to open.
#[test]
fn files_added_join_the_open_case_and_wait_for_the_one_opening() {
    let phantom = read("labelmaps/case_phantom_shared.seg.nrrd");
    let sphere = read("synthetic/synthetic_sphere_r20.stl");
    let mut session = Session::default();
    open_in_session(
        &mut session,
        "case_phantom_shared.seg.nrrd",
        phantom.clone(),
    );
    let model = session.case().model_id();
    session.begin_add("synthetic_sphere_r20.stl", sphere.clone());
    session.poll_opening().expect("done").expect("added");
    assert_eq!(session.case().model_id(), model, "the model stays");
    let list = session.case().as_case().structures.as_slice();
    assert_eq!(list.len(), 5);
    let added = &list[4];
    assert_eq!(added.name, "synthetic sphere r20");
    assert_eq!(added.source.as_deref(), Some("synthetic_sphere_r20.stl"));
    let [r, g, b] = meshsmooth::segmentation::default_color(4);
    assert_eq!(added.color, [r, g, b, 1.0]);
    assert_eq!(
        added.params.max_displacement, None,
        "a surface knows no voxels"
    );

    session.begin_add(
        "sphere_r20_mask.nii.gz",
        read("synthetic/sphere_r20_mask.nii.gz"),
    );
    session.poll_opening().expect("done").expect("added");
    let mask = &session.case().as_case().structures[5];
    assert!(mask.voxel_size.is_some() && mask.label.is_some());
    assert_eq!(mask.params.max_displacement, mask.default_bound());
    let bound = mask.default_bound();
    // It smooths as the model with its own bound.
    session.select_structure(5).unwrap();
    assert_eq!(session.case().params().max_displacement, bound);
    assert_eq!(session.case().to_case().unwrap().structures.len(), 6);

    // Dropped together: the second waits for the first, then joins its case.
    session.begin_open("case_phantom_shared.seg.nrrd", phantom);
    session.begin_add("synthetic_sphere_r20.stl", sphere.clone());
    session.poll_opening().expect("done").expect("opens");
    assert!(session.loading().is_some(), "the addition follows");
    assert_eq!(session.case().as_case().structures.len(), 4);
    session.poll_opening().expect("done").expect("added");
    assert_eq!(session.case().as_case().structures.len(), 5);
    assert!(session.loading().is_none());

    // A file that fails to open takes the files meant for its case with it.
    let mut broken = read("labelmaps/case_phantom_shared.nii.gz");
    broken.truncate(broken.len() / 2);
    session.begin_open("half.nii.gz", broken);
    session.begin_add("synthetic_sphere_r20.stl", sphere);
    let e = session.poll_opening().expect("finished").unwrap_err();
    assert!(e.starts_with("Cannot open half.nii.gz: "), "{e}");
    assert!(session.loading().is_none(), "nothing left to add");
    assert_eq!(
        session.case().as_case().structures.len(),
        5,
        "the case stays"
    );
}

/// The viewer shows a structure the file holds no smoothing of as the file holds it: nothing
/// is computed for it and its surface is the file's; the authoring page smooths it as before.
#[test]
fn a_viewer_shows_a_structure_without_a_smoothing_record_as_the_file_holds_it() {
    let unsmoothed = meshsmooth::export::write_case(&label_maps::phantom_case(), &page_export())
        .expect("writes");
    let mut viewer = Session::default();
    viewer.case_mut().show_as_read(true);
    open_in_session(&mut viewer, "case.glb", unsmoothed.clone());
    assert!(viewer.case().shown_as_read(0));
    assert!(!viewer.case().needs_smoothing(), "nothing to compute");
    assert!(smooth_cpu(&mut viewer).is_none());
    assert!(viewer.case().result().is_none());
    let held = &viewer.case().as_case().structures[0];
    assert!(held.smoothed.is_none());
    assert_eq!(viewer.case().model().expect("open").mesh(), &held.original);

    let mut author = Session::default();
    open_in_session(&mut author, "case.glb", unsmoothed);
    assert!(!author.case().shown_as_read(0));
    assert!(
        author.case().needs_smoothing(),
        "the author's page smooths it"
    );

    // A structure the file holds a smoothing of is measured in the viewer too.
    smooth_cpu(&mut author);
    let smoothed = author.case().export_case(&page_export()).expect("writes");
    let mut viewer = Session::default();
    viewer.case_mut().show_as_read(true);
    open_in_session(&mut viewer, "case.glb", smoothed);
    assert!(!viewer.case().shown_as_read(0));
    assert!(viewer.case().needs_smoothing());
}
