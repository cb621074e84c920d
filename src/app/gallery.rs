//! The gallery: the model smoothed at several target smoothness values (tau), each as a small
//! picture colour-coded by local error with its numbers, in a grid of cards that wraps to the
//! available width. A click on a card picks that result.
//!
//! The pictures are drawn on the CPU ([`crate::view::thumbnail`]) and uploaded once as egui
//! textures ([`texture`]); the gallery only lays them out.

use crate::view::thumbnail::Thumbnail;
use eframe::egui;

/// Size the pictures are shown at (points); [`pixel_size`] is what to render for this display.
pub const IMAGE_SIZE: egui::Vec2 = egui::vec2(160.0, 120.0);
/// Between the card's edge and its picture and caption.
const PADDING: f32 = 6.0;
/// Between cards, both ways.
const SPACING: f32 = 8.0;
/// Between the picture and the caption.
const CAPTION_GAP: f32 = 4.0;
const CAPTION_SIZE: f32 = 12.0;
const CORNER_RADIUS: f32 = 6.0;

/// One result in the gallery.
pub struct GalleryItem {
    /// The rendered picture (see [`texture`]).
    pub texture: egui::TextureHandle,
    /// The target smoothness the result was made for.
    pub tau: f64,
    /// K/K0: mean |Gaussian curvature| against the original's (lower is smoother).
    pub curvature_ratio: f64,
    /// Mean local distance of the vertices from the original surface, mm.
    pub mean_error: f64,
    /// Signed change of the enclosed volume as a fraction (0.01 = +1 %, -0.01 = shrunk by 1 %);
    /// `None` for open meshes.
    pub volume_change: Option<f64>,
    /// The result currently applied to the model.
    pub selected: bool,
}

/// The picture size to render (pixels) for the pictures to be sharp at [`IMAGE_SIZE`] on this
/// display; at most 3 pixels per point, which is as sharp as a thumbnail needs to be.
pub fn pixel_size(ctx: &egui::Context) -> [u32; 2] {
    let scale = ctx.pixels_per_point().clamp(1.0, 3.0);
    [IMAGE_SIZE.x, IMAGE_SIZE.y].map(|s| (s * scale).round() as u32)
}

/// Uploads a rendered picture as an egui texture (`name` shows in egui's debug views). Filtered
/// linearly, so a picture shown at another size than it was rendered at stays smooth. An empty
/// picture becomes one transparent pixel: textures cannot be empty.
pub fn texture(ctx: &egui::Context, name: &str, thumbnail: &Thumbnail) -> egui::TextureHandle {
    let [w, h] = thumbnail.size.map(|s| s as usize);
    let image = if w > 0 && h > 0 && thumbnail.pixels.len() == w * h {
        egui::ColorImage::from_rgba_unmultiplied([w, h], thumbnail.as_bytes())
    } else {
        egui::ColorImage::new([1, 1], vec![egui::Color32::TRANSPARENT])
    };
    ctx.load_texture(name, image, egui::TextureOptions::LINEAR)
}

/// Shows `items` as cards in rows that fill the available width; returns the index of the card
/// clicked this frame, if any. `cards` gets each card's visible part (empty when scrolled away).
pub fn show(
    ui: &mut egui::Ui,
    items: &[GalleryItem],
    cards: &mut Vec<egui::Rect>,
) -> Option<usize> {
    let font = egui::FontId::proportional(CAPTION_SIZE);
    let line = ui.fonts_mut(|f| f.row_height(&font));
    // In a panel narrower than one card, the pictures shrink to fit.
    let image_width = IMAGE_SIZE
        .x
        .min(ui.available_width() - 2.0 * PADDING)
        .max(IMAGE_SIZE.x * 0.25);
    let image = IMAGE_SIZE * (image_width / IMAGE_SIZE.x);
    let card = egui::vec2(
        image.x + 2.0 * PADDING,
        2.0 * PADDING + image.y + CAPTION_GAP + 2.0 * line,
    );
    let columns = (((ui.available_width() + SPACING) / (card.x + SPACING)).floor() as usize).max(1);

    let mut clicked = None;
    ui.scope(|ui| {
        ui.spacing_mut().item_spacing = egui::vec2(SPACING, SPACING);
        for (row, chunk) in items.chunks(columns).enumerate() {
            ui.horizontal(|ui| {
                for (column, item) in chunk.iter().enumerate() {
                    let response = show_card(ui, item, card, image, &font, line);
                    cards.push(response.rect.intersect(ui.clip_rect()));
                    if response.clicked() {
                        clicked = Some(row * columns + column);
                    }
                }
            });
        }
    });
    clicked
}

