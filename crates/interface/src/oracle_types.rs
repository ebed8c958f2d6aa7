//! Records of the oracle kernels (glsl/oracle/), which run GLSL functions on inputs a test
//! chose and write what they returned, for tests/suite/ to compare with the Rust twins.
//! Declared here like every other record, so the kernels and the tests read one layout.

use bytemuck::{Pod, Zeroable};

use crate::gpu_record;

gpu_record! {
    struct;
    /// One input of a resampling on the GRIS toy's analytic domains (glsl/oracle/reuse_oracle.comp).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ReuseToyInput {
        /// The sample's position in its domain, in [0, 1].
        pub x: f32,
        /// W_X: 1 / pdf(x); 0 for an empty reservoir.
        pub weight: f32,
        /// The confidence weight c.
        pub confidence: f32,
        /// The domain: 0 (canonical), 1 or 2.
        pub domain: u32,
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/reuse_oracle.comp writes per resampling: the reservoir that
    /// `resample_inputs` returned and its counters.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct ReuseOracleOutput {
        /// The expectation of f(Y) W_Y over the choice, linear RGB.
        pub expected: [f32; 3],
        /// W of the result.
        pub weight: f32,
        /// M of the result.
        pub confidence: f32,
        /// The chosen sample's position in the canonical domain.
        pub chosen_x: f32,
        /// The input the chosen sample came from; -1: none.
        pub chosen_input: i32,
        /// The domain the chosen sample came from.
        pub chosen_domain: u32,
        /// Shifts that failed.
        pub shifts_failed: u32,
        /// Resampling weights that were not finite.
        pub nonfinite_weights: u32,
        /// Zero; pads the record to 48 bytes.
        pub pad: [u32; 2],
    }
}

gpu_record! {
    struct;
    /// What glsl/oracle/rng_oracle.comp writes per key k (its input, one `uvec4` per item): the
    /// random numbers of crates/shading-core/src/rng.rs, compared bit for bit.
    #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
    pub struct RngOracleOutput {
        /// `pcg4d(k)`, the hash of all four words.
        pub pcg4d: [u32; 4],
        /// `path_seed(k.x, k.y, k.z)`: k read as (pixel, sample index, seed).
        pub path_seed: u32,
        /// Zero; this and the next two align `uniforms` to 16 bytes.
        pub pad0: u32,
        /// Zero.
        pub pad1: u32,
        /// Zero.
        pub pad2: u32,
        /// `rng_uniform4(k.x, k.y, k.z)`: k read as (seed, vertex, stream); four uniforms in [0, 1).
        pub uniforms: [f32; 4],
    }
}
