#version 460
// ReSTIR PT pass 4: the pixel's estimate, the mean over its reservoirs of the emission seen
// directly plus the last resampling's expectation of f(Y) W_Y (the same mean as f(Y) W_Y,
// without the choice's noise), added to the accumulation (the average of a static camera's
// frames). Non-finite estimates are counted, not clamped.
#extension GL_GOOGLE_include_directive : require

#include "shader_interface.glsl"

layout(local_size_x = IMAGE_LOCAL_SIZE, local_size_y = IMAGE_LOCAL_SIZE) in;

#include "interface/restir_bindings.glsl"

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    bool inside = p.x < width && p.y < height;
    uint pixel = p.y * width + p.x;
    if (inside) {
        vec3 estimate = vec3(0.0);
        for (uint layer = 0u; layer < reservoirs; ++layer) {
            uint index = reservoir_index(pixel, layer);
            estimate += direct[index].rgb + expectation[index].rgb;
        }
        estimate /= float(reservoirs);
        if (any(isnan(estimate)) || any(isinf(estimate))) local_nonfinite_pixels += 1u;
        accum[pixel] += vec4(estimate, 1.0);
        accum_sq[pixel].rgb += estimate * estimate;
    }
    report_pass_stats();
}
