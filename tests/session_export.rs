//! The page's case glTF: written a structure per step with its size before it is saved, and a
//! reopened case showing and writing the surfaces its file holds.

#[path = "common/label_maps.rs"]
mod label_maps;

#[path = "common/vertex_match.rs"]
mod vertex_match;

use label_maps::{open_in_session, read};
use meshsmooth::export::{CaseGltfOptions, Simplification};
use meshsmooth::session::{Session, StructureChange};
use vertex_match::match_vertices;
mod common_session;
use common_session::smooth_cpu;

fn phantom_session() -> Session {
    let mut session = Session::default();
    let bytes = read("labelmaps/case_phantom_shared.seg.nrrd");
    open_in_session(&mut session, "case_phantom_shared.seg.nrrd", bytes);
    smooth_cpu(&mut session);
    session
}

fn simplified() -> CaseGltfOptions {
    CaseGltfOptions {
        local_error: true,
        simplify: Some(Simplification::VoxelDiagonals(0.1)),
        ..CaseGltfOptions::default()
    }
}

/// Steps the case glTF being written to its end; the progress seen at each step.
fn write_all(session: &mut Session) -> Vec<(usize, usize, usize)> {
    let mut seen = Vec::new();
    while let Some(p) = session.case_export().progress() {
        seen.push((p.structures_done, p.bytes, p.triangles));
        assert!(session.case_export_mut().step());
        assert!(seen.len() < 100, "it ends");
    }
    seen
}

#[test]
fn the_page_writes_the_case_a_structure_per_step_as_the_cli_writes_it() {
    let mut session = phantom_session();
    let options = simplified();
    session.case_export_mut().start(options).unwrap();
    let seen = write_all(&mut session);
    // One structure per step, the size and triangles growing, then the file put together.
    let done: Vec<usize> = seen.iter().map(|s| s.0).collect();
    assert_eq!(done, [0, 1, 2, 3, 4]);
    assert!(seen.windows(2).all(|w| w[1].1 > w[0].1 && w[1].2 > w[0].2));
    let written = session.case_export().written().expect("written");
    assert_eq!(written.options, options);
    let at_once = session.case().export_case(&options).unwrap();
    assert!(written.bytes == at_once, "the same file as written at once");
    let before: usize = (session.case().as_case().structures.iter())
        .map(|s| s.original.triangle_count())
        .sum();
    assert_eq!(written.triangles, seen[4].2);
    assert!(
        written.triangles < before / 2,
        "simplified: {} of {before} triangles",
        written.triangles
    );
    assert!(session.case_export().error().is_none());

    // A change to the case makes the file stale.
    let change = StructureChange {
        color: Some([0.2, 0.4, 0.6]),
        ..Default::default()
    };
    session.case_mut().set_structure(1, change).unwrap();
    assert!(
        session.case_export().written().is_none(),
        "stale after a change"
    );
}

#[test]
fn a_case_changed_while_it_is_written_is_written_again_and_cancelling_stops() {
    let mut session = phantom_session();
    let options = CaseGltfOptions {
        local_error: true,
        ..CaseGltfOptions::default()
    };
    session.case_export_mut().start(options).unwrap();
    session.case_export_mut().step();
    session.case_export_mut().step();
    assert_eq!(session.case_export().progress().unwrap().structures_done, 2);
    let change = StructureChange {
        name: Some("hepar".into()),
        ..Default::default()
    };
    session.case_mut().set_structure(0, change).unwrap();
    write_all(&mut session);
    let written = session.case_export().written().expect("written");
    assert!(written.bytes == session.case().export_case(&options).unwrap());

    session.case_export_mut().start(options).unwrap();
    session.case_export_mut().step();
    session.case_export_mut().cancel();
    assert!(session.case_export().progress().is_none());
    assert!(
        session.case_export().written().is_none(),
        "the new file was not finished"
    );
    assert!(!session.case_export_mut().step(), "nothing left to write");
}

#[test]
fn a_reopened_case_shows_and_writes_the_surfaces_its_file_holds() {
    let session = phantom_session();
    let plain = CaseGltfOptions::default();
    let first = session.case().export_case(&plain).unwrap();
    let mut again = Session::default();
    open_in_session(&mut again, "case.glb", first.clone());
    let files = [meshsmooth::segmentation::NamedBytes {
        name: "case.glb",
        bytes: &first,
    }];
    let read_back = meshsmooth::case::open(&files, None, &Default::default()).unwrap();
    // The engine measures the model's surface anew; what is shown stays the file's.
    smooth_cpu(&mut again);
    let model = again.case().result().expect("measured");
    assert!(model.vertex_measures().is_some());
    assert!(model.positions == read_back.structures[0].positions());
    // Written again, the same points (the codecs may number them anew).
    let second = again.case().export_case(&plain).unwrap();
    let files = [meshsmooth::segmentation::NamedBytes {
        name: "again.glb",
        bytes: &second,
    }];
    let twice = meshsmooth::case::open(&files, None, &Default::default()).unwrap();
    for (a, b) in read_back.structures.iter().zip(&twice.structures) {
        let matched = match_vertices(a.positions(), b.positions(), 1e-5);
        assert!(matched
            .iter()
            .enumerate()
            .all(|(i, &j)| a.positions()[j] == b.positions()[i]));
    }
}
