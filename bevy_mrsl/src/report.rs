//! What each camera's last frame did: its statistics or its error, carried
//! from the render world to the camera's [`MrslReport`].

use bevy::ecs::prelude::*;
use mrsl_runtime_wgpu29::{Mode, Stats};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// The outcome of the camera's last frame that has been read back: one
/// frame behind (statistics are read after the frame's commands ran).
#[derive(Component, Clone, Debug, Default)]
pub struct MrslReport {
    /// Frames the program ran for this camera.
    pub frames: u64,
    /// The mode and statistics of the last frame that ran with statistics
    /// on (`MrslCamera::statistics`).
    pub stats: Option<(Mode, Stats)>,
    /// Why the last frame did not run (a runtime error: a channel whose
    /// prepass is missing, a uniform out of range, an unsupported mode, a
    /// program the device refused, ...) or why its statistics could not
    /// be read back; `None` when it ran and read back without one.
    pub error: Option<String>,
}

impl MrslReport {
    /// Takes in one frame of the camera: the statistics it read back (those
    /// of the frame before, when that one counted them) and whether it ran
    /// (`Ok(true)`), waited for its outputs (`Ok(false)`) or failed. The
    /// error is the read-back's and the frame's, joined; a frame that ran
    /// and read back without one clears it, a waiting one leaves it.
    pub(crate) fn frame(&mut self, stats: Option<Result<(Mode, Stats), String>>, ran: Result<bool, String>) {
        let mut errors = vec![];
        match stats {
            Some(Ok(stats)) => self.stats = Some(stats),
            Some(Err(error)) => errors.push(error),
            None => {}
        }
        let ran = match ran {
            Ok(ran) => ran,
            Err(error) => {
                errors.push(error);
                false
            }
        };
        self.frames += u64::from(ran);
        if !errors.is_empty() {
            self.error = Some(errors.join("; "));
        } else if ran {
            self.error = None;
        }
    }
}

/// The reports by main-world camera, written in the render world and
/// copied to the cameras by [`publish`].
#[derive(Resource, Clone, Default)]
pub(crate) struct Shared(pub(crate) Arc<Mutex<HashMap<Entity, MrslReport>>>);

impl Shared {
    pub(crate) fn update(&self, camera: Entity, change: impl FnOnce(&mut MrslReport)) {
        let mut reports = self.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        change(reports.entry(camera).or_default());
    }
}

/// Copies the render world's reports onto the cameras.
pub(crate) fn publish(mut commands: Commands, shared: Res<Shared>, cameras: Query<Entity, With<crate::MrslCamera>>) {
    let reports = shared.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    for entity in &cameras {
        if let Some(report) = reports.get(&entity) {
            commands.entity(entity).insert(report.clone());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A read-back error stays in the report of the frame that read it, even
    /// when that frame ran (it was cleared by the same frame before).
    #[test]
    fn a_frame_keeps_its_read_back_error_and_a_clean_frame_clears_it() {
        let mut report = MrslReport::default();
        report.frame(Some(Err("the statistics could not be read".into())), Ok(true));
        assert_eq!((report.frames, report.error.as_deref()), (1, Some("the statistics could not be read")));
        report.frame(None, Ok(false));
        assert_eq!(report.error.as_deref(), Some("the statistics could not be read"), "waiting keeps it");
        report.frame(None, Err("uniform `x` out of range".into()));
        assert_eq!((report.frames, report.error.as_deref()), (1, Some("uniform `x` out of range")));
        report.frame(Some(Err("a".into())), Err("b".into()));
        assert_eq!(report.error.as_deref(), Some("a; b"));
        report.frame(None, Ok(true));
        assert_eq!((report.frames, report.error), (2, None));
    }
}
