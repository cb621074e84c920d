//! How often the page redraws for what changes without the author: a file's bytes, the
//! workers' progress, "Suggest all"'s new surfaces. Chosen once at start from the GPU the page
//! draws on and kept in egui's context, where the frame and the workers' replies find it.
//! Each frame draws the whole page and its model, which a software GPU (SwiftShader, llvmpipe)
//! pays for with the CPU the workers need; a graphics card pays little.

use std::time::Duration;

use eframe::egui;

/// How often a progress that is not the workers' moves on (bytes read, an opening's stage):
/// once a second keeps a software GPU's share small.
pub(super) const PROGRESS_REPAINT: Duration = Duration::from_millis(1000);

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Pacing {
    /// How often the page redraws only to move the workers' progress on (their replies wake
    /// it when what it shows changes).
    pub work_repaint: Duration,
    /// How far apart the view shows the new surfaces of "Suggest all", in milliseconds: each
    /// upload redraws every structure.
    pub looks_every_ms: f64,
}

impl Pacing {
    /// The pacing for a page drawing on a `software` GPU or on a graphics card.
    pub fn for_gpu(software: bool) -> Self {
        match software {
            true => Pacing {
                work_repaint: Duration::from_millis(3000),
                looks_every_ms: 30_000.0,
            },
            false => Pacing {
                work_repaint: PROGRESS_REPAINT,
                looks_every_ms: 1000.0,
            },
        }
    }

    /// Makes this the page's pacing.
    pub fn keep(self, ctx: &egui::Context) {
        ctx.data_mut(|d| d.insert_temp(id(), self));
    }

    /// The page's pacing; a graphics card's until one is kept.
    pub fn of(ctx: &egui::Context) -> Self {
        ctx.data(|d| d.get_temp::<Pacing>(id()))
            .unwrap_or_else(|| Pacing::for_gpu(false))
    }
}

fn id() -> egui::Id {
    egui::Id::unique("meshsmooth pacing")
}
