//! Typed errors for failures a caller may want to tell apart (device loss, out-of-memory, limits).
//! Everything else travels as `anyhow::Error` with context added at the boundary.

use ash::vk;

/// A GPU failure; `during` and `what` name the operation or buffer, sizes are in bytes.
/// Reach it from an `anyhow::Error` with `downcast_ref::<GpuError>()`.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// VK_ERROR_DEVICE_LOST: the device and everything made on it are unusable.
    #[error("the Vulkan device was lost (VK_ERROR_DEVICE_LOST) during {during}; the GPU work was abandoned")]
    DeviceLost {
        /// The operation that was running, e.g. "waiting for GPU work".
        during: &'static str,
    },
    /// A submission's fence did not signal within `seconds`.
    #[error("a GPU submission did not finish within {seconds} s; the device is considered hung")]
    Timeout {
        /// The wait that ran out, in seconds.
        seconds: u64,
    },
    /// Device or host memory ran out (`bytes` is 0 when Vulkan did not say how much).
    #[error("out of GPU memory while allocating {what} ({bytes} bytes)")]
    OutOfMemory {
        /// The buffer or operation being allocated.
        what: String,
        /// The requested size in bytes; 0 when unknown.
        bytes: u64,
    },
    /// The allocator refused for another reason than memory (no compatible memory type, a
    /// failed map, an internal error): gpu-allocator's `AllocationError` other than `OutOfMemory`.
    #[error("the GPU memory allocator could not allocate {what} ({bytes} bytes): {reason}")]
    Allocation {
        /// The buffer being allocated.
        what: String,
        /// The requested size in bytes.
        bytes: u64,
        /// gpu-allocator's message.
        reason: String,
    },
    /// A buffer larger than one storage-buffer binding may be.
    #[error("{what} needs {needed} bytes but the device allows at most {limit} bytes per storage-buffer binding (maxStorageBufferRange)")]
    BindingTooLarge {
        /// The buffer that does not fit.
        what: String,
        /// Its size in bytes.
        needed: u64,
        /// The device's maxStorageBufferRange in bytes.
        limit: u64,
    },
    /// A buffer larger than one allocation may be.
    #[error("{what} needs {needed} bytes but the device allows at most {limit} bytes per allocation (maxMemoryAllocationSize)")]
    AllocationTooLarge {
        /// The buffer that does not fit.
        what: String,
        /// Its size in bytes.
        needed: u64,
        /// The device's maxMemoryAllocationSize in bytes.
        limit: u64,
    },
    /// Any other failed Vulkan call, with its result code.
    #[error("Vulkan call failed during {during}: {result:?}")]
    Vulkan {
        /// The operation that failed.
        during: &'static str,
        /// The call's result code.
        result: vk::Result,
    },
    /// Kernels count their loop iterations against the driver's budget (`limit` per loop and
    /// invocation); `groups` subgroups ran out, having counted about `counted`.
    #[error("{groups} subgroup(s) of a dispatch ran out of the driver's loop budget ({limit} iterations per loop and shader invocation; about {counted} counted), which truncates paths: the render was stopped rather than written wrong")]
    LoopLimit {
        /// The driver's loop iteration budget per loop and invocation (0 if unknown).
        limit: u32,
        /// The most iterations a subgroup counted in one guarded loop.
        counted: u32,
        /// Subgroups of the dispatch whose loop was cut short.
        groups: u32,
    },
    /// The validation layer (`ContextOptions::validation`) reported `count` messages.
    #[error("{count} Vulkan validation error(s) were reported; first: {first}")]
    Validation {
        /// Error and warning messages reported since the context was made.
        count: u32,
        /// The first message's text.
        first: String,
    },
}

/// Maps a raw Vulkan result to a typed error, keeping device loss and OOM distinguishable.
pub fn vk_error(during: &'static str) -> impl FnOnce(vk::Result) -> GpuError {
    move |result| match result {
        vk::Result::ERROR_DEVICE_LOST => GpuError::DeviceLost { during },
        vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY => GpuError::OutOfMemory {
            what: during.to_string(),
            bytes: 0,
        },
        result => GpuError::Vulkan { during, result },
    }
}

/// Maps gpu-allocator's error for an allocation named `what` of `bytes`: out-of-memory stays
/// out-of-memory; every other kind (no compatible memory type, a failed map, invalid
/// descriptions, internal errors) is reported as what it is.
pub fn allocation_error(what: &str, bytes: u64, error: gpu_allocator::AllocationError) -> GpuError {
    match error {
        gpu_allocator::AllocationError::OutOfMemory => GpuError::OutOfMemory {
            what: what.to_string(),
            bytes,
        },
        other => GpuError::Allocation {
            what: what.to_string(),
            bytes,
            reason: other.to_string(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpu_allocator::AllocationError;

    #[test]
    fn allocation_errors_other_than_out_of_memory_keep_their_kind() {
        let oom = allocation_error("accumulation", 64, AllocationError::OutOfMemory);
        assert!(matches!(oom, GpuError::OutOfMemory { bytes: 64, .. }), "{oom}");
        for (error, needle) in [
            (AllocationError::NoCompatibleMemoryTypeFound, "No compatible memory type"),
            (AllocationError::FailedToMap("denied".into()), "Failed to map memory: denied"),
            (AllocationError::Internal("broken".into()), "Internal error: broken"),
            (AllocationError::InvalidAllocationCreateDesc, "Invalid AllocationCreateDesc"),
        ] {
            let mapped = allocation_error("accumulation", 64, error);
            let text = mapped.to_string();
            assert!(matches!(mapped, GpuError::Allocation { .. }), "{text}");
            assert!(
                text.contains("accumulation") && text.contains(needle) && !text.contains("out of"),
                "{text}"
            );
        }
    }
}
