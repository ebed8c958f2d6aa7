#version 460
// Oracle kernel: the reuse loop (shading/resample_inputs.glsl, MIS_MODE as compiled) on the analytic
// domains of the GRIS toy (tests/suite/gris.rs), one resampling per item. Twin: resample_inputs
// in crates/shading/src/resample_inputs.rs on the same bridge (ToyDomains in tests/suite/reuse_oracle.rs).
//
// Domain 0 is the canonical (target) domain, p̂_0(y) = 1 + sin 3y on [0, 1]. Domain 1 shifts
// into it by T(x) = x^2 on [0, 0.9], p̂_1(x) = 1 + x; domain 2 by T(x) = x + 0.3 on [0, 0.7],
// p̂_2(x) = 2 - x. A sample is a path record whose rc_pos.x is its position, info its domain and
// seed the input it came from; its contribution is the grey p̂ of its domain.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "shading_core/reservoir.glsl"
#include "shading/shift/result.glsl"

struct Domain {
    uint index;
};

// Per item: the number of inputs and the seed of the choice.
layout(std430, set = 0, binding = 0) readonly buffer Cases { uvec2 cases[]; };
layout(std430, set = 0, binding = 1) readonly buffer Inputs { ReuseToyInput toy_inputs[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Outputs { ReuseOracleOutput outputs[]; };
layout(push_constant) uniform Push { uint count; };

uint local_shifts_failed = 0u;
uint local_nonfinite_weights = 0u;
uint item_base = 0u;

float toy_target(uint domain, float x) {
    if (domain == 1u) return 1.0 + x;
    if (domain == 2u) return 2.0 - x;
    return 1.0 + sin(3.0 * x);
}

PathRecord toy_record(uint input_index, uint domain, float x) {
    PathRecord r = reservoir_empty().record;
    r.seed = input_index;
    r.info = domain;
    r.rc_pos = vec3(x, 0.0, 0.0);
    r.contribution = vec3(toy_target(domain, x));
    return r;
}

Reservoir input_reservoir(uint i) {
    ReuseToyInput t = toy_inputs[item_base + i];
    return Reservoir(toy_record(i, t.domain, t.x), t.weight, t.confidence);
}

Domain input_domain(uint i) {
    return Domain(toy_inputs[item_base + i].domain);
}

bool same_domain(Domain a, Domain b) {
    return a.index == b.index;
}

// T_d into domain 0 or T_d^{-1} out of it; the toy has no other shifts.
ShiftResult shift_path(PathRecord x, Domain to) {
    uint from = x.info;
    float p = x.rc_pos.x;
    bool valid = false;
    float y = 0.0;
    float jacobian = 0.0;
    if (to.index == 0u && from == 1u && p <= 0.9) {
        valid = true;
        y = p * p;
        jacobian = 2.0 * p;
    } else if (to.index == 0u && from == 2u && p <= 0.7) {
        valid = true;
        y = p + 0.3;
        jacobian = 1.0;
    } else if (from == 0u && to.index == 1u && p > 0.0 && p <= 0.81) {
        valid = true;
        y = sqrt(p);
        jacobian = 0.5 / y;
    } else if (from == 0u && to.index == 2u && p >= 0.3) {
        valid = true;
        y = p - 0.3;
        jacobian = 1.0;
    }
    if (!valid) return shift_failed();
    ShiftResult s = shift_failed();
    s.valid = true;
    s.record = toy_record(x.seed, to.index, y);
    s.jacobian = jacobian;
    s.contribution = s.record.contribution;
    return s;
}

#include "shading/resample_inputs.glsl"

void main() {
    uint item = gl_GlobalInvocationID.x;
    if (item >= count) return;
    item_base = MAX_INPUTS * item;
    uint n = cases[item].x;
    for (uint l = 0u; l < n; ++l) confidences[l] = toy_inputs[item_base + l].confidence;
    vec3 expected;
    Reservoir r = resample_inputs(n, cases[item].y, expected);
    bool chose = r.W > 0.0;
    outputs[item] = ReuseOracleOutput(expected, r.W, r.M, r.record.rc_pos.x, chose ? int(r.record.seed) : -1,
                                      r.record.info, local_shifts_failed, local_nonfinite_weights, uvec2(0u));
}
