//! Pinhole cameras from glTF perspective cameras (looking down the node's -Z, +Y up).

use glam::{Mat4, Vec3};

use restir_pt_interface::gpu_types::FrameParams;

/// The side of an image whose size neither the command line nor the camera sets.
pub const DEFAULT_IMAGE_SIDE: u32 = 256;

/// From the scene's centre towards the default camera: normalize(0, 1, 2).
pub const DEFAULT_VIEW_DIRECTION: Vec3 = Vec3::new(0.0, 0.447_213_6, 0.894_427_2);

/// The name of the camera the loader makes for a file without cameras, framing the scene.
pub const DEFAULT_CAMERA_NAME: &str = "default camera";
/// Vertical field of view of the default camera (45 degrees).
pub const DEFAULT_YFOV: f32 = std::f32::consts::FRAC_PI_4;

/// A pinhole camera (glTF perspective camera; the image plane at distance 1 along `forward`).
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// The glTF node's or camera's name.
    pub name: String,
    /// Position in scene coordinates; with `forward`, `up` and `right` (an orthonormal frame)
    /// it places the image plane.
    pub position: Vec3,
    /// Unit viewing direction (the glTF camera's -Z), scene coordinates.
    pub forward: Vec3,
    /// Unit up axis of the image (towards its top row), scene coordinates.
    pub up: Vec3,
    /// Unit right axis of the image, `forward × up`, scene coordinates.
    pub right: Vec3,
    /// Vertical field of view in radians.
    pub yfov: f32,
    /// The glTF camera's `aspectRatio` (width / height), if it gives one.
    pub aspect_ratio: Option<f32>,
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
            aspect_ratio: None,
        }
    }

    /// The camera of a scene that has none: it looks at the centre of the bounds `(lo, hi)`
    /// along -[`DEFAULT_VIEW_DIRECTION`] (from the +Z side, glTF's front, 26.6 degrees above the
    /// horizon so that flat ground is seen), from the distance at which their bounding sphere just
    /// fills a vertical field of view of [`DEFAULT_YFOV`] (r / sin(yfov / 2) from the centre).
    /// Its aspect ratio is 1: `--width` alone gives a square image, and a non-square image is
    /// fitted around the square view, so the sphere stays whole either way.
    pub fn framing(bounds: (Vec3, Vec3)) -> Camera {
        let (lo, hi) = bounds;
        let centre = 0.5 * (lo + hi);
        let radius = (0.5 * (hi - lo).length()).max(1e-6);
        let distance = radius / (0.5 * DEFAULT_YFOV).sin();
        let eye = centre + DEFAULT_VIEW_DIRECTION * distance;
        Camera {
            aspect_ratio: Some(1.0),
            ..Camera::look_at(DEFAULT_CAMERA_NAME, eye, centre, Vec3::Y, DEFAULT_YFOV)
        }
    }

    /// A camera at `eye` looking at `target`, with `up` as the image's vertical (not parallel
    /// to the view direction) and a vertical field of view of `yfov` radians.
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
            aspect_ratio: None,
        }
    }

    /// Whether the camera can render: a finite position, a finite orthonormal frame (within
    /// 1e-3) and a vertical field of view in (0, π) radians. Errors: one line naming the camera
    /// and the first problem, e.g. `look_at` with `up` parallel to the view direction.
    pub fn check_pose(&self) -> anyhow::Result<()> {
        let name = &self.name;
        if !self.position.is_finite() {
            anyhow::bail!("camera {name:?}: position {} is not finite", self.position);
        }
        let axes = [self.forward, self.up, self.right];
        let unit = axes.iter().all(|a| a.is_finite() && (a.length() - 1.0).abs() < 1e-3);
        let orthogonal =
            self.forward.dot(self.up).abs() < 1e-3 && self.forward.dot(self.right).abs() < 1e-3 && self.up.dot(self.right).abs() < 1e-3;
        if !(unit && orthogonal) {
            anyhow::bail!("camera {name:?}: forward, up and right must be finite orthonormal axes (is up parallel to the view direction?)");
        }
        if !(self.yfov > 0.0 && self.yfov < std::f32::consts::PI) {
            anyhow::bail!("camera {name:?}: yfov {} must be in (0, pi) radians", self.yfov);
        }
        Ok(())
    }

    /// tan(vertical field of view / 2) for an image of `width` x `height`. The camera's view is
    /// fitted into the image: an image wider than the camera's `aspect_ratio` keeps yfov and shows
    /// more at the sides; a narrower one widens the vertical field of view until the camera's
    /// horizontal field of view (yfov and `aspect_ratio`) fits, so nothing of the intended view
    /// is cropped. Without `aspect_ratio`, yfov is kept (glTF: the viewport's ratio is used).
    pub fn tan_half_fov(&self, width: u32, height: u32) -> f32 {
        let tan_half = (0.5 * self.yfov).tan();
        let image_aspect = width as f32 / height as f32;
        match self.aspect_ratio {
            Some(a) if image_aspect < a => tan_half * a / image_aspect,
            _ => tan_half,
        }
    }

    /// The image size for the requested sides: both given, they are used; one given, the other
    /// follows the camera's `aspect_ratio` (without one, it is [`DEFAULT_IMAGE_SIDE`]); none
    /// given, [`DEFAULT_IMAGE_SIDE`] squared.
    pub fn image_size(&self, width: Option<u32>, height: Option<u32>) -> (u32, u32) {
        let side = |x: f32| (x.round() as u32).max(1);
        match (width, height, self.aspect_ratio) {
            (Some(w), Some(h), _) => (w, h),
            (Some(w), None, Some(a)) => (w, side(w as f32 / a)),
            (None, Some(h), Some(a)) => (side(h as f32 * a), h),
            (w, h, _) => (w.unwrap_or(DEFAULT_IMAGE_SIDE), h.unwrap_or(DEFAULT_IMAGE_SIDE)),
        }
    }

    /// Writes the camera rows of the frame parameters for an image of `width` x `height`.
    pub fn fill_params(&self, params: &mut FrameParams, width: u32, height: u32) {
        let tan_half = self.tan_half_fov(width, height);
        params.cam_position = self.position.extend(tan_half).into();
        params.cam_right = self.right.extend(width as f32 / height as f32).into();
        params.cam_up = self.up.extend(0.0).into();
        params.cam_forward = self.forward.extend(0.0).into();
    }

    /// Twin of GLSL `camera_ray_dir` (glsl/scene/camera.glsl): direction through image point (px, py),
    /// in pixels from the top-left corner.
    pub fn ray_dir(&self, px: f32, py: f32, width: u32, height: u32) -> Vec3 {
        let tan_half = self.tan_half_fov(width, height);
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
    use super::{camera_on_path, Camera};
    use glam::Vec3;

    #[test]
    fn framing_camera_is_square_when_one_side_is_given() {
        let camera = Camera::framing((Vec3::splat(-1.0), Vec3::new(3.0, 1.0, 1.0)));
        assert_eq!(camera.image_size(Some(128), None), (128, 128));
        assert_eq!(camera.image_size(None, Some(64)), (64, 64));
        assert_eq!(camera.image_size(Some(200), Some(100)), (200, 100));
    }

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
