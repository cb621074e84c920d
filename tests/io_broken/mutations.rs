//! Cheap deterministic fuzzing inside the test suite: mutated real and hand-made files go to
//! every parser; none may panic, and whatever loads must be a valid mesh.

use super::{binary_stl, read_data, small_binary_ply, TRI};
use meshsmooth::io::{load_as, Format};
use meshsmooth::mesh::{MeshReport, Topology};

/// xorshift64: deterministic, so a failure names a reproducible case.
pub(super) struct XorShift(pub(super) u64);

impl XorShift {
    pub(super) fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// One random edit: byte flips, interesting values, deletions, duplications, truncation.
/// Edits favour the first few hundred bytes, where the headers and counts live.
fn mutate(rng: &mut XorShift, input: &mut Vec<u8>) {
    if input.is_empty() {
        input.push(rng.next() as u8);
        return;
    }
    let len = input.len();
    let at = if rng.below(3) == 0 {
        rng.below(len)
    } else {
        rng.below(len.min(400))
    };
    match rng.below(7) {
        0 => input[at] ^= 1 << rng.below(8),
        1 => input[at] = rng.next() as u8,
        2 => {
            const VALUES: [&[u8]; 8] = [
                b"\xff\xff\xff\xff",
                b"\0\0\0\0",
                b"\x7f\xc0\0\0",
                b"-1",
                b"4294967295",
                b"nan",
                b"\r",
                b"\n",
            ];
            let v = VALUES[rng.below(VALUES.len())];
            let end = (at + v.len()).min(len);
            input.splice(at..end, v.iter().copied());
        }
        3 => {
            let end = (at + 1 + rng.below(64)).min(len);
            input.drain(at..end);
        }
        4 => {
            let end = (at + 1 + rng.below(64)).min(len);
            let chunk = input[at..end].to_vec();
            let to = rng.below(len);
            input.splice(to..to, chunk);
        }
        5 => input.truncate(at),
        _ => {
            let digit = b'0' + rng.below(10) as u8;
            input.insert(at, digit);
        }
    }
}

#[test]
fn mutated_real_and_hand_made_files_never_panic() {
    let seeds: Vec<(Vec<u8>, Format)> = vec![
        (read_data("synthetic/synthetic_bent_tube_r3.5.ply"), Format::Ply),
        (read_data("synthetic/synthetic_bent_tube_r3.5.stl"), Format::Stl),
        (read_data("real/fsaverage_head_scalp_mne.obj")[..20_000].to_vec(), Format::Obj),
        (small_binary_ply(TRI, [0, 1, 2]).0, Format::Ply),
        (
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
              element edge 1\nproperty list uchar int e\nelement face 1\nproperty list uchar int vertex_indices\n\
              end_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 1 2\n"
                .to_vec(),
            Format::Ply,
        ),
        (binary_stl(2, &[TRI, TRI]), Format::Stl),
        (
            b"solid a b\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n"
                .to_vec(),
            Format::Stl,
        ),
        (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nf 1/1 2//3 -2 4\n".to_vec(), Format::Obj),
    ];
    let mut rng = XorShift(0x2545_F491_4F6C_DD1D);
    let mut loaded = 0;
    let cases = 3000;
    for case in 0..cases {
        let (seed, native) = &seeds[case % seeds.len()];
        let mut input = seed.clone();
        for _ in 0..1 + rng.below(4) {
            mutate(&mut rng, &mut input);
        }
        // Each input goes to its own parser and, now and then, to the others.
        let formats: &[Format] = if case % 5 == 0 {
            &[Format::Stl, Format::Obj, Format::Ply]
        } else {
            std::slice::from_ref(native)
        };
        for &format in formats {
            let outcome = std::panic::catch_unwind(|| load_as(&input, format));
            let result =
                outcome.unwrap_or_else(|_| panic!("case {case}: {format} parser panicked"));
            if let Ok(mesh) = result {
                loaded += 1;
                let n = mesh.positions.len();
                assert!(!mesh.triangles.is_empty(), "case {case}");
                assert!(
                    mesh.triangles.iter().flatten().all(|&v| (v as usize) < n),
                    "case {case}"
                );
                assert!(
                    mesh.positions.iter().flatten().all(|c| c.is_finite()),
                    "case {case}"
                );
                let report = MeshReport::new(&mesh, &Topology::build(&mesh));
                assert_eq!(report.faces, mesh.triangles.len());
            }
        }
    }
    // Many mutations (in coordinates, say) leave a loadable file: the invariants above ran.
    assert!(
        loaded > cases / 10,
        "only {loaded} of {cases} mutated inputs loaded"
    );
}
