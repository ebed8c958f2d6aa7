//! Storage and uniform buffers allocated through gpu-allocator and freed on drop.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::Context;
use crate::error::{allocation_error, vk_error, GpuError};

/// What a buffer is for, which sets its Vulkan usage flags and its memory location.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BufferUsage {
    /// Read or written by kernels; lives in device memory, reached by staging copies. Also
    /// bindable as a uniform buffer, which small read-only scene arrays use on CPU devices.
    Storage,
    /// Small parameter blocks rewritten from the host between frames; host-visible, bound as
    /// read-only storage buffers. Not uniform buffers: lavapipe inlines uniform-buffer and
    /// push-constant values that steer a kernel's control flow and compiles the kernel again
    /// whenever those values change (Mesa's lvp_execute.c, update_inline_shader_state), which
    /// made reuse passes recompile for seconds mid-run.
    Params,
    /// Staging memory the host maps for uploads and readbacks.
    Staging,
    /// A read-only scene array too large for one binding, which kernels reach by its device
    /// address (`Buffer::device_address`); bounded by maxMemoryAllocationSize instead of
    /// maxStorageBufferRange. Needs `DeviceInfo::buffer_device_address`.
    Addressed,
}

impl BufferUsage {
    /// The Vulkan usage flags and the memory the allocator places the buffer in.
    fn flags_and_location(self) -> (vk::BufferUsageFlags, MemoryLocation) {
        match self {
            BufferUsage::Storage => (
                vk::BufferUsageFlags::STORAGE_BUFFER
                    | vk::BufferUsageFlags::UNIFORM_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_SRC
                    | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            ),
            BufferUsage::Params => (vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::CpuToGpu),
            BufferUsage::Staging => (
                vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            ),
            BufferUsage::Addressed => (
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            ),
        }
    }
}

/// A Vulkan buffer with its gpu-allocator memory; both are freed on drop. It holds its
/// [`Context`], which therefore outlives it.
pub struct Buffer {
    /// The raw buffer handle, for descriptor writes and commands recorded by hand.
    pub handle: vk::Buffer,
    /// Size in bytes (at least 16).
    pub size: u64,
    allocation: Option<Allocation>,
    ctx: Arc<Context>,
}

