//! Pinhole cameras from glTF perspective cameras (looking down the node's -Z, +Y up).

use glam::{Mat4, Vec3};

use crate::gpu_types::FrameParams;

#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    pub name: String,
    pub position: Vec3,
    pub forward: Vec3,
    pub up: Vec3,
    pub right: Vec3,
    /// Vertical field of view in radians.
    pub yfov: f32,
}

impl Camera {
    /// Orientation from a world transform; scale and shear are removed.
    pub fn from_transform(name: String, world: &Mat4, yfov: f32) -> Camera {
        let position = world.transform_point3(Vec3::ZERO);
        let forward = world.transform_vector3(-Vec3::Z).normalize();
        let up_hint = world.transform_vector3(Vec3::Y);
        let right = forward.cross(up_hint).normalize();
        let up = right.cross(forward);
        Camera {
            name,
            position,
            forward,
            up,
            right,
            yfov,
        }
    }

    pub fn look_at(name: &str, eye: Vec3, target: Vec3, up: Vec3, yfov: f32) -> Camera {
        let forward = (target - eye).normalize();
        let right = forward.cross(up).normalize();
        Camera {
            name: name.to_string(),
            position: eye,
            forward,
            up: right.cross(forward),
            right,
            yfov,
        }
    }

    /// Writes the camera rows of the frame parameters for an image of `width` x `height`.
    pub fn fill_params(&self, params: &mut FrameParams, width: u32, height: u32) {
        let tan_half = (0.5 * self.yfov).tan();
        params.cam_position = self.position.extend(tan_half).into();
        params.cam_right = self.right.extend(width as f32 / height as f32).into();
        params.cam_up = self.up.extend(0.0).into();
        params.cam_forward = self.forward.extend(0.0).into();
    }

    /// Twin of GLSL `camera_ray_dir` (glsl/camera.glsl): direction through image point (px, py),
    /// in pixels from the top-left corner.
    pub fn ray_dir(&self, px: f32, py: f32, width: u32, height: u32) -> Vec3 {
        let tan_half = (0.5 * self.yfov).tan();
        let aspect = width as f32 / height as f32;
        let x = (2.0 * px / width as f32 - 1.0) * tan_half * aspect;
        let y = (1.0 - 2.0 * py / height as f32) * tan_half;
        (self.forward + x * self.right + y * self.up).normalize()
    }
}

/// The camera of frame `frame` of a moving camera that starts at camera `start` and walks the
/// scene's `cameras` poses in order, back at the last and forward again at the first
/// (0, 1, ..., n-1, n-2, ..., 1, 0, 1, ...), so that any number of frames follows the path and
/// every frame after the first has moved. A scene with one camera stays on it.
pub fn camera_on_path(start: usize, frame: u32, cameras: usize) -> usize {
    if cameras < 2 {
        return 0;
    }
    let period = 2 * (cameras - 1);
    let k = (start + frame as usize) % period;
    if k < cameras {
        k
    } else {
        period - k
    }
}

#[cfg(test)]
mod tests {
    use super::camera_on_path;

    #[test]
    fn camera_path_goes_back_and_forth_and_moves_every_frame() {
        let path: Vec<usize> = (0..16).map(|f| camera_on_path(0, f, 8)).collect();
        assert_eq!(path, [0, 1, 2, 3, 4, 5, 6, 7, 6, 5, 4, 3, 2, 1, 0, 1]);
        assert!(path.windows(2).all(|w| w[0] != w[1]));
        assert_eq!(camera_on_path(6, 2, 8), 6);
        assert_eq!(camera_on_path(3, 0, 8), 3);
        assert_eq!((0..5).map(|f| camera_on_path(0, f, 1)).collect::<Vec<_>>(), [0; 5]);
        assert_eq!((0..4).map(|f| camera_on_path(1, f, 2)).collect::<Vec<_>>(), [1, 0, 1, 0]);
    }
}
