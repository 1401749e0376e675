//! Camera paths: where the camera is at each frame of an animation, for
//! `mrslc render --frames` and the controller run of `mrslc bench`. The
//! scenes are static, so a path is all that moves between frames, and the
//! rasteriser's `velocity` channel ([`crate::raster`]) is the difference of
//! two consecutive cameras' projections.
//!
//! A path spans the whole sequence whatever its length: frame `i` of `n` is
//! at the parameter t = i / (n − 1), so fewer frames move farther per frame
//! (and have larger motion vectors).

use crate::camera::Camera;

/// One keyframe of a [`CameraPath::Keyframes`] path: where the eye is and
/// what it looks at. Up and field of view come from the scene's camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Keyframe {
    pub eye: [f32; 3],
    pub target: [f32; 3],
}

/// How the camera moves over a sequence of frames.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraPath {
    /// From the scene's camera, the eye walks half-way towards its target
    /// while the view swings 25 degrees left and right once (Sponza's
    /// default; the path `mrslc bench` steers its controller along).
    Walk,
    /// Keyframes passed through in order, equally spaced in time, joined by
    /// a uniform Catmull-Rom spline (eye and target each), so that the
    /// motion has no kinks at the keyframes. At least two.
    Keyframes(Vec<Keyframe>),
}

impl CameraPath {
    /// The camera of frame `i` of `n` (`i` < `n`), starting from `base`
    /// (the scene's camera, whose up and field of view every frame keeps).
    /// One frame (`n` = 1) is the path's start.
    pub fn camera(&self, base: &Camera, i: usize, n: usize) -> Camera {
        let t = if n > 1 { i.min(n - 1) as f32 / (n - 1) as f32 } else { 0.0 };
        self.at(base, t)
    }

    /// The camera at the path's parameter `t` in [0, 1].
    pub fn at(&self, base: &Camera, t: f32) -> Camera {
        let t = t.clamp(0.0, 1.0);
        match self {
            CameraPath::Walk => {
                let d: [f32; 3] = std::array::from_fn(|k| base.target[k] - base.eye[k]);
                let eye: [f32; 3] = std::array::from_fn(|k| base.eye[k] + 0.5 * t * d[k]);
                let yaw = 25f32.to_radians() * (std::f32::consts::TAU * t).sin();
                let (s, c) = yaw.sin_cos();
                let turned = [c * d[0] + s * d[2], d[1], -s * d[0] + c * d[2]];
                Camera { eye, target: std::array::from_fn(|k| eye[k] + turned[k]), ..*base }
            }
            CameraPath::Keyframes(keys) => match keys.as_slice() {
                [] => *base,
                [only] => Camera { eye: only.eye, target: only.target, ..*base },
                _ => {
                    let segments = keys.len() - 1;
                    let x = t * segments as f32;
                    let s = (x.floor() as usize).min(segments - 1);
                    let u = x - s as f32;
                    // The neighbours of segment s, the end keyframes repeated.
                    let k = |j: isize| keys[j.clamp(0, segments as isize) as usize];
                    let (a, b, c, d) = (k(s as isize - 1), k(s as isize), k(s as isize + 1), k(s as isize + 2));
                    Camera {
                        eye: catmull_rom(a.eye, b.eye, c.eye, d.eye, u),
                        target: catmull_rom(a.target, b.target, c.target, d.target, u),
                        ..*base
                    }
                }
            },
        }
    }

    /// A name for messages and the frames' statistics.
    pub fn describe(&self) -> String {
        match self {
            CameraPath::Walk => "walk".into(),
            CameraPath::Keyframes(keys) => format!("{} keyframes", keys.len()),
        }
    }
}

/// The uniform Catmull-Rom spline through `p1` (u = 0) and `p2` (u = 1),
/// with tangents from `p0` and `p3`.
fn catmull_rom(p0: [f32; 3], p1: [f32; 3], p2: [f32; 3], p3: [f32; 3], u: f32) -> [f32; 3] {
    let (u2, u3) = (u * u, u * u * u);
    std::array::from_fn(|k| {
        0.5 * (2.0 * p1[k]
            + (p2[k] - p0[k]) * u
            + (2.0 * p0[k] - 5.0 * p1[k] + 4.0 * p2[k] - p3[k]) * u2
            + (3.0 * p1[k] - p0[k] - 3.0 * p2[k] + p3[k]) * u3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    #[test]
    fn the_walk_starts_at_the_scene_camera_and_walks_forward() {
        let start = Camera::look_at([0.0, 1.0, 0.0], [10.0, 1.0, 0.0], 60.0);
        let first = CameraPath::Walk.camera(&start, 0, 10);
        assert_eq!(first.eye, start.eye);
        assert!((first.target[0] - 10.0).abs() < 1e-5 && first.target[2].abs() < 1e-5);
        let last = CameraPath::Walk.camera(&start, 9, 10);
        assert!((last.eye[0] - 5.0).abs() < 1e-5);
        // Mid-way the view has turned.
        let mid = CameraPath::Walk.camera(&start, 2, 10);
        assert!(mid.target[2].abs() > 1.0);
    }

    #[test]
    fn keyframes_are_passed_through_smoothly_and_keep_up_and_fov() {
        let base = Camera { up: [0.0, 0.0, 1.0], ..Camera::look_at([9.0; 3], [0.0; 3], 33.0) };
        let keys = vec![
            Keyframe { eye: [0.0, 0.0, 0.0], target: [1.0, 0.0, 0.0] },
            Keyframe { eye: [2.0, 0.0, 0.0], target: [3.0, 1.0, 0.0] },
            Keyframe { eye: [4.0, 2.0, 0.0], target: [5.0, 2.0, 0.0] },
        ];
        let path = CameraPath::Keyframes(keys.clone());
        // 5 frames over 2 segments: frames 0, 2 and 4 are the keyframes.
        for (frame, key) in [(0, keys[0]), (2, keys[1]), (4, keys[2])] {
            let c = path.camera(&base, frame, 5);
            assert!(close(c.eye, key.eye) && close(c.target, key.target), "frame {frame}: {c:?}");
            assert_eq!((c.up, c.fov_y_degrees), (base.up, base.fov_y_degrees));
        }
        // In between, on the curve: the first segment's middle lies between its keyframes.
        let mid = path.camera(&base, 1, 5);
        assert!(mid.eye[0] > 0.5 && mid.eye[0] < 1.5, "{mid:?}");
        // No kink: the velocity just before and after keyframe 1 agrees.
        let e = 1e-3;
        let before: Vec<f32> = (0..3).map(|k| path.at(&base, 0.5).eye[k] - path.at(&base, 0.5 - e).eye[k]).collect();
        let after: Vec<f32> = (0..3).map(|k| path.at(&base, 0.5 + e).eye[k] - path.at(&base, 0.5).eye[k]).collect();
        for k in 0..3 {
            assert!((before[k] - after[k]).abs() < 1e-4, "axis {k}: {before:?} vs {after:?}");
        }
    }

    #[test]
    fn one_frame_is_the_start() {
        let base = Camera::look_at([0.0, 1.0, 0.0], [10.0, 1.0, 0.0], 60.0);
        assert_eq!(CameraPath::Walk.camera(&base, 0, 1), base);
    }
}