impl Buffer {
    /// Creates an uninitialised buffer of `size` bytes (at least 16: Vulkan has no empty
    /// buffers) for `usage`; `name` labels the allocation and errors. Errors:
    /// [`GpuError::BindingTooLarge`] for a `Storage` buffer past maxStorageBufferRange,
    /// [`GpuError::AllocationTooLarge`] for an `Addressed` one past maxMemoryAllocationSize,
    /// [`GpuError::OutOfMemory`], [`GpuError::Allocation`] or [`GpuError::Vulkan`] when
    /// creating, allocating or binding fails.
    pub fn new(ctx: &Arc<Context>, name: &str, size: u64, usage: BufferUsage) -> Result<Self, GpuError> {
        // Zero-sized buffers are illegal in Vulkan; empty arrays still get a valid binding.
        let size = size.max(16);
        if usage == BufferUsage::Storage {
            ctx.check_binding_size(name, size)?;
        }
        if usage == BufferUsage::Addressed && size > ctx.info.max_allocation_bytes {
            return Err(GpuError::AllocationTooLarge {
                what: name.to_string(),
                needed: size,
                limit: ctx.info.max_allocation_bytes,
            });
        }
        let (flags, location) = usage.flags_and_location();
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(flags)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let handle = unsafe { ctx.device.create_buffer(&info, None) }.map_err(|e| match vk_error("creating a buffer")(e) {
            GpuError::OutOfMemory { .. } => GpuError::OutOfMemory {
                what: name.to_string(),
                bytes: size,
            },
            other => other,
        })?;
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(handle) };
        let allocation = ctx.allocator().allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear: true,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        });
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                unsafe { ctx.device.destroy_buffer(handle, None) };
                return Err(allocation_error(name, size, e));
            }
        };
        if let Err(e) = unsafe { ctx.device.bind_buffer_memory(handle, allocation.memory(), allocation.offset()) } {
            // Dropping the partly built buffer frees both halves.
            drop(Buffer {
                handle,
                size,
                allocation: Some(allocation),
                ctx: ctx.clone(),
            });
            return Err(vk_error("binding buffer memory")(e));
        }
        Ok(Self {
            handle,
            size,
            allocation: Some(allocation),
            ctx: ctx.clone(),
        })
    }

    /// Creates a storage buffer holding `data`.
    pub fn from_slice<T: bytemuck::Pod>(ctx: &Arc<Context>, name: &str, data: &[T]) -> Result<Self, GpuError> {
        Self::with_data(ctx, name, data, BufferUsage::Storage)
    }

    /// Creates a buffer of `usage` holding `data`.
    pub fn with_data<T: bytemuck::Pod>(ctx: &Arc<Context>, name: &str, data: &[T], usage: BufferUsage) -> Result<Self, GpuError> {
        let buffer = Self::new(ctx, name, std::mem::size_of_val(data) as u64, usage)?;
        buffer.write(data)?;
        Ok(buffer)
    }

    /// The address kernels reach an `Addressed` buffer by (GL_EXT_buffer_reference).
    pub fn device_address(&self) -> u64 {
        let info = vk::BufferDeviceAddressInfo::default().buffer(self.handle);
        unsafe { self.ctx.device.get_buffer_device_address(&info) }
    }

    fn mapped(&self) -> Option<&[u8]> {
        self.allocation.as_ref().and_then(|a| a.mapped_slice())
    }

    /// Writes `data` at offset 0, directly when mapped, through a staging copy otherwise.
    pub fn write<T: bytemuck::Pod>(&self, data: &[T]) -> Result<(), GpuError> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        assert!(
            bytes.len() as u64 <= self.size,
            "write of {} bytes into a {}-byte buffer",
            bytes.len(),
            self.size
        );
        if bytes.is_empty() {
            return Ok(());
        }
        if let Some(ptr) = self.allocation.as_ref().and_then(|a| a.mapped_ptr()) {
            unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), ptr.as_ptr() as *mut u8, bytes.len()) };
            return Ok(());
        }
        let staging = Buffer::new(&self.ctx, "staging upload", bytes.len() as u64, BufferUsage::Staging)?;
        staging.write(bytes)?;
        self.ctx.submit_and_wait(|cmd| unsafe {
            let region = [vk::BufferCopy::default().size(bytes.len() as u64)];
            self.ctx.device.cmd_copy_buffer(cmd, staging.handle, self.handle, &region);
        })
    }

    /// Reads the first `count` elements back to the host.
    pub fn read<T: bytemuck::Pod>(&self, count: usize) -> Result<Vec<T>, GpuError> {
        let bytes = (count * std::mem::size_of::<T>()) as u64;
        assert!(bytes <= self.size, "read of {bytes} bytes from a {}-byte buffer", self.size);
        if let Some(mapped) = self.mapped() {
            return Ok(bytemuck::pod_collect_to_vec(&mapped[..bytes as usize]));
        }
        let staging = Buffer::new(&self.ctx, "staging readback", bytes, BufferUsage::Staging)?;
        self.ctx.submit_and_wait(|cmd| unsafe {
            let region = [vk::BufferCopy::default().size(bytes)];
            self.ctx.device.cmd_copy_buffer(cmd, self.handle, staging.handle, &region);
        })?;
        staging.read(count)
    }

    /// Reads `count` elements from `offset` bytes into a host-visible buffer (a readback
    /// buffer after the copies into it completed).
    pub fn read_mapped<T: bytemuck::Pod>(&self, offset: u64, count: usize) -> Result<Vec<T>, GpuError> {
        let bytes = (count * std::mem::size_of::<T>()) as u64;
        assert!(
            offset + bytes <= self.size,
            "read of {bytes} bytes at {offset} from a {}-byte buffer",
            self.size
        );
        let mapped = self.mapped().ok_or(GpuError::Vulkan {
            during: "mapping a readback buffer",
            result: vk::Result::ERROR_MEMORY_MAP_FAILED,
        })?;
        Ok(bytemuck::pod_collect_to_vec(&mapped[offset as usize..(offset + bytes) as usize]))
    }

    /// Records a copy of this buffer's first `bytes` into `dst` at `dst_offset`.
    pub fn record_copy_to(&self, cmd: vk::CommandBuffer, dst: &Buffer, dst_offset: u64, bytes: u64) {
        let region = [vk::BufferCopy::default().dst_offset(dst_offset).size(bytes)];
        unsafe { self.ctx.device.cmd_copy_buffer(cmd, self.handle, dst.handle, &region) };
    }

    /// Records a fill of the whole buffer with one 32-bit pattern (e.g. NaN bits or zero).
    pub fn record_fill(&self, cmd: vk::CommandBuffer, pattern: u32) {
        unsafe { self.ctx.device.cmd_fill_buffer(cmd, self.handle, 0, vk::WHOLE_SIZE, pattern) };
    }

    /// Fills the whole buffer with one 32-bit pattern and waits.
    pub fn fill(&self, pattern: u32) -> Result<(), GpuError> {
        self.ctx.submit_and_wait(|cmd| self.record_fill(cmd, pattern))
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if self.ctx.is_hung() {
            // An unfinished submission may still read or write it (Context::is_hung).
            std::mem::forget(self.allocation.take());
            return;
        }
        unsafe { self.ctx.device.destroy_buffer(self.handle, None) };
        if let Some(allocation) = self.allocation.take() {
            // Freeing only fails for foreign allocations, which this type never holds.
            let _ = self.ctx.allocator().free(allocation);
        }
    }
}
