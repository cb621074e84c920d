//! What a reader takes away from the view: a picture of it (PNG) and a link that opens the
//! case as it is shown now; and taking up such a link when the page opens with one.

use eframe::egui;

use super::Shell;
use crate::app::document::Document;
use crate::app::download;
use crate::session::StructureChange;
use crate::view::ViewLink;

impl Shell {
    /// Hands a picture that arrived to whoever asked for it, and asks for one the API wants.
    pub(super) fn pictures(&mut self, ctx: &egui::Context) {
        let mut doc = self.doc.borrow_mut();
        let r = doc.view.rect;
        let view =
            egui::Rect::from_min_size(egui::pos2(r.left, r.top), egui::vec2(r.width, r.height));
        if let Some(png) = self.picture.take(view, ctx.pixels_per_point()) {
            if std::mem::take(&mut self.picture.download) {
                let stem = doc
                    .session()
                    .case()
                    .case_file()
                    .split('.')
                    .next()
                    .unwrap_or("");
                let name = format!("{}_view.png", if stem.is_empty() { "case" } else { stem });
                if let Err(e) = (png.as_ref())
                    .map_err(String::clone)
                    .and_then(|b| download::save(&name, b, "image/png"))
                {
                    log::warn!("the picture was not saved: {e}");
                }
            }
            for waiter in std::mem::take(&mut doc.waiting_for_picture) {
                waiter(png.clone());
            }
        }
        if !doc.waiting_for_picture.is_empty() {
            self.picture.ask(ctx, false);
        }
        if self.picture.pending {
            // The frame read back reaches the app in a frame after it, which an idle viewer
            // would not draw.
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }

    /// The view's sharing buttons: save a picture, copy a link to the view (where the case came
    /// from an address).
    pub(super) fn sharing_buttons(&mut self, ui: &mut egui::Ui) {
        if ui
            .button("Save picture")
            .on_hover_text("Save the view as a PNG image")
            .clicked()
        {
            self.picture.ask(ui.ctx(), true);
        }
        // The address is made when asked for, not every frame.
        let linkable = crate::app::query::case_param().is_some();
        let tip = "Copy an address that opens this case as it is shown now";
        let button = ui.add_enabled(linkable, egui::Button::new("Copy link"));
        let button = button
            .on_hover_text(tip)
            .on_disabled_hover_text("Only a case opened from an address (?case=) has a link");
        if let (true, Some(url)) = (
            button.clicked(),
            crate::app::query::viewer_url(&self.doc.borrow().view_link()),
        ) {
            ui.ctx().copy_text(url);
            self.link_copied = true;
        }
        if self.link_copied && !button.hovered() {
            self.link_copied = false;
        }
        if self.link_copied {
            ui.weak("copied");
        }
    }

    /// Shows the case as the page's link asks, once the case it came with is open (or says
    /// why the link does not read).
    pub(super) fn take_up_link(&mut self, link: Result<ViewLink, String>) {
        let mut doc = self.doc.borrow_mut();
        let link = match link {
            Ok(link) => link,
            Err(e) => {
                doc.session_mut().fail("the link", &e);
                return;
            }
        };
        let problems = show_view(&mut doc, &link);
        self.pending_pose = link.camera;
        if !problems.is_empty() {
            doc.session_mut().fail("the link", &problems.join("; "));
        }
    }
}

/// Shows the structures, selection, clip or planes and slide `link` asks for (not its
/// camera); what could not be shown, in words.
pub(super) fn show_view(doc: &mut Document, link: &ViewLink) -> Vec<String> {
    let count = doc.session().case().as_case().structures.len();
    let mut problems = Vec::new();
    for &i in link
        .hidden
        .iter()
        .chain(link.opacity.iter().map(|(i, _)| i))
    {
        if i >= count {
            problems.push(format!("the case has no structure {i}"));
        }
    }
    for i in 0..count {
        let change = StructureChange {
            visible: Some(!link.hidden.contains(&i)),
            opacity: (link.opacity.iter().find(|(j, _)| *j == i)).map(|(_, a)| *a),
            ..Default::default()
        };
        if let Err(e) = doc.session_mut().case_mut().set_structure(i, change) {
            problems.push(e);
        }
    }
    doc.view_asks.clip = link.clip;
    // The image's planes and a clip exclude each other; a view (a tour step) that names
    // neither leaves the planes as the reader set them.
    if link.planes.is_some() || link.clip.is_some() {
        doc.view_asks.planes = link.planes;
    }
    doc.view_asks.toward_segmentation = link.toward_segmentation;
    if let Some(i) = link.selected {
        if let Err(e) = doc.select(i) {
            problems.push(e);
        }
    }
    problems
}
