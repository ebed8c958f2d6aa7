//! The passes of a ReSTIR PT frame, each declared once as a row of [`PASSES`]: its kernel and
//! defines, the buffers it reads and writes, the timer its GPU time is reported under and how
//! it covers the image. The renderer derives from the rows each kernel's bindings (only the
//! buffers a row names are in its pipeline layout and bound), the timers' names and count, the
//! kernels' names and the dispatch sizes; tests/suite/restir_passes.rs checks each row's reads
//! and writes against what its kernel's SPIR-V loads and stores. Adding a pass is adding a row
//! (and a `PassKernel` variant to name it): frame_plan.rs decides when it runs.

use crate::shader_interface::RestirBinding::{self, *};

/// The kernels of a frame (glsl/restir_*.comp), in the order of [`PASSES`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PassKernel {
    /// Initial candidates: traces each pixel's candidate paths and resamples them into a
    /// reservoir (glsl/restir_initial.comp).
    Initial,
    /// Temporal reuse with shifts, for a moved camera.
    Temporal,
    /// Temporal reuse of an unmoved camera, compiled without shift code.
    TemporalUnmoved,
    /// One round of spatial reuse from neighbouring pixels (glsl/restir_spatial.comp).
    Spatial,
    /// Shades the final reservoirs and accumulates the frame (glsl/restir_shade.comp).
    Shade,
}

/// How a pass covers the image with workgroups of `IMAGE_LOCAL_SIZE`² invocations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dispatch {
    /// One invocation per pixel and reservoir (the reservoirs along z).
    PerReservoir,
    /// One invocation per pixel, which reads all of the pixel's reservoirs.
    PerPixel,
}

/// One pass of a ReSTIR PT frame, declared once.
#[derive(Debug, Clone, Copy)]
pub struct PassDeclaration {
    /// The row's name.
    pub kernel: PassKernel,
    /// The kernel's GLSL file under glsl/.
    pub source: &'static str,
    /// `#define`s beside the scene's and the settings' (a variant of a shared source).
    pub defines: &'static [(&'static str, &'static str)],
    /// What tells this kernel apart from another of the same source in reports.
    pub variant: Option<&'static str>,
    /// The timer its GPU time is reported under ([`PASS_NAMES`]); passes may share one.
    pub timer: &'static str,
    /// The ReSTIR buffers it reads (besides the scene's bindings, which every pass reads).
    pub reads: &'static [RestirBinding],
    /// The ReSTIR buffers it writes.
    pub writes: &'static [RestirBinding],
    /// How it covers the image.
    pub dispatch: Dispatch,
}

/// Reads and writes of the reuse passes, which resample the slot before them with the
/// surfaces of this frame and the last.
const REUSE_READS: &[RestirBinding] = &[
    ReuseParams,
    Surfaces0,
    Surfaces1,
    ReservoirHeads0,
    ReservoirTails0,
    ReservoirHeads1,
    ReservoirTails1,
    ReservoirHeads2,
    ReservoirTails2,
    RestirStats,
];
const REUSE_WRITES: &[RestirBinding] = &[
    ReservoirHeads0,
    ReservoirTails0,
    ReservoirHeads1,
    ReservoirTails1,
    ReservoirHeads2,
    ReservoirTails2,
    RestirStats,
    Expectation,
];

