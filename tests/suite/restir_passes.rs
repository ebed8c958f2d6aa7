//! The ReSTIR PT pass table (src/render/restir_passes.rs) against the kernels: the ReSTIR
//! buffers each row says its pass reads and writes are exactly those its kernel's SPIR-V loads
//! from and stores to, for the default shift and MIS, and every other variant stays within them
//! (so the pipeline layout built from the row holds everything the kernel uses).

use std::collections::BTreeSet;

use restir_pt::render::{PassKernel, ReuseMis, ShiftKind, PASSES};
use restir_pt::shader_interface::RestirBinding;
use restir_pt::vk::{compile_kernel, reflect_bindings};

/// (blocks read, blocks written) among the ReSTIR bindings of `pass`'s kernel with `defines`.
fn accessed(pass: PassKernel, defines: &[(&str, &str)]) -> (BTreeSet<String>, BTreeSet<String>) {
    let (file, extra) = pass.source();
    let all: Vec<(&str, &str)> = extra.iter().chain(defines).copied().collect();
    let spirv = compile_kernel(file, &all).expect("kernel compiles");
    let restir = |b: &&restir_pt::vk::ReflectedBinding| RestirBinding::ALL.iter().any(|r| r.block() == b.block && r.binding() == b.binding);
    let found = reflect_bindings(&spirv);
    let blocks = |f: fn(&restir_pt::vk::ReflectedBinding) -> bool| {
        found
            .iter()
            .filter(restir)
            .filter(|b| f(b))
            .map(|b| b.block.clone())
            .collect::<BTreeSet<_>>()
    };
    (blocks(|b| b.reads), blocks(|b| b.writes))
}

fn names(bindings: &[RestirBinding]) -> BTreeSet<String> {
    bindings.iter().map(|b| b.block().to_string()).collect()
}

#[test]
fn each_pass_row_names_the_buffers_its_kernel_reads_and_writes() {
    for row in &PASSES {
        let default = [
            ("SHIFT_MODE", ShiftKind::Hybrid.glsl_name()),
            ("MIS_MODE", ReuseMis::GeneralizedBalance.glsl_name()),
        ];
        let (reads, writes) = accessed(row.kernel, &default);
        for (what, used, declared) in [("reads", reads, names(row.reads)), ("writes", writes, names(row.writes))] {
            let missing: Vec<&String> = used.difference(&declared).collect();
            let unused: Vec<&String> = declared.difference(&used).collect();
            assert!(
                missing.is_empty() && unused.is_empty(),
                "{:?} {what}: missing from its PASSES row {missing:?}; in the row but not in the SPIR-V {unused:?}",
                row.kernel
            );
        }
    }
}

#[test]
fn other_shifts_and_mis_stay_within_their_rows() {
    for kernel in [PassKernel::Temporal, PassKernel::Spatial] {
        let row = kernel.declaration();
        for (shift, mis) in [
            (ShiftKind::Reconnection, ReuseMis::Pairwise),
            (ShiftKind::Replay, ReuseMis::GeneralizedBalance),
        ] {
            let (reads, writes) = accessed(kernel, &[("SHIFT_MODE", shift.glsl_name()), ("MIS_MODE", mis.glsl_name())]);
            assert!(reads.is_subset(&names(row.reads)), "{kernel:?} {shift:?} {mis:?} reads {reads:?}");
            assert!(
                writes.is_subset(&names(row.writes)),
                "{kernel:?} {shift:?} {mis:?} writes {writes:?}"
            );
        }
    }
}
