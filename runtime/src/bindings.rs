//! What an engine binds for one dispatch: the image size and its textures,
//! samplers and outputs by the program's names. A leaf module that the
//! shader, the bind groups and the checks all read.

use std::collections::HashMap;

/// Resources an engine binds for one dispatch. Every name is a declaration of
/// the program; the layout says which are needed.
#[derive(Default)]
pub struct Bindings<'a> {
    /// Width and height of the shaded image in pixels.
    pub size: (u32, u32),
    /// G-buffer channel textures, by `in` name.
    pub channels: HashMap<String, &'a wgpu::Texture>,
    /// Sampled textures, by `uniform texture2d` name.
    pub textures: HashMap<String, &'a wgpu::TextureView>,
    /// Samplers, by `uniform sampler` name.
    pub samplers: HashMap<String, &'a wgpu::Sampler>,
    /// Output storage textures, by `fine out` name.
    pub outputs: HashMap<String, &'a wgpu::Texture>,
    /// The rate-image mode's shading-rate image: one texel per
    /// [`crate::DispatchOptions::rate_tile`]-pixel tile
    /// ([`mrsl_abi::shading_rate::rate_image_size`]), an unsigned-integer
    /// texture (R8Uint, R16Uint or R32Uint) holding the codes of
    /// [`mrsl_abi::ShadingRate`]. Other modes ignore it.
    pub shading_rate: Option<&'a wgpu::Texture>,
}
