//! The panel under the view: the model quality graphs or the gallery, one at a time. The
//! graphs are kept current in the background only while they are shown.

use super::document::Document;
use super::gallery_view::GalleryView;
use super::graphs;
use super::layout::{GraphColumn, PanelLayout};
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
        self.gallery.update(ctx, doc.session());
        if std::mem::take(&mut doc.show_gallery) {
            self.gallery_tab = true;
            self.set_open(true, doc.session_mut());
        }
    }

    /// The panel's contents; `layout` gets where its graphs or gallery cards were drawn.
    pub fn show(&mut self, ui: &mut egui::Ui, session: &mut Session, layout: &mut PanelLayout) {
        layout.graphs.clear();
        layout.gallery.clear();
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
            let mut cards = Vec::new();
            let picked = self.gallery.show(ui, session, &mut cards);
            layout.gallery = cards.into_iter().map(Into::into).collect();
            if let Some((tau, params)) = picked {
                let _ = session.case_mut().set_tau(tau);
                let _ = session.case_mut().set_params(params);
            }
        } else {
            graphs_tab(ui, session, &mut layout.graphs);
        }
    }
}

fn graphs_tab(ui: &mut egui::Ui, session: &mut Session, layout: &mut Vec<GraphColumn>) {
    ui.horizontal(|ui| {
        let filter = session.case().filter();
        ui.label(format!("{filter} filter: each column varies one parameter"));
        for a in session.background().activities() {
            if let Activity::Graphs(_) = a {
                ui.add(
                    egui::ProgressBar::new(a.fraction())
                        .desired_width(220.0)
                        .text(a.describe()),
                );
            }
        }
    });
    if let Some(p) = graphs::show(ui, session, layout) {
        let _ = session.case_mut().set_params(p);
    }
}
