//! The program's outputs as [`Image`] assets, sized to the camera's viewport.

use crate::MrslCamera;
use bevy::asset::{Assets, Handle, RenderAssetUsages};
use bevy::camera::Camera;
use bevy::ecs::prelude::*;
use bevy::image::Image;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureUsages};

/// The images the camera's program writes, one per `out` declaration in the
/// layout's order, each as large as the camera's physical viewport and in
/// the format the layout gives it (`@format`). The plugin adds this
/// component and replaces an image when the viewport's size changes; read
/// them (Bevy's `Readback`), show them, or let the plugin composite the first.
#[derive(Component, Clone, Debug, Default)]
pub struct MrslOutputs {
    pub images: Vec<(String, Handle<Image>)>,
    pub(crate) size: (u32, u32),
}

impl MrslOutputs {
    /// The image of output `name`.
    pub fn get(&self, name: &str) -> Option<&Handle<Image>> {
        self.images.iter().find(|(n, _)| n == name).map(|(_, h)| h)
    }
}

/// Creates or resizes each camera's output images.
pub(crate) fn fit_outputs(
    mut commands: Commands,
    mut images: ResMut<Assets<Image>>,
    cameras: Query<(Entity, &Camera, &MrslCamera, Option<&MrslOutputs>)>,
) {
    for (entity, camera, mrsl, current) in &cameras {
        let Some(size) = camera.physical_viewport_size() else { continue };
        let size = (size.x, size.y);
        let layout = &mrsl.program.compiled().layout;
        let names: Vec<&str> = layout.outputs.iter().map(|o| o.name.as_str()).collect();
        let fits = current
            .is_some_and(|c| c.size == size && c.images.iter().map(|(n, _)| n.as_str()).eq(names.iter().copied()));
        if fits || size.0 == 0 || size.1 == 0 {
            continue;
        }
        let outputs = layout
            .outputs
            .iter()
            .map(|output| {
                let format = mrsl_runtime_wgpu29::wgpu_format(output.format);
                let extent = Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 };
                let mut image =
                    Image::new_uninit(extent, TextureDimension::D2, format, RenderAssetUsages::RENDER_WORLD);
                image.texture_descriptor.usage =
                    TextureUsages::STORAGE_BINDING | TextureUsages::TEXTURE_BINDING | TextureUsages::COPY_SRC;
                (output.name.clone(), images.add(image))
            })
            .collect();
        commands.entity(entity).insert(MrslOutputs { images: outputs, size });
    }
}
