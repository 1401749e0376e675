//! G-buffers in CPU memory: the channels a scene provides, by name. A leaf
//! module, so that the scenes, the rasteriser and the scene files can all
//! use it without importing each other.

/// Material id of background pixels.
pub const BACKGROUND: u32 = 255;

/// The data of one channel, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub enum ChannelData {
    /// `components` floats per pixel (1 to 4).
    Float {
        components: u32,
        data: Vec<f32>,
    },
    Uint(Vec<u32>),
}

/// A G-buffer in CPU memory.
#[derive(Debug, Clone, PartialEq)]
pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    pub channels: Vec<(String, ChannelData)>,
}
