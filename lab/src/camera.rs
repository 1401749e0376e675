//! A pinhole camera: the view the rasteriser draws, the shadow camera of the
//! light rig and each frame of a camera path. A module of its own, so that
//! the rig and the camera paths do not depend on the rasteriser.

use crate::mesh::Bounds;
use crate::vector::normalize;
use glam::{Mat4, Vec3, Vec4};

/// Why a camera cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("bad camera: {0}")]
pub struct CameraError(pub String);

/// A camera's unit view direction, right axis and up axis.
pub type Basis = ([f32; 3], [f32; 3], [f32; 3]);

/// A pinhole camera. Right-handed world, `up` is a hint (it need not be
/// orthogonal to the view direction); image rows run top to bottom, and
/// pixel `(x, y)` sees along the ray through its centre `(x + 0.5, y + 0.5)`,
/// exactly as the CPU demo scene's camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f32,
}

impl Camera {
    /// A camera with the world's +y as up.
    pub fn look_at(eye: [f32; 3], target: [f32; 3], fov_y_degrees: f32) -> Camera {
        Camera { eye, target, up: [0.0, 1.0, 0.0], fov_y_degrees }
    }

    /// A camera that sees all of `bounds` from the front (+z), a little to
    /// the right and above, for an image of the given aspect ratio (width /
    /// height): the bounding sphere fits in both fields of view.
    pub fn frame(bounds: &Bounds, fov_y_degrees: f32, aspect: f32) -> Camera {
        let center = Vec3::from(bounds.center());
        let radius = (0.5 * bounds.diagonal()).max(1e-6);
        let half_y = (fov_y_degrees.to_radians() / 2.0).clamp(1e-3, 1.55);
        let half_x = (half_y.tan() * aspect.max(1e-3)).atan();
        let distance = radius / half_y.min(half_x).sin();
        let eye = center + distance * normalize(Vec3::new(0.35, 0.3, 1.0));
        Camera::look_at(eye.to_array(), center.to_array(), fov_y_degrees)
    }

    /// The unit view direction and the camera's unit right and up axes.
    pub fn basis(&self) -> Result<Basis, CameraError> {
        let (forward, right, up) = self.axes()?;
        Ok((forward.to_array(), right.to_array(), up.to_array()))
    }

    /// [`Camera::basis`] as vectors.
    pub(crate) fn axes(&self) -> Result<(Vec3, Vec3, Vec3), CameraError> {
        let forward = normalize(Vec3::from(self.target) - Vec3::from(self.eye));
        if forward.dot(forward) == 0.0 {
            return Err(CameraError("the eye and the target are the same point".into()));
        }
        let right = normalize(forward.cross(Vec3::from(self.up)));
        if right.dot(right) == 0.0 || !right.is_finite() {
            return Err(CameraError("`up` is parallel to the view direction".into()));
        }
        if !(self.fov_y_degrees > 0.0 && self.fov_y_degrees < 180.0) {
            return Err(CameraError(format!(
                "the field of view must be between 0 and 180 degrees, not {}",
                self.fov_y_degrees
            )));
        }
        Ok((forward, right, right.cross(forward)))
    }

    /// The unit direction of the ray through the centre of pixel `(x, y)`.
    pub fn ray(&self, x: u32, y: u32, size: (u32, u32)) -> Result<[f32; 3], CameraError> {
        let (forward, right, up) = self.axes()?;
        let tan_half = (self.fov_y_degrees.to_radians() / 2.0).tan();
        let aspect = size.0 as f32 / size.1 as f32;
        let sx = (2.0 * (x as f32 + 0.5) / size.0 as f32 - 1.0) * tan_half * aspect;
        let sy = (1.0 - 2.0 * (y as f32 + 0.5) / size.1 as f32) * tan_half;
        Ok(normalize(forward + sx * right + sy * up).to_array())
    }

    /// The view-projection matrix: reversed depth with an infinite far
    /// plane, clip = (x f / aspect, y f, near, −z_view) with f = 1 /
    /// tan(fov / 2), so `clip.xy / clip.w` is the pixel convention of
    /// [`Camera::ray`] and `clip.w` the depth along the view direction.
    pub fn view_projection(&self, aspect: f32, near: f32) -> Result<Mat4, CameraError> {
        let (forward, right, up) = self.axes()?;
        let f = 1.0 / (self.fov_y_degrees.to_radians() / 2.0).tan();
        let eye = Vec3::from(self.eye);
        let row = |axis: Vec3, scale: f32| (axis * scale).extend(-axis.dot(eye) * scale);
        Ok(Mat4::from_cols(row(right, f / aspect), row(up, f), Vec4::new(0.0, 0.0, 0.0, near), row(forward, 1.0))
            .transpose())
    }
}