/// The passes, one row each, in `PassKernel` order.
pub const PASSES: [PassDeclaration; 5] = [
    PassDeclaration {
        kernel: PassKernel::Initial,
        source: "restir_initial.comp",
        defines: &[],
        variant: None,
        timer: "initial",
        reads: &[ReuseParams, Direct, RestirStats],
        writes: &[
            Surfaces0,
            Surfaces1,
            ReservoirHeads0,
            ReservoirTails0,
            ReservoirHeads1,
            ReservoirTails1,
            ReservoirHeads2,
            ReservoirTails2,
            Direct,
            RestirStats,
            Expectation,
        ],
        dispatch: Dispatch::PerReservoir,
    },
    PassDeclaration {
        kernel: PassKernel::Temporal,
        source: "restir_temporal.comp",
        defines: &[],
        variant: None,
        timer: "temporal",
        reads: REUSE_READS,
        writes: REUSE_WRITES,
        dispatch: Dispatch::PerReservoir,
    },
    PassDeclaration {
        kernel: PassKernel::TemporalUnmoved,
        source: "restir_temporal.comp",
        defines: &[("CANONICAL_DOMAIN_ONLY", "1")],
        variant: Some("(unmoved camera)"),
        timer: "temporal",
        reads: REUSE_READS,
        writes: REUSE_WRITES,
        dispatch: Dispatch::PerReservoir,
    },
    PassDeclaration {
        kernel: PassKernel::Spatial,
        source: "restir_spatial.comp",
        defines: &[],
        variant: None,
        timer: "spatial",
        reads: REUSE_READS,
        writes: REUSE_WRITES,
        dispatch: Dispatch::PerReservoir,
    },
    PassDeclaration {
        kernel: PassKernel::Shade,
        source: "restir_shade.comp",
        defines: &[],
        variant: None,
        timer: "shade",
        reads: &[ReuseParams, Direct, Accum, AccumSq, RestirStats, Expectation],
        writes: &[Accum, AccumSq, RestirStats],
        dispatch: Dispatch::PerPixel,
    },
];

const fn same_name(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// The distinct timers of `passes` in order of first use (`N` of them; the rest "").
const fn timer_names<const N: usize>(passes: &[PassDeclaration]) -> [&'static str; N] {
    let mut names = [""; N];
    let (mut count, mut i) = (0, 0);
    while i < passes.len() {
        let mut j = 0;
        while j < count && !same_name(names[j], passes[i].timer) {
            j += 1;
        }
        if j == count {
            names[count] = passes[i].timer;
            count += 1;
        }
        i += 1;
    }
    names
}

const fn timer_count(passes: &[PassDeclaration]) -> usize {
    let names: [&str; 64] = timer_names(passes);
    let mut n = 0;
    while n < names.len() && !names[n].is_empty() {
        n += 1;
    }
    n
}

/// How many timers a frame has (each pass's GPU time is reported under its row's timer).
pub const PASS_COUNT: usize = timer_count(&PASSES);

/// The timers of a frame, the names its GPU times are reported under.
pub const PASS_NAMES: [&str; PASS_COUNT] = timer_names(&PASSES);

/// GPU milliseconds of each timer of one frame, in the order of `PASS_NAMES`.
pub type PassTimes = [f64; PASS_COUNT];

const fn kernels() -> [PassKernel; PASSES.len()] {
    let mut all = [PassKernel::Initial; PASSES.len()];
    let mut i = 0;
    while i < PASSES.len() {
        // A row's place is its kernel's discriminant: `declaration` indexes by it.
        assert!(PASSES[i].kernel as usize == i, "PASSES is out of PassKernel order");
        all[i] = PASSES[i].kernel;
        i += 1;
    }
    all
}

impl PassKernel {
    /// Every kernel, in the order a frame runs them.
    pub const ALL: [PassKernel; PASSES.len()] = kernels();

    /// The kernel's row of [`PASSES`].
    pub fn declaration(self) -> &'static PassDeclaration {
        &PASSES[self as usize]
    }

    /// The GLSL file and extra `#define`s of the kernel.
    pub fn source(self) -> (&'static str, &'static [(&'static str, &'static str)]) {
        let d = self.declaration();
        (d.source, d.defines)
    }

    /// The timer slot of the pass (an index into `PASS_NAMES`).
    pub fn timer_slot(self) -> usize {
        let timer = self.declaration().timer;
        PASS_NAMES.iter().position(|&n| n == timer).expect("every row's timer is named")
    }
}

impl PassDeclaration {
    /// The ReSTIR buffers of its pipeline layout: what it reads or writes, in binding order.
    pub fn bindings(&self) -> Vec<RestirBinding> {
        let mut all: Vec<RestirBinding> = self.reads.iter().chain(self.writes).copied().collect();
        all.sort_by_key(|b| b.binding());
        all.dedup();
        all
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timers_derive_from_the_rows() {
        assert_eq!(PASS_NAMES, ["initial", "temporal", "spatial", "shade"]);
        assert_eq!(PassKernel::TemporalUnmoved.timer_slot(), PassKernel::Temporal.timer_slot());
        assert_eq!(PassKernel::ALL.len(), PASSES.len());
    }
}
