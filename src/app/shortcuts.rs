//! Keyboard shortcuts for frequent actions, and the help panel that lists them.

use eframe::egui;

/// An action a key triggers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Open,
    ToggleWireframe,
    ToggleOriginal,
    ResetView,
    NextColoring,
    Filter(usize),
    ExportGlb,
    ToggleHelp,
    ApplySuggestion,
    ToggleGraphs,
    ToggleBrush,
    CancelBackground,
}

/// Whether `action` only reads the case (the viewer takes those, and no other).
pub fn reads(action: Action) -> bool {
    matches!(
        action,
        Action::Open
            | Action::ToggleWireframe
            | Action::ResetView
            | Action::NextColoring
            | Action::ToggleHelp
    )
}

const KEYS: [(egui::Key, Action, &str); 15] = [
    (egui::Key::O, Action::Open, "Open a mesh file"),
    (egui::Key::W, Action::ToggleWireframe, "Wireframe on/off"),
    (
        egui::Key::B,
        Action::ToggleOriginal,
        "Before/after: show the original",
    ),
    (egui::Key::R, Action::ResetView, "Reset the view"),
    (
        egui::Key::C,
        Action::NextColoring,
        "Next colouring (shading, error, curvature, displacement)",
    ),
    (egui::Key::Num1, Action::Filter(0), "Laplace"),
    (egui::Key::Num2, Action::Filter(1), "Taubin λ/μ"),
    (egui::Key::Num3, Action::Filter(2), "Laplace + HC"),
    (egui::Key::Num4, Action::Filter(3), "Windowed sinc"),
    (
        egui::Key::E,
        Action::ExportGlb,
        "Export the smoothed mesh as GLB",
    ),
    (
        egui::Key::A,
        Action::ApplySuggestion,
        "Apply the suggested parameters",
    ),
    (
        egui::Key::G,
        Action::ToggleGraphs,
        "Model quality graphs on/off",
    ),
    (
        egui::Key::P,
        Action::ToggleBrush,
        "Weight brush on/off (paint where smoothing may act)",
    ),
    (
        egui::Key::Escape,
        Action::CancelBackground,
        "Cancel the suggestion or gallery under way",
    ),
    (egui::Key::H, Action::ToggleHelp, "This help"),
];

/// The actions whose keys were pressed this frame (none while a text field has focus).
pub fn pressed(ctx: &egui::Context) -> Vec<Action> {
    if ctx.egui_wants_keyboard_input() {
        return Vec::new();
    }
    ctx.input(|i| {
        KEYS.iter()
            .filter(|(key, _, _)| i.key_pressed(*key) && !i.modifiers.command)
            .map(|(_, action, _)| *action)
            .collect()
    })
}

/// The help window listing every shortcut and the mouse controls.
pub fn help_window(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("Help")
        .open(open)
        .resizable(false)
        .collapsible(false)
        .show(ctx, |ui| {
            ui.label(egui::RichText::new("Mouse").strong());
            egui::Grid::new("mouse_help").num_columns(2).show(ui, |ui| {
                for (what, does) in [
                    ("Left or middle drag", "Orbit"),
                    ("Shift + left drag", "Pan"),
                    ("Scroll / pinch", "Zoom"),
                    ("Double click", "Reset the view"),
                    (
                        "Right drag",
                        "Drive two smoothing parameters: left/right and down/up \
                         (chosen in the Smoothing panel)",
                    ),
                    (
                        "Brush on (P): left drag",
                        "Paint weights; Ctrl/⌘ + left or middle drag orbits",
                    ),
                ] {
                    ui.monospace(what);
                    ui.label(does);
                    ui.end_row();
                }
            });
            ui.add_space(6.0);
            ui.label(egui::RichText::new("Keys").strong());
            egui::Grid::new("key_help").num_columns(2).show(ui, |ui| {
                for (key, _, does) in KEYS {
                    ui.monospace(key.name());
                    ui.label(does);
                    ui.end_row();
                }
            });
        });
}
