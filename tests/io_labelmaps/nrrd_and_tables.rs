//! NRRD label maps built here (Slicer's layers and segments, type spellings, spaces, byte
//! orders) and colour tables in their three forms.

use super::build::{gzip, i16s, nrrd};
use super::{load_named, voxel_values};
use meshsmooth::io::parse_color_table;
use meshsmooth::io::Affine;

#[test]
fn seg_nrrd_layers_and_segments() {
    // Two layers interleaved (Slicer's list axis first): layer 0 holds 1 and 2, layer 1 holds 5.
    let layer0 = [0u8, 1, 1, 2, 0, 0, 2, 2];
    let layer1 = [5u8, 5, 0, 0, 0, 5, 0, 0];
    let interleaved: Vec<u8> = layer0
        .iter()
        .zip(&layer1)
        .flat_map(|(&a, &b)| [a, b])
        .collect();
    let header = "type: unsigned char\ndimension: 4\nspace: left-posterior-superior\n\
        sizes: 2 2 2 2\nspace directions: none (2,0,0) (0,3,0) (0,0,4)\n\
        kinds: list domain domain domain\nencoding: gzip\nspace origin: (10,20,30)\n\
        Segment0_Name:=left lobe\nSegment0_Color:=1 0.5 0\nSegment0_LabelValue:=1\n\
        Segment1_Name:=vessel: portal\nSegment1_LabelValue:=5\nSegment1_Layer:=1\n\
        Segment2_Color:=0 0 2";
    let map = load_named(&nrrd(header, &gzip(&interleaved)), "two.seg.nrrd");
    assert_eq!(map.dims, [2, 2, 2]);
    assert_eq!(map.layers.len(), 2);
    assert_eq!(voxel_values(&map, 0), layer0.map(i64::from));
    assert_eq!(voxel_values(&map, 1), layer1.map(i64::from));
    let expect = [
        [-2.0, 0.0, 0.0, -10.0],
        [0.0, -3.0, 0.0, -20.0],
        [0.0, 0.0, 4.0, 30.0],
    ];
    assert_eq!(map.affine.0, expect);
    let s = &map.segments;
    assert_eq!(s.len(), 3);
    assert_eq!(
        (s[0].name.as_str(), s[0].value, s[0].layer),
        ("left lobe", 1, 0)
    );
    assert_eq!(s[0].color, Some([1.0, 0.5, 0.0]));
    assert_eq!(
        (s[1].name.as_str(), s[1].value, s[1].layer),
        ("vessel: portal", 5, 1)
    );
    assert_eq!(
        (s[2].value, s[2].layer, s[2].color),
        (3, 0, Some([0.0, 0.0, 1.0]))
    );
    // The same layers one after another (list axis last), raw, without directions.
    let planar: Vec<u8> = layer0.iter().chain(&layer1).copied().collect();
    let header = "type: uint8\ndimension: 4\nsizes: 2 2 2 2\nspacings: 0.5 0.5 2 nan\n\
        kinds: domain domain domain list\nencoding: raw\nspace: RAS";
    let flat = load_named(&nrrd(header, &planar), "flat.nrrd");
    assert_eq!(flat.layers, map.layers);
    assert_eq!(flat.affine, Affine::scaled([0.5, 0.5, 2.0], [0.0; 3]));
}

