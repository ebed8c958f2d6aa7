// Resampling MIS weights of generalized RIS (docs/restir.md): the generalized balance heuristic
// m_i(y) = c_i p̂_{<-i}(y) / sum_j c_j p̂_{<-j}(y) and defensive pairwise MIS, over the inputs of
// one resampling. Twin: crates/shading-core/src/gris.rs (mis_weight); MIS_MODE selects the weight at compile time.
// Needs nothing but the loop budget and the shader interface's limits, so that an oracle kernel can include it alone.
#ifndef GRIS_GLSL
#define GRIS_GLSL

#include "shader_interface.glsl"
#include "interface/loop_budget.glsl"

#ifndef MIS_MODE
#define MIS_MODE MIS_GBH
#endif

// The confidence weights c_l of the current resampling's inputs (0: the canonical one), and
// p̂_{<-l}(y) for the sample y whose weight is wanted: [0] p̂(y) of the canonical domain, [l]
// p̂_l(T_l^{-1}(y)) |(T_l^{-1})'(y)| (0 where y cannot be shifted into domain l). Globals rather
// than parameters: glslang's optimiser mistypes arrays passed by value.
float confidences[MAX_INPUTS];
float targets_from[MAX_INPUTS];

// m_i(y) for input i's sample shifted to y, of n inputs.
float mis_weight(uint n, uint i) {
#if MIS_MODE == MIS_GBH
    float numerator = confidences[i] * targets_from[i];
    float total = numerator;
    if (i != 0u) total += confidences[0] * targets_from[0];
    for (uint l = 1u; l < n; ++l) {
        loop_tick();
        if (l != i) total += confidences[l] * targets_from[l];
    }
    return total > 0.0 ? numerator / total : 0.0;
#else
    // The canonical input against each neighbour in turn; it keeps at least 1 / n.
    if (n == 1u) return 1.0;
    float k = float(n - 1u);
    float canonical = confidences[0] * targets_from[0] / k;
    if (i != 0u) {
        float neighbour = confidences[i] * targets_from[i];
        return neighbour + canonical > 0.0 ? neighbour / (neighbour + canonical) / (k + 1.0) : 0.0;
    }
    float sum = 1.0;
    for (uint l = 1u; l < n; ++l) {
        loop_tick();
        float neighbour = confidences[l] * targets_from[l];
        sum += neighbour + canonical > 0.0 ? canonical / (neighbour + canonical) : 1.0;
    }
    return sum / (k + 1.0);
#endif
}

// Whether input i's MIS weight needs p̂_{<-l} of its shifted sample for l >= 1, l != i: every l
// under the generalized balance heuristic, only the canonical input's under pairwise MIS.
bool needs_targets_from(uint i) {
#if MIS_MODE == MIS_GBH
    return true;
#else
    return i == 0u;
#endif
}

#endif
