//! The suggestion panel: the target smoothness tau ("accuracy <-> smoothness"), a search with
//! progress and cancel, and the suggestion ready to apply with one click. After a grid search
//! the suggestion follows tau at once, and "Apply as τ moves" turns tau into the one parameter
//! that drives them all.

use crate::session::{Activity, Session};
use crate::suggest::SearchMethod;
use eframe::egui;

pub struct Guide {
    pub method: SearchMethod,
    /// Applies the grid's suggestion whenever tau moves.
    pub follow_tau: bool,
}

impl Default for Guide {
    fn default() -> Self {
        Self {
            method: SearchMethod::Local,
            follow_tau: false,
        }
    }
}

impl Guide {
    pub fn show(&mut self, ui: &mut egui::Ui, session: &mut Session) {
        let mut tau = session.case().tau();
        ui.horizontal(|ui| {
            ui.label("accuracy");
            let r = ui
                .add(
                    egui::Slider::new(&mut tau, 0.0..=1.0)
                        .step_by(0.01)
                        .text("τ"),
                )
                .on_hover_text(
                    "Target smoothness τ: 0 keeps the mesh as accurate as it is, 1 asks for the \
                     smoothest result. It weighs the score S = τ·K/K0 + (1-τ)·accuracy.",
                );
            ui.label("smoothness");
            if r.changed() {
                let _ = session.case_mut().set_tau(tau);
            }
        });
        self.search_row(ui, session);
        for a in session.background().activities() {
            if let Activity::Suggest { .. } = a {
                ui.add(egui::ProgressBar::new(a.fraction()).text(a.describe()));
            }
        }
        let Some(suggested) = session.background().suggestion() else {
            if !session.background().suggesting() {
                ui.small("No suggestion for this filter yet.");
            }
            return;
        };
        let s = &suggested.suggestion;
        let current = *session.case().params();
        let applied = s.params == current;
        egui::Frame::group(ui.style()).show(ui, |ui| {
            let for_tau = if (s.tau - session.case().tau()).abs() > 1e-9 {
                format!(
                    " (for τ {:.2}: suggest again for {:.2})",
                    s.tau,
                    session.case().tau()
                )
            } else {
                String::new()
            };
            ui.label(format!(
                "Suggested by the {} search{for_tau}:",
                s.search.name()
            ));
            ui.monospace(s.params.describe());
            let volume = s
                .terms
                .volume_change
                .map_or("n/a".to_string(), |v| format!("{:.2} %", 100.0 * v));
            ui.small(format!(
                "K/K0 {:.3}, mean error {:.3} mm, |ΔV| {volume}, S {:.4}; {} sets in {:.1} s",
                s.terms.curvature_ratio,
                s.terms.mean_error,
                s.score,
                s.evaluations,
                suggested.elapsed_ms / 1000.0
            ));
            ui.horizontal(|ui| {
                if ui
                    .add_enabled(
                        !applied,
                        egui::Button::new(if applied { "Applied" } else { "Apply" }),
                    )
                    .clicked()
                {
                    let _ = session.case_mut().set_params(s.params);
                }
                if s.search == SearchMethod::Grid {
                    ui.checkbox(&mut self.follow_tau, "Apply as τ moves");
                }
            });
        });
        if self.follow_tau && s.search == SearchMethod::Grid && !applied {
            let _ = session.case_mut().set_params(s.params);
        }
    }

    /// The search method, and Suggest (or Cancel while a search is under way).
    fn search_row(&mut self, ui: &mut egui::Ui, session: &mut Session) {
        ui.horizontal(|ui| {
            ui.label("search");
            egui::ComboBox::from_id_salt("search_method")
                .selected_text(match self.method {
                    SearchMethod::Local => "local (fast)",
                    SearchMethod::Grid => "grid (all points)",
                })
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut self.method, SearchMethod::Local, "local (fast)")
                        .on_hover_text(
                            "The paper's local search from opposite corners of the grid",
                        );
                    ui.selectable_value(&mut self.method, SearchMethod::Grid, "grid (all points)")
                        .on_hover_text(
                            "Every grid point: slower, but then the suggestion follows τ at once",
                        );
                });
            if session.background().suggesting() {
                if ui.button("Cancel").clicked() {
                    session.cancel_suggest();
                }
            } else if ui
                .button("Suggest")
                .on_hover_text("Search the parameters with the lowest score S for this τ")
                .clicked()
            {
                session.start_suggest(self.method);
            }
        });
    }
}
