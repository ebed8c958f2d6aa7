//! The storage of a ReSTIR PT render besides the scene: parameter blocks, surfaces, reservoir
//! layers, the accumulated image and the counters, and the binding table that names each.

use std::sync::Arc;

use anyhow::Result;

use super::super::reservoir_layers::ReservoirLayers;
use super::super::restir_passes::PassDeclaration;
use super::super::SceneGpu;
use crate::gpu_types::{FrameParams, RestirStats, ReuseParams, Surface};
use crate::shader_interface::{RestirBinding, SURFACE_SLOTS};
use crate::vk::{BindingFamilyExt, BoundBuffer, Buffer, BufferUsage, Context};

pub(super) struct RestirBuffers {
    /// `FrameParams`, host-written before each frame.
    pub params: Buffer,
    /// `ReuseParams` with the frame's pass table, host-written before each frame.
    pub reuse: Buffer,
    /// Each pixel's surface, this frame's and the previous one's, shared by its reservoirs.
    pub surfaces: [Buffer; SURFACE_SLOTS],
    pub layers: ReservoirLayers,
    pub accum: Buffer,
    pub accum_sq: Buffer,
    pub stats: Buffer,
}

impl RestirBuffers {
    /// For `pixels` pixels of `reservoirs` reservoirs each; fails before allocating when a
    /// per-pixel array exceeds the device's binding range.
    pub fn new(ctx: &Arc<Context>, pixels: u64, reservoirs: u32) -> Result<Self> {
        ctx.check_binding_size("the accumulation image", pixels * 16)?;
        let surface_bytes = pixels * std::mem::size_of::<Surface>() as u64;
        ctx.check_binding_size("the surfaces", surface_bytes)?;
        let layers = ReservoirLayers::new(ctx, pixels, reservoirs)?;
        let storage = |name: &str, bytes: u64| Buffer::new(ctx, name, bytes, BufferUsage::Storage);
        let params = |name: &str, bytes: usize| Buffer::new(ctx, name, bytes as u64, BufferUsage::Params);
        let buffers = Self {
            params: params("frame parameters", std::mem::size_of::<FrameParams>())?,
            reuse: params("reuse parameters", std::mem::size_of::<ReuseParams>())?,
            surfaces: [storage("surfaces 0", surface_bytes)?, storage("surfaces 1", surface_bytes)?],
            layers,
            accum: storage("accumulation", pixels * 16)?,
            accum_sq: storage("accumulation of squares", pixels * 16)?,
            stats: storage("ReSTIR statistics", std::mem::size_of::<RestirStats>() as u64)?,
        };
        buffers.accum.fill(0)?;
        buffers.accum_sq.fill(0)?;
        Ok(buffers)
    }

    /// The bindings of `pass`'s kernel: the scene's, then those of these buffers its row reads
    /// or writes.
    pub fn pass_table<'a>(&'a self, scene: &'a SceneGpu, pass: &PassDeclaration) -> Vec<BoundBuffer<'a>> {
        let ours = pass.bindings();
        let restir = |b: &BoundBuffer| RestirBinding::ALL.iter().any(|r| r.block() == b.slot.block);
        let mut table = self.binding_table(scene);
        table.retain(|b| !restir(b) || ours.iter().any(|r| r.block() == b.slot.block));
        table
    }

    /// Every binding of the ReSTIR kernels, by name: the scene's, then these buffers.
    fn binding_table<'a>(&'a self, scene: &'a SceneGpu) -> Vec<BoundBuffer<'a>> {
        use RestirBinding as B;
        let layers = &self.layers;
        let mut table = scene.buffers(&self.params);
        table.push(B::ReuseParams.to(&self.reuse));
        for (slot, surfaces) in self.surfaces.iter().enumerate() {
            table.push(B::surface_slot(slot).to(surfaces));
        }
        for (slot, (heads, tails)) in layers.heads.iter().zip(&layers.tails).enumerate() {
            let (head_binding, tail_binding) = B::reservoir_slot(slot);
            table.extend([head_binding.to(heads), tail_binding.to(tails)]);
        }
        table.extend([
            B::Direct.to(&layers.direct),
            B::Accum.to(&self.accum),
            B::AccumSq.to(&self.accum_sq),
            B::RestirStats.to(&self.stats),
            B::Expectation.to(&layers.expectation),
        ]);
        table
    }
}
