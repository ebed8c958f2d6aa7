// Profile counters of a kernel compiled with TRAVERSAL_COUNTERS=1 (`restir-pt bench --counters`):
// per invocation ("lane") how many traversals (one ray or one pair of rays), BVH node visits,
// triangle tests and path steps it ran, and per subgroup (one llvmpipe SIMD group of lanes in
// lockstep) how many iterations the node, triangle and path loops took, counted once by the
// elected lane. A lane idles in an iteration its subgroup runs without it, so lane counts over
// (subgroup iterations * subgroup size) are the share of SIMD lanes doing work. The host reads
// them as TraversalCounters (src/render/counters.rs).
#ifndef COUNTERS_GLSL
#define COUNTERS_GLSL

#include "shader_interface.glsl"

#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#ifndef TRAVERSAL_COUNTERS
#define TRAVERSAL_COUNTERS 0
#endif

#if TRAVERSAL_COUNTERS
uint profile_counts[COUNTER_COUNT] = uint[COUNTER_COUNT](0u, 0u, 0u, 0u, 0u, 0u, 0u);
#endif

// A kernel compiled with COUNT_TRAVERSALS=1 counts the traversals each lane starts apart from
// the profile counters, always on: the ReSTIR PT reuse kernels, whose every traversal belongs to
// a shift, report them per frame (rays per shift; RestirStats::reuse_traversals).
#ifndef COUNT_TRAVERSALS
#define COUNT_TRAVERSALS 0
#endif
#if COUNT_TRAVERSALS
uint traversals_started = 0u;
#endif

// Counts one event of this lane.
void count_lane(uint counter) {
#if TRAVERSAL_COUNTERS
    profile_counts[counter] += 1u;
#endif
#if COUNT_TRAVERSALS
    if (counter == COUNTER_TRAVERSALS) traversals_started += 1u;
#endif
}

// Counts one iteration of the enclosing loop for the subgroup, once, whichever lanes are active.
void count_subgroup(uint counter) {
#if TRAVERSAL_COUNTERS
    if (subgroupElect()) profile_counts[counter] += 1u;
#endif
}

// The subgroup's total of a counter; call from uniform control flow.
uint subgroup_count(uint counter) {
#if TRAVERSAL_COUNTERS
    return subgroupAdd(profile_counts[counter]);
#else
    return 0u;
#endif
}

#endif
