//! On x86-64 (this module exists there only) the measure pass's two vector kernels, the
//! triangle shapes and the local error's prism tests, come in two builds: the baseline one
//! (SSE2, four lanes) and one for processors with AVX-512, chosen at run time. The wide build
//! does the same IEEE operations in the same order (the compiler contracts no multiply-add
//! without being told), so both give the same bits; it only takes more lanes at a time
//! (`meshsmooth bench` measures the difference).
//!
//! The wide copies are `#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,
//! fma")]` functions whose bodies are the baseline kernels, inlined: one source, two builds.

/// Whether the wide kernels may run: the processor has the features they are built with (and a
/// test has not asked for the baseline ones).
#[inline]
pub(crate) fn available() -> bool {
    #[cfg(test)]
    if BASELINE_ONLY.load(std::sync::atomic::Ordering::Relaxed) {
        return false;
    }
    std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512bw")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
}

/// Set by a test to run the baseline kernels on a processor that has the wide ones. Both give
/// the same bits, so other tests running meanwhile see no difference.
#[cfg(test)]
pub(crate) static BASELINE_ONLY: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Topology;
    use crate::metrics::{measure_vertices, smooth_drifting, Original};
    use crate::smooth::{Filter, Params};
    use std::sync::atomic::Ordering;

    /// The wide kernels give the baseline's bits: every measure and every per-vertex value of
    /// smoothed real meshes (a cortex with sharp folds, a staircase segmentation), smoothed and
    /// not. On a processor without AVX-512 both runs take the baseline kernels.
    #[test]
    fn wide_kernels_measure_the_same_bits() {
        println!("wide kernels on this processor: {}", available());
        for name in [
            "real/fsaverage5_pial_left.ply",
            "segmentations/seg_mni152_brainmask_2mm.ply",
        ] {
            let path = format!("{}/../shared/data/{name}", env!("CARGO_MANIFEST_DIR"));
            let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
            let mesh = crate::io::load(&bytes, name).unwrap();
            let topology = Topology::build(&mesh);
            let original = Original::new(&mesh, &topology);
            for iterations in [0, 10] {
                let params = Params {
                    iterations,
                    ..Params::defaults(Filter::Hc)
                };
                let (positions, reference) = smooth_drifting(&original, &params, None);
                let measure = || measure_vertices(&original, &positions, &reference, 0.5);
                BASELINE_ONLY.store(true, Ordering::Relaxed);
                let baseline = measure();
                BASELINE_ONLY.store(false, Ordering::Relaxed);
                let wide = measure();
                assert_eq!(wide.0, baseline.0, "{name}, {iterations} iterations");
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    bits(&wide.1.local_error),
                    bits(&baseline.1.local_error),
                    "{name}"
                );
                assert_eq!(
                    bits(&wide.1.gaussian_curvature),
                    bits(&baseline.1.gaussian_curvature),
                    "{name}"
                );
            }
        }
    }
}
