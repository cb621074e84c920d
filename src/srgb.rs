//! The sRGB transfer function, both ways. Colours are kept and edited as display (sRGB) values;
//! glTF's material factors and the view's shading work in linear light (shaders/render.wgsl
//! decodes vertex colours with the same curve).

/// Linear light from a display (sRGB-encoded) channel; input clamped to [0, 1].
pub fn to_linear(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A display (sRGB-encoded) channel from linear light; input clamped to [0, 1].
pub fn from_linear(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decoding_matches_known_values() {
        assert_eq!(to_linear(0.0), 0.0);
        assert!((to_linear(1.0) - 1.0).abs() < 1e-6);
        // sRGB 0.5 is about 21.4% linear light; the linear segment ends at 0.04045.
        assert!((to_linear(0.5) - 0.214_041).abs() < 1e-5);
        assert!((to_linear(0.04045) - 0.04045 / 12.92).abs() < 1e-7);
        assert_eq!(to_linear(-0.5), 0.0);
        assert_eq!(to_linear(2.0), 1.0);
    }

    #[test]
    fn encoding_inverts_decoding() {
        for v in 0..=255 {
            let c = v as f32 / 255.0;
            assert!((from_linear(to_linear(c)) - c).abs() < 1e-5, "{c}");
        }
    }
}
