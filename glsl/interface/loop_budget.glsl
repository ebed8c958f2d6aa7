// llvmpipe (lavapipe) gives every loop of a shader invocation a budget of 65535 iterations in
// total, over all the times that loop runs, and then silently leaves it: an over-long dispatch
// renders a wrong image with no error. Kernels therefore
// - count the loop iterations of each subgroup (one llvmpipe SIMD group), an estimate of the cost
//   the host uses to size dispatches, and
// - note every loop that ended while its condition still held (the exact sign of a cut), which
//   the host turns into an error.
#ifndef LOOP_BUDGET_GLSL
#define LOOP_BUDGET_GLSL

#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_vote : require

uint loop_iterations = 0u;
bool loop_budget_cut = false;

// Counts one iteration of the enclosing loop for the subgroup, once, whichever lanes are active.
void loop_tick() {
    if (subgroupElect()) loop_iterations += 1u;
}

// Call after a loop with the loop's own condition: true there means the driver cut the loop.
void note_loop_exit(bool condition_still_true) {
    if (condition_still_true) loop_budget_cut = true;
}

// Total iterations of this subgroup so far; call from uniform control flow.
uint subgroup_loop_iterations() {
    return subgroupAdd(loop_iterations);
}

// True if any lane of the subgroup saw a loop cut; call from uniform control flow.
bool subgroup_loop_budget_cut() {
    return subgroupAny(loop_budget_cut);
}

#endif
