//! Which of Bevy's prepass textures each channel of a program reads, and
//! the prepass components a camera needs for them.

use crate::MrslCamera;
use bevy::core_pipeline::prepass::{
    DeferredPrepass, DepthPrepass, MotionVectorPrepass, NormalPrepass, ViewPrepassTextures,
};
use bevy::ecs::prelude::*;
use bevy::render::render_resource::Texture;
use mrsl_abi::{Channel, Decode, Scalar, ValueType};
use mrsl_runtime_wgpu29::Layout;

/// One of the textures of Bevy's `ViewPrepassTextures`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PrepassTexture {
    /// The prepass depth (`Depth32Float`; `DepthPrepass`): for `@depth` channels.
    Depth,
    /// World-space normals as `Rgb10a2Unorm` (`NormalPrepass`): for
    /// `@encoded(unorm) in float3` channels.
    Normal,
    /// Motion vectors, `Rg16Float` (`MotionVectorPrepass`): for `float2` channels.
    MotionVectors,
    /// The deferred G-buffer, `Rgba32Uint` (`DeferredPrepass`): for
    /// `@packed(bevy_deferred, ...)` channels.
    Deferred,
    /// The deferred lighting-pass id, `R8Uint` (`DeferredPrepass`): for
    /// `uint` channels (a `@foreground(id)` rule owns one material's pixels).
    DeferredLightingPassId,
}

impl PrepassTexture {
    /// The texture a channel reads unless the camera binds it otherwise:
    /// the one its decoding says (`@depth`, `@packed(bevy_deferred, ..)`,
    /// `@encoded(unorm)` normals), a `uint` channel the lighting-pass id, a
    /// `float2` the motion vectors; `None` for any other channel.
    pub fn for_channel(channel: &Channel) -> Option<PrepassTexture> {
        match (&channel.decode, &channel.ty) {
            (Some(Decode::Depth { .. }), _) => Some(PrepassTexture::Depth),
            (Some(Decode::BevyDeferred { .. }), _) => Some(PrepassTexture::Deferred),
            (Some(Decode::Unorm), ValueType::Vector(Scalar::Float, 3)) => Some(PrepassTexture::Normal),
            (None, ValueType::Scalar(Scalar::Uint)) => Some(PrepassTexture::DeferredLightingPassId),
            (None, ValueType::Vector(Scalar::Float, 2)) => Some(PrepassTexture::MotionVectors),
            _ => None,
        }
    }

    /// The component that makes Bevy's prepass write this texture.
    pub fn component(self) -> &'static str {
        match self {
            PrepassTexture::Depth => "DepthPrepass",
            PrepassTexture::Normal => "NormalPrepass",
            PrepassTexture::MotionVectors => "MotionVectorPrepass",
            PrepassTexture::Deferred | PrepassTexture::DeferredLightingPassId => "DeferredPrepass",
        }
    }

    /// This texture of a view's prepass, if the prepass wrote it.
    pub(crate) fn of(self, textures: &ViewPrepassTextures) -> Option<&Texture> {
        let attachment = match self {
            PrepassTexture::Depth => &textures.depth,
            PrepassTexture::Normal => &textures.normal,
            PrepassTexture::MotionVectors => &textures.motion_vectors,
            PrepassTexture::Deferred => &textures.deferred,
            PrepassTexture::DeferredLightingPassId => &textures.deferred_lighting_pass_id,
        };
        attachment.as_ref().map(|a| &a.texture.texture)
    }
}

/// Each channel of `layout` with the prepass texture it reads, or the names
/// of the channels nothing binds.
pub(crate) fn resolve(layout: &Layout, camera: &MrslCamera) -> Result<Vec<(String, PrepassTexture)>, Vec<String>> {
    let mut bound = Vec::new();
    let mut unbound = Vec::new();
    for channel in &layout.channels {
        match camera.bindings.get(&channel.name).copied().or_else(|| PrepassTexture::for_channel(channel)) {
            Some(texture) => bound.push((channel.name.clone(), texture)),
            None => unbound.push(channel.name.clone()),
        }
    }
    if unbound.is_empty() { Ok(bound) } else { Err(unbound) }
}

/// Adds the prepass components a camera's program reads (depth for
/// `@depth`, the deferred prepass for Bevy's G-buffer, ...), so that an
/// `MrslCamera` works without the user listing them.
pub(crate) fn require_prepasses(mut commands: Commands, cameras: Query<(Entity, &MrslCamera), Changed<MrslCamera>>) {
    for (entity, camera) in &cameras {
        let Ok(bound) = resolve(&camera.program.compiled().layout, camera) else {
            continue; // reported by the pass, which names the channels
        };
        let mut entity = commands.entity(entity);
        for (_, texture) in bound {
            match texture {
                PrepassTexture::Depth => entity.insert_if_new(DepthPrepass),
                PrepassTexture::Normal => entity.insert_if_new(NormalPrepass),
                PrepassTexture::MotionVectors => entity.insert_if_new(MotionVectorPrepass),
                PrepassTexture::Deferred | PrepassTexture::DeferredLightingPassId => {
                    entity.insert_if_new(DeferredPrepass)
                }
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Mode, MrslProgram};

    fn camera(source: &str) -> MrslCamera {
        MrslCamera::new(MrslProgram::compile(source, "test.mrsl").expect("compiles"), Mode::Coarse4x4)
    }

    #[test]
    fn the_example_program_binds_every_channel_by_its_decoding() {
        let camera = camera(include_str!("../examples/lighting.mrsl"));
        let bound = resolve(&camera.program.compiled().layout, &camera).expect("every channel bound");
        let expected = [
            ("position", PrepassTexture::Depth),
            ("normal", PrepassTexture::Deferred),
            ("base_color", PrepassTexture::Deferred),
            ("lighting_pass", PrepassTexture::DeferredLightingPassId),
        ];
        assert_eq!(bound, expected.map(|(n, t)| (n.to_string(), t)));
    }

    #[test]
    fn a_channel_no_prepass_texture_stores_is_named_until_bound() {
        let source = "@encoded(unorm) in float3 normal; in float4 albedo; in float2 motion;\n\
                      fine out float4 color = float4(normal + albedo.rgb, motion.x);";
        let camera = camera(source);
        let program = camera.program.clone();
        let layout = &program.compiled().layout;
        assert_eq!(resolve(layout, &camera), Err(vec!["albedo".to_string()]));
        let camera = camera.bind("albedo", PrepassTexture::Normal);
        let bound = resolve(layout, &camera).expect("bound");
        assert!(bound.contains(&("normal".into(), PrepassTexture::Normal)));
        assert!(bound.contains(&("motion".into(), PrepassTexture::MotionVectors)));
        assert!(bound.contains(&("albedo".into(), PrepassTexture::Normal)));
    }
}
