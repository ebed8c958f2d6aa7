//! The Vulkan devices present, for a caller choosing one before opening a [`super::Context`].

use std::sync::Arc;

use anyhow::{anyhow, Context as _, Result};
use ash::vk;

use super::device_setup::{create_instance, device_name};
use super::ValidationLog;

/// One physical device as the loader reports it.
#[derive(Debug, Clone, PartialEq)]
pub struct DeviceSummary {
    /// Index in the loader's order: what `ContextOptions::device` takes as a number.
    pub index: usize,
    /// The driver's device name, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)" for lavapipe.
    pub name: String,
    /// Discrete, integrated, virtual or CPU (Vulkan's `VkPhysicalDeviceType`).
    pub device_type: vk::PhysicalDeviceType,
    /// Whether it has a compute queue (a [`super::Context`] needs one).
    pub compute: bool,
}

/// Every Vulkan device, in the loader's order, through a short-lived instance without
/// validation. Errors: no Vulkan loader or no instance (one line, as [`super::Context::new`]).
pub fn list_devices() -> Result<Vec<DeviceSummary>> {
    let entry =
        unsafe { ash::Entry::load() }.map_err(|e| anyhow!("cannot load the Vulkan loader (libvulkan.so.1): {e}; run tools/setup.sh"))?;
    let guard = create_instance(&entry, false, &Arc::<ValidationLog>::default())?;
    let instance = guard.instance();
    let devices = unsafe { instance.enumerate_physical_devices() }.context("enumerating Vulkan devices")?;
    Ok(devices
        .iter()
        .enumerate()
        .map(|(index, &d)| {
            let props = unsafe { instance.get_physical_device_properties(d) };
            let families = unsafe { instance.get_physical_device_queue_family_properties(d) };
            DeviceSummary {
                index,
                name: device_name(&props),
                device_type: props.device_type,
                compute: families.iter().any(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE)),
            }
        })
        .collect())
}
