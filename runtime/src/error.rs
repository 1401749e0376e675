//! The runtime's typed errors: every mismatch between a program's layout and
//! what the engine binds, and what the device or a readback refused.

/// What went wrong, naming the binding at fault.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum Error {
    #[error("G-buffer channel `{0}` is not bound")]
    MissingChannel(String),
    /// `accepted` says in words which other formats the channel takes.
    #[error(
        "G-buffer channel `{channel}` has format {found:?}, but the program reads it as `{ty}`: bind {expected:?} (the layout's format) or {accepted}"
    )]
    ChannelFormat {
        channel: String,
        ty: String,
        expected: wgpu::TextureFormat,
        accepted: String,
        found: wgpu::TextureFormat,
    },
    #[error(
        "G-buffer channel `{channel}` has the depth/stencil format {found:?}, which is not accepted as a channel (the kernels read channels as colour textures): in an engine pass, write what the program reads as `{ty}` into a {expected:?} texture, or declare the channel `@depth(inverse_view_projection) in float3` to have the kernels rebuild a position from this depth texture"
    )]
    ChannelDepthFormat { channel: String, ty: String, expected: wgpu::TextureFormat, found: wgpu::TextureFormat },
    /// A channel the program rebuilds from depth (`@depth(..)`) bound with a colour texture.
    #[error(
        "G-buffer channel `{channel}` is rebuilt from depth (`@depth`), so it binds the engine's depth texture (Depth32Float, Depth24Plus, Depth16Unorm or a depth-stencil format), but a {found:?} texture was bound"
    )]
    ChannelNotDepth { channel: String, found: wgpu::TextureFormat },
    /// A channel the kernels read through a storage binding
    /// ([`mrsl_abi::ChannelAccess::Storage`]), whose format must be the layout's.
    #[error(
        "G-buffer channel `{channel}` has format {found:?}, but the kernels read it through a storage binding of format {expected:?}, which takes no other: bind a {expected:?} texture, or compile without storage channels (`Options::storage_channels`) to read it sampled"
    )]
    ChannelStorageFormat { channel: String, expected: wgpu::TextureFormat, found: wgpu::TextureFormat },
    #[error(
        "G-buffer channel `{channel}` was not created with TextureUsages::{missing}, which the kernels need to read it: add it to the texture's usage"
    )]
    ChannelUsage { channel: String, missing: &'static str },
    /// A channel's or output's texture is not a single-sample 2D texture of
    /// one layer (and, for an output, one mip level); `found` says what it is.
    #[error(
        "{what} `{name}` is {found}, but the kernels bind a single-sample 2D texture of one layer (and, for an output, one mip level)"
    )]
    TextureShape { what: &'static str, name: String, found: String },
    #[error("{what} `{name}` is {found_width}x{found_height}, but the target is {width}x{height}")]
    SizeMismatch { what: &'static str, name: String, width: u32, height: u32, found_width: u32, found_height: u32 },
    #[error("uniform `{0}` has no default and was not set")]
    MissingUniform(String),
    #[error("the program has no uniform `{0}`")]
    UnknownUniform(String),
    #[error("uniform `{name}` is `{ty}` ({expected} components), but {found} values were given")]
    UniformComponents { name: String, ty: String, expected: usize, found: usize },
    /// A value the uniform's scalar type does not hold as given: `reason`
    /// says why (not an integer, out of range, not 0 or 1, not finite).
    #[error("uniform `{name}` is `{ty}`, but {} {reason}", value_at(ty, *index, *value))]
    UniformValue { name: String, ty: String, index: usize, value: f64, reason: &'static str },
    /// A typed setter (`Shader::set_uniform_u32`, ...) for another scalar type.
    #[error(
        "uniform `{name}` is `{ty}`, but {given} values were given: use the setter of its scalar type (set_uniform_f32, set_uniform_i32, set_uniform_u32, set_uniform_bool) or set_uniform"
    )]
    UniformType { name: String, ty: String, given: &'static str },
    #[error("texture `{0}` is not bound")]
    MissingTexture(String),
    #[error(
        "texture `{0}` was not created with TextureUsages::TEXTURE_BINDING, which the kernels need to sample it: add it to the texture's usage"
    )]
    TextureUsage(String),
    #[error("sampler `{0}` is not bound")]
    MissingSampler(String),
    #[error("output `{0}` is not bound")]
    MissingOutput(String),
    /// `hint` says how to fix it: the `@format` that declares the found
    /// format, where the language has one for the output's type.
    #[error("output `{name}` must be a {expected:?} storage texture, found {found:?}: {hint}")]
    OutputFormat { name: String, expected: wgpu::TextureFormat, found: wgpu::TextureFormat, hint: String },
    #[error(
        "output `{0}` was not created with TextureUsages::STORAGE_BINDING, which the kernels need to write it: add it to the texture's usage"
    )]
    OutputUsage(String),
    #[error("target size {width}x{height} is not supported: {reason}")]
    BadSize { width: u32, height: u32, reason: String },
    #[error("mode `{0}` is not supported by this program: {1}")]
    UnsupportedMode(String, String),
    #[error("{0}")]
    UnknownMode(#[from] mrsl_abi::UnknownMode),
    #[error("the rate-image mode needs a shading-rate image (`Bindings::shading_rate`), and none is bound")]
    MissingShadingRate,
    #[error("the device rejected a pipeline: {0}")]
    Pipeline(String),
    #[error("reading results back failed: {0}")]
    Readback(String),
    #[error("the last dispatch ran with DispatchOptions::statistics off, so it counted nothing")]
    StatisticsOff,
    /// The program did not compile (the `compile` feature); the rendered diagnostics.
    #[cfg(feature = "compile")]
    #[error("the program does not compile:\n{0}")]
    Compile(String),
    // Shading-rate images (the rate-image mode's and the rate source's): inputs, outputs, options.
    #[error("{what} is {}x{}, but a {}x{} image with {tile}x{tile} tiles needs {}x{} texels", found.0, found.1, image.0, image.1, expected.0, expected.1)]
    RateImageSize { what: &'static str, image: (u32, u32), tile: u32, expected: (u32, u32), found: (u32, u32) },
    #[error("{what} has format {found:?}, expected {expected}")]
    RateFormat { what: &'static str, expected: &'static str, found: wgpu::TextureFormat },
    #[error("{what} was not created with TextureUsages::{missing}")]
    RateUsage { what: &'static str, missing: &'static str },
    #[error("motion is on (RateOptions::motion) but no velocity texture was given")]
    MissingVelocity,
    #[error("rate tile size {0} is not supported (expected 8 or 16)")]
    BadTileSize(u32),
    #[error("rate option `{name}` is {value}, but it must be a finite number >= 0")]
    BadRateOption { name: &'static str, value: f32 },
}

/// Where a uniform's value at fault is: "its value V" for a scalar,
/// "component K, V," for a vector, matrix or array.
fn value_at(ty: &str, index: usize, value: f64) -> String {
    match ty.parse::<mrsl_abi::ValueType>() {
        Ok(t) if t.components() == 1 => format!("its value {value}"),
        _ => format!("component {index}, {value},"),
    }
}
