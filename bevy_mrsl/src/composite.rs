//! Draws a camera's first output over its image after Bevy's main pass,
//! before post-processing (so Bevy's tonemapping sees it), with
//! premultiplied alpha: alpha 1 replaces Bevy's lighting, alpha 0 keeps it.
//!
//! A fullscreen triangle in wgpu directly rather than Bevy's
//! `FullscreenMaterial`: that material samples the view's own image, not a
//! second texture, and its uniform is a Bevy type per material.

use crate::extract::ExtractedMrsl;
use bevy::ecs::prelude::*;
use bevy::render::render_asset::RenderAssets;
use bevy::render::renderer::{RenderContext, RenderDevice, ViewQuery};
use bevy::render::texture::GpuImage;
use bevy::render::view::ViewTarget;
use std::collections::HashMap;

const SHADER: &str = r"
@group(0) @binding(0) var image: texture_2d<f32>;

@vertex
fn fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn copy(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(image, vec2<i32>(p.xy), 0);
}
";

/// The composite pipeline for each view-target format.
#[derive(Resource, Default)]
pub(crate) struct Pipelines(HashMap<wgpu::TextureFormat, (wgpu::RenderPipeline, wgpu::BindGroupLayout)>);

impl Pipelines {
    fn get(
        &mut self,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
    ) -> &(wgpu::RenderPipeline, wgpu::BindGroupLayout) {
        self.0.entry(format).or_insert_with(|| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("mrsl composite"),
                source: wgpu::ShaderSource::Wgsl(SHADER.into()),
            });
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("mrsl composite"),
                entries: &[wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                }],
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("mrsl composite"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let blend = wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
                operation: wgpu::BlendOperation::Add,
            };
            let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("mrsl composite"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("fullscreen"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("copy"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: Some(wgpu::BlendState { color: blend, alpha: blend }),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                multiview_mask: None,
                cache: None,
            });
            (pipeline, layout)
        })
    }
}

pub(crate) fn run(
    view: ViewQuery<(&ExtractedMrsl, &ViewTarget)>,
    mut pipelines: ResMut<Pipelines>,
    device: Res<RenderDevice>,
    images: Res<RenderAssets<GpuImage>>,
    mut ctx: RenderContext,
) {
    let (mrsl, target) = view.into_inner();
    if !mrsl.settings.composite {
        return;
    }
    let Some(image) = mrsl.outputs.first().and_then(|(_, id)| images.get(*id)) else { return };
    let main = target.main_texture();
    let float = matches!(image.texture.format().sample_type(None, None), Some(wgpu::TextureSampleType::Float { .. }));
    if !float || (image.texture.width(), image.texture.height()) != (main.width(), main.height()) {
        return; // an integer output, or one being resized with the viewport
    }
    let device = device.wgpu_device();
    let (pipeline, layout) = pipelines.get(device, target.main_texture_format());
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("mrsl composite"),
        layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(&image.texture_view),
        }],
    });
    let mut pass = ctx.command_encoder().begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("mrsl composite"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target.main_texture_view(),
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
        })],
        ..Default::default()
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &group, &[]);
    pass.draw(0..3, 0..1);
}
