//! Host side of glsl/interface/counters.glsl: the profile counters a path-tracer kernel compiled with
//! `TRAVERSAL_COUNTERS=1` sums over a dispatch (`restir-pt bench --counters`).

use serde::Serialize;

pub use crate::shader_interface::COUNTER_COUNT;

/// Totals over one or more dispatches. "Lane" counts are per invocation; "iterations" are per
/// subgroup (llvmpipe: one SIMD group of `subgroup_size` lanes in lockstep).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct TraversalCounters {
    /// Calls of a traversal (`trace_pair`: one per path step, for up to two rays).
    pub traversals: u64,
    /// BVH nodes whose box a lane tested.
    pub node_visits: u64,
    /// Ray-triangle tests a lane ran.
    pub triangle_tests: u64,
    /// Path steps (bounces) a lane ran.
    pub path_steps: u64,
    /// Iterations of the node loop, once per subgroup.
    pub node_iterations: u64,
    /// Iterations of the triangle loop, once per subgroup.
    pub triangle_iterations: u64,
    /// Iterations of the path-step loop, once per subgroup.
    pub step_iterations: u64,
    /// Lanes per subgroup on the device that counted.
    pub subgroup_size: u32,
}

impl TraversalCounters {
    /// From the (low, high) word pairs the kernel accumulates.
    pub fn from_words(words: &[u32], subgroup_size: u32) -> Self {
        let c = |i: usize| words[2 * i] as u64 | (words[2 * i + 1] as u64) << 32;
        Self {
            traversals: c(0),
            node_visits: c(1),
            triangle_tests: c(2),
            path_steps: c(3),
            node_iterations: c(4),
            triangle_iterations: c(5),
            step_iterations: c(6),
            subgroup_size,
        }
    }

    /// Adds `o`'s counts to these (a render's dispatches summed); the subgroup size becomes `o`'s.
    pub fn add(&mut self, o: &Self) {
        self.traversals += o.traversals;
        self.node_visits += o.node_visits;
        self.triangle_tests += o.triangle_tests;
        self.path_steps += o.path_steps;
        self.node_iterations += o.node_iterations;
        self.triangle_iterations += o.triangle_iterations;
        self.step_iterations += o.step_iterations;
        self.subgroup_size = o.subgroup_size;
    }

    /// Share of SIMD lanes busy in a loop's iterations: lane events / (iterations * lanes).
    pub fn lane_use(&self, lane_events: u64, iterations: u64) -> f64 {
        lane_events as f64 / (iterations as f64 * self.subgroup_size.max(1) as f64)
    }

    /// Prints the per-path and per-ray figures of `paths` paths to stderr.
    pub fn print(&self, paths: u64) {
        let per = |a: u64, b: u64| a as f64 / b.max(1) as f64;
        eprintln!(
            "per path: {:.2} steps, {:.2} traversals; per traversal: {:.2} node visits, {:.2} triangle tests",
            per(self.path_steps, paths),
            per(self.traversals, paths),
            per(self.node_visits, self.traversals),
            per(self.triangle_tests, self.traversals)
        );
        eprintln!(
            "SIMD lanes busy ({} lanes): path loop {:.0}%, node loop {:.0}%, triangle loop {:.0}%; subgroup iterations per path: {:.2} steps, {:.1} node, {:.1} triangle",
            self.subgroup_size,
            100.0 * self.lane_use(self.path_steps, self.step_iterations),
            100.0 * self.lane_use(self.node_visits, self.node_iterations),
            100.0 * self.lane_use(self.triangle_tests, self.triangle_iterations),
            per(self.step_iterations * self.subgroup_size as u64, paths),
            per(self.node_iterations * self.subgroup_size as u64, paths),
            per(self.triangle_iterations * self.subgroup_size as u64, paths)
        );
    }
}
