// Pinhole camera rays from the frame parameters. Twin: Camera::ray_dir in crates/scene/src/camera.rs.
#ifndef CAMERA_GLSL
#define CAMERA_GLSL

// A camera pose laid out like FrameParams' camera: position.w = tan(yfov / 2), right.w = aspect.
struct CameraPose {
    vec4 position;
    vec4 right;
    vec4 up;
    vec4 forward;
};

CameraPose frame_camera() {
    return CameraPose(cam_position, cam_right, cam_up, cam_forward);
}

// Direction from `pose` through image point (px, py), in pixels from the top-left corner.
vec3 pose_ray_dir(CameraPose pose, float px, float py) {
    float x = (2.0 * px / float(width) - 1.0) * pose.position.w * pose.right.w;
    float y = (1.0 - 2.0 * py / float(height)) * pose.position.w;
    return normalize(pose.forward.xyz + x * pose.right.xyz + y * pose.up.xyz);
}

// Direction from this frame's camera through image point (px, py).
vec3 camera_ray_dir(float px, float py) {
    return pose_ray_dir(frame_camera(), px, py);
}

#endif
