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
    /// prepass is missing, a uniform out of range, an unsupported mode,
    /// ...), or `None` when it ran.
    pub error: Option<String>,
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
