//! A picture of the view: the frame after the one that asks, as drawn, cut to the 3D view and
//! encoded as PNG, for the "Save picture" button and the API's `screenshot()`. The view's own
//! tools and messages are left out of that frame.

use std::sync::{Arc, Mutex};

use eframe::egui;

/// The picture asked for and not yet taken.
#[derive(Default)]
pub struct Picture {
    /// Where eframe puts the frame it read back.
    arrived: Arc<Mutex<Option<Arc<egui::ColorImage>>>>,
    /// A picture is on its way.
    pub pending: bool,
    /// It is to be saved as a file (else only the API's callers want it).
    pub download: bool,
}

impl Picture {
    /// Asks eframe for the next frame's pixels (a request under way covers this one too).
    pub fn ask(&mut self, ctx: &egui::Context, download: bool) {
        self.download |= download;
        if self.pending {
            return;
        }
        self.pending = true;
        let (arrived, wake) = (self.arrived.clone(), ctx.clone());
        ctx.request_screenshot(move |image| {
            if let Ok(mut slot) = arrived.lock() {
                *slot = Some(image);
            }
            super::wake(&wake);
        });
        ctx.request_repaint();
    }

    /// The picture of `view` (points) once the frame arrived: PNG bytes, or why there are none.
    pub fn take(
        &mut self,
        view: egui::Rect,
        pixels_per_point: f32,
    ) -> Option<Result<Vec<u8>, String>> {
        let image = self.arrived.lock().ok()?.take()?;
        self.pending = false;
        let region = view.intersect(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::vec2(image.size[0] as f32, image.size[1] as f32) / pixels_per_point,
        ));
        if !(region.width() >= 1.0 && region.height() >= 1.0) {
            return Some(Err("the view is not on the page".into()));
        }
        Some(png(&image.region(&region, Some(pixels_per_point))))
    }
}

/// `image` as an 8-bit RGBA PNG.
fn png(image: &egui::ColorImage) -> Result<Vec<u8>, String> {
    let [width, height] = image.size;
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width as u32, height as u32);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let rgba: Vec<u8> = (image.pixels.iter())
        .flat_map(|c| c.to_srgba_unmultiplied())
        .collect();
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(&rgba).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(bytes)
}
