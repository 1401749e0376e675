//! The mrsl passes of each view, recorded into Bevy's command encoder after
//! the prepass: mrsl-runtime's [`Shader::encode`] interprets the mode's plan.

use crate::MrslProgram;
use crate::bindings::{self, PrepassTexture};
use crate::extract::ExtractedMrsl;
use crate::report::Shared;
use bevy::core_pipeline::prepass::ViewPrepassTextures;
use bevy::ecs::prelude::*;
use bevy::render::Extract;
use bevy::render::render_asset::RenderAssets;
use bevy::render::renderer::{RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::texture::GpuImage;
use bevy::render::view::ExtractedView;
use mrsl_abi::Decode;
use mrsl_runtime_wgpu29::{Bindings, DispatchOptions, Mode, Shader};
use std::collections::HashMap;

/// Each camera's program on the render device, by main-world camera.
#[derive(Resource, Default)]
pub(crate) struct Shaders(HashMap<Entity, CameraShader>);

/// Drops the programs of cameras that no longer have an `MrslCamera` (or
/// no longer exist), with their pipelines and buffers.
pub(crate) fn drop_unused(mut shaders: ResMut<Shaders>, cameras: Extract<Query<Entity, With<crate::MrslCamera>>>) {
    if shaders.0.keys().any(|camera| !cameras.contains(*camera)) {
        shaders.0.retain(|camera, _| cameras.contains(*camera));
    }
}

struct CameraShader {
    program: MrslProgram,
    /// The program's kernels on the device, or why the device refused
    /// them: kept, so that a program that fails is not rebuilt every frame
    /// (only a new program is tried again).
    shader: Result<Shader, String>,
    /// The mode of the last frame recorded with statistics on, whose
    /// statistics have not been read yet.
    unread: Option<Mode>,
}

/// What became of a view's frame.
enum Outcome {
    Ran,
    /// The output images are not on the GPU yet, or are being resized.
    Waiting,
}

pub(crate) fn run(
    view: ViewQuery<(&ExtractedMrsl, &ExtractedView, Option<&ViewPrepassTextures>)>,
    mut shaders: ResMut<Shaders>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    images: Res<RenderAssets<GpuImage>>,
    shared: Res<Shared>,
    mut ctx: RenderContext,
) {
    let (mrsl, view, prepass) = view.into_inner();
    let device = device.wgpu_device();
    let queue: &wgpu::Queue = &queue.0;
    let state = match shaders.0.get_mut(&mrsl.camera) {
        Some(state) if state.program.same(&mrsl.settings.program) => state,
        _ => {
            let shader = Shader::new(device, mrsl.settings.program.compiled()).map_err(|e| e.to_string());
            let state = CameraShader { program: mrsl.settings.program.clone(), shader, unread: None };
            shaders.0.entry(mrsl.camera).insert_entry(state).into_mut()
        }
    };
    let shader = match &mut state.shader {
        Ok(shader) => shader,
        Err(error) => return shared.update(mrsl.camera, |r| r.frame(None, Err(error.clone()))),
    };
    let stats = state.unread.take().map(|mode| shader.read_stats(device).map(|s| (mode, s)).map_err(|e| e.to_string()));
    let outcome = record(shader, &mut state.unread, mrsl, view, prepass, &images, device, queue, ctx.command_encoder());
    shared.update(mrsl.camera, |r| r.frame(stats, outcome.map(|o| matches!(o, Outcome::Ran))));
}

/// Sets the uniforms, binds the prepass textures and outputs, and records
/// the passes; every check is done before anything is recorded.
#[allow(clippy::too_many_arguments)] // the render world's resources, each used once
fn record(
    shader: &mut Shader,
    unread: &mut Option<Mode>,
    mrsl: &ExtractedMrsl,
    view: &ExtractedView,
    prepass: Option<&ViewPrepassTextures>,
    images: &RenderAssets<GpuImage>,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    encoder: &mut bevy::render::render_resource::CommandEncoder,
) -> Result<Outcome, String> {
    let settings = &mrsl.settings;
    shader.supports(settings.mode).map_err(|e| e.to_string())?;
    for (name, values) in &mrsl.uniforms.0 {
        shader.set_uniform(name, values).map_err(|e| e.to_string())?;
    }
    let world_from_clip = world_from_clip(view).to_cols_array();
    let matrices: Vec<String> = shader
        .layout()
        .channels
        .iter()
        .filter_map(|c| match &c.decode {
            Some(Decode::Depth { inverse_view_projection }) => Some(inverse_view_projection.clone()),
            _ => None,
        })
        .collect();
    for matrix in matrices {
        shader.set_uniform_f32(&matrix, &world_from_clip).map_err(|e| e.to_string())?;
    }
    let size = (view.viewport.z, view.viewport.w);
    let mut outputs = HashMap::new();
    for (name, id) in &mrsl.outputs {
        match images.get(*id) {
            Some(image) if (image.texture.width(), image.texture.height()) == size => {
                outputs.insert(name.clone(), &*image.texture);
            }
            _ => return Ok(Outcome::Waiting),
        }
    }
    let channels = prepass_channels(shader, settings, prepass)?;
    let bindings = Bindings { size, channels, outputs, ..Default::default() };
    let options = DispatchOptions {
        force_refine: settings.force_refine,
        similarity: settings.similarity,
        statistics: settings.statistics,
        ..DispatchOptions::new(settings.mode)
    };
    shader.encode(device, queue, encoder, &bindings, options).map_err(|e| e.to_string())?;
    *unread = settings.statistics.then_some(settings.mode);
    Ok(Outcome::Ran)
}

/// Each channel's prepass texture, or an error naming the channel and what
/// to add to the camera.
fn prepass_channels<'a>(
    shader: &Shader,
    settings: &crate::MrslCamera,
    prepass: Option<&'a ViewPrepassTextures>,
) -> Result<HashMap<String, &'a wgpu::Texture>, String> {
    let bound = bindings::resolve(shader.layout(), settings).map_err(|unbound| {
        format!(
            "no prepass texture is bound to channel{} `{}`: bind {} with MrslCamera::bind (depth, normals, motion vectors, the deferred G-buffer or its lighting-pass id)",
            if unbound.len() == 1 { "" } else { "s" },
            unbound.join("`, `"),
            if unbound.len() == 1 { "it" } else { "them" },
        )
    })?;
    let mut channels = HashMap::new();
    for (name, texture) in bound {
        match prepass.and_then(|p| texture.of(p)) {
            Some(found) => {
                channels.insert(name, &**found);
            }
            None => return Err(missing_prepass(&name, texture)),
        }
    }
    Ok(channels)
}

fn missing_prepass(channel: &str, texture: PrepassTexture) -> String {
    format!(
        "channel `{channel}` reads Bevy's {texture:?} prepass texture, which this view's prepass did not write: add {} to the camera",
        texture.component()
    )
}

/// The inverse of the view's view-projection: clip space to world space.
fn world_from_clip(view: &ExtractedView) -> bevy::math::Mat4 {
    let clip_from_world =
        view.clip_from_world.unwrap_or_else(|| view.clip_from_view * view.world_from_view.to_matrix().inverse());
    clip_from_world.inverse()
}
