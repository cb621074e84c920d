use super::*;

fn tetra() -> Mesh {
    Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

#[test]
fn a_surface_mesh_has_no_bound_and_a_label_map_structure_half_its_voxel_diagonal() {
    let mesh = CaseStructure::from_mesh("skull", tetra(), [1.0, 1.0, 1.0]);
    assert_eq!(mesh.params.max_displacement, None);
    assert_eq!(mesh.default_bound(), None);
    let labelled = CaseStructure::from_label_map(
        Structure {
            label: 3,
            layer: 0,
            name: "vessel".into(),
            color: [0.0, 0.5, 1.0],
            voxels: 1,
            voxel_size: [0.7, 0.7, 2.0],
            grid: crate::io::Affine::scaled([0.7, 0.7, 2.0], [0.0; 3]),
            codes: None,
            mesh: tetra(),
        },
        Some("ct.nii.gz"),
    );
    let half = 0.5 * (0.7f64 * 0.7 * 2.0 + 4.0).sqrt();
    assert_eq!(labelled.params.max_displacement, Some(half as f32));
    assert_eq!(labelled.label, Some(3));
    assert_eq!(labelled.color, [0.0, 0.5, 1.0, 1.0]);
}

/// Only a label map's structure is known closed; its winding is checked by its volume.
#[test]
fn a_label_maps_structure_wound_outward_is_closed_and_outward() {
    let labelled = |mesh| {
        let structure = Structure {
            label: 1,
            layer: 0,
            name: "kidney".into(),
            color: [1.0, 0.0, 0.0],
            voxels: 1,
            voxel_size: [1.0; 3],
            grid: crate::io::Affine::scaled([1.0; 3], [0.0; 3]),
            codes: None,
            mesh,
        };
        CaseStructure::from_label_map(structure, None)
    };
    let mut outward = tetra();
    if outward.signed_volume() < 0.0 {
        outward.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
    let mut inward = outward.clone();
    inward.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    assert!(labelled(outward.clone()).closed_outward());
    assert!(!labelled(inward).closed_outward(), "wound inward");
    let surface = CaseStructure::from_mesh("skull", outward, [1.0; 3]);
    assert!(!surface.closed_outward(), "a surface file may be open");
}

#[test]
fn changing_the_filter_keeps_the_bound_and_outdates_the_result() {
    let mut s = CaseStructure::from_mesh("a", tetra(), [1.0, 0.0, 0.0]);
    s.params.max_displacement = Some(0.25);
    pipeline::smooth_structure(&mut s);
    assert!(s.smoothed.is_some());
    s.set_filter(Filter::Taubin);
    assert_eq!(s.params.filter, Filter::Taubin);
    assert_eq!(s.params.max_displacement, Some(0.25));
    assert_eq!(s.params.lambda, Params::defaults(Filter::Taubin).lambda);
    assert!(
        s.smoothed_now().is_none(),
        "no longer the result of its settings"
    );
    assert!(s.smoothed.is_some(), "shown until a newer one replaces it");
    // Each filter keeps its own values: Taubin's lambda comes back with it.
    s.set_params(Params {
        lambda: 0.25,
        ..s.params
    });
    s.set_filter(Filter::Hc);
    assert_eq!(s.params.filter, Filter::Hc);
    assert_eq!(s.params.max_displacement, Some(0.25));
    s.set_filter(Filter::Taubin);
    assert_eq!(s.params.lambda, 0.25);
}

#[test]
fn groups_are_listed_once_in_the_order_they_first_appear() {
    let mut case = Case::default();
    for (name, group) in [
        ("a", Some("Vessels")),
        ("b", None),
        ("c", Some("Organs")),
        ("d", Some("Vessels")),
    ] {
        let mut s = CaseStructure::from_mesh(name, tetra(), [1.0; 3]);
        s.group = group.map(str::to_string);
        case.structures.push(s);
    }
    assert_eq!(case.groups(), ["Vessels", "Organs"]);
    let mut other = Case {
        title: "second".into(),
        ..Case::default()
    };
    other
        .structures
        .push(CaseStructure::from_mesh("e", tetra(), [1.0; 3]));
    case.add(other);
    assert_eq!(
        case.title, "second",
        "an untitled case takes the added one's title"
    );
    assert_eq!(case.structures.len(), 5);
}

#[test]
fn structures_are_equal_when_they_would_be_written_the_same() {
    let mut a = CaseStructure::from_mesh("a", tetra(), [1.0, 0.0, 0.0]);
    pipeline::smooth_structure(&mut a);
    let mut b = a.clone();
    // The editor's memory of other filters and its revision count are not written.
    b.set_filter(Filter::Taubin);
    b.set_filter(Filter::Hc);
    assert_ne!(a.revision, b.revision);
    assert_eq!(a, b);
    b.tau += 0.1;
    assert_ne!(a, b, "a written setting differs");
}

#[test]
fn searches_start_where_the_structures_before_ended_most_often() {
    let s = CaseStructure::from_mesh("a", tetra(), [1.0, 0.0, 0.0]);
    assert!(starts_from(&[], s.params.filter).is_empty(), "the corners");
    let hc = |alpha, iterations| Params {
        alpha,
        iterations,
        ..Params::defaults(Filter::Hc)
    };
    let learned = [
        hc(0.1, 10),
        hc(0.0, 20),
        Params::defaults(Filter::Taubin),
        hc(0.0, 20),
        hc(0.2, 30),
        hc(0.3, 40),
    ];
    let starts = starts_from(&learned, s.params.filter);
    // The most frequent first, then the latest; Taubin's set is not HC's start.
    assert_eq!(starts, vec![hc(0.0, 20), hc(0.3, 40), hc(0.2, 30)]);
}

#[test]
fn a_list_shows_the_ungrouped_first_then_each_group_and_filters_by_name_or_group() {
    let structure = |name: &str, group: Option<&str>| CaseStructure {
        group: group.map(str::to_string),
        ..CaseStructure::from_mesh(name, tetra(), [1.0, 0.0, 0.0])
    };
    let case = Case {
        structures: vec![
            structure("Aorta", Some("Vessels")),
            structure("Liver", None),
            structure("rib_left_1", Some("Bones")),
            structure("Portal vein", Some("Vessels")),
            structure("kidney_left", None),
        ],
        ..Case::default()
    };
    let listed = |filter| listed(&case.structures, filter);
    let all = listed("");
    assert_eq!(
        all,
        vec![
            (None, vec![1, 4]),
            (Some("Vessels"), vec![0, 3]),
            (Some("Bones"), vec![2])
        ]
    );
    assert_eq!(
        listed(" LEFT"),
        vec![(None, vec![4]), (Some("Bones"), vec![2])]
    );
    // A group's name keeps all its members.
    assert_eq!(listed("vessel"), vec![(Some("Vessels"), vec![0, 3])]);
    assert!(listed("spleen").is_empty());
}