#[test]
fn nrrd_types_spaces_and_byte_orders() {
    let labels: Vec<i16> = vec![0, 4, -2, 4];
    for (spelling, big) in [
        ("short", false),
        ("int16", true),
        ("signed short int", true),
        ("int16_t", false),
    ] {
        let endian = if big { "big" } else { "little" };
        let header = format!(
            "type: {spelling}\ndimension: 3\nsizes: 2 2 1\nendian: {endian}\nencoding: raw"
        );
        let map = load_named(&nrrd(&header, &i16s(&labels, big)), "t.nrrd");
        assert_eq!(voxel_values(&map, 0), [0, 4, -2, 4], "{spelling}");
        assert_eq!(
            map.affine,
            Affine::scaled([1.0; 3], [0.0; 3]),
            "no spacing: 1"
        );
    }
    for spelling in [
        "uchar",
        "unsigned char",
        "uint8",
        "uint8_t",
        "signed char",
        "int8",
    ] {
        let header = format!("type: {spelling}\ndimension: 3\nsizes: 2 1 1\nencoding: raw");
        assert_eq!(
            load_named(&nrrd(&header, &[0, 9]), "t.nrrd").layers[0].values,
            [0, 9]
        );
    }
    let space = |name: &str| {
        let header = format!(
            "type: uint8\ndimension: 3\nspace: {name}\nsizes: 1 1 2\n\
             space directions: (1,2,0) (0,1,0) (0,0,3)\nspace origin: (1,2,3)\nencoding: raw"
        );
        load_named(&nrrd(&header, &[0, 1]), "s.nrrd").affine.0
    };
    let ras = [
        [1.0, 0.0, 0.0, 1.0],
        [2.0, 1.0, 0.0, 2.0],
        [0.0, 0.0, 3.0, 3.0],
    ];
    assert_eq!(space("RAS"), ras);
    assert_eq!(space("right-anterior-superior"), ras);
    let lps = [
        [-1.0, 0.0, 0.0, -1.0],
        [-2.0, -1.0, 0.0, -2.0],
        [0.0, 0.0, 3.0, 3.0],
    ];
    assert_eq!(space("LPS"), lps);
    assert_eq!(space("left-posterior-superior"), lps);
    assert_eq!(space("left-anterior-superior")[1], ras[1]);
}

#[test]
fn colour_tables_in_three_forms() {
    let itk = b"# ITK-SnAP Label Description File\n\
        #    IDX   -R-  -G-  -B-  -A--  VIS MSH  LABEL\n\
            0     0    0    0        0  0  0    \"Clear Label\"\n\
            1   255    0    0        1  1  1    \"Left hippocampus proper\"\n\
           12     0  255  128      0.5  1  0    \"x\"\n";
    let t = parse_color_table(itk).expect("ITK-SNAP");
    assert_eq!(t.len(), 3);
    assert_eq!(t[0].name, "Clear Label");
    assert_eq!(t[1].color, Some([1.0, 0.0, 0.0]));
    assert_eq!(t[1].name, "Left hippocampus proper");
    assert_eq!(
        (t[2].value, t[2].color),
        (12, Some([0.0, 1.0, 128.0 / 255.0]))
    );
    let freesurfer = b"#$Id: FreeSurferColorLUT.txt\r\n\r\n\
        #No. Label Name:                            R   G   B   A\r\n\
        0   Unknown                                 0   0   0   0\r\n\
        2   Left-Cerebral-White-Matter              245 245 245 0\r\n\
        1000    ctx-lh-unknown                      25  5   25  0\r\n";
    let t = parse_color_table(freesurfer).expect("FreeSurfer");
    assert_eq!(t.len(), 3);
    assert_eq!(t[1].name, "Left-Cerebral-White-Matter");
    assert_eq!(t[1].color, Some([245.0 / 255.0; 3]));
    assert_eq!(t[2].value, 1000);
    let tabs = b"\xEF\xBB\xBF1\tLeft lobe of liver\n-2\tscar tissue\t9\t9\t9\n";
    let tabs = parse_color_table(tabs).unwrap();
    assert_eq!(
        (tabs[0].value, tabs[0].name.as_str(), tabs[0].color),
        (1, "Left lobe of liver", None)
    );
    assert_eq!((tabs[1].value, tabs[1].name.as_str()), (-2, "scar tissue"));
    assert_eq!(tabs[1].color, Some([9.0 / 255.0; 3]));
    let rgb = parse_color_table(b"3 vein 10 20 30\n").unwrap();
    assert_eq!(
        rgb[0].color,
        Some([10.0 / 255.0, 20.0 / 255.0, 30.0 / 255.0])
    );
    for (bad, words) in [
        (&b"x liver 1 2 3\n"[..], "line 1"),
        (
            b"# c\n1 liver 300 0 0 255\n",
            "line 2: colour channel \"300\"",
        ),
        (b"1 2 3 4 0 0 \"open\n", "closing quote"),
        (b"7\n", "no name"),
        (b"# only comments\n\n", "empty"),
    ] {
        let e = parse_color_table(bad).unwrap_err().to_string();
        assert!(e.contains(words) && e.starts_with("colour table"), "{e}");
    }
}