/// One card: the picture, a badge when applied, and two caption lines (tau and K/K0; mean error
/// and volume change). The full numbers are in the tooltip.
fn show_card(
    ui: &mut egui::Ui,
    item: &GalleryItem,
    size: egui::Vec2,
    image: egui::Vec2,
    font: &egui::FontId,
    line: f32,
) -> egui::Response {
    let (rect, response) = ui.allocate_exact_size(size, egui::Sense::click());
    let tau = format!("τ = {}", format_tau(item.tau));
    response.widget_info(|| {
        egui::WidgetInfo::selected(egui::Role::ListBoxOption, true, item.selected, &tau)
    });
    if ui.is_rect_visible(rect) {
        let visuals = ui.visuals();
        let hovered = response.hovered();
        let (fill, stroke) = card_frame(visuals, item.selected, hovered, response.has_focus());
        let painter = ui.painter();
        painter.rect(rect, CORNER_RADIUS, fill, stroke, egui::StrokeKind::Inside);

        let picture = egui::Rect::from_min_size(rect.min + egui::vec2(PADDING, PADDING), image);
        // Hovering brightens the picture a little, beyond the card's own highlight.
        let tint = if hovered && !item.selected {
            egui::Color32::WHITE
        } else {
            egui::Color32::from_gray(230)
        };
        let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        painter.image(item.texture.id(), picture, uv, tint);
        if item.selected {
            badge(painter, picture, visuals);
        }

        paint_captions(painter, visuals, item, picture, (font, line), tau);
    }
    response
        .on_hover_cursor(egui::CursorIcon::PointingHand)
        .on_hover_text(format!(
            "Target smoothness τ = {}\nCurvature K/K0: {:.4}\nMean error: {:.3} mm\nVolume change: {}\n{}",
            format_tau(item.tau),
            item.curvature_ratio,
            item.mean_error,
            item.volume_change
                .map_or("undefined (open mesh)".into(), |v| format!("{:+.2} %", v * 100.0)),
            if item.selected {
                "Applied to the model."
            } else {
                "Click to apply this result."
            },
        ))
}

/// A card's fill and outline: selected, hovered or neither, and focused.
fn card_frame(
    visuals: &egui::Visuals,
    selected: bool,
    hovered: bool,
    focused: bool,
) -> (egui::Color32, egui::Stroke) {
    let (fill, stroke) = if selected {
        (
            visuals.widgets.hovered.weak_bg_fill,
            egui::Stroke::new(2.0, visuals.selection.bg_fill),
        )
    } else if hovered {
        (
            visuals.widgets.hovered.weak_bg_fill,
            visuals.widgets.hovered.bg_stroke,
        )
    } else {
        (
            visuals.faint_bg_color,
            visuals.widgets.noninteractive.bg_stroke,
        )
    };
    (
        fill,
        if focused {
            visuals.selection.stroke
        } else {
            stroke
        },
    )
}

/// The two caption lines under a card's picture: tau and K/K0, mean error and volume change.
fn paint_captions(
    painter: &egui::Painter,
    visuals: &egui::Visuals,
    item: &GalleryItem,
    picture: egui::Rect,
    (font, line): (&egui::FontId, f32),
    tau: String,
) {
    let text = visuals.text_color();
    let weak = visuals.weak_text_color();
    let top = picture.bottom() + CAPTION_GAP;
    let (left, right) = (picture.left(), picture.right());
    let (left_top, right_top) = (egui::Align2::LEFT_TOP, egui::Align2::RIGHT_TOP);
    let captions = [
        (left, top, left_top, tau, visuals.strong_text_color()),
        (
            right,
            top,
            right_top,
            format!("K/K0 {:.3}", item.curvature_ratio),
            text,
        ),
        (
            left,
            top + line,
            left_top,
            format!("{:.3} mm", item.mean_error),
            text,
        ),
        (
            right,
            top + line,
            right_top,
            format!("ΔV {}", format_volume(item.volume_change)),
            weak,
        ),
    ];
    for (x, y, align, caption, color) in captions {
        painter.text(egui::pos2(x, y), align, caption, font.clone(), color);
    }
}

/// "applied" in the picture's top-left corner.
fn badge(painter: &egui::Painter, picture: egui::Rect, visuals: &egui::Visuals) {
    let galley = painter.layout_no_wrap(
        "applied".into(),
        egui::FontId::proportional(11.0),
        visuals.selection.stroke.color,
    );
    let rect = egui::Rect::from_min_size(
        picture.min + egui::vec2(4.0, 4.0),
        galley.size() + egui::vec2(8.0, 2.0),
    );
    painter.rect_filled(rect, 3.0, visuals.selection.bg_fill);
    painter.galley(
        rect.min + egui::vec2(4.0, 1.0),
        galley,
        visuals.selection.stroke.color,
    );
}

/// Tau with as many decimals as it needs, up to three (0.5, 0.25, 0.125).
fn format_tau(tau: f64) -> String {
    let s = format!("{tau:.3}");
    let s = s.trim_end_matches('0');
    s.strip_suffix('.').unwrap_or(s).to_string()
}

fn format_volume(change: Option<f64>) -> String {
    change.map_or("n/a".into(), |v| format!("{:+.1} %", v * 100.0))
}
