//! Vulkan instance, device and queue, the memory allocator and the validation messenger.
//! Field order is drop order: the allocator goes before the device, the device before the instance.

use std::ffi::{c_void, CStr, CString};
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex};

use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use crate::error::{vk_error, GpuError};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";
/// llvmpipe's LP_MAX_TGSI_LOOP_ITERATIONS: each loop's budget per shader invocation.
const LLVMPIPE_LOOP_LIMIT: u32 = 65535;
/// One submission must never block the caller forever; a healthy chunk finishes in well under this.
const FENCE_TIMEOUT_NS: u64 = 120_000_000_000;

/// How [`Context::new`] picks and sets up the device.
#[derive(Debug, Clone, Default)]
pub struct ContextOptions {
    /// Device name substring or index in enumeration order; `None` picks the best device.
    pub device: Option<String>,
    /// Enables VK_LAYER_KHRONOS_validation and counts every message it reports.
    pub validation: bool,
    /// Bytes past which a scene array is reached by buffer device address rather than bound (at most
    /// maxStorageBufferRange, the default). Tests lower it so that small scenes take the addressed path.
    pub scene_binding_limit: Option<u64>,
}

/// What the chosen device is and the limits the renderers plan around.
#[derive(Debug, Clone)]
pub struct DeviceInfo {
    /// The driver's device name (e.g. "llvmpipe (LLVM 15.0.7, 256 bits)").
    pub name: String,
    /// CPU (lavapipe), integrated or discrete: CPU devices get uniform-buffer scene bindings.
    pub device_type: vk::PhysicalDeviceType,
    /// maxStorageBufferRange: the most bytes one storage-buffer binding may cover.
    pub max_storage_buffer_range: u64,
    /// maxUniformBufferRange: the most bytes one uniform-buffer binding may cover.
    pub max_uniform_buffer_range: u64,
    /// Bytes one scene array may take in a binding (maxStorageBufferRange, or less where
    /// `ContextOptions::scene_binding_limit` says so); larger ones are addressed.
    pub scene_binding_limit: u64,
    /// Whether bufferDeviceAddress is enabled: scene arrays past `scene_binding_limit` are then
    /// reached by address, bounded by `max_allocation_bytes` instead.
    pub buffer_device_address: bool,
    /// The largest single allocation (maxMemoryAllocationSize; lavapipe: 2 GiB).
    pub max_allocation_bytes: u64,
    /// Bytes of shared memory a compute workgroup may use (Vulkan's floor: 16384).
    pub max_compute_shared_memory: u32,
    /// Nanoseconds per timestamp tick (timestampPeriod).
    pub timestamp_period_ns: f32,
    /// Whether the compute queue writes timestamps (timestampValidBits > 0, timestampComputeAndGraphics).
    pub timestamps_supported: bool,
    /// Iterations each loop of one shader invocation may run in total before the driver silently
    /// leaves it (llvmpipe: 65535); `None` where no such cap is known.
    pub loop_iteration_limit: Option<u32>,
}

/// Collects the validation layer's output so that tests can fail on it. It may outlive the
/// context: leaks are reported while the device is destroyed.
#[derive(Default)]
pub struct ValidationLog {
    errors: Mutex<Vec<String>>,
}

impl ValidationLog {
    /// The messages counted so far (errors and warnings), in order.
    pub fn messages(&self) -> Vec<String> {
        self.errors.lock().map(|e| e.clone()).unwrap_or_default()
    }
}

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

