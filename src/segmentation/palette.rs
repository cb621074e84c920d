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

/// The default colour of the `ordinal`-th structure.
pub fn default_color(ordinal: usize) -> [f32; 3] {
    PALETTE[ordinal % PALETTE.len()]
}
