// Pinhole camera rays from the frame parameters. Twin: Camera::ray_dir in src/scene/camera.rs.
#ifndef CAMERA_GLSL
#define CAMERA_GLSL

// Direction through image point (px, py), in pixels from the top-left corner.
vec3 camera_ray_dir(float px, float py) {
    float x = (2.0 * px / float(width) - 1.0) * cam_position.w * cam_right.w;
    float y = (1.0 - 2.0 * py / float(height)) * cam_position.w;
    return normalize(cam_forward.xyz + x * cam_right.xyz + y * cam_up.xyz);
}

#endif
