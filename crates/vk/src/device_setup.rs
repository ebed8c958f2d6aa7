//! Instance, device and queue creation for [`Context::new`](super::Context::new): the
//! validation messenger, the device choice and the limits read from it.

use std::ffi::{c_void, CStr, CString};
use std::sync::Arc;

use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;

use super::context::{DeviceInfo, ValidationLog, LLVMPIPE_LOOP_LIMIT, VALIDATION_LAYER};
use crate::error::vk_error;

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    let message = if data.is_null() || (*data).p_message.is_null() {
        "<no message>".to_string()
    } else {
        CStr::from_ptr((*data).p_message).to_string_lossy().into_owned()
    };
    let counts = severity.intersects(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING);
    if counts && !user.is_null() {
        eprintln!("vulkan validation: {message}");
        let log = &*(user as *const ValidationLog);
        if let Ok(mut errors) = log.errors.lock() {
            errors.push(message);
        }
    }
    vk::FALSE
}

pub(super) fn device_name(props: &vk::PhysicalDeviceProperties) -> String {
    props
        .device_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn type_rank(t: vk::PhysicalDeviceType) -> u32 {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

/// Owns the instance (and messenger) while the device is being created.
pub(super) struct InstanceGuard {
    instance: Option<ash::Instance>,
    debug: DebugMessenger,
}

pub(super) type DebugMessenger = Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>;

impl InstanceGuard {
    pub(super) fn instance(&self) -> &ash::Instance {
        self.instance.as_ref().expect("instance is present until released")
    }
    pub(super) fn release(mut self) -> (ash::Instance, DebugMessenger) {
        (self.instance.take().expect("released once"), self.debug.take())
    }
}

impl Drop for InstanceGuard {
    fn drop(&mut self) {
        if let Some(instance) = self.instance.take() {
            unsafe {
                if let Some((loader, messenger)) = self.debug.take() {
                    loader.destroy_debug_utils_messenger(messenger, None);
                }
                instance.destroy_instance(None);
            }
        }
    }
}

/// The instance, with the validation layer and a messenger that reports into `log` when
/// `validation` is set; owned by the returned guard.
pub(super) fn create_instance(entry: &ash::Entry, validation: bool, log: &Arc<ValidationLog>) -> Result<InstanceGuard> {
    let app_name = CString::new("restir-pt").expect("static name has no NUL");
    let app_info = vk::ApplicationInfo::default()
        .application_name(&app_name)
        .engine_name(&app_name)
        .api_version(vk::API_VERSION_1_2);
    let layer_ptrs = if validation { vec![VALIDATION_LAYER.as_ptr()] } else { vec![] };
    let ext_ptrs = if validation {
        vec![ash::ext::debug_utils::NAME.as_ptr()]
    } else {
        vec![]
    };
    let log_ptr = &**log as *const ValidationLog as *mut c_void;
    let messenger_info = || {
        vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING)
            .message_type(vk::DebugUtilsMessageTypeFlagsEXT::GENERAL | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION)
            .pfn_user_callback(Some(debug_callback))
            .user_data(log_ptr)
    };
    let mut instance_messenger = messenger_info();
    let mut instance_info = vk::InstanceCreateInfo::default()
        .application_info(&app_info)
        .enabled_layer_names(&layer_ptrs)
        .enabled_extension_names(&ext_ptrs);
    if validation {
        // Chained so that messages from instance creation itself are caught too.
        instance_info = instance_info.push_next(&mut instance_messenger);
    }
    let instance = unsafe { entry.create_instance(&instance_info, None) }
        .map_err(|e| anyhow!("cannot create a Vulkan instance: {e:?} (is a Vulkan driver such as mesa-vulkan-drivers installed?)"))?;
    let mut guard = InstanceGuard {
        instance: Some(instance),
        debug: None,
    };
    if validation {
        let loader = ash::ext::debug_utils::Instance::new(entry, guard.instance());
        let messenger =
            unsafe { loader.create_debug_utils_messenger(&messenger_info(), None) }.map_err(vk_error("creating the debug messenger"))?;
        guard.debug = Some((loader, messenger));
    }
    Ok(guard)
}

/// The logical device with one queue of `queue_family` (and buffer device addresses when
/// `device_address`), that queue and a command pool on it.
pub(super) fn create_device(
    instance: &ash::Instance,
    physical_device: vk::PhysicalDevice,
    queue_family: u32,
    device_address: bool,
) -> Result<(ash::Device, vk::Queue, vk::CommandPool)> {
    let priorities = [1.0f32];
    let queue_infos = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(queue_family)
        .queue_priorities(&priorities)];
    let mut address_features = vk::PhysicalDeviceBufferDeviceAddressFeatures::default().buffer_device_address(true);
    let mut device_info = vk::DeviceCreateInfo::default().queue_create_infos(&queue_infos);
    if device_address {
        device_info = device_info.push_next(&mut address_features);
    }
    let device = unsafe { instance.create_device(physical_device, &device_info, None) }.map_err(vk_error("creating the logical device"))?;
    let queue = unsafe { device.get_device_queue(queue_family, 0) };
    let pool_info = vk::CommandPoolCreateInfo::default()
        .queue_family_index(queue_family)
        .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
    match unsafe { device.create_command_pool(&pool_info, None) } {
        Ok(pool) => Ok((device, queue, pool)),
        Err(e) => {
            unsafe { device.destroy_device(None) };
            Err(vk_error("creating the command pool")(e).into())
        }
    }
}

