//! The gallery tab: makes the gallery (with progress and cancel), draws its pictures one per
//! frame once it is finished (a large mesh's picture takes a good part of a frame), all on one
//! local-error scale, and hands back the picked result's parameters and tau.

use super::gallery::{self, GalleryItem};
use crate::session::{shared_error_colors, Activity, Session, GALLERY_TAUS};
use crate::smooth::Params;
use crate::view::{first_view, thumbnail};
use eframe::egui;

#[derive(Default)]
pub struct GalleryView {
    /// The session's gallery version the items were drawn for.
    version: u64,
    items: Vec<GalleryItem>,
    /// Colours of the picks still to draw, on the shared scale.
    colors: Vec<Vec<[u8; 4]>>,
    scale_mm: f64,
}

impl GalleryView {
    /// Draws the next picture of a newly finished gallery (one per frame).
    pub fn update(&mut self, ctx: &egui::Context, session: &Session) {
        let picks = session.background().gallery();
        if session.background().gallery_version() != self.version {
            self.version = session.background().gallery_version();
            self.items.clear();
            let sets: Vec<&[f32]> = picks
                .iter()
                .map(|p| p.vertex.local_error.as_slice())
                .collect();
            (self.colors, self.scale_mm) = shared_error_colors(&sets);
        }
        if picks.is_empty() {
            self.items.clear();
            return;
        }
        let Some(model) = session.case().model() else {
            return;
        };
        let k = self.items.len();
        let (Some(pick), Some(colors)) = (picks.get(k), self.colors.get(k)) else {
            return;
        };
        let camera = first_view(&model.mesh().positions);
        let picture = thumbnail::render(
            &pick.positions,
            &model.mesh().triangles,
            Some(colors),
            &camera,
            gallery::pixel_size(ctx),
        );
        self.items.push(GalleryItem {
            texture: gallery::texture(ctx, &format!("gallery {k}"), &picture),
            tau: pick.tau,
            curvature_ratio: pick.terms.curvature_ratio,
            mean_error: pick.terms.mean_error,
            volume_change: pick.volume_change,
            selected: false,
        });
        ctx.request_repaint();
    }

    /// The tab's contents; returns the picked result's tau and parameters. `cards` gets where
    /// the cards were drawn.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        session: &mut Session,
        cards: &mut Vec<egui::Rect>,
    ) -> Option<(f64, Params)> {
        ui.horizontal(|ui| {
            if session.background().making_gallery() {
                if ui.button("Cancel").clicked() {
                    session.cancel_gallery();
                }
            } else if ui
                .button(if session.background().gallery().is_empty() { "Make gallery" } else { "Make again" })
                .on_hover_text(format!(
                    "Smooth the model as suggested for τ = {} with the active filter",
                    GALLERY_TAUS.map(|t| t.to_string()).join(", ")
                ))
                .clicked()
            {
                session.start_gallery();
            }
            for a in session.background().activities() {
                if let Activity::Gallery { .. } = a {
                    ui.add(
                        egui::ProgressBar::new(a.fraction())
                            .desired_width(220.0)
                            .text(a.describe()),
                    );
                }
            }
            if !self.items.is_empty() {
                ui.label(format!(
                    "Colour: local error, 0 to {} mm on every picture. Click one to take its parameters.",
                    self.scale_mm
                ));
            }
        });
        if session.background().gallery().is_empty() && !session.background().making_gallery() {
            ui.label(
                "The gallery shows the model smoothed as suggested at several target smoothness \
                 values, from accurate (τ 0.1) to smooth (τ 0.9), to choose from by eye.",
            );
            return None;
        }
        let current = *session.case().params();
        let picks = session.background().gallery();
        for (item, pick) in self.items.iter_mut().zip(picks) {
            item.selected = pick.params == current;
        }
        let clicked = egui::ScrollArea::vertical()
            .show(ui, |ui| gallery::show(ui, &self.items, cards))
            .inner?;
        picks.get(clicked).map(|p| (p.tau, p.params))
    }
}
