//! The panel under the view: the model quality graphs or the gallery, one at a time. The
//! graphs are kept current in the background only while they are shown.

use super::document::Document;
use super::gallery_view::GalleryView;
use super::graphs;
use crate::session::{Activity, Session};
use eframe::egui;

pub struct BottomPanel {
    pub open: bool,
    gallery_tab: bool,
    gallery: GalleryView,
}

impl BottomPanel {
    pub fn new() -> Self {
        Self {
            open: true,
            gallery_tab: false,
            gallery: GalleryView::default(),
        }
    }

    pub fn set_open(&mut self, open: bool, session: &mut Session) {
        self.open = open;
        session.set_graphs_wanted(open && !self.gallery_tab);
    }

    /// Draws the next gallery picture, and shows the gallery when the API asked for it.
    pub fn update(&mut self, ctx: &egui::Context, doc: &mut Document) {
        self.gallery.update(ctx, &doc.session);
        if std::mem::take(&mut doc.show_gallery) {
            self.gallery_tab = true;
            self.set_open(true, &mut doc.session);
        }
    }

    pub fn show(&mut self, ui: &mut egui::Ui, session: &mut Session) {
        ui.horizontal(|ui| {
            let mut gallery = self.gallery_tab;
            ui.selectable_value(
                &mut gallery,
                false,
                egui::RichText::new("Quality graphs").heading(),
            );
            ui.selectable_value(&mut gallery, true, egui::RichText::new("Gallery").heading());
            if gallery != self.gallery_tab {
                self.gallery_tab = gallery;
                session.set_graphs_wanted(!gallery);
            }
        });
        if self.gallery_tab {
            if let Some((tau, params)) = self.gallery.show(ui, session) {
                let _ = session.set_tau(tau);
                let _ = session.set_params(params);
            }
        } else {
            graphs_tab(ui, session);
        }
    }
}

fn graphs_tab(ui: &mut egui::Ui, session: &mut Session) {
    ui.horizontal(|ui| {
        let filter = session.filter();
        ui.label(format!("{filter} filter: each column varies one parameter"));
        for a in session.activities() {
            if let Activity::Graphs(_) = a {
                ui.add(
                    egui::ProgressBar::new(a.fraction())
                        .desired_width(220.0)
                        .text(a.describe()),
                );
            }
        }
    });
    if let Some(p) = graphs::show(ui, session) {
        let _ = session.set_params(p);
    }
}
