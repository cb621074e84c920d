//! Default colours for labels the file and its colour table leave uncoloured: tissue-like hues
//! (organ pink, artery red, vein blue, bone ivory...) in an order that keeps neighbours in the
//! list, which are often neighbours in the body, apart.

/// Display (sRGB) colours, cycled.
const PALETTE: [[f32; 3]; 12] = [
    [0.86, 0.55, 0.60], // organ pink
    [0.78, 0.21, 0.21], // artery red
    [0.27, 0.40, 0.75], // vein blue
    [0.87, 0.80, 0.64], // bone ivory
    [0.56, 0.29, 0.20], // liver brown
    [0.55, 0.70, 0.45], // gall green
    [0.95, 0.82, 0.33], // nerve yellow
    [0.70, 0.55, 0.78], // lilac
    [0.45, 0.70, 0.80], // cartilage cyan
    [0.85, 0.42, 0.31], // muscle red
    [0.91, 0.71, 0.36], // fat ochre
    [0.60, 0.62, 0.65], // grey
];

/// How each further round of the palette is shaded: towards white (positive) or black, by
/// that fraction, so an atlas of dozens of structures does not repeat a colour every twelve.
const ROUNDS: [f32; 6] = [0.0, 0.4, -0.35, 0.65, -0.55, 0.2];

/// The default colour of the `ordinal`-th structure: distinct for the first 72.
pub fn default_color(ordinal: usize) -> [f32; 3] {
    let base = PALETTE[ordinal % PALETTE.len()];
    let shade = ROUNDS[(ordinal / PALETTE.len()) % ROUNDS.len()];
    base.map(|c| {
        if shade >= 0.0 {
            c + (1.0 - c) * shade
        } else {
            c * (1.0 + shade)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_seventy_two_colours_differ_visibly() {
        let colors: Vec<[f32; 3]> = (0..72).map(default_color).collect();
        for (i, a) in colors.iter().enumerate() {
            assert!(a.iter().all(|c| (0.0..=1.0).contains(c)), "{i}: {a:?}");
            for (j, b) in colors.iter().enumerate().skip(i + 1) {
                let distance = a
                    .iter()
                    .zip(b)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f32::max);
                assert!(distance > 4.0 / 255.0, "{i} and {j}: {a:?} {b:?}");
            }
        }
        assert_eq!(default_color(0), PALETTE[0]);
    }
}
