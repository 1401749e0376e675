//! Copies each camera's mrsl settings into the render world.

use crate::{MrslCamera, MrslOutputs, MrslUniforms};
use bevy::asset::AssetId;
use bevy::ecs::prelude::*;
use bevy::image::Image;
use bevy::render::Extract;
use bevy::render::sync_world::RenderEntity;

/// A camera's settings in the render world, with the main-world entity its
/// report goes to.
#[derive(Component, Clone)]
pub(crate) struct ExtractedMrsl {
    pub(crate) camera: Entity,
    pub(crate) settings: MrslCamera,
    pub(crate) uniforms: MrslUniforms,
    pub(crate) outputs: Vec<(String, AssetId<Image>)>,
}

/// The main world's cameras with whatever of the plugin's components each has.
type CameraQuery<'w, 's> = Query<
    'w,
    's,
    (Entity, RenderEntity, Option<&'static MrslCamera>, Option<&'static MrslUniforms>, Option<&'static MrslOutputs>),
    With<bevy::camera::Camera>,
>;

pub(crate) fn extract_cameras(mut commands: Commands, cameras: Extract<CameraQuery>) {
    for (camera, render_entity, settings, uniforms, outputs) in &cameras {
        let mut entity = commands.entity(render_entity);
        match (settings, outputs) {
            (Some(settings), Some(outputs)) => {
                entity.insert(ExtractedMrsl {
                    camera,
                    settings: settings.clone(),
                    uniforms: uniforms.cloned().unwrap_or_default(),
                    outputs: outputs.images.iter().map(|(name, handle)| (name.clone(), handle.id())).collect(),
                });
            }
            _ => {
                entity.remove::<ExtractedMrsl>();
            }
        }
    }
}