/// Lists every device as "index: name (type)" for error messages and `--device` help.
fn describe_devices(instance: &ash::Instance, devices: &[vk::PhysicalDevice]) -> String {
    devices
        .iter()
        .enumerate()
        .map(|(i, &d)| {
            let props = unsafe { instance.get_physical_device_properties(d) };
            format!("{i}: {} ({:?})", device_name(&props), props.device_type)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

pub(super) fn pick_device(instance: &ash::Instance, wanted: Option<&str>) -> Result<(vk::PhysicalDevice, u32, DeviceInfo)> {
    let devices = unsafe { instance.enumerate_physical_devices() }.context("enumerating Vulkan devices")?;
    if devices.is_empty() {
        bail!("no Vulkan device found; install mesa-vulkan-drivers (lavapipe) with tools/setup.sh");
    }
    let compute_family = |d: vk::PhysicalDevice| {
        let families = unsafe { instance.get_physical_device_queue_family_properties(d) };
        families
            .iter()
            .position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE))
            .map(|i| (i as u32, families[i].timestamp_valid_bits))
    };
    let chosen = match wanted {
        Some(w) => {
            let by_index = w.parse::<usize>().ok().and_then(|i| devices.get(i).copied());
            let by_name = || {
                devices.iter().copied().find(|&d| {
                    let props = unsafe { instance.get_physical_device_properties(d) };
                    device_name(&props).to_lowercase().contains(&w.to_lowercase())
                })
            };
            by_index.or_else(by_name).ok_or_else(|| {
                anyhow!(
                    "no Vulkan device matches --device {w:?}; available: {}",
                    describe_devices(instance, &devices)
                )
            })?
        }
        None => devices
            .iter()
            .copied()
            .filter(|&d| compute_family(d).is_some())
            .min_by_key(|&d| type_rank(unsafe { instance.get_physical_device_properties(d) }.device_type))
            .ok_or_else(|| {
                anyhow!(
                    "no Vulkan device has a compute queue; available: {}",
                    describe_devices(instance, &devices)
                )
            })?,
    };
    let (family, timestamp_bits) = compute_family(chosen).ok_or_else(|| {
        anyhow!(
            "the chosen Vulkan device has no compute queue; available: {}",
            describe_devices(instance, &devices)
        )
    })?;
    let props = unsafe { instance.get_physical_device_properties(chosen) };
    let mut address_features = vk::PhysicalDeviceBufferDeviceAddressFeatures::default();
    let mut features = vk::PhysicalDeviceFeatures2::default().push_next(&mut address_features);
    unsafe { instance.get_physical_device_features2(chosen, &mut features) };
    let mut maintenance3 = vk::PhysicalDeviceMaintenance3Properties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut maintenance3);
    unsafe { instance.get_physical_device_properties2(chosen, &mut props2) };
    let info = DeviceInfo {
        name: device_name(&props),
        device_type: props.device_type,
        max_storage_buffer_range: props.limits.max_storage_buffer_range as u64,
        max_uniform_buffer_range: props.limits.max_uniform_buffer_range as u64,
        scene_binding_limit: props.limits.max_storage_buffer_range as u64,
        buffer_device_address: address_features.buffer_device_address == vk::TRUE,
        max_allocation_bytes: maintenance3.max_memory_allocation_size,
        max_compute_shared_memory: props.limits.max_compute_shared_memory_size,
        timestamp_period_ns: props.limits.timestamp_period,
        timestamps_supported: timestamp_bits > 0 && props.limits.timestamp_compute_and_graphics == vk::TRUE,
        loop_iteration_limit: device_name(&props).contains("llvmpipe").then_some(LLVMPIPE_LOOP_LIMIT),
    };
    Ok((chosen, family, info))
}