/// One Vulkan device with its compute queue, memory allocator and (optionally) validation messenger:
/// what every buffer, kernel and renderer is made on, shared as `Arc<Context>` (each holds a clone).
pub struct Context {
    allocator: ManuallyDrop<Mutex<Allocator>>,
    command_pool: vk::CommandPool,
    /// The compute queue all submissions use; raw handles, for code recording its own work.
    pub queue: vk::Queue,
    /// The compute queue's family index.
    pub queue_family: u32,
    /// The logical device (ash's loaded function table).
    pub device: ash::Device,
    /// The physical device chosen.
    pub physical_device: vk::PhysicalDevice,
    /// The device's name and limits.
    pub info: DeviceInfo,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    validation_log: Arc<ValidationLog>,
    /// Compute pipelines created on this device (see `pipelines_created`).
    pipelines: std::sync::atomic::AtomicU64,
    /// The raw instance handle.
    pub instance: ash::Instance,
    _entry: ash::Entry,
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

impl Context {
    /// Loads Vulkan, picks a device (`options.device`, else the first discrete, integrated,
    /// virtual then CPU device) and creates the queue, allocator and messenger.
    ///
    /// # Errors
    /// One line: no Vulkan loader, validation asked for without the layer installed, no device, no
    /// device matching `options.device` (the available ones listed), or a failed Vulkan call ([`GpuError`]).
    pub fn new(options: &ContextOptions) -> Result<Self> {
        let entry = unsafe { ash::Entry::load() }
            .map_err(|e| anyhow!("cannot load the Vulkan loader (libvulkan.so.1): {e}; run tools/setup.sh"))?;
        let validation = options.validation && {
            let layers = unsafe { entry.enumerate_instance_layer_properties() }.unwrap_or_default();
            let found = layers.iter().any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER));
            if !found {
                bail!("validation requested but VK_LAYER_KHRONOS_validation is not installed (package vulkan-validationlayers)");
            }
            true
        };
        let validation_log = Arc::<ValidationLog>::default();
        // From here on a failure must destroy the instance; the guard does that until ownership moves.
        let guard = create_instance(&entry, validation, &validation_log)?;
        let (physical_device, queue_family, mut info) = pick_device(guard.instance(), options.device.as_deref())?;
        info.scene_binding_limit = options
            .scene_binding_limit
            .map_or(info.max_storage_buffer_range, |l| l.min(info.max_storage_buffer_range));
        let (device, queue, command_pool) = create_device(guard.instance(), physical_device, queue_family, info.buffer_device_address)?;
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: guard.instance().clone(),
            device: device.clone(),
            physical_device,
            debug_settings: Default::default(),
            buffer_device_address: info.buffer_device_address,
            allocation_sizes: Default::default(),
        });
        let allocator = match allocator {
            Ok(a) => a,
            Err(e) => {
                unsafe {
                    device.destroy_command_pool(command_pool, None);
                    device.destroy_device(None);
                }
                bail!("cannot create the GPU memory allocator: {e}");
            }
        };
        let (instance, debug) = guard.release();
        Ok(Self {
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            command_pool,
            queue,
            queue_family,
            device,
            physical_device,
            info,
            debug,
            validation_log,
            pipelines: std::sync::atomic::AtomicU64::new(0),
            instance,
            _entry: entry,
        })
    }

    /// The device's memory allocator, locked (a poisoned lock is recovered: the allocator
    /// holds no invariant a panic elsewhere could break).
    pub fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Every validation message (errors and warnings) reported so far.
    pub fn validation_messages(&self) -> Vec<String> {
        self.validation_log.messages()
    }

    /// The log itself, to read after the context is dropped (leaked objects are reported then).
    pub fn validation_log(&self) -> Arc<ValidationLog> {
        self.validation_log.clone()
    }

    /// Fails if the validation layer has reported anything; tests call this at their end.
    pub fn check_validation(&self) -> Result<(), GpuError> {
        let messages = self.validation_messages();
        match messages.first() {
            None => Ok(()),
            Some(first) => Err(GpuError::Validation {
                count: messages.len() as u32,
                first: first.clone(),
            }),
        }
    }

    /// The compute pipelines created on this device so far: a renderer creates all of its
    /// own at start-up, so a run's count stays put across its frames.
    pub fn pipelines_created(&self) -> u64 {
        self.pipelines.load(std::sync::atomic::Ordering::Relaxed)
    }

    pub(super) fn count_pipeline(&self) {
        self.pipelines.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// The most bytes one scene array may take: a buffer reached by device address where the
    /// device has bufferDeviceAddress, else one storage binding.
    pub fn scene_array_limit(&self) -> crate::scene::ArrayLimit {
        if self.info.buffer_device_address {
            crate::scene::ArrayLimit {
                bytes: self.info.max_allocation_bytes,
                name: "maxMemoryAllocationSize",
            }
        } else {
            crate::scene::ArrayLimit {
                bytes: self.info.max_storage_buffer_range,
                name: "maxStorageBufferRange",
            }
        }
    }

    /// Checks a storage binding against maxStorageBufferRange before anything is allocated.
    pub fn check_binding_size(&self, what: &str, bytes: u64) -> Result<(), GpuError> {
        if bytes > self.info.max_storage_buffer_range {
            return Err(GpuError::BindingTooLarge {
                what: what.to_string(),
                needed: bytes,
                limit: self.info.max_storage_buffer_range,
            });
        }
        Ok(())
    }

    /// Records commands with `record`, submits them with a fence and waits for completion.
    pub fn submit_and_wait(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<(), GpuError> {
        let alloc_info = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = unsafe { self.device.allocate_command_buffers(&alloc_info) }.map_err(vk_error("allocating a command buffer"))?[0];
        let result = (|| {
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            unsafe { self.device.begin_command_buffer(cmd, &begin) }.map_err(vk_error("beginning a command buffer"))?;
            record(cmd);
            unsafe { self.device.end_command_buffer(cmd) }.map_err(vk_error("ending a command buffer"))?;
            let fence = unsafe { self.device.create_fence(&vk::FenceCreateInfo::default(), None) }.map_err(vk_error("creating a fence"))?;
            let cmds = [cmd];
            let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
            let submitted = unsafe { self.device.queue_submit(self.queue, &submit, fence) }.map_err(vk_error("submitting GPU work"));
            let waited = submitted.and_then(|_| match unsafe { self.device.wait_for_fences(&[fence], true, FENCE_TIMEOUT_NS) } {
                Err(vk::Result::TIMEOUT) => Err(GpuError::Timeout {
                    seconds: FENCE_TIMEOUT_NS / 1_000_000_000,
                }),
                other => other.map_err(vk_error("waiting for GPU work")),
            });
            unsafe { self.device.destroy_fence(fence, None) };
            waited
        })();
        unsafe { self.device.free_command_buffers(self.command_pool, &[cmd]) };
        result
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        unsafe {
            // A lost device may refuse to idle; teardown proceeds regardless.
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// Owns the instance (and messenger) while the device is being created.
pub(super) struct InstanceGuard {
    instance: Option<ash::Instance>,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
}

type DebugMessenger = Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>;

impl InstanceGuard {
    pub(super) fn instance(&self) -> &ash::Instance {
        self.instance.as_ref().expect("instance is present until released")
    }
    fn release(mut self) -> (ash::Instance, DebugMessenger) {
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
fn create_device(
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

fn pick_device(instance: &ash::Instance, wanted: Option<&str>) -> Result<(vk::PhysicalDevice, u32, DeviceInfo)> {
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
