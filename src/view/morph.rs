//! Sliding between a structure's segmentation (the staircase it was extracted as) and its
//! smoothed surface, as a glTF viewer's morph weight does with the case glTF's morph target:
//! a reader sees how far the smooth surface moved.

/// `smoothed` moved `toward` (0 = as smoothed, 1 = the segmentation) of the way back to
/// `original`; `None` when the two differ in length.
pub fn toward_original(
    original: &[[f32; 3]],
    smoothed: &[[f32; 3]],
    toward: f32,
) -> Option<Vec<[f32; 3]>> {
    if original.len() != smoothed.len() {
        return None;
    }
    let w = if toward.is_finite() {
        toward.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let out = (original.iter().zip(smoothed))
        .map(|(o, s)| [0, 1, 2].map(|k| s[k] + w * (o[k] - s[k])))
        .collect();
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slide_runs_from_the_smoothed_surface_to_the_segmentation() {
        let original = [[0.0, 0.0, 0.0], [2.0, 4.0, -2.0]];
        let smoothed = [[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]];
        assert_eq!(
            toward_original(&original, &smoothed, 0.0).unwrap(),
            smoothed
        );
        assert_eq!(
            toward_original(&original, &smoothed, 1.0).unwrap(),
            original
        );
        let half = toward_original(&original, &smoothed, 0.5).unwrap();
        assert_eq!(half, [[0.5, 0.5, 0.5], [2.0, 3.0, 0.0]]);
        assert_eq!(
            toward_original(&original, &smoothed, 7.0).unwrap(),
            original
        );
        assert_eq!(
            toward_original(&original, &smoothed, f32::NAN).unwrap(),
            smoothed
        );
        assert!(toward_original(&original, &smoothed[..1], 0.5).is_none());
    }
}
